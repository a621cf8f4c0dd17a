//! Stage A force models of the generated fixtures against the generator's true applied
//! force (CORRECTIONS issue 3 item 9), and a round trip of the force model through
//! `stances.parquet`. The truth and the loaders are those of `stances_truth` (its module
//! doc states what is exact on the fixtures).

use std::f64::consts::PI;
use std::path::PathBuf;

use polars::prelude::*;
use stancelib::ingest::DEFAULT_MASS_KG;
use stancelib::library::codec::table::read_parquet;
use stancelib::pipeline::engine::streaming::{build, write_library, BuildOptions};
use stancelib::stances::Stance;
use stancelib::synth::{SynthClip, SynthMotion};

use super::stances_truth::{load, model_world, norm, true_interval, true_stances, G};
use crate::util::{self, outln};

// ------------------------------------------------------------------ the true force

/// The generator's force model (module doc of `src/synth.rs`) in continuous time: the
/// applied force per unit mass (m/s², world Z up) at clip time `t`.
struct TrueForce {
    motion: SynthMotion,
    dt: f64,
    /// Run: (touchdown time, left foot) of every stance.
    run_stances: Vec<(f64, bool)>,
}

impl TrueForce {
    fn new(c: &util::FixtureCase, truth: &SynthClip, dt: f64) -> Self {
        let run_stances = true_stances(truth, dt)
            .iter()
            .map(|s| (s.t0, s.label == "L"))
            .collect();
        TrueForce {
            motion: c.motion,
            dt,
            run_stances,
        }
    }

    /// Frames of a duration, `round(s·F)` half away from zero (the generator's rule).
    fn frames(&self, s: f64) -> f64 {
        (s / self.dt).round()
    }

    fn at(&self, t: f64) -> [f64; 3] {
        match self.motion {
            SynthMotion::Run => {
                // Ts = round(0.25 s·F)/F, Tf = 2·round(0.06 s·F)/F, Tc = Ts + Tf.
                let ts = self.frames(0.25).max(2.0) * self.dt;
                let tf = 2.0 * self.frames(0.06).max(1.0) * self.dt;
                let tc = ts + tf;
                let a = PI * G * tc / (2.0 * ts);
                let b = 4.0;
                let cc = PI * 0.1 / ts;
                for &(t_a, left) in &self.run_stances {
                    let tau = t - t_a;
                    if (0.0..=ts).contains(&tau) {
                        let s1 = (PI * tau / ts).sin();
                        let s2 = (2.0 * PI * tau / ts).sin();
                        let sway = if left { -cc } else { cc };
                        return [-b * s2, sway * s1, a * s1];
                    }
                }
                [0.0; 3]
            }
            SynthMotion::Jump => {
                let (ns, np, nf) = (
                    self.frames(0.3).max(2.0),
                    self.frames(0.6).max(2.0),
                    self.frames(0.35).max(2.0),
                );
                let (tp, tf) = (np * self.dt, nf * self.dt);
                let v0 = G * tf / 2.0;
                let b1 = PI * (v0 + G * tp / 2.0) / (2.0 * tp);
                let b2 = 2.0 * PI * G * (0.25 - 1.0 / (PI * PI)) - 2.0 * b1;
                let push = |tau: f64, s: f64| {
                    let (w1, w2) = (PI * tau / tp, 2.0 * PI * tau / tp);
                    G / 2.0 + s * (G / 2.0) * w1.cos() + b1 * w1.sin() + s * b2 * w2.sin()
                };
                let t_push = ns * self.dt;
                let t_flight = t_push + tp;
                let t_land = t_flight + tf;
                let fz = if t < t_push {
                    G
                } else if t <= t_flight {
                    push(t - t_push, 1.0)
                } else if t < t_land {
                    0.0
                } else if t <= t_land + tp {
                    push(t - t_land, -1.0)
                } else {
                    G
                };
                [0.0, 0.0, fz]
            }
        }
    }
}

/// CORRECTIONS issue 3 item 9: the Stage A model against the true applied force over the
/// union of the detected and the true stance.
#[test]
fn fixture_force_models_match_the_true_force() {
    let mut out = String::new();
    let mut failures = Vec::new();
    for c in &util::FIXTURES {
        let l = load(c);
        let n = l.truth.com.len();
        let truth = true_stances(&l.truth, l.dt);
        let tf = TrueForce::new(c, &l.truth, l.dt);
        // The continuous truth is the generator's documented model: it must reproduce the
        // per-frame truth (1e-9 m/s²: round-off of two closed-form evaluations).
        for k in 0..n {
            let a = tf.at(k as f64 * l.dt);
            let b = l.truth.force_n_per_kg[k];
            let d = (0..3).map(|i| (a[i] - b[i]).abs()).fold(0.0, f64::max);
            assert!(
                d < 1e-9,
                "{} frame {k}: formula {a:?} vs truth {b:?}",
                c.file
            );
        }
        // CORRECTIONS item 9, Stage A: ≤ 6 % at 120 Hz, ≤ 10 % at 30 Hz (the 0.1 s SG
        // window's floor is 5 % / 9 %); 60 and 100 Hz take the 120 Hz target (their SG
        // windows are also ~0.1 s wide).
        let target = if c.rate <= 30.0 { 0.10 } else { 0.06 };
        let m = DEFAULT_MASS_KG;
        outln!(
            out,
            "== {} at {} Hz (target RMS < {:.0} % of the true peak)",
            c.file,
            c.rate,
            target * 100.0
        );
        assert_eq!(l.stances.len(), truth.len(), "{}: stance count", c.file);
        for (s, t) in l.stances.iter().zip(&truth) {
            let (a, b) = true_interval(s, t);
            let (u0, u1) = (a.min(s.td_clip_s), b.max(s.lo_clip_s));
            // A dense grid (2001 points) over the union: the true force is continuous, the
            // model is 0 outside [t_TD, t_LO].
            let pts = 2001;
            let mut peak = 0.0f64;
            let (mut se, mut se_axis) = (0.0, [0.0; 3]);
            for j in 0..pts {
                let tt = u0 + (u1 - u0) * j as f64 / (pts - 1) as f64;
                let f_true = if tt >= a && tt <= b {
                    tf.at(tt).map(|x| x * m)
                } else {
                    [0.0; 3]
                };
                let f_mod = model_world(s, tt);
                peak = peak.max(norm(f_true));
                let e: [f64; 3] = std::array::from_fn(|i| f_mod[i] - f_true[i]);
                se += norm(e).powi(2);
                (0..3).for_each(|i| se_axis[i] += e[i] * e[i]);
            }
            let rms = (se / pts as f64).sqrt();
            let rms_axis = se_axis.map(|x| (x / pts as f64).sqrt());
            // The same at the frames in the union, against force_n_per_kg × m (reported).
            let (mut se_f, mut nf) = (0.0, 0);
            for k in 0..n {
                let tt = k as f64 * l.dt;
                if tt < u0 - 1e-9 || tt > u1 + 1e-9 {
                    continue;
                }
                let f_true = if tt >= a - 1e-9 && tt <= b + 1e-9 {
                    l.truth.force_n_per_kg[k].map(|x| x * m)
                } else {
                    [0.0; 3]
                };
                let f_mod = model_world(s, tt);
                se_f += norm(std::array::from_fn(|i| f_mod[i] - f_true[i])).powi(2);
                nf += 1;
            }
            let rms_frames = (se_f / nf as f64).sqrt();
            outln!(
                out,
                "  {:<24} union {u0:.4}..{u1:.4} s: RMS {:6.1} N = {:5.2} % of peak {:6.1} N (x {:.1}, y {:.1}, z {:.1} N); at the {nf} frames {:5.2} %; fit_rms (h,p,v) ({:.1}, {:.1}, {:.1}) N, harmonics (h,p,v) {:?} {:?} {:?}",
                s.stance_id,
                rms,
                100.0 * rms / peak,
                peak,
                rms_axis[0],
                rms_axis[1],
                rms_axis[2],
                100.0 * rms_frames / peak,
                s.model.axes[0].fit_rms,
                s.model.axes[1].fit_rms,
                s.model.axes[2].fit_rms,
                s.model.axes[0].harmonics,
                s.model.axes[1].harmonics,
                s.model.axes[2].harmonics,
            );
            if rms >= target * peak {
                failures.push(format!(
                    "{}: force RMS {:.2} % of the true peak ≥ {:.0} %",
                    s.stance_id,
                    100.0 * rms / peak,
                    target * 100.0
                ));
            }
        }
    }
    print!("{out}");
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

/// Reading a `stances.parquet` list column entry as f64 values.
fn list_f64(df: &DataFrame, name: &str, i: usize) -> Vec<f64> {
    let s = df
        .column(name)
        .unwrap()
        .list()
        .unwrap()
        .get_as_series(i)
        .unwrap();
    s.f64().unwrap().iter().map(|v| v.unwrap()).collect()
}

/// The force model survives `stances.parquet`: the §11 reconstruction from the stored
/// columns alone equals the in-process model; row count and order.
#[test]
fn force_models_round_trip_through_parquet() {
    let files: Vec<PathBuf> = util::FIXTURES.iter().map(util::fixture_path).collect();
    let opts = BuildOptions::default();
    let report = build(&files, &opts);
    let dir = tempfile::tempdir().unwrap();
    let lib = dir.path().join("lib");
    write_library(&lib, &report, &opts).unwrap();
    let df = read_parquet(&lib.join("stances.parquet")).unwrap();

    // In process, independently of the pipeline: ingest and assemble_clip per fixture.
    let mut in_process: Vec<Stance> = util::FIXTURES
        .iter()
        .flat_map(|c| load(c).stances)
        .collect();
    in_process.sort_by(|a, b| a.stance_id.cmp(&b.stance_id));
    assert_eq!(
        df.height(),
        in_process.len(),
        "row count vs in-process stances"
    );
    assert_eq!(report.stances.len(), in_process.len());

    let clip = df.column("clip").unwrap().str().unwrap().clone();
    let label = df.column("label").unwrap().str().unwrap().clone();
    let id = df.column("stance_id").unwrap().str().unwrap().clone();
    let first = df.column("first_frame").unwrap().i64().unwrap().clone();
    let f64col = |name: &str| -> Vec<f64> {
        df.column(name)
            .unwrap()
            .f64()
            .unwrap()
            .iter()
            .map(|v| v.unwrap())
            .collect()
    };
    let (td, dts, hx, hy) = (
        f64col("td_clip_s"),
        f64col("dt_s"),
        f64col("heading_x"),
        f64col("heading_y"),
    );
    let c0: Vec<Vec<f64>> = ["c0_h_n", "c0_p_n", "c0_v_n"]
        .iter()
        .map(|n| f64col(n))
        .collect();
    let mut keys = Vec::new();
    let mut worst = 0.0f64;
    for i in 0..df.height() {
        let key = (
            clip.get(i).unwrap().to_string(),
            first.get(i).unwrap(),
            label.get(i).unwrap().to_string(),
        );
        keys.push(key);
        let sid = id.get(i).unwrap();
        let s = in_process
            .iter()
            .find(|s| s.stance_id == sid)
            .unwrap_or_else(|| panic!("row {i}: {sid} not built in process"));
        // Per stance axis, from the stored columns only (spec §11).
        let axes: Vec<StoredAxis> = ["h", "p", "v"]
            .iter()
            .enumerate()
            .map(|(a, ax)| {
                let h = df
                    .column(&format!("harmonic_{ax}"))
                    .unwrap()
                    .list()
                    .unwrap()
                    .get_as_series(i)
                    .unwrap();
                // Cycles per stance: whole for the periodic fit, halves for half-range cosines.
                let h: Vec<f64> = h.f64().unwrap().iter().map(|v| v.unwrap()).collect();
                let amp = list_f64(&df, &format!("amp_{ax}_n"), i);
                let ph = list_f64(&df, &format!("phase_{ax}_rad"), i);
                assert_eq!((h.len(), amp.len()), (ph.len(), ph.len()), "{sid} {ax}");
                let poly = list_f64(&df, &format!("poly_{ax}_n"), i);
                (c0[a][i], h, amp, ph, poly)
            })
            .collect();
        let (eh, ep) = ([hx[i], hy[i], 0.0], [-hy[i], hx[i], 0.0]);
        let ev = [0.0, 0.0, 1.0];
        // 50 points from τ = −0.1 to 1.1: both sides of the stance (0 there) and inside.
        for j in 0..50 {
            let t = td[i] + dts[i] * (-0.1 + 1.2 * j as f64 / 49.0);
            let tau = (t - td[i]) / dts[i];
            let f: Vec<f64> = axes
                .iter()
                .map(|(c0, h, amp, ph, poly)| {
                    if !(0.0..=1.0).contains(&tau) {
                        return 0.0;
                    }
                    c0 + h
                        .iter()
                        .zip(amp)
                        .zip(ph)
                        .map(|((&h, &a), &p)| a * (2.0 * PI * h * tau + p).cos())
                        .sum::<f64>()
                        + poly
                            .iter()
                            .enumerate()
                            .map(|(k, &c)| c * tau.powi(k as i32))
                            .sum::<f64>()
                })
                .collect();
            let stored: [f64; 3] =
                std::array::from_fn(|d| f[0] * eh[d] + f[1] * ep[d] + f[2] * ev[d]);
            let mine = model_world(s, t);
            let d = norm(std::array::from_fn(|d| stored[d] - mine[d]));
            worst = worst.max(d);
            // 1e-9 N: the columns hold the model's f64 values exactly; only the order of
            // the floating-point operations differs.
            assert!(
                d < 1e-9,
                "{sid} t {t}: stored {stored:?} vs in process {mine:?}"
            );
        }
    }
    let mut sorted = keys.clone();
    sorted.sort();
    assert_eq!(
        keys, sorted,
        "rows not sorted by (clip, first_frame, label)"
    );
    println!(
        "{} rows = {} in-process stances; sorted; worst reconstruction difference {worst:.2e} N over 50 points each",
        df.height(),
        in_process.len()
    );
}

/// One stance axis as stored: (c0, harmonics in cycles per stance, amplitudes, phases,
/// polynomial coefficients).
type StoredAxis = (f64, Vec<f64>, Vec<f64>, Vec<f64>, Vec<f64>);
