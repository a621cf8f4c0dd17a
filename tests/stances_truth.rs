//! Stances of the generated fixtures against the generator's ground truth: segmentation
//! (count, labels, frames, Δt) and the six stance parameters against the exact ballistic
//! flights. The force models against the true force are in `force_truth`.
//!
//! # Truth
//! The generator (`src/synth.rs`, module doc) integrates the COM in closed form from a
//! piecewise force model whose phase edges fall on frames; in flight the COM is exactly
//! ballistic (`c̈ = −g e_z`, g = 9.81 m/s²), and the truth contact flags mark the closed
//! frame range `k_a..=k_b` of each contact phase (the force is 0 at both edge frames).
//! Contact edges are therefore exact on the fixtures: a contact phase starts and ends on a
//! frame, and no noise blurs them.
//!
//! # References
//! spec stance-model §1 (segmentation, half-frame convention), §3 (parameters), §4.1 and
//! §4.2 (Stage A and its error table), §11 (columns, reconstructing the force);
//! CORRECTIONS issue 3 item 9 (fixture force target).

use stancelib::contacts::runs;
use stancelib::ingest::DEFAULT_MASS_KG;
use stancelib::math::savgol::{window_for_rate, SavGol, DEFAULT_ORDER};
use stancelib::stances::segment::Boundary;
use stancelib::stances::{assemble_clip, Stance, StanceOptions};

use crate::util::{self, outln};
use stancelib::synth::{generate, SynthClip, SynthMotion};

/// Gravity of the generator and of the spec, m/s².
pub(super) const G: f64 = 9.81;

/// A fixture with its truth and what the library made of it.
pub(super) struct Loaded {
    pub(super) truth: SynthClip,
    pub(super) stances: Vec<Stance>,
    /// Frame time, s.
    pub(super) dt: f64,
}

pub(super) fn load(c: &util::FixtureCase) -> Loaded {
    let truth = generate(&util::fixture_opts(c));
    let text = std::fs::read_to_string(util::fixture_path(c)).unwrap();
    // The truth below is the generator's; the committed file must be its output.
    assert!(
        text == truth.bvh,
        "{}: differs from the generator (run `make fixtures`)",
        c.file
    );
    let (summary, frames, contacts) = util::ingest_fixture(c);
    assert_eq!(frames.frame.len(), truth.com.len(), "{}", c.file);
    let (stances, _) = assemble_clip(
        c.file,
        &frames,
        &summary,
        &contacts,
        DEFAULT_MASS_KG,
        &StanceOptions::default(),
    );
    let dt = summary.frame_time_s;
    Loaded { truth, stances, dt }
}

/// One true support run.
#[derive(Debug, Clone)]
pub(super) struct TrueStance {
    /// First and last truth contact frame (closed range; the force is 0 at both).
    pub(super) k0: usize,
    pub(super) k1: usize,
    /// `L`, `R` or `LR`.
    pub(super) label: &'static str,
    /// The contact phase in clip time: from frame `k0` to frame `k1`, or the clip edge.
    pub(super) t0: f64,
    pub(super) t1: f64,
}

pub(super) fn true_stances(truth: &SynthClip, dt: f64) -> Vec<TrueStance> {
    let n = truth.com.len();
    let support: Vec<bool> = (0..n)
        .map(|k| truth.contact_left[k] || truth.contact_right[k])
        .collect();
    runs(&support)
        .into_iter()
        .map(|(k0, k1)| {
            let l = (k0..=k1).any(|k| truth.contact_left[k]);
            let r = (k0..=k1).any(|k| truth.contact_right[k]);
            let label = match (l, r) {
                (true, true) => "LR",
                (true, false) => "L",
                _ => "R",
            };
            TrueStance {
                k0,
                k1,
                label,
                t0: k0 as f64 * dt,
                t1: k1 as f64 * dt,
            }
        })
        .collect()
}

// ------------------------------------------------------------------ helpers

/// SG COM speed per frame from the true COM (spec stance-model §1 step 3 defines the quiet
/// periods on the SG speed; computed here from the generator's COM, not from ingest).
fn sg_speed(truth: &SynthClip, dt: f64) -> Vec<f64> {
    let sg = SavGol::new(window_for_rate(1.0 / dt), DEFAULT_ORDER).unwrap();
    let v: Vec<Vec<f64>> = (0..3)
        .map(|i| sg.apply(&truth.com.iter().map(|c| c[i]).collect::<Vec<_>>(), 1, dt))
        .collect();
    (0..truth.com.len())
        .map(|k| (v[0][k].powi(2) + v[1][k].powi(2) + v[2][k].powi(2)).sqrt())
        .collect()
}

/// The quiet periods (spec §1 step 3: speed < 0.15 m/s for ≥ 0.3 s) inside frames `a..=b`.
fn quiet_periods(speed: &[f64], a: usize, b: usize, dt: f64) -> Vec<(usize, usize)> {
    let q: Vec<bool> = speed[a..=b].iter().map(|v| *v < 0.15).collect();
    runs(&q)
        .into_iter()
        .map(|(x, y)| (a + x, a + y))
        // A run of n frames lasts n·dt (the library's convention); 1e-9 s: round-off.
        .filter(|(x, y)| (y - x + 1) as f64 * dt >= 0.3 - 1e-9)
        .collect()
}

/// The world applied force (N) of a stance's model at clip time `t`: 0 outside
/// [`td_clip_s`, `lo_clip_s`] (spec §11).
pub(super) fn model_world(s: &Stance, t: f64) -> [f64; 3] {
    if t < s.td_clip_s || t > s.lo_clip_s {
        return [0.0; 3];
    }
    let tau = (t - s.td_clip_s) / s.dt_s;
    let f: [f64; 3] = std::array::from_fn(|a| s.model.axes[a].eval(tau));
    // R_s rows are e_h, e_p, e_v: world = R_sᵀ · f_stance.
    let r = s.heading.rotation();
    std::array::from_fn(|i| (0..3).map(|a| r[a][i] * f[a]).sum())
}

pub(super) fn norm(v: [f64; 3]) -> f64 {
    (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt()
}

/// The true stance interval each detected stance is compared with, in clip time: the
/// contact phase (frame `k0` to frame `k1`, where the true force starts and ends), except at
/// an end where the stance is bounded by a quiet period (no contact event there: the split
/// is a rule on the SG speed, checked separately) or by the clip edge.
pub(super) fn true_interval(s: &Stance, t: &TrueStance) -> (f64, f64) {
    let a = match s.boundary_start {
        Boundary::Rest => s.td_clip_s,
        _ => t.t0,
    };
    let b = match s.boundary_end {
        Boundary::Rest => s.lo_clip_s,
        _ => t.t1,
    };
    (a, b)
}

// ------------------------------------------------------------------ tests

/// Stance count, labels, frames and Δt of every fixture against the true contact runs.
#[test]
fn fixture_stances_match_the_true_contact_runs() {
    let mut out = String::new();
    let mut failures = Vec::new();
    for c in &util::FIXTURES {
        let l = load(c);
        let n = l.truth.com.len();
        let truth = true_stances(&l.truth, l.dt);
        let speed = sg_speed(&l.truth, l.dt);
        outln!(
            out,
            "== {} ({n} frames at {} Hz): {} true support runs, {} stances",
            c.file,
            c.rate,
            truth.len(),
            l.stances.len()
        );
        // Here a stance is a support run: no walking split (no alternating single supports
        // within a run) and a quiet split never leaves two parts of one run (the quiet
        // periods of the jump's runs touch the clip edges).
        if l.stances.len() != truth.len() {
            failures.push(format!(
                "{}: {} stances, {} true contact runs",
                c.file,
                l.stances.len(),
                truth.len()
            ));
            continue;
        }
        match c.motion {
            SynthMotion::Run => {
                for w in l.stances.windows(2) {
                    if w[0].label == w[1].label {
                        failures.push(format!(
                            "{}: run stances do not alternate: {} then {}",
                            c.file, w[0].stance_id, w[1].stance_id
                        ));
                    }
                }
            }
            SynthMotion::Jump => {
                // Jump: two-footed stances (CORRECTIONS issue 3 item 1: one flight, one stance
                // with a flight after it and one with a flight before it).
                let flights: Vec<_> = l
                    .stances
                    .iter()
                    .map(|s| (s.boundary_start, s.boundary_end))
                    .collect();
                if flights.iter().filter(|b| b.1 == Boundary::Flight).count() != 1
                    || flights.iter().filter(|b| b.0 == Boundary::Flight).count() != 1
                {
                    failures.push(format!("{}: boundaries {flights:?}", c.file));
                }
            }
        }
        for (s, t) in l.stances.iter().zip(&truth) {
            if s.label != t.label {
                failures.push(format!(
                    "{}: {} label, truth {}",
                    s.stance_id, s.label, t.label
                ));
            }
            let (f0, f1) = (s.first_frame as usize, s.last_frame as usize);
            // Contact edges are exact on the fixtures (phase edges on frames, no noise):
            // the detector is allowed one frame (spec com-from-bvh §7.3).
            let mut frames_ok = true;
            let mut note = String::new();
            if s.boundary_start == Boundary::Rest {
                // The part after a quiet period starts at its last frame (spec §1 step 3).
                let q = quiet_periods(&speed, t.k0, t.k1, l.dt);
                frames_ok &= q.iter().any(|&(_, qb)| qb == f0);
                note += &format!(" quiet periods {q:?} (start at a quiet end)");
            } else {
                frames_ok &= f0.abs_diff(t.k0) <= 1;
            }
            if s.boundary_end == Boundary::Rest {
                // The part before a quiet period ends at its first frame.
                let q = quiet_periods(&speed, t.k0, t.k1, l.dt);
                frames_ok &= q.iter().any(|&(qa, _)| qa == f1);
                note += &format!(" quiet periods {q:?} (end at a quiet start)");
            } else {
                frames_ok &= f1.abs_diff(t.k1) <= 1;
            }
            if !frames_ok {
                failures.push(format!(
                    "{}: frames {f0}..{f1}, true run {}..{}{note}",
                    s.stance_id, t.k0, t.k1
                ));
            }
            let (a, b) = true_interval(s, t);
            let err_dt = s.dt_s - (b - a);
            outln!(
                out,
                "  {:<24} {:?}/{:?}: frames {f0}..{f1} (true run {}..{}), td {:.5} lo {:.5} s (true contact {a:.5}..{b:.5}), Δt {:.5} s, true {:.5}, Δt − true = {:+.3} frames{note}",
                s.stance_id,
                s.boundary_start,
                s.boundary_end,
                t.k0,
                t.k1,
                s.td_clip_s,
                s.lo_clip_s,
                s.dt_s,
                b - a,
                err_dt / l.dt
            );
            // One frame time: the stance edges are sub-frame events (contacts::timing),
            // met on the generator's feet at the force's first and last frame, or the
            // half-frame edges (spec §1 step 5) of a quiet split; 1e-9 s: round-off.
            if err_dt.abs() > l.dt + 1e-9 {
                failures.push(format!(
                    "{}: Δt {:.5} s vs true {:.5} s",
                    s.stance_id,
                    s.dt_s,
                    b - a
                ));
            }
        }
    }
    print!("{out}");
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

/// The ballistic flight state (position, velocity) at clip time `t` from two consecutive
/// flight frames `k`, `k + 1` of the true COM: exact for a parabola of curvature −g.
fn ballistic_at(truth: &SynthClip, dt: f64, k: usize, t: f64) -> ([f64; 3], [f64; 3]) {
    let (c0, c1) = (truth.com[k], truth.com[k + 1]);
    let a = [0.0, 0.0, -G];
    // The chord slope is the velocity at the mid time, exactly, for a parabola.
    let t_mid = (k as f64 + 0.5) * dt;
    let v_mid: [f64; 3] = std::array::from_fn(|i| (c1[i] - c0[i]) / dt);
    let v0: [f64; 3] = std::array::from_fn(|i| v_mid[i] - a[i] * (t_mid - k as f64 * dt));
    let s = t - k as f64 * dt;
    let p = std::array::from_fn(|i| c0[i] + v0[i] * s + 0.5 * a[i] * s * s);
    let v = std::array::from_fn(|i| v0[i] + a[i] * s);
    (p, v)
}

/// Apex of the ballistic parabola through a state: (horizontal position, height, velocity).
fn apex(p: [f64; 3], v: [f64; 3]) -> ([f64; 2], f64, [f64; 2]) {
    let e = v[2] / G; // time from the state to the apex
    (
        [p[0] + v[0] * e, p[1] + v[1] * e],
        p[2] + v[2] * v[2] / (2.0 * G),
        [v[0], v[1]],
    )
}

/// Stage A tolerances per frame rate: (|Δv| m/s, |Δz| m, |Δx| m).
fn param_tolerances(rate: f64) -> (f64, f64, f64) {
    // Spec §4.2 table, Stage A only at 1 mm noise: the ceiling of every tolerance here.
    let spec: (f64, f64, f64) = if rate <= 30.0 {
        (0.08, 0.032, 0.12)
    } else if rate <= 60.0 {
        (0.07, 0.020, 0.06)
    } else {
        (0.06, 0.019, 0.05)
    };
    // Measured on these noise-free fixtures (the SG window straddling the contact edges is
    // the only error source), worst over the stances with flights on both sides, × 1.5.
    let measured = if rate <= 30.0 {
        (MEAS_30[0], MEAS_30[1], MEAS_30[2])
    } else if rate <= 60.0 {
        (MEAS_60[0], MEAS_60[1], MEAS_60[2])
    } else {
        (MEAS_120[0], MEAS_120[1], MEAS_120[2])
    };
    (
        spec.0.min(1.5 * measured.0),
        spec.1.min(1.5 * measured.1),
        spec.2.min(1.5 * measured.2),
    )
}

/// Worst |Δv| (m/s: vs, ve, vp), |Δz| (m: zs, ze), |Δx| (m) measured on the noise-free run
/// fixtures (printed by the test), rounded up. The model-consistent `ze` and `x` (spec §3)
/// carry the Stage A force model's impulse error; the measured-LO values are 3-10× closer.
/// With the ratio model's flight edge states (issue 12) v and z are exact at 60 and 120 Hz;
/// at 30 Hz x measured 0.0229 m (the sub-frame events of a 3-frame flight).
const MEAS_120: [f64; 3] = [0.0024, 0.0087, 0.0124];
const MEAS_60: [f64; 3] = [0.0018, 0.0082, 0.0103];
const MEAS_30: [f64; 3] = [0.0032, 0.0110, 0.0155];

/// zs, vs, ze, ve, vp, x of the run stances with flights on both sides against the apices
/// of the generator's exact ballistic flights.
#[test]
fn run_stance_parameters_match_the_ballistic_truth() {
    let mut out = String::new();
    let mut failures = Vec::new();
    for c in util::FIXTURES
        .iter()
        .filter(|c| c.motion == SynthMotion::Run)
    {
        let l = load(c);
        let truth = true_stances(&l.truth, l.dt);
        let (tol_v, tol_z, tol_x) = param_tolerances(c.rate);
        outln!(
            out,
            "== {} at {} Hz: tolerances |Δv| {tol_v:.4} m/s, |Δz| {tol_z:.4} m, |Δx| {tol_x:.4} m",
            c.file,
            c.rate
        );
        let mut worst = [0.0f64; 3];
        let mut checked = 0;
        for (i, s) in l.stances.iter().enumerate() {
            if s.boundary_start != Boundary::Flight || s.boundary_end != Boundary::Flight {
                continue;
            }
            let t = &truth[i];
            let (prev, next) = (&truth[i - 1], &truth[i + 1]);
            // The flights: frames prev.k1..=t.k0 and t.k1..=next.k0 are on one parabola each
            // (the force is 0 from the contact's last frame to the next one's first).
            assert!(
                t.k0 - prev.k1 >= 3 && next.k0 - t.k1 >= 3,
                "flight too short"
            );
            let kb = t.k0 - 2; // frames t.k0 − 2, t.k0 − 1: inside the flight before
            let ka = t.k1 + 1; // frames t.k1 + 1, t.k1 + 2: inside the flight after
                               // The truth is exactly ballistic: a third flight frame lies on the parabola
                               // through two (1e-9 m: f64 round-off of the closed-form integration).
            for (k, k3) in [(kb, prev.k1 + 1), (ka, next.k0 - 1)] {
                let (p, _) = ballistic_at(&l.truth, l.dt, k, k3 as f64 * l.dt);
                let d = norm(std::array::from_fn(|j| p[j] - l.truth.com[k3][j]));
                assert!(
                    d < 1e-9,
                    "{}: flight frame {k3} off the parabola by {d:e} m",
                    c.file
                );
            }
            let (pb, vb) = ballistic_at(&l.truth, l.dt, kb, s.td_clip_s);
            let (pa, va) = ballistic_at(&l.truth, l.dt, ka, s.lo_clip_s);
            let (hs, zs, vhs) = apex(pb, vb);
            let (he, ze, vhe) = apex(pa, va);
            // True heading: the horizontal velocity of the flight before (spec §2); the true
            // contact height is the floor, z = 0 (toe tips on it).
            let vn = vhs[0].hypot(vhs[1]);
            let eh = [vhs[0] / vn, vhs[1] / vn];
            let ep = [-eh[1], eh[0]];
            let dot = |a: [f64; 2], b: [f64; 2]| a[0] * b[0] + a[1] * b[1];
            let tr = [
                zs,
                dot(vhs, eh),
                ze,
                dot(vhe, eh),
                dot(vhe, ep),
                dot([he[0] - hs[0], he[1] - hs[1]], eh),
            ];
            let p = &s.params;
            let got = [p.zs, p.vs, p.ze, p.ve, p.vp, p.x];
            let m = &s.measured;
            let meas = [m.zs, m.vs, m.ze, m.ve, m.vp, m.x];
            let names = ["zs_m", "vs_mps", "ze_m", "ve_mps", "vp_mps", "x_m"];
            let tols = [tol_z, tol_v, tol_z, tol_v, tol_v, tol_x];
            let kind = [1, 0, 1, 0, 0, 2]; // index into worst: v, z, x
            outln!(
                out,
                "  {:<24} z_c {:+.2e} m, heading error {:.3}°",
                s.stance_id,
                s.z_c,
                (s.heading.e_h[1].atan2(s.heading.e_h[0]) - eh[1].atan2(eh[0])).to_degrees()
            );
            for j in 0..6 {
                let err = got[j] - tr[j];
                worst[kind[j]] = worst[kind[j]].max(err.abs());
                outln!(
                    out,
                    "    {:<2} truth {:+.5}  model-consistent {:+.5} (err {:+.5})  measured-LO {:+.5} (err {:+.5})",
                    names[j],
                    tr[j],
                    got[j],
                    err,
                    meas[j],
                    meas[j] - tr[j]
                );
                if err.abs() > tols[j] {
                    failures.push(format!(
                        "{}: {} = {:.5}, truth {:.5}, |err| {:.5} > {:.5}",
                        s.stance_id,
                        names[j],
                        got[j],
                        tr[j],
                        err.abs(),
                        tols[j]
                    ));
                }
            }
            checked += 1;
        }
        outln!(
            out,
            "  worst over {checked} stances: |Δv| {:.5} m/s, |Δz| {:.5} m, |Δx| {:.5} m",
            worst[0],
            worst[1],
            worst[2]
        );
        if checked == 0 {
            failures.push(format!("{}: no stance with flights on both sides", c.file));
        }
    }
    print!("{out}");
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

/// Generated runs beyond the fixtures, at the frame rates where the whole-frame phases fall
/// differently (Hz): the edges of the synth tests' range and rates whose stance is an odd
/// number of frames.
const EXTRA_RUN_RATES_HZ: [f64; 5] = [24.0, 50.0, 100.0, 240.0, 1000.0];

// See: issue 39 item 5 — sub-frame stance durations 12–20 ms (1.2–1.4 frames at 60 and
// 120 Hz) longer than the generator's truth on every running stance: its rigid feet stopped
// dead at full swing speed on their resting height, so the event test (a captured foot's
// state at the plates' first and last 20 N: within 3 cm, below 3 and 2 m/s) was met a frame
// before the force began and a third of a frame after it ended.
#[test]
fn run_stance_durations_are_within_a_frame_of_the_truth() {
    use stancelib::ingest::IngestOptions;
    use stancelib::synth::SynthOptions;
    let mut cases: Vec<(String, SynthClip, stancelib::bvh::Bvh)> = util::FIXTURES
        .iter()
        .filter(|c| c.motion == SynthMotion::Run)
        .map(|c| {
            let bvh = stancelib::bvh::parse_file(&util::fixture_path(c)).expect("fixture parses");
            (c.file.to_string(), generate(&util::fixture_opts(c)), bvh)
        })
        .collect();
    for rate in EXTRA_RUN_RATES_HZ {
        let clip = generate(&SynthOptions {
            frame_rate_hz: rate,
            duration_s: 2.0,
            ..Default::default()
        });
        let bvh = stancelib::bvh::parse_reader(clip.bvh.as_bytes()).expect("generated BVH");
        cases.push((format!("run at {rate} Hz (generated)"), clip, bvh));
    }
    let mut out = String::new();
    let mut failures = Vec::new();
    for (name, truth, bvh) in &cases {
        let (summary, frames, contacts) = util::ingest_body(bvh, &IngestOptions::default(), name);
        let dt = summary.frame_time_s;
        let (stances, _) = assemble_clip(
            name,
            &frames,
            &summary,
            &contacts,
            DEFAULT_MASS_KG,
            &StanceOptions::default(),
        );
        let true_runs = true_stances(truth, dt);
        let mut worst: f64 = 0.0;
        let mut checked = 0;
        for s in &stances {
            // Every running stance with a contact event at both ends (not cut by the clip).
            if s.boundary_start != Boundary::Flight || s.boundary_end != Boundary::Flight {
                continue;
            }
            let Some(t) = true_runs
                .iter()
                .find(|t| t.k0 as i64 <= s.last_frame && t.k1 as i64 >= s.first_frame)
            else {
                failures.push(format!("{}: no true contact run", s.stance_id));
                continue;
            };
            let err = s.dt_s - (t.t1 - t.t0);
            worst = worst.max(err.abs() / dt);
            checked += 1;
            // The target of issue 39: within one frame; 1e-9 s: round-off.
            if err.abs() > dt + 1e-9 {
                failures.push(format!(
                    "{}: duration {:.5} s, truth {:.5} s ({:+.2} frames)",
                    s.stance_id,
                    s.dt_s,
                    t.t1 - t.t0,
                    err / dt
                ));
            }
        }
        outln!(
            out,
            "{name:<28} {checked} running stances: worst |duration − truth| {:.4} ms ({worst:.4} frames of {:.2} ms)",
            worst * dt * 1e3,
            dt * 1e3
        );
        if checked == 0 {
            failures.push(format!(
                "{name}: no running stance with flights on both sides"
            ));
        }
    }
    print!("{out}");
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}
