//! Issue 38 item 3 — duplicate inputs (the same file content under two names) are
//! reported by `info` and enter every query answer once; the clips a query leaves out are
//! named, and `--keep-left-out` keeps them.

use stancelib::library::codec::table::Table;

use crate::util::{ok, s, stancelib};

/// A library of the fixture jump clip under two names (a copy), and the fixture run.
fn library_with_a_copy(dir: &std::path::Path) -> std::path::PathBuf {
    let inputs = dir.join("in");
    std::fs::create_dir_all(&inputs).unwrap();
    let fixtures = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("fixtures/bvh");
    for (src, dst) in [
        ("jump_120hz_cmu_yup.bvh", "a_jump.bvh"),
        ("jump_120hz_cmu_yup.bvh", "b_jump_copy.bvh"),
        ("run_120hz_m_yup.bvh", "run.bvh"),
    ] {
        std::fs::copy(fixtures.join(src), inputs.join(dst)).unwrap();
    }
    let lib = dir.join("lib");
    // The build's summary says so too (stderr, and the `--json` line).
    let (code, out, err) = stancelib(&["build", &s(&inputs), "--out", &s(&lib), "--json"]);
    assert_eq!(code, 0, "{err}");
    assert!(
        err.contains("1 duplicate clip(s)") && err.contains("b_jump_copy = a_jump"),
        "{err}"
    );
    let line = out.lines().last().unwrap_or_default();
    let v: serde_json::Value = serde_json::from_str(line).expect("the --json summary line");
    assert_eq!(v["duplicates"], 1, "{line}");
    lib
}

/// The clips of a `query jump` table's pairs (liftoff and landing clips).
fn pair_clips(t: &Table) -> Vec<String> {
    let ids = t.strings("liftoff_stance_id").unwrap();
    let ids2 = t.strings("landing_stance_id").unwrap();
    ids.iter()
        .chain(&ids2)
        .map(|id| id.split(':').next().unwrap().to_string())
        .collect()
}

// See: issue 38 item 3 — a copied clip entered every jump answer twice, silently.
#[test]
fn duplicate_inputs_are_reported_and_answer_once() {
    let dir = tempfile::tempdir().unwrap();
    let lib = library_with_a_copy(dir.path());
    // info names the copy and the clip it repeats, in text and JSON.
    let text = ok(&["info", &s(&lib)]);
    assert!(
        text.contains("duplicate clips (1;") && text.contains("b_jump_copy = a_jump"),
        "{text}"
    );
    let v: serde_json::Value =
        serde_json::from_str(ok(&["info", &s(&lib), "--json"]).trim()).unwrap();
    assert_eq!(
        v["duplicates"],
        serde_json::json!([["b_jump_copy", "a_jump"]])
    );
    // query jump: the copy's stances answer nothing, and stderr says so by name.
    let out = dir.path().join("jump.parquet");
    let (code, _, err) = stancelib(&[
        "query",
        "jump",
        "--lib",
        &s(&lib),
        "--height",
        "1.2",
        "--distance",
        "0",
        "--out",
        &s(&out),
    ]);
    assert_eq!(code, 0, "{err}");
    assert!(
        err.contains("left out: b_jump_copy (same content as a_jump)")
            && err.contains("--keep-left-out"),
        "{err}"
    );
    let once = pair_clips(&Table::open(&out).unwrap());
    assert!(once.iter().all(|c| c != "b_jump_copy"), "{once:?}");
    assert!(once.iter().any(|c| c == "a_jump"));
    // --keep-left-out: the copy's pairs come back (each liftoff × landing of both copies).
    let kept = dir.path().join("kept.parquet");
    ok(&[
        "query",
        "jump",
        "--lib",
        &s(&lib),
        "--height",
        "1.2",
        "--distance",
        "0",
        "--out",
        &s(&kept),
        "--keep-left-out",
    ]);
    let t_once = Table::open(&out).unwrap().height();
    let t_kept = Table::open(&kept).unwrap().height();
    let with_copy = pair_clips(&Table::open(&kept).unwrap());
    assert!(with_copy.iter().any(|c| c == "b_jump_copy"));
    assert!(t_kept > t_once, "{t_kept} rows kept vs {t_once}");
    // The jump map leaves the copy out the same way.
    let (code, _, err) = stancelib(&[
        "map",
        "jumps",
        "--lib",
        &s(&lib),
        "--out",
        &s(&dir.path().join("map")),
    ]);
    assert_eq!(code, 0, "{err}");
    assert!(
        err.contains("map jumps:") && err.contains("b_jump_copy"),
        "{err}"
    );
}

// See: issue 38 item 3 — "3 cycles left out: s_eff outside [0.9, 1.1]" named no clip.
#[test]
fn clips_left_out_of_a_query_are_named_and_can_be_kept() {
    let dir = tempfile::tempdir().unwrap();
    let inputs = dir.path().join("in");
    std::fs::create_dir_all(&inputs).unwrap();
    let fixtures = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("fixtures/bvh");
    for name in ["run_120hz_m_yup.bvh", "run_60hz_cm_zup.bvh"] {
        std::fs::copy(fixtures.join(name), inputs.join(name)).unwrap();
    }
    // The same run again as a copy: its cycles are left out of query run, by name.
    std::fs::copy(
        fixtures.join("run_120hz_m_yup.bvh"),
        inputs.join("z_run_copy.bvh"),
    )
    .unwrap();
    let lib = dir.path().join("lib");
    ok(&["build", &s(&inputs), "--out", &s(&lib), "--quiet"]);
    let out = dir.path().join("runs.parquet");
    let args = [
        "query",
        "run",
        "--lib",
        &s(&lib),
        "--speed",
        "3",
        "--out",
        &s(&out),
    ];
    let (code, _, err) = stancelib(&args);
    assert_eq!(code, 0, "{err}");
    assert!(
        err.contains("query run:") && err.contains("z_run_copy (same content as run_120hz_m_yup)"),
        "{err}"
    );
    let cycles = |p: &std::path::Path| {
        let t = Table::open(p).unwrap();
        crate::util::first_stance_ids(&t)
    };
    assert!(cycles(&out).iter().all(|id| !id.starts_with("z_run_copy:")));
    let kept = dir.path().join("kept.parquet");
    let mut with_keep = args.to_vec();
    with_keep[7] = kept.to_str().unwrap();
    with_keep.push("--keep-left-out");
    let (code, _, err) = stancelib(&with_keep);
    assert_eq!(code, 0, "{err}");
    assert!(!err.contains("left out"), "{err}");
    let k = cycles(&kept);
    assert!(k.iter().any(|id| id.starts_with("z_run_copy:")), "{k:?}");
    assert_eq!(
        k.iter().filter(|id| id.starts_with("z_run_copy:")).count(),
        k.iter()
            .filter(|id| id.starts_with("run_120hz_m_yup:"))
            .count()
    );
}
