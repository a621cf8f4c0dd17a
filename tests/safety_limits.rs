//! Issue 11 items 6, 10, 11 and 12 (duplicate keys): bounded work from small inputs
//! (every documented limit refused before any work, exit 2, the field and the limit
//! named, nothing written), the whole pipeline file validated before the library is
//! touched, no option accepted and ignored, duplicate JSON and TOML keys refused.
//!
//! Everything runs on the committed fixtures (`fixtures/bvh`, `fixtures/twopac`).

use crate::util::{ok, root, stancelib};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::sync::OnceLock;

use polars::prelude::*;
use stancelib::library::read::read_parquet;

/// Runs a command that must exit 2 with every one of `needles` in its stderr; returns it.
fn refused(args: &[&str], needles: &[&str]) -> String {
    let (code, out, err) = stancelib(args);
    assert_eq!(code, 2, "stancelib {args:?} must exit 2:\n{out}\n{err}");
    for n in needles {
        assert!(
            err.contains(n),
            "stancelib {args:?}: stderr lacks {n:?}:\n{err}"
        );
    }
    err
}

fn s(p: &Path) -> String {
    p.display().to_string()
}

/// The five generated clips.
fn fixture_clips() -> Vec<String> {
    let mut v: Vec<String> = std::fs::read_dir(root().join("fixtures/bvh"))
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "bvh"))
        .map(|p| s(&p))
        .collect();
    v.sort();
    v
}

/// A library built from the fixtures once per test binary (read-only for the tests).
fn fixture_library() -> &'static Path {
    static LIB: OnceLock<(tempfile::TempDir, PathBuf)> = OnceLock::new();
    let (_, lib) = LIB.get_or_init(|| {
        let dir = tempfile::tempdir().unwrap();
        let lib = dir.path().join("lib");
        let clips = fixture_clips();
        let mut args = vec!["build"];
        args.extend(clips.iter().map(String::as_str));
        let lib_s = s(&lib);
        args.extend(["--out", &lib_s]);
        ok(&args);
        (dir, lib)
    });
    lib
}

/// Every file below `dir` with its bytes (relative paths).
fn snapshot(dir: &Path) -> BTreeMap<PathBuf, Vec<u8>> {
    fn walk(base: &Path, dir: &Path, out: &mut BTreeMap<PathBuf, Vec<u8>>) {
        for e in std::fs::read_dir(dir).unwrap() {
            let p = e.unwrap().path();
            if p.is_dir() {
                walk(base, &p, out);
            } else {
                let rel = p.strip_prefix(base).unwrap().to_path_buf();
                out.insert(rel, std::fs::read(&p).unwrap());
            }
        }
    }
    let mut out = BTreeMap::new();
    walk(dir, dir, &mut out);
    out
}

/// The names in a folder (empty when it does not exist).
fn listing(dir: &Path) -> Vec<String> {
    let Ok(rd) = std::fs::read_dir(dir) else {
        return Vec::new();
    };
    let mut v: Vec<String> = rd
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    v.sort();
    v
}

// ---------------------------------------------------------------- item 6: query ranges

// See: issue 11 item 6 — `query run --speeds 0:1e9:0.001` aborted on a huge allocation.
#[test]
fn query_run_speeds_beyond_max_axis_values_is_refused_before_work() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("runs.parquet");
    // The library does not exist: the range is refused before it would be read.
    let err = refused(
        &[
            "query",
            "run",
            "--lib",
            &s(&dir.path().join("no-lib")),
            "--speeds",
            "0:1e9:0.001",
            "--out",
            &s(&out),
        ],
        &["--speeds", "MAX_AXIS_VALUES", "10000"],
    );
    assert!(!err.contains("no-lib"), "{err}");
    assert!(!out.exists());
}

// See: issue 11 item 6 — `map jumps --heights 0:1000:0.000001` aborted on a huge allocation.
#[test]
fn map_jumps_heights_beyond_max_axis_values_is_refused_before_work() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("map");
    refused(
        &[
            "map",
            "jumps",
            "--lib",
            &s(fixture_library()),
            "--heights",
            "0:1000:0.000001",
            "--out",
            &s(&out),
        ],
        &["--heights", "MAX_AXIS_VALUES"],
    );
    assert!(!out.exists());
}

// See: issue 11 item 6 — a grid of heights × speeds beyond MAX_GRID_CELLS.
#[test]
fn map_jumps_grid_beyond_max_grid_cells_is_refused_before_work() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("map");
    // 1001 × 1001 values: each axis within MAX_AXIS_VALUES, the grid above 10⁶ cells.
    refused(
        &[
            "map",
            "jumps",
            "--lib",
            &s(fixture_library()),
            "--heights",
            "0:1000:1",
            "--speeds",
            "0:1000:1",
            "--out",
            &s(&out),
        ],
        &["--heights × --speeds", "MAX_GRID_CELLS", "1002001"],
    );
    assert!(!out.exists());
}

// See: issue 11 item 6 — the whole map (cells × pairs) beyond MAX_MAP_CELLS on a real
// library: refused after reading the library, before any stance grid is computed.
#[test]
fn map_jumps_beyond_max_map_cells_is_refused_before_work() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("map");
    // 1000 × 1000 = MAX_GRID_CELLS (allowed), times the fixture's pairs and grids.
    refused(
        &[
            "map",
            "jumps",
            "--lib",
            &s(fixture_library()),
            "--heights",
            "0:999:1",
            "--speeds",
            "0:999:1",
            "--out",
            &s(&out),
        ],
        &["jump map", "MAX_MAP_CELLS"],
    );
    assert!(!out.exists());
}

// See: issue 11 item 6 — step ≤ 0, NaN and infinity in a hand-parsed range.
#[test]
fn ranges_with_a_zero_negative_nan_or_infinite_part_are_refused() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("runs.parquet");
    let lib = s(fixture_library());
    for bad in [
        "0:6:0",
        "0:6:-0.5",
        "NaN:6:0.5",
        "0:inf:0.5",
        "0:6:1e-320x",
        "6:0:0.5",
    ] {
        refused(
            &[
                "query",
                "run",
                "--lib",
                &lib,
                "--speeds",
                bad,
                "--out",
                &s(&out),
            ],
            &["--speeds", bad],
        );
        refused(
            &[
                "map",
                "jumps",
                "--lib",
                &lib,
                "--speeds",
                bad,
                "--out",
                &s(&out),
            ],
            &["--speeds", bad],
        );
    }
    assert!(!out.exists());
}

// See: issue 11 item 6 — a range just within the limits still works.
#[test]
fn query_run_with_max_axis_values_speeds_still_works() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("runs.parquet");
    // 0, 0.001, …, 9.999: exactly MAX_AXIS_VALUES = 10,000 speeds.
    let printed = ok(&[
        "query",
        "run",
        "--lib",
        &s(fixture_library()),
        "--speeds",
        "0:9.999:0.001",
        "--out",
        &s(&out),
    ]);
    assert!(printed.contains("× 10000 speed(s)"), "{printed}");
    let df = read_parquet(&out).unwrap();
    let speeds = df.column("speed_mps").unwrap().f64().unwrap().clone();
    let distinct: std::collections::BTreeSet<u64> =
        speeds.into_no_null_iter().map(f64::to_bits).collect();
    assert_eq!(distinct.len(), 10_000);
}

// ---------------------------------------------------------------- item 6: threads

// See: issue 11 item 6 — `--threads 100000` spawned 100,000 threads.
#[test]
fn threads_beyond_four_per_core_are_refused_before_work() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("frames");
    let clips = fixture_clips();
    for cmd in ["frames", "build"] {
        refused(
            &[cmd, &clips[0], "--out", &s(&out), "--threads", "100000"],
            &["--threads", "100000", "MAX_THREADS_PER_CORE"],
        );
    }
    assert!(!out.exists());
    // Four per core is allowed.
    let cores = std::thread::available_parallelism().map_or(1, usize::from);
    ok(&[
        "frames",
        &clips[0],
        "--out",
        &s(&out),
        "--threads",
        &(4 * cores).to_string(),
    ]);
    assert!(out.join("frames.parquet").is_file());
}

// ---------------------------------------------------------------- item 6: twopac inputs

/// A phases file of `n` phases alternating one foot and two feet (inline boxes).
fn phases_json(n: usize, duration_s: f64) -> String {
    let kin = r#"{"kinematics": {"A": [[1,0,0],[-1,0,0],[0,1,0],[0,-1,0],[0,0,1],[0,0,-1]], "b": [0.5,0.5,0.5,0.5,1.2,-0.5]}}"#;
    let left = r#"{"effector": "left_foot", "position": [0, 0.1, 0], "normal": [0, 0, 1], "surface": {"length_m": 0.2, "width_m": 0.1}}"#;
    let right = r#"{"effector": "right_foot", "position": [0, -0.1, 0], "normal": [0, 0, 1], "surface": {"length_m": 0.2, "width_m": 0.1}}"#;
    let phases: Vec<String> = (0..n)
        .map(|j| {
            let contacts = if j % 2 == 0 {
                format!("[{left}, {right}]")
            } else {
                format!("[{left}]")
            };
            format!(r#"{{"duration_s": {duration_s}, "com": [0, 0, 0.9], "contacts": {contacts}}}"#)
        })
        .collect();
    format!(
        r#"{{"schema": "stancelib.twopac.phases/1", "mass_kg": 60,
  "effectors": {{"left_foot": {kin}, "right_foot": {kin}}},
  "phases": [{}]}}"#,
        phases.join(",\n")
    )
}

// See: issue 11 item 6 — `duration_s: 1e9` tried an 8 GB allocation.
#[test]
fn twopac_duration_beyond_max_samples_is_refused_before_work() {
    let dir = tempfile::tempdir().unwrap();
    let phases = dir.path().join("p.json");
    let out = dir.path().join("out");
    std::fs::write(&phases, phases_json(3, 1e9)).unwrap();
    refused(
        &["twopac", "--phases", &s(&phases), "--out", &s(&out)],
        &["phases[0].duration_s", "MAX_SAMPLES", "100000"],
    );
    assert!(!out.exists());
    // (At the limit a run takes minutes in the test profile: the boundary itself is a
    // unit test of `twopac::validate::check_span`.)
}

// See: issue 11 item 6 — 10⁶ phases would have run for about 8 hours.
#[test]
fn twopac_phases_beyond_max_phases_are_refused_before_work() {
    let dir = tempfile::tempdir().unwrap();
    let phases = dir.path().join("p.json");
    let out = dir.path().join("out");
    std::fs::write(&phases, phases_json(1001, 0.1)).unwrap();
    refused(
        &["twopac", "--phases", &s(&phases), "--out", &s(&out)],
        &["phases: 1001 phases", "MAX_PHASES", "1000"],
    );
    assert!(!out.exists());
}

/// `n` rectangle contacts in a ring (for a contacts file or a phase).
fn ring(n: usize) -> String {
    (0..n)
        .map(|k| {
            let a = k as f64 * std::f64::consts::TAU / n as f64;
            format!(
                r#"{{"effector": "c{k}", "position": [{:.6}, {:.6}, 0], "normal": [0, 0, 1], "friction": 0.5, "surface": {{"length_m": 0.05, "width_m": 0.05}}}}"#,
                0.3 * a.cos(),
                0.3 * a.sin()
            )
        })
        .collect::<Vec<_>>()
        .join(", ")
}

fn write_points(path: &Path, n: usize) {
    let mut df = DataFrame::new_infer_height(vec![
        Column::new("x".into(), vec![0.0; n]),
        Column::new("y".into(), vec![0.0; n]),
        Column::new("z".into(), vec![1.0; n]),
    ])
    .unwrap();
    ParquetWriter::new(std::fs::File::create(path).unwrap())
        .finish(&mut df)
        .unwrap();
}

// See: issue 11 item 6 — 1,000 contacts cost 0.5 GB and 40 s, 20,000 aborted.
#[test]
fn contacts_beyond_max_contacts_are_refused_before_work() {
    let dir = tempfile::tempdir().unwrap();
    let (contacts, points) = (dir.path().join("c.json"), dir.path().join("p.parquet"));
    let out = dir.path().join("r.parquet");
    write_points(&points, 2);
    let file = |n: usize| {
        format!(
            r#"{{"schema": "stancelib.twopac.contacts/1", "mass_kg": 54, "contacts": [{}]}}"#,
            ring(n)
        )
    };
    std::fs::write(&contacts, file(1000)).unwrap();
    refused(
        &[
            "equilibrium",
            "--contacts",
            &s(&contacts),
            "--points",
            &s(&points),
            "--out",
            &s(&out),
        ],
        &["contacts: 1000 contacts", "MAX_CONTACTS", "64"],
    );
    assert!(!out.exists());
    // Exactly MAX_CONTACTS still works.
    std::fs::write(&contacts, file(64)).unwrap();
    ok(&[
        "equilibrium",
        "--contacts",
        &s(&contacts),
        "--points",
        &s(&points),
        "--out",
        &s(&out),
    ]);
    assert_eq!(read_parquet(&out).unwrap().height(), 2);

    // The same limit per phase of a phases file.
    let phases = dir.path().join("ph.json");
    let effectors: Vec<String> = (0..65)
        .map(|k| format!(r#""c{k}": {{"kinematics": "left_foot"}}"#))
        .collect();
    std::fs::write(
        &phases,
        format!(
            r#"{{"schema": "stancelib.twopac.phases/1", "mass_kg": 60, "effectors": {{{}}},
                "phases": [{{"com": [0, 0, 1], "contacts": [{}]}}]}}"#,
            effectors.join(", "),
            ring(65)
        ),
    )
    .unwrap();
    let tw = dir.path().join("tw");
    refused(
        &["twopac", "--phases", &s(&phases), "--out", &s(&tw)],
        &["phases[0].contacts: 65 contacts", "MAX_CONTACTS"],
    );
    assert!(!tw.exists());
}

// See: issue 11 item 6 — the number of equilibrium points is bounded (read from the
// Parquet footer before the table itself).
#[test]
fn equilibrium_points_beyond_max_com_states_are_refused_before_work() {
    let dir = tempfile::tempdir().unwrap();
    let points = dir.path().join("p.parquet");
    let out = dir.path().join("r.parquet");
    write_points(&points, 1_000_001);
    refused(
        &[
            "equilibrium",
            "--contacts",
            &s(&root().join("fixtures/twopac/r2_contacts.json")),
            "--points",
            &s(&points),
            "--out",
            &s(&out),
        ],
        &["--points", "1000001 rows", "MAX_COM_STATES"],
    );
    assert!(!out.exists());
}

// See: issue 11 item 6 — an inline polytope's rows are bounded too.
#[test]
fn inline_polytope_rows_beyond_max_rows_are_refused() {
    let dir = tempfile::tempdir().unwrap();
    let phases = dir.path().join("p.json");
    let rows: Vec<&str> = (0..1025).map(|_| "[0, 0, 1]").collect();
    let b: Vec<&str> = (0..1025).map(|_| "1").collect();
    let text = phases_json(1, 1.0).replacen(
        r#"{"kinematics": {"A": [[1,0,0],[-1,0,0],[0,1,0],[0,-1,0],[0,0,1],[0,0,-1]], "b": [0.5,0.5,0.5,0.5,1.2,-0.5]}}"#,
        &format!(r#"{{"kinematics": {{"A": [{}], "b": [{}]}}}}"#, rows.join(","), b.join(",")),
        1,
    );
    std::fs::write(&phases, text).unwrap();
    let out = dir.path().join("out");
    refused(
        &["twopac", "--phases", &s(&phases), "--out", &s(&out)],
        &["effectors.left_foot.kinematics.A: 1025 rows", "MAX_ROWS"],
    );
    assert!(!out.exists());
}

// See: issue 11 item 6 (audit) — `synth --rate`/`--duration` beyond the generator's
// range were clamped silently (another clip than asked for).
#[test]
fn synth_rate_and_duration_out_of_range_are_refused() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("x.bvh");
    refused(
        &["synth", "--rate", "100000", "--out", &s(&out)],
        &["--rate", "MAX_FRAME_RATE_HZ"],
    );
    refused(
        &["synth", "--duration", "1e9", "--out", &s(&out)],
        &["--duration", "MAX_DURATION_S"],
    );
    assert!(!out.exists());
    ok(&[
        "synth",
        "--rate",
        "1000",
        "--duration",
        "0.5",
        "--out",
        &s(&out),
    ]);
    assert!(out.is_file());
}

// ---------------------------------------------------------------- item 10: pipelines

/// A pipeline file on the fixtures into `out`, plus `extra` TOML.
fn write_pipeline(path: &Path, out: &Path, extra: &str) {
    let glob = root().join("fixtures/bvh/*.bvh");
    std::fs::write(
        path,
        format!(
            "inputs = [\"{}\"]\nout = \"{}\"\nthreads = 1\n{extra}",
            s(&glob),
            s(out)
        ),
    )
    .unwrap();
}

// See: issue 11 item 10 — an invalid `[queries]` value was reported only after the
// library had been rebuilt and swapped in.
#[test]
fn a_bad_queries_value_leaves_the_existing_library_byte_identical() {
    let dir = tempfile::tempdir().unwrap();
    let lib = dir.path().join("lib");
    let pipe = dir.path().join("job.toml");
    write_pipeline(&pipe, &lib, "");
    ok(&["run", &s(&pipe)]);
    let before = snapshot(&lib);
    let around = listing(dir.path());
    assert!(before.contains_key(Path::new("stances.parquet")));
    for (bad, key_line, needle) in [
        ("[queries]\nrun_speeds = \"0:6:0\"\n", 5, "run_speeds"),
        (
            "[queries]\nrun_speeds = \"0:1e9:0.001\"\n",
            5,
            "MAX_AXIS_VALUES",
        ),
        (
            "[queries]\njump_map = true\nmap_heights = \"0:1000:1\"\nmap_speeds = \"0:1000:1\"\n",
            7,
            "MAX_GRID_CELLS",
        ),
        (
            "[queries]\nrun_speeds = \"0:6:0.5\"\nlength_scale = -1\n",
            6,
            "length_scale",
        ),
        (
            "[queries]\nlength_scale = 1.2\n",
            5,
            "has no effect without run_speeds",
        ),
        (
            "[queries]\nmap_speeds = \"0:5:0.1\"\n",
            5,
            "has no effect without jump_map",
        ),
    ] {
        write_pipeline(&pipe, &lib, bad);
        let err = refused(&["run", &s(&pipe)], &[needle]);
        let at = format!("{}:{key_line}:", s(&pipe));
        assert!(err.contains(&at), "{bad}: expected {at} in {err}");
        assert_eq!(snapshot(&lib), before, "{bad}: the library changed");
        assert_eq!(
            listing(dir.path()),
            around,
            "{bad}: files appeared beside it"
        );
    }
}

// See: issue 11 item 10 — `[constraints] mu = -1` was accepted.
#[test]
fn pipeline_constraints_mu_must_be_positive_and_finite() {
    let dir = tempfile::tempdir().unwrap();
    let lib = dir.path().join("lib");
    let pipe = dir.path().join("job.toml");
    for mu in ["-1", "0", "nan", "inf"] {
        write_pipeline(
            &pipe,
            &lib,
            &format!("[constraints]\nmu = {mu}\n[queries]\nrun_speeds = \"0:6:0.5\"\n"),
        );
        refused(
            &["run", &s(&pipe)],
            &[&format!("{}:5:", s(&pipe)), "[constraints] mu"],
        );
    }
    // Without a query stage `[constraints]` has no effect: refused as well.
    write_pipeline(&pipe, &lib, "[constraints]\nmu = 0.5\n");
    refused(
        &["run", &s(&pipe)],
        &[&format!("{}:5:", s(&pipe)), "no [queries] stage"],
    );
    assert!(!lib.exists());
}

// See: issue 11 item 10 — every value is range-checked before work: threads, contact
// thresholds.
#[test]
fn pipeline_threads_and_contact_values_are_range_checked() {
    let dir = tempfile::tempdir().unwrap();
    let lib = dir.path().join("lib");
    let pipe = dir.path().join("job.toml");
    let glob = root().join("fixtures/bvh/*.bvh");
    std::fs::write(
        &pipe,
        format!(
            "inputs = [\"{}\"]\nout = \"{}\"\nthreads = 100000\n",
            s(&glob),
            s(&lib)
        ),
    )
    .unwrap();
    refused(
        &["run", &s(&pipe)],
        &[&format!("{}:3:", s(&pipe)), "MAX_THREADS_PER_CORE"],
    );
    for (key, v) in [
        ("floor_window_s", "0"),
        ("min_on_s", "-0.1"),
        ("foot_h_on", "nan"),
    ] {
        write_pipeline(&pipe, &lib, &format!("[contacts]\n{key} = {v}\n"));
        refused(&["run", &s(&pipe)], &[&format!("{}:5:", s(&pipe)), key]);
    }
    assert!(!lib.exists());
}

// See: issue 11 item 12 — duplicate keys: the toml crate refuses them (with the line).
#[test]
fn duplicate_toml_keys_are_refused_with_their_line() {
    let dir = tempfile::tempdir().unwrap();
    let lib = dir.path().join("lib");
    let pipe = dir.path().join("job.toml");
    write_pipeline(&pipe, &lib, "threads = 2\n");
    refused(
        &["run", &s(&pipe)],
        &[&format!("{}:4:", s(&pipe)), "duplicate key"],
    );
    write_pipeline(
        &pipe,
        &lib,
        "[contacts]\nmin_on_s = 0.03\nmin_on_s = 0.04\n",
    );
    refused(
        &["run", &s(&pipe)],
        &[&format!("{}:6:", s(&pipe)), "duplicate key"],
    );
    assert!(!lib.exists());
}

// ---------------------------------------------------------------- item 11: options

// See: issue 11 item 11 — `build --joints` wrote no joints.parquet.
#[test]
fn build_joints_writes_joints_parquet_with_the_rows_of_frames_joints() {
    let dir = tempfile::tempdir().unwrap();
    let (lib, frames) = (dir.path().join("lib"), dir.path().join("frames"));
    let clips = fixture_clips();
    let mut args: Vec<&str> = vec!["build"];
    args.extend(clips.iter().map(String::as_str));
    let (lib_s, frames_s) = (s(&lib), s(&frames));
    ok(&[&args[..], &["--out", &lib_s, "--joints"]].concat());
    args[0] = "frames";
    ok(&[&args[..], &["--out", &frames_s, "--joints"]].concat());
    let a = read_parquet(&lib.join("joints.parquet")).unwrap();
    let b = read_parquet(&frames.join("joints.parquet")).unwrap();
    assert!(a.height() > 1000, "{} joint rows", a.height());
    assert!(a.equals(&b), "joints.parquet of build and frames differ");
    // Without --joints a library has none.
    let plain = dir.path().join("plain");
    ok(&["build", &clips[0], "--out", &s(&plain)]);
    assert!(!plain.join("joints.parquet").exists());
    assert!(plain.join("stances.parquet").is_file());
}

// See: issue 11 item 11 — `frames --stage-b` was accepted and changed nothing. Stage B is
// gone (issue 12); the stance-stage option that replaced it is refused by `frames` too.
#[test]
fn frames_refuses_stance_stage_options() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("frames");
    let clips = fixture_clips();
    for opt in [&["--stage-b"][..], &["--force-model", "ratio"][..]] {
        let mut args = vec!["frames", clips[0].as_str(), "--out"];
        let o = s(&out);
        args.push(&o);
        args.extend_from_slice(opt);
        refused(&args, &[opt[0]]);
    }
    assert!(!out.exists());
}

/// `query jump` on the fixture library: `(stance pair, feasible)` per row.
fn jump_verdicts(height: &str, distance: &str, extra: &[&str]) -> Vec<((String, String), bool)> {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("j.parquet");
    let (lib, out_s) = (s(fixture_library()), s(&out));
    let args = [
        &[
            "query",
            "jump",
            "--lib",
            &lib,
            "--height",
            height,
            "--distance",
            distance,
        ][..],
        extra,
        &["--out", &out_s],
    ]
    .concat();
    ok(&args);
    let df = read_parquet(&out).unwrap();
    let col = |n: &str| -> Vec<String> {
        df.column(n)
            .unwrap()
            .str()
            .unwrap()
            .iter()
            .map(|v| v.unwrap().to_string())
            .collect()
    };
    let feasible: Vec<bool> = df
        .column("feasible")
        .unwrap()
        .bool()
        .unwrap()
        .iter()
        .map(|v| v.unwrap())
        .collect();
    let mut v: Vec<((String, String), bool)> = col("liftoff_stance_id")
        .into_iter()
        .zip(col("landing_stance_id"))
        .zip(feasible)
        .collect();
    v.sort();
    v
}

// See: issue 11 item 11 — `--mu` was ignored under relative limits (the default of
// `query jump` and `map jumps`).
#[test]
fn mu_acts_under_relative_limits() {
    // On the fixtures every recorded μ_req is small (the jumps push straight up), so
    // 1.05 μ_req refuses these jumps and μ = 0.3 lets some through.
    let (h, d) = ("1.1", "0");
    let default = jump_verdicts(h, d, &[]);
    let relative = jump_verdicts(h, d, &["--limits", "relative"]);
    assert_eq!(
        default, relative,
        "relative is the default form of query jump"
    );
    let with_mu = jump_verdicts(h, d, &["--mu", "0.3"]);
    assert_eq!(
        default.iter().map(|r| &r.0).collect::<Vec<_>>(),
        with_mu.iter().map(|r| &r.0).collect::<Vec<_>>()
    );
    assert!(!default.is_empty());
    assert_ne!(
        default, with_mu,
        "--mu 0.3 changed no verdict under relative limits"
    );
    let count = |v: &[((String, String), bool)]| v.iter().filter(|r| r.1).count();
    assert!(count(&with_mu) > count(&default), "{with_mu:?}");
}

// See: issue 11 item 11 (audit) — `twopac --character` without `--lib`, and `--lib`
// for a phases file that uses no library polytope, were accepted and ignored.
#[test]
fn twopac_library_options_without_effect_are_refused() {
    let dir = tempfile::tempdir().unwrap();
    let phases = dir.path().join("p.json");
    std::fs::write(&phases, phases_json(2, 0.5)).unwrap();
    let out = dir.path().join("out");
    refused(
        &[
            "twopac",
            "--phases",
            &s(&phases),
            "--character",
            "sk-x",
            "--out",
            &s(&out),
        ],
        &["--lib"],
    );
    refused(
        &[
            "twopac",
            "--phases",
            &s(&phases),
            "--lib",
            &s(fixture_library()),
            "--out",
            &s(&out),
        ],
        &["--lib", "uses no library polytope"],
    );
    assert!(!out.exists());
}

// See: issue 11 item 11 (audit) — an unknown `[landmarks]` name in a body file was ignored.
#[test]
fn body_file_refuses_unknown_landmark_names() {
    let dir = tempfile::tempdir().unwrap();
    let body = dir.path().join("body.toml");
    std::fs::write(
        &body,
        "mass_kg = 70\n[landmarks]\nAJC_L = \"LeftFoot\"\nankle_l = \"LeftFoot\"\n",
    )
    .unwrap();
    let out = dir.path().join("frames");
    refused(
        &[
            "frames",
            &fixture_clips()[0],
            "--body",
            &s(&body),
            "--out",
            &s(&out),
        ],
        &[&format!("{}:4:", s(&body)), "ankle_l"],
    );
    assert!(!out.exists());
}

// ---------------------------------------------------------------- item 12: JSON keys

// See: issue 11 item 12 — duplicate JSON keys were accepted (last wins).
#[test]
fn duplicate_json_keys_are_refused_with_their_path() {
    let dir = tempfile::tempdir().unwrap();
    let (contacts, points) = (dir.path().join("c.json"), dir.path().join("p.parquet"));
    write_points(&points, 1);
    let out = dir.path().join("r.parquet");
    let text = std::fs::read_to_string(root().join("fixtures/twopac/r2_contacts.json")).unwrap();
    std::fs::write(
        &contacts,
        text.replacen("\"mass_kg\"", "\"mass_kg\": 1, \"mass_kg\"", 1),
    )
    .unwrap();
    refused(
        &[
            "equilibrium",
            "--contacts",
            &s(&contacts),
            "--points",
            &s(&points),
            "--out",
            &s(&out),
        ],
        &["mass_kg: duplicate key \"mass_kg\"", "(line "],
    );
    assert!(!out.exists());

    let phases = dir.path().join("p.json");
    let tw = dir.path().join("tw");
    let text = phases_json(2, 0.5).replacen(
        "\"duration_s\": 0.5",
        "\"duration_s\": 0.5, \"duration_s\": 9",
        2,
    );
    std::fs::write(&phases, text).unwrap();
    refused(
        &["twopac", "--phases", &s(&phases), "--out", &s(&tw)],
        &["phases[0].duration_s: duplicate key \"duration_s\""],
    );
    let text = phases_json(2, 0.5).replacen(
        "\"left_foot\": {",
        "\"right_foot\": {}, \"left_foot\": {",
        1,
    );
    std::fs::write(&phases, text).unwrap();
    refused(
        &["twopac", "--phases", &s(&phases), "--out", &s(&tw)],
        &["effectors.right_foot: duplicate key"],
    );
    assert!(!tw.exists());
}
