//! Issue 11 item 6: bounded work from small inputs (every documented work cap refused before
//! any work, exit 2, the field and the cap named, nothing written): query ranges, map
//! grids, threads, twopac inputs, `synth`. Items 10–12 are in `safety_options`.
//!
//! Everything runs on the committed fixtures (`fixtures/bvh`, `fixtures/twopac`).

use crate::util::{fixture_clips, fixture_library, ok, refused, root, s};
use std::path::Path;

use polars::prelude::*;
use stancelib::library::codec::table::read_parquet;

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
pub(super) fn phases_json(n: usize, duration_s: f64) -> String {
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
pub(super) fn ring(n: usize) -> String {
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

pub(super) fn write_points(path: &Path, n: usize) {
    let mut df = DataFrame::new_infer_height(vec![
        Column::new("x_m".into(), vec![0.0; n]),
        Column::new("y_m".into(), vec![0.0; n]),
        Column::new("z_m".into(), vec![1.0; n]),
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
