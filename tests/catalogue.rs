//! Issue 38 item 2 — `stancelib list LIB`: the catalogue of a library (characters, run
//! cycles, recorded jumps), checked against the tables and against `query run` on the
//! fixture library.

use std::collections::BTreeMap;

use stancelib::library::codec::table::Table;
use stancelib::library::readers::read::{open_library, read_stances};
use stancelib::pipeline::commands::catalogue::catalogue;
use stancelib::query::jump::recorded_jump;

use crate::util::{first_stance_ids, fixture_library, ok, refused, s, string_at};

/// `list LIB --json`, parsed.
fn list_json(lib: &str) -> serde_json::Value {
    let out = ok(&["list", lib, "--json"]);
    serde_json::from_str(out.trim()).expect("one JSON object")
}

fn strings(v: &serde_json::Value) -> Vec<String> {
    serde_json::from_value(v.clone()).unwrap()
}

/// The fixture library's clips by character, read here from `clips.parquet`.
fn clips_by_character(lib: &std::path::Path) -> BTreeMap<String, Vec<String>> {
    let t = Table::open(&lib.join("clips.parquet")).unwrap();
    let mut m: BTreeMap<String, Vec<String>> = BTreeMap::new();
    for i in 0..t.height() {
        if let (Some(ch), Some(clip)) = (string_at(&t, "character_id", i), string_at(&t, "clip", i))
        {
            m.entry(ch).or_default().push(clip);
        }
    }
    m.values_mut().for_each(|v| v.sort());
    m
}

// See: issue 38 item 2 — characters are opaque `sk-…` ids and nothing lists the clips.
#[test]
fn list_names_every_character_with_its_clips() {
    let lib = fixture_library();
    let v = list_json(&s(lib));
    let expected = clips_by_character(lib);
    assert!(!expected.is_empty());
    let chars = v["characters"].as_array().unwrap();
    let got: BTreeMap<String, Vec<String>> = chars
        .iter()
        .map(|c| {
            let id = c["character_id"].as_str().unwrap().to_string();
            assert_eq!(c["n_clips"], c["clips"].as_array().unwrap().len());
            (id, strings(&c["clips"]))
        })
        .collect();
    assert_eq!(got, expected);
    // Every stance counted once, under its character.
    let stances = read_stances(&lib.join("stances.parquet")).unwrap();
    let n: u64 = chars.iter().map(|c| c["n_stances"].as_u64().unwrap()).sum();
    assert_eq!(n, stances.len() as u64);
    // Built without a body file: the default mass; legs are those `clips.parquet` records.
    let legs = open_library(lib).unwrap().clips;
    for c in chars {
        let mass = c["mass_kg"].as_f64().unwrap();
        let want = stancelib::ingest::DEFAULT_MASS_KG;
        assert!((mass - want).abs() < 1e-9, "mass {mass}");
        let leg = c["leg_length_m"].as_f64().unwrap();
        let first = c["clips"][0].as_str().unwrap();
        assert!(
            (leg - legs[first].leg_m.unwrap()).abs() < 1e-12,
            "leg {leg}"
        );
    }
    // The text names each character and its first clip.
    let text = ok(&["list", &s(lib)]);
    for (id, clips) in &expected {
        let line = text
            .lines()
            .find(|l| l.contains(id.as_str()))
            .unwrap_or_else(|| panic!("no {id} in\n{text}"));
        assert!(line.contains(&clips[0]), "{line}");
        assert!(line.contains(&format!("{} clip(s)", clips.len())), "{line}");
    }
}

// See: issue 38 item 2 — the run cycles are those `query run` answers, at its speeds.
#[test]
fn list_run_cycles_are_query_runs_cycles_with_its_speeds_and_verdicts() {
    let lib = fixture_library();
    let v = list_json(&s(lib));
    let cycles = v["run_cycles"].as_array().unwrap();
    assert!(!cycles.is_empty(), "the fixtures hold run clips");
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("x.parquet");
    ok(&[
        "query",
        "run",
        "--lib",
        &s(lib),
        "--speed",
        "3",
        "--out",
        &s(&out),
    ]);
    let t = Table::open(&out).unwrap();
    let query: BTreeMap<String, f64> = first_stance_ids(&t)
        .into_iter()
        .zip(t.f64s("v_orig_mps").unwrap())
        .collect();
    let listed: BTreeMap<String, f64> = cycles
        .iter()
        .filter(|c| !c["time_scaled"].as_bool().unwrap())
        .map(|c| {
            let id = c["stance_ids"][0].as_str().unwrap().to_string();
            (id, c["v_orig_mps"].as_f64().unwrap())
        })
        .collect();
    assert_eq!(
        listed.keys().collect::<Vec<_>>(),
        query.keys().collect::<Vec<_>>()
    );
    for (id, v) in &listed {
        // The same Σx/ΣT of the same floats: equal to the last bits.
        assert_eq!(*v, query[id], "{id}");
    }
    // Feasible at its own speed: what `query run --speed v_orig` says of that cycle.
    for c in cycles {
        let (id, v) = (
            c["stance_ids"][0].as_str().unwrap(),
            c["v_orig_mps"].as_f64().unwrap(),
        );
        let out = dir
            .path()
            .join(format!("own-{}.parquet", id.replace(':', "_")));
        ok(&[
            "query",
            "run",
            "--lib",
            &s(lib),
            "--speed",
            &v.to_string(),
            "--out",
            &s(&out),
        ]);
        let t = Table::open(&out).unwrap();
        let row = first_stance_ids(&t).iter().position(|x| x == id).unwrap();
        let feasible = t.bools("feasible").unwrap()[row];
        assert_eq!(c["feasible_at_own_speed"].as_bool(), Some(feasible), "{id}");
    }
}

// See: issue 38 item 2 — a clip whose time base is wrong is listed, marked, not judged.
#[test]
fn list_marks_cycles_of_a_clip_with_a_wrong_time_base() {
    let lib = fixture_library();
    let mut opened = open_library(lib).unwrap();
    let character_of: BTreeMap<String, String> = clips_by_character(lib)
        .into_iter()
        .flat_map(|(ch, clips)| clips.into_iter().map(move |c| (c, ch.clone())))
        .collect();
    let before = catalogue(&opened, &character_of);
    let clip = before.run_cycles[0].clip.clone();
    assert!(before.run_cycles.iter().all(|c| !c.time_scaled));
    // s_eff = 2: twice the recorded time base, far outside the accepted range.
    opened.clips.get_mut(&clip).unwrap().s_eff = Some(2.0);
    let after = catalogue(&opened, &character_of);
    assert_eq!(after.run_cycles.len(), before.run_cycles.len());
    for c in &after.run_cycles {
        assert_eq!(c.time_scaled, c.clip == clip, "{:?}", c.stance_ids);
        assert_eq!(c.feasible_at_own_speed.is_none(), c.clip == clip);
    }
}

// See: issue 38 item 2 — the recorded jumps: liftoff → landing pairs of one clip.
#[test]
fn list_jumps_are_the_recorded_liftoff_landing_pairs() {
    let lib = fixture_library();
    let v = list_json(&s(lib));
    // The pairs found here from the table's boundary columns, not by the tool's rule.
    let t = Table::open(&lib.join("stances.parquet")).unwrap();
    let (ids, clips) = (t.strings("stance_id").unwrap(), t.strings("clip").unwrap());
    let (start, end) = (
        t.strings("boundary_start").unwrap(),
        t.strings("boundary_end").unwrap(),
    );
    let grounded = |b: &str| b == "rest" || b == "clip_edge";
    let pairs: Vec<(String, String)> = (1..ids.len())
        .filter(|&i| clips[i - 1] == clips[i])
        .filter(|&i| grounded(&start[i - 1]) && end[i - 1] == "flight")
        .filter(|&i| start[i] == "flight" && grounded(&end[i]))
        .map(|i| (ids[i - 1].clone(), ids[i].clone()))
        .collect();
    assert!(!pairs.is_empty(), "the fixtures hold jump clips");
    let jumps = v["jumps"].as_array().unwrap();
    let listed: Vec<(String, String)> = jumps
        .iter()
        .map(|j| {
            let f = |k: &str| j[k].as_str().unwrap().to_string();
            (f("liftoff"), f("landing"))
        })
        .collect();
    assert_eq!(listed, pairs);
    let stances = read_stances(&lib.join("stances.parquet")).unwrap();
    let by_id = |id: &str| stances.iter().find(|s| s.stance_id == id).unwrap();
    for j in jumps {
        let (a, b) = (
            by_id(j["liftoff"].as_str().unwrap()),
            by_id(j["landing"].as_str().unwrap()),
        );
        let (h, d) = recorded_jump(a, b);
        assert_eq!(j["height_m"].as_f64().unwrap(), h);
        assert_eq!(j["distance_m"].as_f64().unwrap(), d);
        // A jump, not a step: the generated jumps' apex lies 1.12 m above the contact.
        assert!(h > 0.5, "height {h}");
    }
}

/// `N` of a text header line `<title> (N…`.
fn header_count(text: &str, title: &str) -> usize {
    let line = text
        .lines()
        .find(|l| l.starts_with(&format!("{title} (")))
        .unwrap_or_else(|| panic!("no {title} header in\n{text}"));
    let n: String = line[title.len() + 2..]
        .chars()
        .take_while(char::is_ascii_digit)
        .collect();
    n.parse().unwrap()
}

// See: issue 38 item 2 — `--json` holds what the text shows.
#[test]
fn list_json_has_the_counts_of_the_text() {
    let lib = fixture_library();
    let v = list_json(&s(lib));
    let text = ok(&["list", &s(lib)]);
    for (title, key) in [
        ("characters", "characters"),
        ("run cycles", "run_cycles"),
        ("jumps", "jumps"),
    ] {
        assert_eq!(
            header_count(&text, title),
            v[key].as_array().unwrap().len(),
            "{title}"
        );
    }
    // One text row per cycle and per jump, each naming its first stance.
    for c in v["run_cycles"].as_array().unwrap() {
        let id = c["stance_ids"][0].as_str().unwrap();
        assert_eq!(text.matches(&format!("{id} →")).count(), 1, "{id}\n{text}");
    }
    for j in v["jumps"].as_array().unwrap() {
        let id = j["liftoff"].as_str().unwrap();
        assert_eq!(text.matches(&format!("{id} →")).count(), 1, "{id}\n{text}");
    }
    // `list --help` documents every key the JSON has.
    let help = ok(&["list", "--help"]);
    let obj = v.as_object().unwrap();
    let mut keys: Vec<&String> = obj.keys().collect();
    for arr in ["characters", "run_cycles", "jumps"] {
        keys.extend(obj[arr][0].as_object().unwrap().keys());
    }
    for k in keys {
        // Arrays are written `key[]`.
        let named = help.contains(&format!("`{k}`")) || help.contains(&format!("`{k}[]`"));
        assert!(named, "`{k}` not in list --help:\n{help}");
    }
}

// See: issue 38 item 2 — not a library: exit 2, the path named.
#[test]
fn list_of_an_unknown_library_exits_2_naming_it() {
    let dir = tempfile::tempdir().unwrap();
    let missing = dir.path().join("no-such-library");
    refused(&["list", &s(&missing)], &[&s(&missing)]);
    refused(&["list", &s(&missing), "--json"], &[&s(&missing)]);
}
