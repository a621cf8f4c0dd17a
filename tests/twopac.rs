//! The `equilibrium` and `twopac` commands end to end on `fixtures/twopac/` (spec two-pac
//! §1.1, §8, §8.2, §9): reference margins, the single-point-contact verdict, trajectory
//! boundary states, transition points inside kinematic boxes recomputed here from the
//! JSON, `timings.json` keys, and bad JSON rejected with its JSON path (exit 2, nothing
//! written).

use std::path::{Path, PathBuf};

use polars::prelude::*;
use stancelib::library::codec::table::Table;

use crate::util::{fails, ok};

fn fixture(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("fixtures/twopac")
        .join(name)
}

fn s(p: &Path) -> String {
    p.display().to_string()
}

/// Writes a points table with the given columns.
fn write_points(path: &Path, cols: &[(&str, Vec<f64>)]) {
    let mut df = DataFrame::new_infer_height(
        cols.iter()
            .map(|(n, v)| Column::new((*n).into(), v.clone()))
            .collect(),
    )
    .unwrap();
    ParquetWriter::new(std::fs::File::create(path).unwrap())
        .finish(&mut df)
        .unwrap();
}

fn equilibrium(contacts: &Path, cols: &[(&str, Vec<f64>)]) -> (tempfile::TempDir, Table) {
    let dir = tempfile::tempdir().unwrap();
    let (p, r) = (dir.path().join("p.parquet"), dir.path().join("r.parquet"));
    write_points(&p, cols);
    ok(&[
        "equilibrium",
        "--contacts",
        &s(contacts),
        "--points",
        &s(&p),
        "--out",
        &s(&r),
    ]);
    let t = Table::open(&r).unwrap();
    (dir, t)
}

#[test]
fn equilibrium_reference_case_r2() {
    // Spec §9 R2: m = 54, μ = 0.3, four points (±0.05, ±0.1, 0): margin ≈ 38.05 N at
    // (0, 0, 1), ≈ −77546 N with c̈ = (1000, 0, 0). Tolerances: the spec gives 4 and 5
    // significant figures.
    let (_d, t) = equilibrium(
        &fixture("r2_contacts.json"),
        &[
            ("x_m", vec![0.0, 0.0]),
            ("y_m", vec![0.0, 0.0]),
            ("z_m", vec![1.0, 1.0]),
            ("ax_mps2", vec![0.0, 1000.0]),
        ],
    );
    let margin = t.opt_f64("margin_n").unwrap();
    assert!((margin[0].unwrap() - 38.05).abs() < 0.01, "{margin:?}");
    assert!((margin[1].unwrap() + 77546.0).abs() < 1.0, "{margin:?}");
    assert_eq!(t.bools("in_equilibrium").unwrap(), [true, false]);
    assert_eq!(t.strings("status").unwrap(), ["solved", "solved"]);
    assert_eq!(t.f64s("z_m").unwrap(), [1.0, 1.0]);
}

#[test]
fn equilibrium_single_point_contact_only_on_its_vertical() {
    let dir = tempfile::tempdir().unwrap();
    let c = dir.path().join("c.json");
    std::fs::write(
        &c,
        r#"{"schema": "stancelib.twopac.contacts/1", "mass_kg": 60,
            "contacts": [{"effector": "hand", "position": [0.2, -0.1, 0.0], "normal": [0, 0, 1]}]}"#,
    )
    .unwrap();
    let (_d, t) = equilibrium(
        &c,
        &[
            ("x_m", vec![0.2, 0.25, 0.2]),
            ("y_m", vec![-0.1, -0.1, 0.0]),
            ("z_m", vec![1.0, 1.0, 0.8]),
        ],
    );
    assert_eq!(
        t.strings("status").unwrap(),
        ["solved", "infeasible", "infeasible"]
    );
    assert_eq!(t.bools("in_equilibrium").unwrap(), [true, false, false]);
    let m = t.opt_f64("margin_n").unwrap();
    assert!(
        m[0].unwrap() > 0.0 && m[1].is_none() && m[2].is_none(),
        "{m:?}"
    );
}

#[test]
fn equilibrium_ring_scene_centre_in_far_out() {
    // §8.1 ring scene: a COM above the ring's centre is held, one 3 m away is not
    // (unless the set were in force closure, which would say so for every point).
    let (_d, t) = equilibrium(
        &fixture("ring_contacts.json"),
        &[
            ("x_m", vec![0.0, 3.0]),
            ("y_m", vec![0.0, 0.0]),
            ("z_m", vec![0.9, 0.9]),
        ],
    );
    let status = t.strings("status").unwrap();
    let inside = t.bools("in_equilibrium").unwrap();
    assert!(inside[0], "{status:?}");
    assert!(
        status[1] == "force_closure" || !inside[1],
        "{status:?} {inside:?}"
    );
}

#[test]
fn equilibrium_missing_column_names_file_and_column() {
    let dir = tempfile::tempdir().unwrap();
    let p = dir.path().join("p.parquet");
    write_points(&p, &[("x_m", vec![0.0]), ("y_m", vec![0.0])]);
    let r = dir.path().join("r.parquet");
    let err = fails(&[
        "equilibrium",
        "--contacts",
        &s(&fixture("r2_contacts.json")),
        "--points",
        &s(&p),
        "--out",
        &s(&r),
    ]);
    assert!(err.contains("p.parquet") && err.contains("'z_m'"), "{err}");
    assert!(!r.exists());
}

fn read_json(path: &Path) -> serde_json::Value {
    serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap()
}

fn twopac(phases: &Path) -> (tempfile::TempDir, PathBuf, String) {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("out");
    let printed = ok(&["twopac", "--phases", &s(phases), "--out", &s(&out)]);
    (dir, out, printed)
}

fn xyz(t: &Table, i: usize) -> [f64; 3] {
    ["x_m", "y_m", "z_m"].map(|c| t.f64s(c).unwrap()[i])
}

/// The world box of a flat contact's inline box polytope (yaw 0 and axis-aligned rows
/// in the fixtures): `lo ≤ c − p ≤ hi`.
fn world_box(kin: &serde_json::Value, p: [f64; 3]) -> ([f64; 3], [f64; 3]) {
    let a: Vec<[f64; 3]> = serde_json::from_value(kin["A"].clone()).unwrap();
    let b: Vec<f64> = serde_json::from_value(kin["b"].clone()).unwrap();
    let (mut lo, mut hi) = ([f64::NEG_INFINITY; 3], [f64::INFINITY; 3]);
    for (r, bi) in a.iter().zip(&b) {
        let k = r.iter().position(|v| *v != 0.0).unwrap();
        if r[k] > 0.0 {
            hi[k] = hi[k].min(bi / r[k] + p[k]);
        } else {
            lo[k] = lo[k].max(bi / r[k] + p[k]);
        }
    }
    (lo, hi)
}

#[test]
fn twopac_flat_walk_outputs() {
    let input = fixture("walk_flat.json");
    let json = read_json(&input);
    let (_d, out, printed) = twopac(&input);
    let traj = Table::open(&out.join("trajectory.parquet")).unwrap();
    let phases = Table::open(&out.join("phases.parquet")).unwrap();
    let trans = Table::open(&out.join("transitions.parquet")).unwrap();
    let n = traj.height();
    assert!(n > 100, "{printed}");

    // Boundary states: the curve starts at phase 0's state with the start velocity and
    // ends at the last phase's state at rest (§5.1, §6); 1e-9 m is round-off.
    let time = traj.f64s("time_s").unwrap();
    let vel = |i: usize| ["vx_mps", "vy_mps", "vz_mps"].map(|c| traj.f64s(c).unwrap()[i]);
    for k in 0..3 {
        assert!((xyz(&traj, 0)[k] - xyz(&phases, 0)[k]).abs() < 1e-9);
        assert!((xyz(&traj, n - 1)[k] - xyz(&phases, phases.height() - 1)[k]).abs() < 1e-9);
        assert!(vel(0)[k].abs() < 1e-9 && vel(n - 1)[k].abs() < 1e-9);
    }
    // The data clock: starts at the middle of phase 0, ends at the middle of the last.
    let durs: Vec<f64> = json["phases"]
        .as_array()
        .unwrap()
        .iter()
        .map(|p| p["duration_s"].as_f64().unwrap())
        .collect();
    let last_mid = durs.iter().sum::<f64>() - durs[durs.len() - 1] / 2.0;
    assert!((time[0] - durs[0] / 2.0).abs() < 1e-12);
    assert!(
        (time[n - 1] - last_mid).abs() < 1e-9,
        "{} vs {last_mid}",
        time[n - 1]
    );
    assert!(time.windows(2).all(|w| w[1] > w[0]));

    // One transition per boundary, each inside the world boxes of the phase with more
    // contacts (recomputed from the JSON; 1e-9 m is the QP's round-off).
    assert_eq!(trans.height(), durs.len() - 1);
    let kin_phase = trans.i64s("kinematics_phase").unwrap();
    for (i, &kp) in kin_phase.iter().enumerate() {
        let c = xyz(&trans, i);
        for contact in json["phases"][kp as usize]["contacts"].as_array().unwrap() {
            let eff = contact["effector"].as_str().unwrap();
            let p: [f64; 3] = serde_json::from_value(contact["position"].clone()).unwrap();
            let (lo, hi) = world_box(&json["effectors"][eff]["kinematics"], p);
            for k in 0..3 {
                assert!(
                    c[k] >= lo[k] - 1e-9 && c[k] <= hi[k] + 1e-9,
                    "transition {i} at {c:?} outside {eff}'s box {lo:?}..{hi:?}"
                );
            }
        }
    }
    // Flat feet with generous boxes: every transition is statically feasible.
    assert!(trans.bools("static_feasible").unwrap().iter().all(|v| *v));
    assert_eq!(
        trans.strings("change").unwrap(),
        ["remove", "add", "remove", "add", "remove", "add", "remove", "add", "remove"]
    );

    // The §5.4 guarantee is consistent with the per-control-point violations.
    let win = Table::open(&out.join("windows.parquet")).unwrap();
    let viol = win.f64_lists("kept_violation_m", None).unwrap();
    let nv = win.i64s("n_violations").unwrap();
    for (v, n) in viol.iter().zip(&nv) {
        assert_eq!(v.iter().filter(|x| **x > 1e-9).count() as i64, *n);
    }
    // A remove-then-add pair makes a two-attractor window (§6 step 1).
    assert_eq!(win.i64s("n_attractors").unwrap()[0], 2);

    // timings.json: the layout of CORRECTIONS Issue 5 item 5.
    let t = read_json(&out.join("timings.json"));
    let stat = |v: &serde_json::Value| {
        let (m, p) = (v["median"].as_f64().unwrap(), v["p95"].as_f64().unwrap());
        assert!(m > 0.0 && p >= m, "{v}");
    };
    assert_eq!(t["phases"].as_array().unwrap().len(), durs.len());
    for (j, p) in t["phases"].as_array().unwrap().iter().enumerate() {
        assert_eq!(p["phase"], j);
        assert!(p["n_contacts"].as_u64().unwrap() >= 1);
        stat(&p["constraint_build_s"]);
    }
    assert_eq!(t["transitions"].as_array().unwrap().len(), durs.len() - 1);
    for (j, p) in t["transitions"].as_array().unwrap().iter().enumerate() {
        assert_eq!(p["transition"], j);
        stat(&p["qp_eq6_s"]);
        stat(&p["qp_eq13_s"]);
    }
    stat(&t["trajectory_s"]);
    stat(&t["validation_s"]);

    // No solve time in the Parquet files (§8).
    for f in [
        "trajectory",
        "transitions",
        "phases",
        "windows",
        "validation",
    ] {
        let cols = Table::open(&out.join(format!("{f}.parquet")))
            .unwrap()
            .df
            .get_column_names()
            .iter()
            .map(|c| c.as_str())
            .collect::<Vec<_>>()
            .join(",");
        for word in ["solve", "elapsed", "timing", "qp_"] {
            assert!(!cols.contains(word), "{f}: {cols}");
        }
    }
    let png = std::fs::read(out.join("trajectory.png")).unwrap();
    assert!(png.starts_with(b"\x89PNG") && png.len() > 10_000);
}

#[test]
fn twopac_hand_on_wall_runs_and_is_deterministic() {
    let input = fixture("hand_wall.json");
    let (_d1, a, _) = twopac(&input);
    let (_d2, b, _) = twopac(&input);
    for f in [
        "trajectory",
        "transitions",
        "phases",
        "windows",
        "validation",
    ] {
        let name = format!("{f}.parquet");
        let (ta, tb) = (
            Table::open(&a.join(&name)).unwrap(),
            Table::open(&b.join(&name)).unwrap(),
        );
        assert!(ta.df.equals_missing(&tb.df), "{name} differs between runs");
    }
    let trans = Table::open(&a.join("transitions.parquet")).unwrap();
    assert_eq!(
        trans.strings("effector").unwrap(),
        ["right_hand", "left_foot", "left_foot", "right_hand"]
    );
    // The hand's polytope (wall normal −X, symmetric box) bounds the transitions that
    // keep the hand: z ≤ 1.3 + 0.2 m.
    let kp = trans.i64s("kinematics_phase").unwrap();
    for (i, z) in trans.f64s("z_m").unwrap().iter().enumerate() {
        if kp[i] != 0 && kp[i] != 4 {
            assert!(
                *z <= 1.5 + 1e-9 && *z >= 1.3 - 0.75 - 1e-9,
                "transition {i}: z = {z}"
            );
        }
    }
}

const WALK: &str = "walk_flat.json";

/// Runs `twopac` on the walk fixture edited by `edit`; it must exit 2 naming `path`, and
/// write nothing.
fn rejected(edit: impl Fn(&mut serde_json::Value), path: &str) -> String {
    let mut json = read_json(&fixture(WALK));
    edit(&mut json);
    let dir = tempfile::tempdir().unwrap();
    let input = dir.path().join("bad.json");
    std::fs::write(&input, serde_json::to_string_pretty(&json).unwrap()).unwrap();
    let out = dir.path().join("out");
    let err = fails(&["twopac", "--phases", &s(&input), "--out", &s(&out)]);
    assert!(
        err.contains("bad.json") && err.contains(path),
        "expected {path}: {err}"
    );
    assert!(!out.exists(), "{err}");
    err
}

#[test]
fn twopac_rejects_unknown_key_with_its_path_and_line() {
    let err = rejected(
        |j| j["phases"][2]["contacts"][1]["frictoin"] = 0.5.into(),
        "phases[2].contacts[1]: unknown field `frictoin`",
    );
    assert!(err.contains("line "), "{err}");
    rejected(|j| j["mass"] = 70.into(), "unknown field `mass`");
}

#[test]
fn twopac_rejects_zero_normal() {
    rejected(
        |j| j["phases"][3]["contacts"][0]["normal"] = serde_json::json!([0, 0, 0]),
        "phases[3].contacts[0].normal: zero length",
    );
}

#[test]
fn twopac_rejects_two_changes_in_one_boundary() {
    // Phase 2 moves the right foot and adds the left foot: two changes.
    let err = rejected(
        |j| j["phases"][2]["contacts"][1]["position"] = serde_json::json!([0.3, -0.1, 0.0]),
        "phases[2]: differs from phases[1] by 2 added and 1 removed",
    );
    assert!(err.contains("exactly one change"), "{err}");
}

#[test]
fn twopac_named_kinematics_need_a_library() {
    let err = rejected(
        |j| j["effectors"]["left_foot"]["kinematics"] = "left_foot".into(),
        "--lib",
    );
    assert!(err.contains("left_foot"), "{err}");
    rejected(
        |j| j["effectors"]["left_foot"]["kinematics"] = "left_elbow".into(),
        "effectors.left_foot.kinematics: unknown polytope \"left_elbow\"",
    );
}

#[test]
fn twopac_eq6_and_eq13_agree_when_static() {
    // Spec §4: with s = 0 both forms give the same transition point (to 1e-4 m there;
    // here the same tolerance, the QPs' regularisation moves points by far less).
    let input = fixture(WALK);
    let dir = tempfile::tempdir().unwrap();
    let (a, b) = (dir.path().join("eq13"), dir.path().join("eq6"));
    ok(&["twopac", "--phases", &s(&input), "--out", &s(&a)]);
    ok(&[
        "twopac",
        "--phases",
        &s(&input),
        "--form",
        "eq6",
        "--out",
        &s(&b),
    ]);
    let (ta, tb) = (
        Table::open(&a.join("transitions.parquet")).unwrap(),
        Table::open(&b.join("transitions.parquet")).unwrap(),
    );
    assert!(ta.strings("form").unwrap().iter().all(|f| f == "eq13"));
    assert!(tb.strings("form").unwrap().iter().all(|f| f == "eq6"));
    assert!(tb
        .opt_f64("slack_m")
        .unwrap()
        .iter()
        .all(|v| v.unwrap() < 1e-9));
    for i in 0..ta.height() {
        let (pa, pb) = (xyz(&ta, i), xyz(&tb, i));
        for k in 0..3 {
            assert!(
                (pa[k] - pb[k]).abs() < 1e-4,
                "transition {i}: {pa:?} vs {pb:?}"
            );
        }
    }
}

/// A recorded walk with the library's own foot polytopes (`--lib`): the contact phases of
/// `cmu_07_01_walk_mb` (foot contact runs from `contacts.parquet`, data COM at each phase's
/// middle frame) planned against `kinematics.parquet` of the same library. The data COM
/// lies in its own polytopes, so the plan must succeed, and every transition point lies
/// inside the world-frame polytopes of its phase (kinematic feasibility never violated).
#[test]
fn twopac_plans_a_recorded_walk_with_the_library_polytopes() {
    let Some(data) =
        crate::util::shared_or_skip("twopac_plans_a_recorded_walk_with_the_library_polytopes")
    else {
        return;
    };
    let data = data.join("bvh");
    let dir = tempfile::tempdir().unwrap();
    let lib = dir.path().join("lib");
    let clip = "cmu_07_01_walk_mb";
    let files = vec![data.join("walk").join(format!("{clip}.bvh"))];
    let opts = stancelib::pipeline::engine::streaming::BuildOptions::default();
    stancelib::pipeline::engine::streaming::build_and_write(&files, &lib, &opts, false).unwrap();
    let c = Table::open(&lib.join("contacts.parquet")).unwrap();
    let (eff, first, last) = (
        c.strings("effector").unwrap(),
        c.i64s("first_frame").unwrap(),
        c.i64s("last_frame").unwrap(),
    );
    let (ox, oy, oz, yaw) = (
        c.f64s("origin_x_m").unwrap(),
        c.f64s("origin_y_m").unwrap(),
        c.f64s("origin_z_m").unwrap(),
        c.f64s("yaw_rad").unwrap(),
    );
    let f = Table::open(&lib.join("frames.parquet")).unwrap();
    let (frame, time) = (f.i64s("frame").unwrap(), f.f64s("time_clip_s").unwrap());
    let com = [
        f.f64s("com_x_m").unwrap(),
        f.f64s("com_y_m").unwrap(),
        f.f64s("com_z_m").unwrap(),
    ];
    let row_of = |k: i64| frame.iter().position(|&x| x == k).unwrap();
    // Events: a foot run starts at first_frame, ends after last_frame; additions first.
    let mut events: Vec<(i64, u8, usize)> = Vec::new();
    for i in (0..c.height()).filter(|&i| eff[i].ends_with("_foot")) {
        events.push((first[i], 0, i));
        events.push((last[i] + 1, 1, i));
    }
    events.sort();
    let mut active: Vec<usize> = Vec::new();
    let mut phases = Vec::new();
    for w in events.windows(2).take(12) {
        let (k, kind, run) = w[0];
        if kind == 0 {
            active.push(run);
        } else {
            active.retain(|&r| r != run);
        }
        let next = w[1].0;
        if active.is_empty() || next <= k {
            continue;
        }
        let mid = row_of((k + next - 1) / 2);
        let contacts: Vec<serde_json::Value> = active
            .iter()
            .map(|&r| {
                serde_json::json!({
                    "effector": eff[r], "position": [ox[r], oy[r], oz[r]],
                    "normal": [0.0, 0.0, 1.0], "yaw_rad": yaw[r],
                    "surface": {"length_m": 0.22, "width_m": 0.09}
                })
            })
            .collect();
        let dur = time[row_of(next - 1)] - time[row_of(k)];
        phases.push(serde_json::json!({
            "duration_s": dur, "com": [com[0][mid], com[1][mid], com[2][mid]],
            "contacts": contacts
        }));
    }
    assert!(phases.len() >= 4, "{} phases", phases.len());
    let walk = serde_json::json!({
        "schema": "stancelib.twopac.phases/1", "mass_kg": 70.0,
        "effectors": {"left_foot": {"kinematics": "left_foot"},
                      "right_foot": {"kinematics": "right_foot"}},
        "phases": phases,
    });
    let file = dir.path().join("walk_lib.json");
    std::fs::write(&file, serde_json::to_string_pretty(&walk).unwrap()).unwrap();
    let out = dir.path().join("out");
    ok(&[
        "twopac",
        "--phases",
        &s(&file),
        "--lib",
        &s(&lib),
        "--out",
        &s(&out),
    ]);
    let t = Table::open(&out.join("transitions.parquet")).unwrap();
    assert_eq!(t.height(), phases.len() - 1);
    for (i, m) in t.opt_f64("kinematic_margin_m").unwrap().iter().enumerate() {
        let m = m.unwrap_or_else(|| panic!("transition {i}: no kinematic margin"));
        assert!(
            m >= -1e-9,
            "transition {i} outside the library polytopes by {m} m"
        );
    }
    // The same clip through `--clip` (static / multi-contact mode, phases from its own
    // contact runs): planned, and its COM compared with the recorded one.
    let out = dir.path().join("clip");
    let walk_bvh = s(&files[0]);
    let printed = ok(&[
        "twopac",
        "--clip",
        &walk_bvh,
        "--lib",
        &s(&lib),
        "--out",
        &s(&out),
    ]);
    let rec: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("recorded.json")).unwrap()).unwrap();
    let rms = rec["rms_to_recorded_m"].as_f64().unwrap();
    assert!(rec["n_phases"].as_u64().unwrap() >= 4, "{rec}");
    // Measured 0.10 m on this walk (dynamic walking is not quasi-static); 0.2 m would
    // mean the phases or the clock were wrong.
    assert!(rms > 0.0 && rms < 0.2, "RMS {rms} m\n{printed}");
    let t = Table::open(&out.join("transitions.parquet")).unwrap();
    for (i, m) in t.opt_f64("kinematic_margin_m").unwrap().iter().enumerate() {
        assert!(
            m.unwrap() >= -1e-9,
            "--clip transition {i} outside the polytopes"
        );
    }
    let no_lib = fails(&["twopac", "--clip", &walk_bvh, "--out", &s(&out)]);
    assert!(no_lib.contains("--lib"), "{no_lib}");
}

// See: issue 38 item 7 — the bundled `walk_flat.json` failed its own dynamic validation
// (227 of 321 samples, "max s* 238.665 N") and nothing said why. Every bundled phases
// file must now pass it, as `twopac` prints and `validation.parquet` stores.
#[test]
fn issue38_item7_bundled_twopac_examples_pass_their_own_validation() {
    let mut n = 0;
    for entry in std::fs::read_dir(fixture("")).unwrap() {
        let path = entry.unwrap().path();
        let is_phases = path.extension().is_some_and(|e| e == "json")
            && read_json(&path)["schema"] == "stancelib.twopac.phases/1";
        if !is_phases {
            continue;
        }
        let (_d, out, printed) = twopac(&path);
        assert!(
            printed.contains("2PAC curve: dynamically valid at all"),
            "{}:\n{printed}",
            path.display()
        );
        // A valid curve says how much room it leaves (the walk: none, on the feet's edge).
        assert!(printed.contains("smallest robustness margin"), "{printed}");
        let v = Table::open(&out.join("validation.parquet")).unwrap();
        assert_eq!(v.strings("trajectory").unwrap()[0], "2pac");
        assert!(v.bools("trajectory_valid").unwrap()[0], "{printed}");
        // The baseline stops at every knot: when it fails, the terminal says why.
        if !v.bools("trajectory_valid").unwrap()[1] {
            assert!(printed.contains("why: "), "{printed}");
        }
        n += 1;
    }
    assert!(n >= 2, "walk_flat.json and hand_wall.json are phases files");
}

// See: issue 38 item 7 — the walk as first bundled (pasted in as
// `fixtures/twopac/regressions/walk_flat_issue38.json`: 0.2 s double support, feet 20 cm
// apart) still fails, and the output says why in words: the COM off the single foot's
// support (by how many cm) and too fast (|c̈|), in which phases, and the worst s*.
#[test]
fn issue38_item7_an_invalid_trajectory_says_why() {
    let input = fixture("regressions/walk_flat_issue38.json");
    let (_d, out, printed) = twopac(&input);
    let curve = printed
        .lines()
        .skip_while(|l| !l.contains("2PAC curve"))
        .take(2)
        .collect::<Vec<_>>()
        .join("\n");
    assert!(
        curve.contains("NOT dynamically valid (94 of 321 samples valid"),
        "{printed}"
    );
    for words in [
        "why: 227 of 321 samples fail",
        "174 sample(s): the COM is outside the region where the active contacts hold it at rest, up to 6.0 cm outside",
        "53 sample(s): the contacts hold the COM at rest there but not with its acceleration",
        "phases 1 [right_foot]",
        "a contact would have to pull with s* = 238.7 N",
    ] {
        assert!(curve.contains(words), "missing {words:?} in\n{curve}");
    }
    // The picture's verdict line says the same (its text is not readable back from the
    // PNG; the picture is written and larger than an empty one).
    let png = std::fs::read(out.join("trajectory.png")).unwrap();
    assert!(png.starts_with(b"\x89PNG") && png.len() > 10_000);
}

// See: issue 38 item 7 — "status ok" of `equilibrium` meant "the solver ran", also for a
// COM far outside the support; the status is now `solved`, and the summary counts the
// states in equilibrium and says why the others are not.
#[test]
fn issue38_item7_equilibrium_status_says_how_and_the_summary_says_whether() {
    let dir = tempfile::tempdir().unwrap();
    let (p, r) = (dir.path().join("p.parquet"), dir.path().join("r.parquet"));
    // Spec §9 R2: above the centre (in), 1000 m/s² sideways (out, margin < 0).
    write_points(
        &p,
        &[
            ("x_m", vec![0.0, 0.0]),
            ("y_m", vec![0.0, 0.0]),
            ("z_m", vec![1.0, 1.0]),
            ("ax_mps2", vec![0.0, 1000.0]),
        ],
    );
    let contacts = s(&fixture("r2_contacts.json"));
    let printed = ok(&[
        "equilibrium",
        "--contacts",
        &contacts,
        "--points",
        &s(&p),
        "--out",
        &s(&r),
    ]);
    let t = Table::open(&r).unwrap();
    assert_eq!(t.strings("status").unwrap(), ["solved", "solved"]);
    assert_eq!(t.bools("in_equilibrium").unwrap(), [true, false]);
    assert!(
        printed
            .contains("1 of 2 COM state(s) in equilibrium; not: 1 outside the region (margin ≤ 0)"),
        "{printed}"
    );
    assert!(!printed.contains("status ok"), "{printed}");
}

// See: issue 38 item 7 — `equilibrium --png` ran 8 s without a word while reporting the
// 0.46 s of the verdicts. The summary now times the picture too, and the slice solves
// LPs only near the region (a handful of the 6,400 cells for four points).
#[test]
fn issue38_item7_equilibrium_png_time_is_reported() {
    let dir = tempfile::tempdir().unwrap();
    let (p, r, png) = (
        dir.path().join("p.parquet"),
        dir.path().join("r.parquet"),
        dir.path().join("r.png"),
    );
    write_points(
        &p,
        &[
            ("x_m", vec![0.0, 0.3]),
            ("y_m", vec![0.0, 0.0]),
            ("z_m", vec![0.9, 0.9]),
        ],
    );
    let printed = ok(&[
        "equilibrium",
        "--contacts",
        &s(&fixture("r2_contacts.json")),
        "--points",
        &s(&p),
        "--out",
        &s(&r),
        "--png",
        &s(&png),
    ]);
    let slice = printed
        .split("region slice 6400 cells (")
        .nth(1)
        .unwrap_or_else(|| panic!("{printed}"));
    let lps: usize = slice.split(' ').next().unwrap().parse().unwrap();
    // The 0.1 × 0.2 m rectangle and a cell diagonal around it: well under a tenth.
    assert!(lps > 0 && lps < 640, "{lps} LPs: {printed}");
    assert!(slice.contains(" s, total "), "{printed}");
    assert!(png.is_file());
}
