//! Issue 17: the analyst's first hour. The README's demo commands run, its column tables
//! are the written schemas, the library's provenance (manifest date, command line, tool
//! version; `stancelib.*` Parquet metadata; query outputs naming their library), `info`,
//! and the options a newcomer tries first.

use std::collections::{BTreeMap, BTreeSet};
use std::path::Path;
use std::process::Command;

use crate::util::{root, Demo};

fn readme() -> String {
    std::fs::read_to_string(root().join("README.md")).unwrap()
}

/// The fenced code blocks of `text` with info string `lang`, each as its lines.
fn fenced_blocks(text: &str, lang: &str) -> Vec<Vec<String>> {
    let mut blocks = Vec::new();
    let mut cur: Option<Vec<String>> = None;
    for line in text.lines() {
        let t = line.trim_start();
        match &mut cur {
            None if t.starts_with("```") && t[3..].trim() == lang => cur = Some(Vec::new()),
            Some(_) if t.starts_with("```") => blocks.extend(cur.take()),
            Some(b) => b.push(line.to_string()),
            None => {}
        }
    }
    blocks
}

/// A shell line without its comment (a `#` at the start or after a space).
fn without_comment(line: &str) -> &str {
    let t = line.trim();
    if t.starts_with('#') {
        return "";
    }
    t.find(" #").map_or(t, |i| t[..i].trim_end())
}

/// The commands of the README's `sh` blocks that use the demo outputs (`out/demo` outside a
/// comment), in README order.
fn demo_commands(text: &str) -> Vec<String> {
    fenced_blocks(text, "sh")
        .into_iter()
        .filter(|b| b.iter().any(|l| without_comment(l).contains("out/demo")))
        .flatten()
        .map(|l| without_comment(&l).to_string())
        .filter(|l| !l.is_empty())
        .collect()
}

#[test]
fn demo_commands_are_found_outside_comments_only() {
    let text = "```sh\nmake demo   # into out/demo/\n```\n\n```sh\n# out/demo first\n\
                stancelib info out/demo\nstancelib x --out out/demo/a  # note\n```\n\
                ```python\nopen('out/demo/x')\n```\n";
    assert_eq!(
        demo_commands(text),
        vec!["stancelib info out/demo", "stancelib x --out out/demo/a"]
    );
}

// See: issue 17 item 1 — the README's query examples pointed to paths `make demo` does not
// write, and called built commands "not built yet".
#[test]
fn readme_sh_blocks_that_use_the_demo_outputs_run() {
    let commands = demo_commands(&readme());
    assert!(
        commands.len() >= 5,
        "the README shows too few demo commands: {commands:?}"
    );
    let demo = Demo::build();
    for c in &commands {
        let (code, out, err) = demo.sh(c);
        assert_eq!(code, 0, "README command `{c}` failed:\n{out}\n{err}");
    }
}

/// Expands a README column token: `a_{x,y,z}`, `<e>` (the four effectors) and
/// `c0_h/p/v` (alternatives for the last `_` part).
fn expand(token: &str) -> Vec<String> {
    if let Some(i) = token.find("<e>") {
        return ["left_foot", "right_foot", "left_hand", "right_hand"]
            .iter()
            .flat_map(|e| expand(&format!("{}{e}{}", &token[..i], &token[i + 3..])))
            .collect();
    }
    if let (Some(a), Some(b)) = (token.find('{'), token.find('}')) {
        return token[a + 1..b]
            .split(',')
            .flat_map(|alt| expand(&format!("{}{alt}{}", &token[..a], &token[b + 1..])))
            .collect();
    }
    let mut parts = token.split('/');
    let first = parts.next().unwrap_or_default().to_string();
    let stem = first.rfind('_').map_or("", |i| &first[..=i]).to_string();
    std::iter::once(first)
        .chain(parts.map(|p| format!("{stem}{p}")))
        .collect()
}

#[test]
fn column_tokens_expand_as_the_readme_writes_them() {
    assert_eq!(expand("c0_h/p/v"), ["c0_h", "c0_p", "c0_v"]);
    assert_eq!(expand("ell_r_min/max"), ["ell_r_min", "ell_r_max"]);
    assert_eq!(
        expand("com_v{x,y,z}_mps"),
        ["com_vx_mps", "com_vy_mps", "com_vz_mps"]
    );
    assert_eq!(expand("contact_<e>").len(), 4);
    assert_eq!(expand("<e>_{x,y,z}").len(), 12);
    assert_eq!(
        expand("{left,right}_toe_{x,y}_m"),
        [
            "left_toe_x_m",
            "left_toe_y_m",
            "right_toe_x_m",
            "right_toe_y_m"
        ]
    );
}

/// The backticked names of a table cell, parenthesised remarks left out.
fn cell_columns(cell: &str) -> Vec<String> {
    let mut plain = String::new();
    let mut depth = 0usize;
    for ch in cell.chars() {
        match ch {
            '(' => depth += 1,
            ')' => depth = depth.saturating_sub(1),
            c if depth == 0 => plain.push(c),
            _ => {}
        }
    }
    plain
        .split('`')
        .skip(1)
        .step_by(2)
        .flat_map(expand)
        .collect()
}

/// The columns the README documents per file: rows of a table whose first cell is a
/// backticked `*.parquet` name (columns in its last cell), and tables after a
/// `<!-- columns: FILE -->` marker (columns in the first cell of each row).
fn readme_columns(text: &str) -> BTreeMap<String, BTreeSet<String>> {
    let mut out: BTreeMap<String, BTreeSet<String>> = BTreeMap::new();
    let mut marker: Option<String> = None;
    for line in text.lines() {
        let t = line.trim();
        if let Some(rest) = t.strip_prefix("<!-- columns:") {
            marker = Some(rest.trim_end_matches("-->").trim().to_string());
            continue;
        }
        if !t.starts_with('|') {
            if !t.is_empty() {
                marker = None;
            }
            continue;
        }
        let cells: Vec<&str> = t.trim_matches('|').split('|').map(str::trim).collect();
        if cells
            .iter()
            .all(|c| c.chars().all(|ch| ch == '-' || ch == ':'))
        {
            continue;
        }
        if let Some(file) = &marker {
            out.entry(file.clone())
                .or_default()
                .extend(cell_columns(cells[0]));
        } else if let Some(file) = cells[0]
            .strip_prefix('`')
            .and_then(|c| c.strip_suffix('`'))
            .filter(|c| c.ends_with(".parquet"))
        {
            out.entry(file.to_string())
                .or_default()
                .extend(cell_columns(cells[cells.len() - 1]));
        }
    }
    out
}

fn parquet_columns(path: &Path) -> BTreeSet<String> {
    let mut f = std::fs::File::open(path).unwrap();
    let meta = polars_parquet::read::read_metadata(&mut f).unwrap();
    meta.schema()
        .fields()
        .iter()
        .map(|f| f.name().to_string())
        .collect()
}

// See: issue 17 item 1 — columns were missing from the README's tables
// (`clips.frame_time_s`, `handedness_ok`, `character_id`, `flight_az_median`,
// `contacts.normal_x/y/z`).
#[test]
fn readme_column_tables_are_the_written_schemas() {
    let documented = readme_columns(&readme());
    let demo = Demo::build();
    // `joints.parquet` needs `--joints`: write it beside the demo library.
    let (code, out, err) =
        demo.sh("stancelib frames fixtures/bvh/run_120hz_m_yup.bvh --joints --out joints");
    assert_eq!(code, 0, "{out}{err}");
    let files = [
        ("frames.parquet", demo.lib()),
        ("clips.parquet", demo.lib()),
        ("contacts.parquet", demo.lib()),
        ("stances.parquet", demo.lib()),
        ("errors.parquet", demo.lib()),
        ("kinematics.parquet", demo.lib()),
        ("joints.parquet", demo.dir.path().join("joints")),
    ];
    for (file, dir) in files {
        let written = parquet_columns(&dir.join(file));
        let doc = documented
            .get(file)
            .unwrap_or_else(|| panic!("the README has no column table for {file}"));
        let missing: Vec<_> = written.difference(doc).collect();
        let extra: Vec<_> = doc.difference(&written).collect();
        assert!(
            missing.is_empty() && extra.is_empty(),
            "{file}: written but not in the README: {missing:?}; in the README but not \
             written: {extra:?}"
        );
    }
}

fn manifest(lib: &Path) -> serde_json::Value {
    serde_json::from_str(&std::fs::read_to_string(lib.join("manifest.json")).unwrap()).unwrap()
}

fn kv(path: &Path) -> BTreeMap<String, String> {
    super::util::parquet_kv(path)
}

fn sha256_hex(bytes: &[u8]) -> String {
    use sha2::{Digest, Sha256};
    Sha256::digest(bytes)
        .iter()
        .map(|b| format!("{b:02x}"))
        .collect()
}

// See: issue 17 item 5 — the manifest had no date or command line, and query outputs did
// not say which library they came from.
#[test]
fn manifest_records_date_command_line_and_tool_version_and_queries_name_their_library() {
    let demo = Demo::build();
    let lib = demo.lib();
    let m = manifest(&lib);
    assert_eq!(m["tool_version"], env!("CARGO_PKG_VERSION"));
    let date = m["created_utc"].as_str().expect("created_utc");
    // RFC 3339 UTC, and today (the test's own clock, within a day).
    assert_eq!(date.len(), 20, "{date}");
    assert!(date.ends_with('Z') && &date[10..11] == "T", "{date}");
    let now = stancelib::library::provenance::now_utc();
    let days = |d: &str| -> i64 {
        let (y, mo, da): (i64, i64, i64) = (
            d[0..4].parse().unwrap(),
            d[5..7].parse().unwrap(),
            d[8..10].parse().unwrap(),
        );
        y * 372 + mo * 31 + da
    };
    assert!((days(&now) - days(date)).abs() <= 1, "{date} vs {now}");
    let cmd: Vec<String> = serde_json::from_value(m["command_line"].clone()).unwrap();
    assert!(cmd[0].ends_with("stancelib"), "{cmd:?}");
    assert_eq!(cmd[1..], ["run", "pipelines/demo.toml"]);
    // The query stages of the demo and a query run by hand name the library's manifest.
    let hash = sha256_hex(&std::fs::read(lib.join("manifest.json")).unwrap());
    let (code, out, err) =
        demo.sh("stancelib query run --lib out/demo --speed 2 --out q/runs.parquet");
    assert_eq!(code, 0, "{out}{err}");
    for f in [
        lib.join("queries/runs.parquet"),
        lib.join("queries/jump_map/jump_map.parquet"),
        demo.dir.path().join("q/runs.parquet"),
    ] {
        let meta = kv(&f);
        assert_eq!(
            meta.get("stancelib.library_manifest_sha256"),
            Some(&hash),
            "{}",
            f.display()
        );
        assert_eq!(meta["stancelib.tool_version"], env!("CARGO_PKG_VERSION"));
    }
    // The library's own tables keep only deterministic provenance.
    let meta = kv(&lib.join("stances.parquet"));
    assert!(meta.contains_key("stancelib.options"), "{meta:?}");
    assert!(
        !meta.values().any(|v| v.contains(date)),
        "the date leaked into the tables' metadata"
    );
}

// See: issue 17 item 5 — `pyarrow.parquet.read_table(...).schema.metadata` showed no
// `stancelib.*` keys.
#[test]
fn pyarrow_schema_metadata_shows_the_stancelib_keys() {
    let has = Command::new("python3")
        .args(["-c", "import pyarrow"])
        .output()
        .is_ok_and(|o| o.status.success());
    if !has {
        // .ci/run installs pyarrow: there, its absence is a failure.
        crate::util::skip_or_fail(
            "pyarrow_schema_metadata_shows_the_stancelib_keys",
            "no pyarrow",
        );
        return;
    }
    let demo = Demo::build();
    let script = "import sys, pyarrow.parquet as pq\n\
        for f in sys.argv[1:]:\n\
        \x20   m = pq.read_table(f).schema.metadata or {}\n\
        \x20   keys = sorted(k.decode() for k in m if k.startswith(b'stancelib.'))\n\
        \x20   print(f.rsplit('/', 1)[-1], ' '.join(keys))\n";
    let lib = demo.lib();
    let o = Command::new("python3")
        .args(["-c", script])
        .arg(lib.join("stances.parquet"))
        .arg(lib.join("queries/runs.parquet"))
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let text = String::from_utf8_lossy(&o.stdout);
    let lines: Vec<&str> = text.lines().collect();
    assert!(
        lines[0].contains("stancelib.schema_version") && lines[0].contains("stancelib.options"),
        "{text}"
    );
    assert!(
        lines[1].contains("stancelib.library_manifest_sha256"),
        "{text}"
    );
}

// See: issue 17 item 5 — `stancelib info LIB`.
#[test]
fn info_summarises_the_library_as_text_and_json() {
    let demo = Demo::library();
    let lib = demo.lib();
    let (code, text, err) = demo.sh("stancelib info out/demo");
    assert_eq!(code, 0, "{err}");
    for needle in [
        "clips",
        "stances by label",
        "failures by stage",
        "per-character limits",
        env!("CARGO_PKG_VERSION"),
    ] {
        assert!(text.contains(needle), "no '{needle}' in\n{text}");
    }
    let (code, json, err) = demo.sh("stancelib info out/demo --json");
    assert_eq!(code, 0, "{err}");
    let v: serde_json::Value = serde_json::from_str(json.trim()).expect("one JSON object");
    // Against the tables, counted here independently.
    let stances = stancelib::library::read::read_parquet(&lib.join("stances.parquet")).unwrap();
    let labels = stances.column("label").unwrap().str().unwrap().clone();
    let mut by_label: BTreeMap<String, u64> = BTreeMap::new();
    for l in labels.iter().flatten() {
        *by_label.entry(l.to_string()).or_default() += 1;
    }
    let got: BTreeMap<String, u64> = serde_json::from_value(v["stances_by_label"].clone()).unwrap();
    assert_eq!(got, by_label);
    let m = manifest(&lib);
    assert_eq!(v["clips_by_status"]["ok"], m["counts"]["ok"]);
    assert_eq!(v["limits"], m["limits"]);
    assert_eq!(v["schema_version"], m["schema_version"]);
    assert_eq!(
        v["manifest_sha256"],
        sha256_hex(&std::fs::read(lib.join("manifest.json")).unwrap())
    );
    let starts: u64 = v["boundary_start"]
        .as_object()
        .unwrap()
        .values()
        .map(|n| n.as_u64().unwrap())
        .sum();
    assert_eq!(starts, stances.height() as u64);
    // Not a library: exit 2, the file named.
    let (code, _, err) = demo.sh("stancelib info fixtures");
    assert_eq!(code, 2);
    assert!(err.contains("manifest.json"), "{err}");
}

// See: issue 17 item 6 — `--speed -3` was parsed as a flag.
#[test]
fn negative_numbers_parse_as_values() {
    let demo = Demo::library();
    let (code, _, err) = demo.sh("stancelib query run --lib out/demo --speed -3 --out q.parquet");
    assert_eq!(code, 2);
    // The value reached the speed check, not clap's "unexpected argument".
    assert!(!err.contains("unexpected argument"), "{err}");
    assert!(err.contains("--speed") && err.contains("-3"), "{err}");
    let (code, out, err) =
        demo.sh("stancelib query jump --lib out/demo --height 0.9 --distance -0.5 --out j.parquet");
    assert_eq!(code, 0, "{out}{err}");
}

// See: issue 17 item 6 — `--help` did not say which limits a command uses or its defaults.
#[test]
fn help_shows_defaults_units_and_limits() {
    let demo = Demo::empty();
    for (cmd, needles) in [
        (
            "stancelib map jumps --help",
            &[
                "[default: 0.6:1.6:0.02]",
                "m/s",
                "MAX_GRID_CELLS",
                "1000000",
            ][..],
        ),
        (
            "stancelib query run --help",
            &["MAX_RUN_ROWS", "MAX_AXIS_VALUES", "m/s"][..],
        ),
        (
            "stancelib build --help",
            &["MAX_BVH_BYTES", "[default: 0]"][..],
        ),
        ("stancelib twopac --help", &["MAX_PHASES"][..]),
    ] {
        let (code, out, err) = demo.sh(cmd);
        assert_eq!(code, 0, "{err}");
        for n in needles {
            assert!(out.contains(n), "`{cmd}` lacks '{n}':\n{out}");
        }
    }
}

// See: issue 17 item 6 — `--quiet` and `--json` summaries.
#[test]
fn quiet_prints_nothing_and_json_prints_one_summary_object() {
    let demo = Demo::empty();
    let clip = "fixtures/bvh/run_120hz_m_yup.bvh";
    let (code, out, err) = demo.sh(&format!("stancelib build {clip} --out a --quiet"));
    assert_eq!(code, 0, "{err}");
    assert_eq!(out, "", "--quiet printed on stdout");
    let (code, out, err) = demo.sh(&format!("stancelib build {clip} --out b --json"));
    assert_eq!(code, 0, "{err}");
    let v: serde_json::Value = serde_json::from_str(out.trim()).expect("one JSON object");
    let stances =
        stancelib::library::read::parquet_rows(&demo.dir.path().join("b/stances.parquet")).unwrap();
    assert_eq!(v["command"], "build");
    assert_eq!((v["clips"].as_u64(), v["ok"].as_u64()), (Some(1), Some(1)));
    assert_eq!(v["stances_rebuilt"].as_u64(), Some(stances as u64));
    assert_eq!(v["clips_reused"].as_u64(), Some(0));
}

// See: issue 17 item 7 — layout 4 renamed the columns; a library of an older layout must be
// refused with a message to rebuild, and never reused column by column.
#[test]
fn a_library_of_an_older_table_layout_is_refused_and_not_reused() {
    let demo = Demo::empty();
    let clip = "fixtures/bvh/run_120hz_m_yup.bvh";
    let (code, _, err) = demo.sh(&format!("stancelib build {clip} --out lib --quiet"));
    assert_eq!(code, 0, "{err}");
    let mpath = demo.dir.path().join("lib/manifest.json");
    let mut m: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&mpath).unwrap()).unwrap();
    m["schema"] = "stancelib.library/3".into();
    std::fs::write(&mpath, serde_json::to_string_pretty(&m).unwrap()).unwrap();
    let (code, _, err) =
        demo.sh("stancelib query run --lib lib --speed 3 --out runs.parquet --quiet");
    assert_eq!(code, 2, "{err}");
    assert!(
        err.contains("manifest.json") && err.contains("table layout 3") && err.contains("rebuild"),
        "{err}"
    );
    assert!(!demo.dir.path().join("runs.parquet").exists());
    let (code, out, err) = demo.sh(&format!(
        "stancelib build {clip} --out lib --incremental --force --json"
    ));
    assert_eq!(code, 0, "{err}");
    let v: serde_json::Value = serde_json::from_str(out.trim()).expect("one JSON object");
    assert_eq!(v["clips_reused"].as_u64(), Some(0), "{v}");
    let again: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&mpath).unwrap()).unwrap();
    let want = format!(
        "stancelib.library/{}",
        stancelib::library::schema::SCHEMA_VERSION
    );
    assert_eq!(again["schema"], want.as_str());
}

/// Width and height of a PNG from its IHDR chunk.
fn png_size(path: &Path) -> (u32, u32) {
    let b = std::fs::read(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    assert_eq!(
        &b[..8],
        b"\x89PNG\r\n\x1a\n",
        "{} is not a PNG",
        path.display()
    );
    let be = |i: usize| u32::from_be_bytes([b[i], b[i + 1], b[i + 2], b[i + 3]]);
    (be(16), be(20))
}

// See: issue 17 item 4 — no plot showed a clip's COM, contacts and flights.
#[test]
fn plot_clip_draws_the_clip_and_refuses_an_unknown_one() {
    let demo = Demo::library();
    let (code, out, err) =
        demo.sh("stancelib plot clip --lib out/demo --clip jump_120hz_cmu_yup --out p/clip.png");
    assert_eq!(code, 0, "{out}{err}");
    assert!(out.contains("flights"), "{out}");
    assert_eq!(png_size(&demo.dir.path().join("p/clip.png")), (1300, 1000));
    let (code, _, err) =
        demo.sh("stancelib plot clip --lib out/demo --clip no_such_clip --out p/none.png");
    assert_eq!(code, 2);
    assert!(
        err.contains("no_such_clip") && err.contains("jump_100hz_m_zup"),
        "{err}"
    );
    assert!(!demo.dir.path().join("p/none.png").exists());
}

// See: issue 17 item 4 — "feasible at 5 m/s" returned nothing and no plot showed why.
#[test]
fn query_run_png_draws_table_1_beside_the_table() {
    let demo = Demo::library();
    let (code, out, err) = demo.sh(
        "stancelib query run --lib out/demo --speeds 0:6:1 --out q/runs.parquet --png q/runs.png",
    );
    assert_eq!(code, 0, "{out}{err}");
    // Four panels since issue 37 (times, peak force, friction, extension), under the
    // legend row of issue 38.
    assert_eq!(
        png_size(&demo.dir.path().join("q/runs.png")),
        stancelib::plot::runs::RUNS_PLOT_PX
    );
    assert!(demo.dir.path().join("q/runs.parquet").is_file());
}

// See: issue 17 item 4 — `equilibrium … --png`: the feasible region with the contacts.
#[test]
fn equilibrium_png_draws_the_region_slice() {
    use polars::prelude::{Column, DataFrame, ParquetWriter};
    let demo = Demo::empty();
    let p = demo.dir.path().join("p.parquet");
    let mut df = DataFrame::new_infer_height(vec![
        Column::new("x_m".into(), [0.0, 0.05, 2.0]),
        Column::new("y_m".into(), [0.0, 0.0, 2.0]),
        Column::new("z_m".into(), [0.9, 0.9, 0.9]),
    ])
    .unwrap();
    ParquetWriter::new(std::fs::File::create(&p).unwrap())
        .finish(&mut df)
        .unwrap();
    let (code, out, err) = demo.sh(
        "stancelib equilibrium --contacts fixtures/twopac/r2_contacts.json --points p.parquet \
         --out r.parquet --png r.png",
    );
    assert_eq!(code, 0, "{out}{err}");
    assert_eq!(png_size(&demo.dir.path().join("r.png")), (900, 820));
    assert!(demo.dir.path().join("r.parquet").is_file());
}
