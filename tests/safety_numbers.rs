//! Issue 40 ("Trust nothing read back"), item 5: every number written is finite, or the
//! clip or input is an error. A segment far longer than its skeleton's others is a per-clip
//! error before forward kinematics (`skeleton::plausibility::MAX_SEGMENT_RATIO`); a stance
//! row with inf or NaN is never written (the clip becomes an error of stage `stances`);
//! `twopac` and `equilibrium` refuse coordinates, durations and friction beyond their
//! documented bounds (`twopac::phases::MAX_*`, `MIN_PHASE_DURATION_S`).

use std::path::Path;

use crate::safety_caps::write_points;
use crate::safety_inputs::{fixture_text, write_temp};
use crate::util::{refused, root, s, stancelib};
use stancelib::library::codec::table::read_parquet;

/// `text` with the OFFSET of joint `joint` replaced by `offset`.
fn with_joint_offset(text: &str, joint: &str, offset: &str) -> String {
    let mut lines: Vec<String> = text.lines().map(String::from).collect();
    let j = lines
        .iter()
        .position(|l| l.trim() == format!("JOINT {joint}"))
        .unwrap_or_else(|| panic!("no joint {joint}"));
    let k = (j..lines.len())
        .find(|&k| lines[k].trim_start().starts_with("OFFSET"))
        .unwrap();
    let indent: String = lines[k].chars().take_while(|c| c.is_whitespace()).collect();
    lines[k] = format!("{indent}OFFSET {offset}");
    lines.join("\n") + "\n"
}

/// Every float of `df` (plain float columns) is finite.
fn all_finite(df: &polars::prelude::DataFrame) -> bool {
    df.columns().iter().all(|c| {
        c.f64()
            .map(|v| v.iter().flatten().all(f64::is_finite))
            .unwrap_or(true)
    })
}

/// `build good bad --out lib`: exit 1, the bad clip an error whose message has `needle`,
/// the good clip's stances written and every stance number finite.
fn build_one_bad(bad_text: &str, needle: &str) {
    let d = tempfile::tempdir().unwrap();
    let good = root().join("fixtures/bvh/run_60hz_cm_zup.bvh");
    let bad = write_temp(d.path(), "bad_head.bvh", bad_text);
    let lib = d.path().join("lib");
    let (code, out, err) = stancelib(&["build", &s(&good), &s(&bad), "--out", &s(&lib)]);
    assert_eq!(code, 1, "{out}\n{err}");
    assert!(err.contains(needle), "{err}");
    let clips = read_parquet(&lib.join("clips.parquet")).unwrap();
    let status: Vec<Option<&str>> = clips
        .column("status")
        .unwrap()
        .str()
        .unwrap()
        .iter()
        .collect();
    assert_eq!(status, [Some("error"), Some("ok")], "bad_head sorts first");
    let stances = read_parquet(&lib.join("stances.parquet")).unwrap();
    assert!(stances.height() > 0);
    assert!(all_finite(&stances));
    let frames = read_parquet(&lib.join("frames.parquet")).unwrap();
    assert!(all_finite(&frames));
}

// See: issue 40 item 5 — a head OFFSET 1e6 gave a COM 1.96 km away with status ok.
#[test]
fn a_head_offset_of_1e6_is_a_per_clip_error() {
    let text = with_joint_offset(&fixture_text("run_120hz_m_yup.bvh"), "Head", "0 1e6 0");
    build_one_bad(&text, "segment 'Head'");
}

// See: issue 40 item 5 — `OFFSET 1e155 -1e155 0` on the head of a real clip: status ok,
// `f_peak_n`, `mu_req`, `fit_rms_*` = inf; the fuzzer found the same with `OFFSET 1e26`.
#[test]
fn a_joint_offset_of_1e155_or_1e26_is_a_per_clip_error() {
    for off in ["1e155 -1e155 0", "0 1e26 0"] {
        let text = with_joint_offset(&fixture_text("run_120hz_m_yup.bvh"), "Head", off);
        build_one_bad(&text, "MAX_SEGMENT_RATIO");
    }
    // Elsewhere in the tree too: a forearm.
    let text = with_joint_offset(
        &fixture_text("run_120hz_m_yup.bvh"),
        "LeftForeArm",
        "0 1e26 0",
    );
    build_one_bad(&text, "segment 'LeftForeArm'");
}

// See: issue 40 item 5 — `--mass 1e300` put inf into the stances with status ok. The last
// guard turns such a clip into an error of stage `stances` (or, once the body-mass bounds
// refuse the option, the run stops before any work): no non-finite row either way.
// TODO(issue 40 item 5): with the lead's body-mass bounds on main, this becomes a refusal
// test and the guard needs another input (none is known that passes every other check).
#[test]
fn a_mass_of_1e300_writes_no_stance_row_of_inf() {
    let d = tempfile::tempdir().unwrap();
    let clip = root().join("fixtures/bvh/run_60hz_cm_zup.bvh");
    let lib = d.path().join("lib");
    let (code, out, err) = stancelib(&["build", &s(&clip), "--out", &s(&lib), "--mass", "1e300"]);
    // Refused before any work, naming the option and the bounds.
    assert_eq!(code, 2, "{out}\n{err}");
    assert!(
        err.contains("--mass") && err.contains("[1, 1000] kg"),
        "{err}"
    );
    assert!(!lib.exists(), "nothing written");
}

/// `walk_flat.json` with `from` replaced once by `to`, written into `dir`.
fn walk_with(dir: &Path, from: &str, to: &str) -> String {
    let text = std::fs::read_to_string(root().join("fixtures/twopac/walk_flat.json")).unwrap();
    assert!(text.contains(from), "{from}");
    s(&write_temp(dir, "phases.json", &text.replacen(from, to, 1)))
}

// See: issue 40 item 5 — `twopac` with `com 1e308`: 2,889 NaN in trajectory.parquet.
#[test]
fn twopac_refuses_a_com_of_1e308() {
    let d = tempfile::tempdir().unwrap();
    let p = walk_with(d.path(), "[0.0, 0.0, 0.85]", "[1e308, 0.0, 0.85]");
    let out = d.path().join("tw");
    refused(
        &["twopac", "--phases", &p, "--out", &s(&out)],
        &["phases[0].com", "MAX_COORDINATE_M"],
    );
    assert!(!out.exists());
}

// See: issue 40 item 5 — `twopac` with `duration_s 5e-324`: NaN accelerations.
#[test]
fn twopac_refuses_a_duration_of_5e_324() {
    let d = tempfile::tempdir().unwrap();
    let p = walk_with(d.path(), "\"duration_s\": 0.8", "\"duration_s\": 5e-324");
    let out = d.path().join("tw");
    refused(
        &["twopac", "--phases", &p, "--out", &s(&out)],
        &["phases[0].duration_s", "MIN_PHASE_DURATION_S"],
    );
    assert!(!out.exists());
}

/// `equilibrium` on `r2_contacts.json` with `from` replaced once by `to`: stderr.
fn equilibrium_refused(from: &str, to: &str, needles: &[&str]) {
    let d = tempfile::tempdir().unwrap();
    let text = std::fs::read_to_string(root().join("fixtures/twopac/r2_contacts.json")).unwrap();
    assert!(text.contains(from), "{from}");
    let c = write_temp(d.path(), "c.json", &text.replacen(from, to, 1));
    let points = d.path().join("p.parquet");
    write_points(&points, 2);
    let out = d.path().join("r.parquet");
    refused(
        &[
            "equilibrium",
            "--contacts",
            &s(&c),
            "--points",
            &s(&points),
            "--out",
            &s(&out),
        ],
        needles,
    );
    assert!(!out.exists());
}

// See: issue 40 item 5 — `equilibrium` with friction 1e308 called a feasible point
// infeasible.
#[test]
fn equilibrium_refuses_a_friction_of_1e308() {
    equilibrium_refused(
        "\"friction\": 0.3",
        "\"friction\": 1e308",
        &["contacts[0].friction", "MAX_FRICTION"],
    );
}

// See: issue 40 item 5 — `equilibrium` with mass 1e100 called a feasible point
// infeasible. The bounds are the body-mass bounds of `ingest::masses`, not repeated here.
#[test]
fn equilibrium_refuses_a_mass_of_1e100() {
    equilibrium_refused(
        "\"mass_kg\": 54.0",
        "\"mass_kg\": 1e100",
        &["mass_kg", "[1, 1000] kg"],
    );
}

// Contact positions and points beyond the coordinate bound are refused too.
#[test]
fn equilibrium_refuses_positions_beyond_max_coordinate() {
    equilibrium_refused(
        "\"position\": [0.05, 0.1, 0]",
        "\"position\": [1e300, 0.1, 0]",
        &["contacts[0].position", "MAX_COORDINATE_M"],
    );
}
