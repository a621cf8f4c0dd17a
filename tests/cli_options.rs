//! Issue 13 items 2–3 (one table layer, a thin CLI): enumerated options are parsed by
//! clap before any work (any case, the documented spellings), and the atomic-write family
//! leaves no temporary behind.

use crate::util::{root, stancelib};

fn fixture(name: &str) -> String {
    root().join("fixtures/bvh").join(name).display().to_string()
}

// See: issue 13 item 3 — `--up-axis`, `--motion`, `--up`, `--form`, `--limits` were strings
// parsed by hand after other work had started.
#[test]
fn enumerated_options_are_refused_before_work_and_accept_every_spelling() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("frames");
    let o = out.display().to_string();
    let clip = fixture("run_30hz_in_yup.bvh");
    // An unknown value: a usage error (exit 2) naming the option, and nothing written.
    let (code, _, err) = stancelib(&["frames", &clip, "--out", &o, "--up-axis", "up"]);
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("--up-axis"), "{err}");
    assert!(!out.exists(), "a refused option wrote {o}");
    // The file's axis in any spelling: `+Y`, `Y`, `y` give the same tables.
    let mut tables = Vec::new();
    for (k, axis) in ["+Y", "Y", "y"].iter().enumerate() {
        let o = dir.path().join(format!("f{k}"));
        let os = o.display().to_string();
        let (code, _, err) =
            stancelib(&["frames", "--quiet", &clip, "--out", &os, "--up-axis", axis]);
        assert_eq!(code, 0, "--up-axis {axis}: {err}");
        tables.push(std::fs::read(o.join("frames.parquet")).unwrap());
    }
    assert!(tables.windows(2).all(|w| w[0] == w[1]));
    // `-Z` is a value, not an option.
    let oz = dir.path().join("fz").display().to_string();
    let (code, _, err) = stancelib(&["frames", "--quiet", &clip, "--out", &oz, "--up-axis", "-Z"]);
    assert_ne!(code, 2, "--up-axis -Z was not taken as a value: {err}");
    for args in [
        &["synth", "--motion", "hop", "--out"][..],
        &["synth", "--up", "X", "--out"][..],
        &["twopac", "--phases", "p.json", "--form", "eq7", "--out"][..],
        &[
            "query", "run", "--lib", "L", "--speed", "1", "--limits", "loose", "--out",
        ][..],
    ] {
        let target = dir.path().join("refused").display().to_string();
        let mut a = args.to_vec();
        a.push(&target);
        let (code, _, err) = stancelib(&a);
        assert_eq!(code, 2, "{a:?}: {err}");
        assert!(err.contains("invalid value"), "{a:?}: {err}");
        assert!(
            !dir.path().join("refused").exists(),
            "{a:?} wrote its output"
        );
    }
    // `synth` takes the motion and axis in any case.
    let bvh = dir.path().join("jump.bvh");
    let (code, _, err) = stancelib(&[
        "synth",
        "--quiet",
        "--motion",
        "JUMP",
        "--up",
        "z",
        "--duration",
        "0.5",
        "--out",
        &bvh.display().to_string(),
    ]);
    assert_eq!(code, 0, "{err}");
    assert!(std::fs::read_to_string(&bvh)
        .unwrap()
        .starts_with("HIERARCHY"));
}

// See: issue 13 item 2 — one atomic-write family for Parquet, JSON and PNG.
#[test]
fn outputs_of_every_kind_leave_no_temporary_behind() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("twopac");
    let phases = root().join("fixtures/twopac/walk_flat.json");
    let (code, _, err) = stancelib(&[
        "twopac",
        "--quiet",
        "--phases",
        &phases.display().to_string(),
        "--out",
        &out.display().to_string(),
    ]);
    assert_eq!(code, 0, "{err}");
    let names: Vec<String> = std::fs::read_dir(&out)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    for want in ["trajectory.parquet", "timings.json", "trajectory.png"] {
        assert!(names.iter().any(|n| n == want), "{want} missing: {names:?}");
    }
    assert!(
        names.iter().all(|n| !n.starts_with('.')),
        "temporaries left: {names:?}"
    );
}
