//! The queries on the library built from the shared clips (`../shared/data/bvh`): the
//! run-at-speed sweep (Table 1's pattern), recorded jumps found feasible at their own
//! height and distance with β ≈ 1, and the jump map. Skipped with a printed reason where
//! `../shared` is absent.

use std::path::{Path, PathBuf};
use std::sync::OnceLock;

use stancelib::library::codec::table::Table;
use stancelib::pipeline::engine::inputs::discover;
use stancelib::pipeline::engine::streaming::{build_and_write, BuildOptions};
use stancelib::query::jump::{is_landing, is_liftoff, recorded_jump};

use crate::util::{first_stance_ids, ok, shared_or_skip, stancelib, string_at};

/// The shared library, built once per test binary into a folder that lives as long.
fn shared_library() -> Option<&'static Path> {
    static LIB: OnceLock<Option<(tempfile::TempDir, PathBuf)>> = OnceLock::new();
    LIB.get_or_init(|| {
        let data = shared_or_skip("queries on the shared library")?;
        let dir = tempfile::tempdir().unwrap();
        let lib = dir.path().join("lib");
        let files = discover(&[data.join("bvh")]).unwrap();
        build_and_write(&files, &lib, &BuildOptions::default(), false).unwrap();
        Some((dir, lib))
    })
    .as_ref()
    .map(|(_, p)| p.as_path())
}

fn list_f64(t: &Table, name: &str) -> Vec<Vec<f64>> {
    t.f64_lists(name, Some(2)).unwrap()
}

#[test]
fn run_sweep_reproduces_table_one_pattern() {
    // The paper's policy (`--gait-law paper`): every time kept, β_h = v/v_orig.
    let Some(lib) = shared_library() else { return };
    let out = lib.parent().unwrap().join("runs.parquet");
    let printed = ok(&[
        "query",
        "run",
        "--lib",
        &lib.display().to_string(),
        "--speeds",
        "0:6:0.5",
        "--gait-law",
        "paper",
        "--out",
        &out.display().to_string(),
    ]);
    let t = Table::open(&out).unwrap();
    assert!(
        t.height() > 0,
        "no run cycle in the shared library:\n{printed}"
    );
    let (speed, v_orig) = (t.f64s("speed_mps").unwrap(), t.f64s("v_orig_mps").unwrap());
    let (bh, bv, bp) = (
        list_f64(&t, "beta_h"),
        list_f64(&t, "beta_v"),
        list_f64(&t, "beta_p"),
    );
    let ids = t.strings("clip").unwrap();
    let mu = t.opt_f64("mu_min").unwrap();
    let feasible = t.bools("feasible").unwrap();
    let n_speeds = 13;
    let n_cycles = t.height() / n_speeds;
    assert_eq!(n_cycles * n_speeds, t.height());
    // β_h = v / v_orig exactly (linear in speed), β_v = β_p = 1 (Table 1's pattern).
    for i in 0..t.height() {
        for k in 0..2 {
            let want = speed[i] / v_orig[i];
            assert!(
                (bh[i][k] - want).abs() < 1e-9,
                "row {i}: β_h {} vs {want}",
                bh[i][k]
            );
            assert!((bv[i][k] - 1.0).abs() < 1e-9 && (bp[i][k] - 1.0).abs() < 1e-9);
        }
    }
    // μ_min non-decreasing with speed, per cycle (rows are speed-major).
    for c in 0..n_cycles {
        let series: Vec<f64> = (0..n_speeds)
            .map(|s| mu[s * n_cycles + c].unwrap())
            .collect();
        for w in series.windows(2) {
            assert!(
                w[1] >= w[0] - 1e-12,
                "cycle {c} ({}): μ_min {series:?}",
                ids[c]
            );
        }
    }
    // The slow end is feasible; the recorded stances' own friction need (μ_req up to 1.4
    // on cmu_09_01's R:40, from the model's edge ringing) exceeds μ = 0.7 near 4 m/s.
    assert!(feasible[0], "the 0 m/s bounce is infeasible:\n{printed}");
    // §7.5 override: at its own speed the recorded cycle (k = 1, the identity) meets its
    // stances' relative limits, while the absolute μ = 0.7 rejects it (μ_req 1.42).
    let own = lib.parent().unwrap().join("own.parquet");
    let v0 = v_orig[0].to_string();
    let l = lib.display().to_string();
    // With the ratio force model (issue 12) the recorded cycle also meets the absolute
    // μ = 0.7 (the Fourier model's edge ringing gave μ_req 1.42 and failed it).
    for (form, want) in [("relative", true), ("absolute", true)] {
        ok(&[
            "query",
            "run",
            "--lib",
            &l,
            "--speed",
            &v0,
            "--limits",
            form,
            "--out",
            &own.display().to_string(),
        ]);
        let t = Table::open(&own).unwrap();
        let f = t.bools("feasible").unwrap();
        assert_eq!(f[0], want, "--limits {form} at the recorded speed");
    }
    eprintln!("query run on the shared library: {n_cycles} cycles\n{printed}");
}

/// The identity jump (stance-model §6.9, CORRECTIONS Issue 4 item 2) of every recorded
/// jump: a liftoff followed, after one flight, by a landing in the same clip.
///
/// Each stance's model gives its own end of the flight, so `ve1` and `vs2` differ by the
/// models' error (Stage A on these clips: up to 0.2 m/s, the COM's horizontal speed is not
/// constant in flight), and `β_h` departs from 1 by `|u_apex − ve1|/|J_h1|` (a vertical
/// jump, with small `J_h`, amplifies it). The test checks β_v within 5 % (the two models
/// agree on the apex height), and feasibility wherever every β is within 5 % of 1.
/// The slack columns of a `query jump` row, one per side and limit.
const MARGINS: [&str; 8] = [
    "margin_force1_n",
    "margin_mu1",
    "margin_ext_min1_m",
    "margin_ext_max1_m",
    "margin_force2_n",
    "margin_mu2",
    "margin_ext_min2_m",
    "margin_ext_max2_m",
];

/// `query jump --height h --distance d` on `lib` into `out`: the table and the row of the
/// pair `(liftoff, landing)`.
fn jump_pair_row(lib: &Path, h: f64, d: f64, pair: (&str, &str), out: &Path) -> (Table, usize) {
    jump_pair_row_with(lib, h, d, pair, out, &[])
}

/// [`jump_pair_row`] with `extra` options (e.g. `--limits relative`).
fn jump_pair_row_with(
    lib: &Path,
    h: f64,
    d: f64,
    pair: (&str, &str),
    out: &Path,
    extra: &[&str],
) -> (Table, usize) {
    let (l, h_s, d_s, o) = (
        lib.display().to_string(),
        h.to_string(),
        format!("--distance={d}"),
        out.display().to_string(),
    );
    let mut args = vec![
        "query", "jump", "--lib", &l, "--height", &h_s, &d_s, "--out", &o,
    ];
    args.extend_from_slice(extra);
    args.push("--quiet");
    ok(&args);
    let t = Table::open(out).unwrap();
    let (up, down) = (
        t.strings("liftoff_stance_id").unwrap(),
        t.strings("landing_stance_id").unwrap(),
    );
    let row = (0..t.height())
        .find(|&r| up[r] == pair.0 && down[r] == pair.1)
        .expect("the recorded pair is a candidate");
    (t, row)
}

#[test]
fn recorded_jumps_are_feasible_at_their_own_height_and_distance() {
    let Some(lib) = shared_library() else { return };
    let stances =
        stancelib::library::readers::read::read_stances(&lib.join("stances.parquet")).unwrap();
    let clips =
        stancelib::library::readers::read::read_clip_info(&lib.join("clips.parquet")).unwrap();
    let recorded: Vec<(usize, usize)> = (1..stances.len())
        .filter(|&i| stances[i - 1].clip == stances[i].clip)
        .filter(|&i| is_liftoff(&stances[i - 1]) && is_landing(&stances[i]))
        .map(|i| (i - 1, i))
        .collect();
    assert!(
        !recorded.is_empty(),
        "no recorded jump in the shared library"
    );
    let mut identities = 0;
    for (n, &(a, b)) in recorded.iter().enumerate() {
        let (s1, s2) = (&stances[a], &stances[b]);
        let (ve1, vs2) = (s1.params.ve, s2.params.vs);
        let s_eff = clips[&s1.clip].s_eff.unwrap_or(1.0);
        // A liftoff from rest takes its heading from the hips (§8.1): when the body turned
        // during that stance, its frame points against the jump (ve1 and vs2 of opposite
        // signs) and the straight-jump model cannot compose the pair. Clips with a wrong
        // time base (s_eff outside [0.9, 1.1]) set no limits and are left out as in runs.
        if ve1 * vs2 < 0.0 || !(0.9..=1.1).contains(&s_eff) {
            eprintln!(
                "identity jump {} → {} left out: ve1 {ve1:.3}, vs2 {vs2:.3} m/s, s_eff {s_eff:.2}",
                s1.stance_id, s2.stance_id
            );
            continue;
        }
        let (h, d) = recorded_jump(s1, s2);
        let out = lib.parent().unwrap().join(format!("jump{n}.parquet"));
        let (t, row) = jump_pair_row(lib, h, d, (&s1.stance_id, &s2.stance_id), &out);
        let feasible = t.bools("feasible").unwrap()[row];
        let why = string_at(&t, "violated", row);
        let get =
            |c: &str| t.opt_f64(c).unwrap()[row].unwrap_or_else(|| panic!("{c} null: {why:?}"));
        let [bh1, bv1, bh2, bv2] = ["beta_h1", "beta_v1", "beta_h2", "beta_v2"].map(get);
        let u = get("u_apex_mps");
        eprintln!(
            "identity jump {} → {}: h {h:.3} m, d {d:.3} m, ve1 {ve1:.3}, vs2 {vs2:.3}, u_apex {u:.3} m/s, β [{bh1:.4}, {bv1:.4}, {bh2:.4}, {bv2:.4}], feasible {feasible} {why:?}",
            s1.stance_id, s2.stance_id
        );
        assert!(
            (bv1 - 1.0).abs() <= 0.05 && (bv2 - 1.0).abs() <= 0.05,
            "β_v {bv1}, {bv2}"
        );
        // The reported margins agree with the verdict: all met iff feasible.
        let margins = MARGINS.map(get);
        assert_eq!(
            margins.iter().all(|&m| m >= 0.0),
            feasible,
            "{margins:?} vs {why:?}"
        );
        // Issue 12: with flight edge states the identity jump is found at β = 1 within 3 %.
        assert!(
            [bh1, bv1, bh2, bv2].iter().all(|b| (b - 1.0).abs() <= 0.03),
            "{} → {}: β [{bh1}, {bv1}, {bh2}, {bv2}] not within 3 % of 1",
            s1.stance_id,
            s2.stance_id
        );
        assert!(feasible, "{} → {}: {why:?}", s1.stance_id, s2.stance_id);
        identities += 1;
    }
    eprintln!("identity jumps: {identities} feasible at β = 1 ± 3 % (near-vertical ones included, J_H_DEGENERATE_MPS)");
    assert!(
        identities >= 5,
        "only {identities} identity jumps within 3 %"
    );
}

#[test]
fn jump_map_has_a_feasible_region_and_reports_agreement() {
    let Some(lib) = shared_library() else { return };
    let out = lib.parent().unwrap().join("map");
    let printed = ok(&[
        "map",
        "jumps",
        "--lib",
        &lib.display().to_string(),
        "--out",
        &out.display().to_string(),
    ]);
    let t = Table::open(&out.join("jump_map.parquet")).unwrap();
    let pairs = Table::open(&out.join("jump_map_pairs.parquet")).unwrap();
    assert!(pairs.height() > 0, "no liftoff/landing pair:\n{printed}");
    assert_eq!(
        t.height(),
        pairs.height() * 51 * 101,
        "one row per pair and cell"
    );
    let (ap, ex) = (
        t.bools("feasible_approx").unwrap(),
        t.bools("feasible_exact").unwrap(),
    );
    let n_exact = ex.iter().filter(|&&e| e).count();
    assert!(n_exact > 0, "empty jump region:\n{printed}");
    let both = ap.iter().zip(&ex).filter(|(a, e)| **a && **e).count();
    let either = ap.iter().zip(&ex).filter(|(a, e)| **a || **e).count();
    let summary: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("jump_map.json")).unwrap()).unwrap();
    let iou = summary["iou"].as_f64().unwrap();
    assert!(
        (iou - both as f64 / either as f64).abs() < 1e-12,
        "IoU {iou}"
    );
    let png = std::fs::read(out.join("jump_map.png")).unwrap();
    assert_eq!(&png[..8], b"\x89PNG\r\n\x1a\n");
    eprintln!("map jumps on the shared library:\n{printed}");
}

#[test]
fn active_set_option_acts_on_the_friction_check() {
    // See: issue 12 item 5 — the queries' friction check uses a configurable active set;
    // a wider one (0.05: down to 5 % of peak f_v) can only need more friction.
    let Some(lib) = shared_library() else { return };
    let l = lib.display().to_string();
    let mu_at = |frac: &str| {
        let out = lib
            .parent()
            .unwrap()
            .join(format!("runs_active_{frac}.parquet"));
        ok(&[
            "query",
            "run",
            "--lib",
            &l,
            "--speeds",
            "0:6:0.5",
            "--active-set",
            frac,
            "--out",
            &out.display().to_string(),
        ]);
        let t = Table::open(&out).unwrap();
        t.opt_f64("mu_min").unwrap()
    };
    let (wide, robust) = (mu_at("0.05"), mu_at("0.2"));
    assert_eq!(wide.len(), robust.len());
    let pairs: Vec<(f64, f64)> = wide
        .iter()
        .zip(&robust)
        .filter_map(|(a, b)| Some(((*a)?, (*b)?)))
        .collect();
    assert!(!pairs.is_empty());
    // A superset of samples: μ_min at 0.05 ≥ μ_min at 0.2 (1e-12: the same f64 ratios).
    assert!(pairs.iter().all(|(w, r)| w + 1e-12 >= *r), "{pairs:?}");
    assert!(
        pairs.iter().any(|(w, r)| w - r > 0.01),
        "the option changed nothing"
    );
    let x = lib
        .parent()
        .unwrap()
        .join("x.parquet")
        .display()
        .to_string();
    let (code, _, _) = stancelib(&[
        "query",
        "run",
        "--lib",
        &l,
        "--speed",
        "3",
        "--active-set",
        "1.5",
        "--out",
        &x,
    ]);
    assert_eq!(code, 2);
}

/// The nightly set's library (shared clips, bulk CMU set, force-plate clips), built once.
fn nightly_library() -> Option<&'static Path> {
    static LIB: OnceLock<Option<(tempfile::TempDir, PathBuf)>> = OnceLock::new();
    LIB.get_or_init(|| {
        let data = shared_or_skip("issue 12 targets on the nightly library")?;
        let dir = tempfile::tempdir().unwrap();
        let lib = dir.path().join("lib");
        let inputs = [
            data.join("bvh"),
            data.join("bvh-bulk"),
            data.join("forceplate"),
        ];
        let files = discover(&inputs).unwrap();
        build_and_write(&files, &lib, &BuildOptions::default(), false).unwrap();
        Some((dir, lib))
    })
    .as_ref()
    .map(|(_, p)| p.as_path())
}

#[test]
fn run_cycles_of_real_clips_are_feasible_over_most_speeds() {
    // See: issue 12 targets — `query run --speeds 0:6:0.5` on the shared + bulk library:
    // the real cycles feasible at ≥ 8 of the 13 speeds on average (5.7 with the Fourier
    // model) and μ_min non-decreasing (Table 1's pattern; β_h = v/v_orig is asserted by
    // `run_sweep_reproduces_table_one_pattern`). Those targets are the paper's policy
    // (`--gait-law paper`, times kept); under the gait law a 3.5 m/s cycle has no flight
    // at 0.5 m/s and needs more force at 6 m/s, as people do
    // (`every_recorded_cycle_is_feasible_at_its_own_speed`).
    let Some(lib) = nightly_library() else { return };
    let out = lib.parent().unwrap().join("nightly_runs.parquet");
    let l = lib.display().to_string();
    let o = out.display().to_string();
    ok(&[
        "query",
        "run",
        "--lib",
        &l,
        "--speeds",
        "0:6:0.5",
        "--gait-law",
        "paper",
        "--out",
        &o,
    ]);
    let t = Table::open(&out).unwrap();
    let ids = t.strings("clip").unwrap();
    let speed = t.f64s("speed_mps").unwrap();
    let v_orig = t.f64s("v_orig_mps").unwrap();
    let feasible = t.bools("feasible").unwrap();
    let mu = t.opt_f64("mu_min").unwrap();
    // A cycle is (clip, recorded speed): every cycle of a clip has its own v_orig.
    let mut cycles: std::collections::BTreeMap<(String, u64), Vec<usize>> = Default::default();
    for i in 0..t.height() {
        cycles
            .entry((ids[i].clone(), v_orig[i].to_bits()))
            .or_default()
            .push(i);
    }
    let (mut total, mut monotone) = (0usize, 0usize);
    for rows in cycles.values() {
        total += rows.iter().filter(|&&i| feasible[i]).count();
        let mut by_speed: Vec<(f64, f64)> = rows
            .iter()
            .filter_map(|&i| mu[i].map(|m| (speed[i], m)))
            .collect();
        by_speed.sort_by(|a, b| a.0.total_cmp(&b.0));
        monotone += usize::from(by_speed.windows(2).all(|w| w[1].1 >= w[0].1 - 1e-9));
    }
    let n = cycles.len();
    let mean = total as f64 / n as f64;
    eprintln!(
        "nightly library: {n} run cycles, feasible at {mean:.2} of 13 speeds on average, μ_min non-decreasing in {monotone} of {n}"
    );
    assert!(n >= 20, "only {n} run cycles");
    assert!(mean >= 8.0, "feasible at {mean:.2} of 13 speeds on average");
    assert!(
        monotone * 10 >= n * 9,
        "μ_min non-decreasing in {monotone} of {n}"
    );
}

#[test]
fn consecutive_stances_describe_the_same_flight() {
    // See: issue 12 item 3 — a liftoff and the next touchdown across one flight agree:
    // apex height median ≤ 5 mm (14.5 mm before), apex velocity median ≤ 2 cm/s (5.0).
    let Some(lib) = nightly_library() else { return };
    let t = Table::open(&lib.join("stances.parquet")).unwrap();
    let (clip, b0, b1) = (
        t.strings("clip").unwrap(),
        t.strings("boundary_start").unwrap(),
        t.strings("boundary_end").unwrap(),
    );
    let f = |c: &str| t.f64s(c).unwrap();
    let (z_c, zs, ze, vs, ve, vp, hx, hy) = (
        f("z_c_m"),
        f("zs_m"),
        f("ze_m"),
        f("vs_mps"),
        f("ve_mps"),
        f("vp_mps"),
        f("heading_x"),
        f("heading_y"),
    );
    let (mut dz, mut dv) = (Vec::new(), Vec::new());
    for i in 1..t.height() {
        let a = i - 1;
        if clip[a] != clip[i] || b1[a] != "flight" || b0[i] != "flight" {
            continue;
        }
        dz.push((z_c[a] + ze[a] - z_c[i] - zs[i]).abs());
        // World horizontal apex velocities: ve e_h + vp e_p after, vs e_h before.
        let after = [ve[a] * hx[a] - vp[a] * hy[a], ve[a] * hy[a] + vp[a] * hx[a]];
        let before = [vs[i] * hx[i], vs[i] * hy[i]];
        dv.push((after[0] - before[0]).hypot(after[1] - before[1]));
    }
    let median = |v: &mut Vec<f64>| {
        v.sort_by(f64::total_cmp);
        v[v.len() / 2]
    };
    let n = dz.len();
    assert!(n >= 50, "only {n} flights between stances");
    let (mz, mv) = (median(&mut dz), median(&mut dv));
    eprintln!(
        "{n} flights: apex height |Δ| median {:.1} mm, apex velocity |Δ| median {:.1} cm/s",
        1e3 * mz,
        1e2 * mv
    );
    assert!(mz <= 0.005, "apex height median {mz} m");
    assert!(mv <= 0.02, "apex velocity median {mv} m/s");
}

#[test]
fn running_stances_are_feasible_as_recorded() {
    // See: issue 12 targets — every single-foot running stance with a flight on both
    // sides, asked for its own speed (the run policy at k = 1: the identity), passes the
    // exact check at μ = 0.7 with its character's absolute limits and the queries' default
    // active set; target ≥ 85 % (54 % with the Fourier model).
    use stancelib::pipeline::commands::queries::load_pool;
    use stancelib::query::feasibility::{LimitForm, DEFAULT_QUERY_ACTIVE_FRACTION};
    use stancelib::query::limits::{absolute_limits, stance_limits};
    use stancelib::query::run::{policy_request, scale_and_check};
    use stancelib::query::solve::Refs;
    use stancelib::stances::segment::Boundary;
    let Some(lib) = nightly_library() else { return };
    let (library, pool) = load_pool(lib, DEFAULT_QUERY_ACTIVE_FRACTION).unwrap();
    let limits = absolute_limits(&library);
    let (mut n, mut ok) = (0usize, 0usize);
    let mut why: std::collections::BTreeMap<String, usize> = Default::default();
    for p in &pool {
        let s = &p.stance;
        let flights = s.boundary_start == Boundary::Flight && s.boundary_end == Boundary::Flight;
        if !flights || !(s.label == "L" || s.label == "R") {
            continue;
        }
        n += 1;
        let lim = stance_limits(p, LimitForm::Absolute, &limits, Some(0.7));
        match scale_and_check(p, &policy_request(&p.stance, 1.0), &Refs::run(1.0), &lim) {
            Ok(c) if c.verdict.feasible => ok += 1,
            Ok(c) => *why.entry(format!("{:?}", c.verdict.violated)).or_default() += 1,
            Err(e) => *why.entry(format!("unsolved: {e:?}")).or_default() += 1,
        }
    }
    let share = 100.0 * ok as f64 / n.max(1) as f64;
    eprintln!("{n} single-foot running stances: {ok} ({share:.0} %) feasible as recorded at μ = 0.7; the others: {why:?}");
    assert!(n >= 20, "only {n} running stances");
    assert!(share >= 85.0, "{share:.0} % feasible as recorded");
}

// See: issue 37 item 4 and targets — on the shared + bulk library under the default
// (absolute, per character) limits: every recorded jump pair is feasible at its own
// height and distance, and "a 10 % higher jump feasible for at least half the recorded
// forward jumps, or each 'no' says which limit and by how much". Since the jump limits
// stop at the body's reach (`query::limits::jump_limits`), 1 of 6 forward jumps goes 10 %
// higher: the five others need the COM 9–69 mm beyond the reach, and edited anyway
// (`--allow-infeasible`) four of them leave their plan by 10–70 mm (the fifth, `01_01`
// LR:150, stays on it: the one refusal the edit does not confirm). Every "no" must name
// its limit and margin; the count is printed.
#[test]
fn recorded_jumps_can_go_higher_under_a_persons_limits() {
    let Some(lib) = nightly_library() else { return };
    let stances =
        stancelib::library::readers::read::read_stances(&lib.join("stances.parquet")).unwrap();
    let clips =
        stancelib::library::readers::read::read_clip_info(&lib.join("clips.parquet")).unwrap();
    // Each stance's heading (unit, horizontal): a pair whose two headings differ by more
    // than 45° turned in the air, which the straight-jump model cannot compose.
    let t = Table::open(&lib.join("stances.parquet")).unwrap();
    let heading: std::collections::BTreeMap<String, (f64, f64)> = t
        .strings("stance_id")
        .unwrap()
        .into_iter()
        .zip(
            t.f64s("heading_x")
                .unwrap()
                .into_iter()
                .zip(t.f64s("heading_y").unwrap()),
        )
        .collect();
    // The queries answer a copied clip once (issue 38 item 3): its pairs are not asked.
    let left_out = stancelib::query::limits::left_out_clips(
        &stancelib::library::readers::read::open_library(lib).unwrap(),
    );
    let (mut own, mut higher, mut forward, mut failures) = (0, 0, 0, Vec::new());
    for i in 1..stances.len() {
        let (s1, s2) = (&stances[i - 1], &stances[i]);
        if s1.clip != s2.clip || !is_liftoff(s1) || !is_landing(s2) {
            continue;
        }
        if let Some(why) = left_out.get(&s1.clip) {
            eprintln!("{} → {} left out: {why:?}", s1.stance_id, s2.stance_id);
            continue;
        }
        let s_eff = clips[&s1.clip].s_eff.unwrap_or(1.0);
        let (h1, h2) = (heading[&s1.stance_id], heading[&s2.stance_id]);
        let turn = (h1.0 * h2.0 + h1.1 * h2.1)
            .clamp(-1.0, 1.0)
            .acos()
            .to_degrees();
        if s1.params.ve * s2.params.vs < 0.0 || turn > 45.0 || !(0.9..=1.1).contains(&s_eff) {
            // Turned in the air, or a wrong time base (as in the identity test).
            eprintln!(
                "{} → {} left out: headings {turn:.0}° apart, s_eff {s_eff:.2}",
                s1.stance_id, s2.stance_id
            );
            continue;
        }
        let (h, d) = recorded_jump(s1, s2);
        let ask = |h: f64, name: &str| {
            let out = lib
                .parent()
                .unwrap()
                .join(format!("higher_{i}_{name}.parquet"));
            let (t, row) = jump_pair_row(lib, h, d, (&s1.stance_id, &s2.stance_id), &out);
            let why = string_at(&t, "violated", row);
            let margins: Vec<String> = MARGINS
                .iter()
                .filter_map(|c| {
                    t.opt_f64(c).unwrap()[row]
                        .filter(|m| *m < 0.0)
                        .map(|m| format!("{c} {m:.3}"))
                })
                .collect();
            (t.bools("feasible").unwrap()[row], why, margins)
        };
        let (ok_own, why_own, _) = ask(h, "own");
        own += usize::from(ok_own);
        if !ok_own {
            failures.push(format!(
                "{} → {}: not feasible as recorded: {why_own:?}",
                s1.stance_id, s2.stance_id
            ));
        }
        let is_forward = d.abs() >= 0.2;
        forward += usize::from(is_forward);
        let (ok_hi, why_hi, margins) = ask(1.1 * h, "higher");
        higher += usize::from(ok_hi && is_forward);
        eprintln!(
            "{} → {}: h {h:.3} m, d {d:.3} m; as recorded {ok_own}; 10 % higher {ok_hi} {}",
            s1.stance_id,
            s2.stance_id,
            if ok_hi {
                String::new()
            } else {
                format!(
                    "({} ; {})",
                    why_hi.clone().unwrap_or_default(),
                    margins.join(", ")
                )
            }
        );
        if !ok_hi && margins.is_empty() && why_hi.as_deref().is_none_or(|w| !w.contains(':')) {
            failures.push(format!(
                "{} → {}: a 'no' without its limit",
                s1.stance_id, s2.stance_id
            ));
        }
    }
    eprintln!("recorded jumps: {own} feasible as recorded; forward jumps 10 % higher: {higher} of {forward}");
    assert!(forward >= 4, "only {forward} forward jumps");
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

// See: issue 37 item 3 — every recorded run cycle of the shared + bulk + force-plate
// library is feasible at its own speed under the default gait law and limits.
#[test]
fn every_recorded_cycle_is_feasible_at_its_own_speed() {
    let Some(lib) = nightly_library() else { return };
    let l = lib.display().to_string();
    let all = lib.parent().unwrap().join("own_all.parquet");
    ok(&[
        "query",
        "run",
        "--lib",
        &l,
        "--speed",
        "3",
        "--out",
        &all.display().to_string(),
        "--quiet",
    ]);
    let t = Table::open(&all).unwrap();
    let (v_orig, firsts) = (t.f64s("v_orig_mps").unwrap(), first_stance_ids(&t));
    let mut failures = Vec::new();
    for (i, (v, first)) in v_orig.iter().zip(&firsts).enumerate() {
        let out = lib.parent().unwrap().join(format!("own_{i}.parquet"));
        ok(&[
            "query",
            "run",
            "--lib",
            &l,
            &format!("--speed={v}"),
            "--out",
            &out.display().to_string(),
            "--quiet",
        ]);
        let o = Table::open(&out).unwrap();
        let row = first_stance_ids(&o)
            .iter()
            .position(|x| x == first)
            .expect("the cycle is in the table");
        let feasible = o.bools("feasible").unwrap()[row];
        let violated = string_at(&o, "violated", row);
        if !feasible {
            failures.push(format!("{first} at its own {v:.3} m/s: {violated:?}"));
        }
    }
    eprintln!(
        "{} recorded cycles, {} infeasible at their own speed",
        v_orig.len(),
        failures.len()
    );
    assert!(v_orig.len() >= 30, "only {} cycles", v_orig.len());
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

// See: issue 37 item 3 — the fixtures' recorded jumps failed their own identity under the
// relative limits by a friction margin of −6e−11 (a vertical jump's μ_req is round-off):
// with the stated tolerances (`LIMIT_REL_TOL`, `MU_ABS_TOL`) every recorded pair of the
// fixture library is feasible at its own height and distance under both limit forms.
#[test]
fn fixture_jumps_are_feasible_as_recorded_under_both_limit_forms() {
    let lib = crate::util::fixture_library();
    let stances =
        stancelib::library::readers::read::read_stances(&lib.join("stances.parquet")).unwrap();
    let mut checked = 0;
    for i in 1..stances.len() {
        let (s1, s2) = (&stances[i - 1], &stances[i]);
        if s1.clip != s2.clip || !is_liftoff(s1) || !is_landing(s2) {
            continue;
        }
        let (h, d) = recorded_jump(s1, s2);
        for form in ["relative", "absolute"] {
            let out = lib
                .parent()
                .unwrap()
                .join(format!("own_{i}_{form}.parquet"));
            let pair = (s1.stance_id.as_str(), s2.stance_id.as_str());
            let (t, row) = jump_pair_row_with(lib, h, d, pair, &out, &["--limits", form]);
            let why = string_at(&t, "violated", row);
            assert!(
                t.bools("feasible").unwrap()[row],
                "{} → {} under {form} limits: {why:?}",
                s1.stance_id,
                s2.stance_id
            );
            checked += 1;
        }
    }
    assert!(checked >= 4, "only {checked} recorded jumps checked");
}

// See: issue 37 (each "no" says which limit and by how much) and issue 38 item 1 — the
// terminal verdict of an infeasible answer names the constraint with its value, the limit
// and the margin in units.
#[test]
fn infeasible_answers_say_which_limit_and_by_how_much() {
    let lib = crate::util::fixture_library().display().to_string();
    let out = tempfile::tempdir().unwrap();
    let o = out.path().join("j.parquet").display().to_string();
    // The fixtures' vertical jumps at an apex 18 cm above the recorded 1.12 m, under the
    // ±5 % relative limits: the push-off needs more force than 1.05 × its own peak.
    let printed = ok(&[
        "query",
        "jump",
        "--lib",
        &lib,
        "--height",
        "1.3",
        "--distance",
        "0",
        "--limits",
        "relative",
        "--out",
        &o,
    ]);
    let line = printed
        .lines()
        .find(|l| l.contains("jump_100hz_m_zup:LR:35") && l.contains("jump_100hz_m_zup:LR:125"))
        .expect("the recorded pair is printed");
    assert!(
        line.contains("infeasible: liftoff: force")
            && line.contains(" N > ")
            && line.contains("(by "),
        "{line}"
    );
    // The margin printed is the table's (margin_force1_n is its negative).
    let t = Table::open(std::path::Path::new(&o)).unwrap();
    let (up, down) = (
        t.strings("liftoff_stance_id").unwrap(),
        t.strings("landing_stance_id").unwrap(),
    );
    let row = (0..t.height())
        .find(|&r| up[r] == "jump_100hz_m_zup:LR:35" && down[r] == "jump_100hz_m_zup:LR:125")
        .unwrap();
    let margin = t.opt_f64("margin_force1_n").unwrap()[row].unwrap();
    assert!(
        margin < 0.0 && line.contains(&format!("(by {:.0} N)", -margin)),
        "{line} vs {margin}"
    );
}
