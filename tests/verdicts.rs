//! Issue 38 items 1 and 2 — answers that explain themselves: `--explain` prints one answer
//! in full (every limit with value, limit and margin), `query jump --height-scale` asks
//! each pair for its own recorded jump times a factor, and an unknown stance id gets the
//! nearest ids.

use stancelib::library::codec::table::Table;
use stancelib::library::readers::read::read_stances;
use stancelib::query::jump::recorded_jump;

use crate::util::{first_stance_ids, fixture_library, ok, refused, s};

/// `(name, value, limit, margin)` of the check lines `    force 1543 N ≤ 1750 N (margin
/// 207 N)` of an explanation (the margin negative when the line says `by`).
fn checks(text: &str) -> Vec<(String, f64, f64, f64)> {
    text.lines()
        .filter_map(|l| {
            let l = l.trim();
            let (name, rest) = l.split_once(' ')?;
            if !["force", "friction", "extension_min", "extension_max"].contains(&name) {
                return None;
            }
            let nums: Vec<f64> = rest
                .split(|c: char| !(c.is_ascii_digit() || c == '.' || c == '-'))
                .filter_map(|t| t.parse().ok())
                .collect();
            let sign = if rest.contains("(by ") { -1.0 } else { 1.0 };
            Some((name.to_string(), nums[0], nums[1], sign * nums[2]))
        })
        .collect()
}

// See: issue 38 item 1 — `--explain ID` prints one answer in full.
#[test]
fn query_run_explain_prints_every_limit_with_value_limit_and_margin() {
    let lib = fixture_library();
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("r.parquet");
    // The cycle query run itself ranks first at 3.5 m/s.
    ok(&[
        "query",
        "run",
        "--lib",
        &s(lib),
        "--speed",
        "3.5",
        "--out",
        &s(&out),
    ]);
    let t = Table::open(&out).unwrap();
    let id = first_stance_ids(&t)[0].clone();
    let text = ok(&[
        "query",
        "run",
        "--lib",
        &s(lib),
        "--speeds",
        "2:5:1.5",
        "--out",
        &s(&out),
        "--explain",
        &id,
    ]);
    eprintln!("{text}");
    // One block per speed, each with the gait law and both stances' four checks.
    assert_eq!(
        text.matches(&format!("cycle {id} at ")).count(),
        3,
        "{text}"
    );
    let law_lines = text
        .lines()
        .filter(|l| l.trim_start().starts_with("gait law "));
    assert_eq!(law_lines.count(), 3, "{text}");
    let c = checks(&text);
    assert_eq!(c.len(), 3 * 2 * 4, "{text}");
    for (name, value, limit, margin) in &c {
        // The margin is the printed limit minus the value (or the reverse for the lower
        // extension limit), to the printed digits.
        let want = if name == "extension_min" {
            value - limit
        } else {
            limit - value
        };
        let digits = if name == "force" { 1.0 } else { 1e-3 };
        assert!(
            (margin - want).abs() <= digits,
            "{name}: {value} {limit} {margin}"
        );
    }
    // The table's verdict is the explanation's: a feasible row has no negative margin.
    let feasible = t.bools("feasible").unwrap();
    assert!(feasible[0], "the nearest cycle is feasible at 3.5 m/s");
    // An id that starts no cycle names the nearest ones.
    let err = refused(
        &[
            "query",
            "run",
            "--lib",
            &s(lib),
            "--speed",
            "3",
            "--out",
            &s(&out),
            "--explain",
            "run_120hz_m_yup:R:9999",
        ],
        &["--explain", "nearest: run_120hz_m_yup:R:"],
    );
    eprintln!("{err}");
}

// See: issue 38 item 2 — `query jump` has no `--height-scale`/`--distance-scale`.
#[test]
fn query_jump_height_scale_asks_each_pair_its_own_recorded_jump() {
    let lib = fixture_library();
    let dir = tempfile::tempdir().unwrap();
    let stances = read_stances(&lib.join("stances.parquet")).unwrap();
    let by_id = |id: &str| stances.iter().find(|s| s.stance_id == id).unwrap();
    for (hs, ds) in [("1.1", None), ("1.05", Some("0.9"))] {
        let out = dir.path().join(format!("j{hs}.parquet"));
        let mut args = vec![
            "query",
            "jump",
            "--lib",
            lib.to_str().unwrap(),
            "--height-scale",
            hs,
        ];
        if let Some(d) = ds {
            args.extend(["--distance-scale", d]);
        }
        let o = s(&out);
        args.extend(["--out", &o, "--explain", "1"]);
        let text = ok(&args);
        eprintln!("{text}");
        let t = Table::open(&out).unwrap();
        let (up, down) = (
            t.strings("liftoff_stance_id").unwrap(),
            t.strings("landing_stance_id").unwrap(),
        );
        let (h, d) = (t.f64s("height_m").unwrap(), t.f64s("distance_m").unwrap());
        assert!(!up.is_empty());
        let (fh, fd): (f64, f64) = (hs.parse().unwrap(), ds.map_or(1.0, |d| d.parse().unwrap()));
        for i in 0..up.len() {
            let (h0, d0) = recorded_jump(by_id(&up[i]), by_id(&down[i]));
            assert!((h[i] - fh * h0).abs() < 1e-12 && (d[i] - fd * d0).abs() < 1e-12);
        }
        // Rank 1 explained: the pair, its flight and both sides' checks.
        assert!(
            text.contains(&format!("pair {} → {}", up[0], down[0])),
            "{text}"
        );
        assert_eq!(checks(&text).len(), 8, "{text}");
    }
    // A scale needs the height's scale; a rank beyond the table is refused.
    let out = s(&dir.path().join("x.parquet"));
    refused(
        &[
            "query",
            "jump",
            "--lib",
            &s(lib),
            "--height",
            "1",
            "--distance-scale",
            "1",
            "--out",
            &out,
        ],
        &["--distance-scale"],
    );
    refused(
        &[
            "query",
            "jump",
            "--lib",
            &s(lib),
            "--height-scale",
            "1.1",
            "--out",
            &out,
            "--explain",
            "100000",
        ],
        &["--explain 100000", "ranks go from 1 to"],
    );
}

// See: issue 38 item 2 — an unknown stance id suggests the nearest ids.
#[test]
fn an_unknown_stance_id_suggests_the_nearest_ones() {
    let lib = fixture_library();
    let stances = read_stances(&lib.join("stances.parquet")).unwrap();
    let held = &stances[stances.len() / 2].stance_id;
    let (clip, rest) = held.split_once(':').unwrap();
    let (label, frame) = rest.rsplit_once(':').unwrap();
    let frame: i64 = frame.parse().unwrap();
    let asked = format!("{clip}:{label}:{}", frame + 1);
    assert!(
        stances.iter().all(|s| s.stance_id != asked),
        "{asked} is held"
    );
    let dir = tempfile::tempdir().unwrap();
    let err = refused(
        &[
            "forces",
            "--lib",
            &s(lib),
            "--stance",
            &asked,
            "--out",
            &s(&dir.path().join("f.parquet")),
        ],
        &["no stance", "nearest: "],
    );
    // The first suggestion is of the same clip and foot, at the nearest frame.
    let near = err
        .split("nearest: ")
        .nth(1)
        .unwrap()
        .split(", ")
        .next()
        .unwrap()
        .trim();
    assert!(near.starts_with(&format!("{clip}:{label}:")), "{err}");
    let nearest_frame = stances
        .iter()
        .filter_map(|s| s.stance_id.strip_prefix(&format!("{clip}:{label}:")))
        .filter_map(|f| f.parse::<i64>().ok())
        .map(|f| (f - (frame + 1)).abs())
        .min()
        .unwrap();
    let got: i64 = near.rsplit(':').next().unwrap().parse().unwrap();
    assert_eq!((got - (frame + 1)).abs(), nearest_frame, "{err}");
}

// See: issue 38 item 1 — `map jumps` printed counts only; each pair now says how much of the
// grid it can jump and whether its recorded jump, and one 10 % higher, are feasible, or which
// limit stops them.
#[test]
fn map_jumps_says_per_pair_what_it_can_jump_and_why_not() {
    let lib = fixture_library();
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("map");
    let text = ok(&[
        "map",
        "jumps",
        "--lib",
        &s(lib),
        "--heights",
        "0.8:1.6:0.05",
        "--speeds",
        "0:4:0.25",
        "--out",
        &s(&out),
    ]);
    eprintln!("{text}");
    let t = Table::open(&out.join("jump_map_pairs.parquet")).unwrap();
    let (up, down) = (
        t.strings("liftoff_stance_id").unwrap(),
        t.strings("landing_stance_id").unwrap(),
    );
    let n_exact = t.i64s("n_exact").unwrap();
    let lines: Vec<&str> = text
        .lines()
        .filter(|l| l.contains(" cells; as recorded "))
        .collect();
    assert_eq!(lines.len(), up.len().min(10), "{text}");
    for l in &lines {
        let (pair, rest) = l.trim().split_once(": ").unwrap();
        let (a, b) = pair.split_once(" → ").unwrap();
        let i = (0..up.len()).find(|&i| up[i] == a && down[i] == b).unwrap();
        let n: i64 = rest.split(' ').next().unwrap().parse().unwrap();
        assert_eq!(n, n_exact[i], "{l}");
        // A "no" names its reason: a limit with its margin, or the solver's reason.
        for part in rest.split("; ").skip(1) {
            assert!(part.ends_with("feasible") || part.contains(" no ("), "{l}");
        }
    }
    // The recorded jumps of the jump clips are feasible as recorded.
    assert!(
        lines.iter().any(|l| l.contains("as recorded feasible")),
        "{text}"
    );
}
