//! Tests of the Stage A fit: exact recovery, DFT reconstruction, j_cap, selection.

use super::*;
use std::f64::consts::TAU;

/// Stance-frame force per axis: `(c0, [(j, A, φ)])`.
type Axis = (f64, Vec<(u32, f64, f64)>);

fn force(ax: &Axis, tau: f64) -> f64 {
    ax.0 + ax
        .1
        .iter()
        .map(|&(j, a, p)| a * (TAU * j as f64 * tau + p).cos())
        .sum::<f64>()
}

fn yaw(psi: f64) -> [[f64; 3]; 3] {
    let (s, c) = psi.sin_cos();
    [[c, s, 0.0], [-s, c, 0.0], [0.0, 0.0, 1.0]]
}

/// World acceleration splines whose knots fall on the sample times, so the sampled
/// stance-frame force is exactly `axes` (up to roundoff).
fn splines(
    axes: &[Axis; 3],
    t_td: f64,
    dt: f64,
    m: f64,
    r_s: [[f64; 3]; 3],
    n: usize,
) -> [NaturalSpline; 3] {
    let ks: Vec<i64> = (-6..n as i64 + 6).collect();
    let t: Vec<f64> = ks
        .iter()
        .map(|&k| t_td + dt * (k as f64 / n as f64))
        .collect();
    let mut a: [Vec<f64>; 3] = Default::default();
    for &k in &ks {
        let tau = k as f64 / n as f64;
        let fs = [
            force(&axes[0], tau),
            force(&axes[1], tau),
            force(&axes[2], tau),
        ];
        for (w, aw) in a.iter_mut().enumerate() {
            let f_world: f64 = (0..3).map(|r| r_s[r][w] * fs[r]).sum(); // R_sᵀ f
            aw.push(f_world / m - if w == 2 { GRAVITY } else { 0.0 });
        }
    }
    a.map(|y| NaturalSpline::new(&t, &y).unwrap())
}

#[test]
fn synthetic_stance_is_recovered_exactly() {
    let axes: [Axis; 3] = [
        (35.0, vec![(1, 120.0, -0.7), (3, 40.0, 1.1)]),
        (-12.0, vec![(2, 60.0, 2.0), (1, 25.0, 0.3)]),
        (1400.0, vec![(1, 900.0, 3.0), (4, 150.0, -2.5)]),
    ];
    let (t_td, dt, m, r_s) = (3.217, 0.23, 68.0, yaw(0.83));
    let acc = splines(&axes, t_td, dt, m, r_s, 64);
    let mut ws = FitWorkspace::new(64);
    let fm = fit_stage_a(&mut ws, &acc, t_td, dt, r_s, m, 14, &FitOptions::default()).unwrap();
    // 1e-9 (N, rad): the samples are exact to ~1e-12 N (float roundoff of R_s, m, g).
    for (got, want) in fm.axes.iter().zip(&axes) {
        assert!(
            (got.c0 - want.0).abs() < 1e-9,
            "c0 {} vs {}",
            got.c0,
            want.0
        );
        assert_eq!(
            got.harmonics,
            want.1.iter().map(|t| f64::from(t.0)).collect::<Vec<_>>()
        );
        for (i, &(_, a, p)) in want.1.iter().enumerate() {
            assert!((got.amps[i] - a).abs() < 1e-9);
            assert!((got.phases[i] - p).abs() < 1e-9);
        }
        assert!(got.fit_rms < 1e-9);
    }
    assert_eq!((fm.mass_kg, fm.dt_s, fm.j_max()), (m, dt, 4.0));
}

#[test]
fn dft_reconstruction_reproduces_all_samples() {
    // All candidates kept (η = 1, K_max large): the model must equal the samples.
    // Tolerance 1e-10 · scale: FFT roundoff is O(log N · ε) relative.
    let all = FitOptions {
        samples: 0,
        max_harmonics: usize::MAX,
        energy: 1.0,
        ..Default::default()
    };
    let mut ws = FitWorkspace::new(63);
    // Odd N: every nonzero bin is a candidate, so arbitrary samples are reproduced.
    let odd: Vec<f64> = (0..63)
        .map(|j| ((j * j * 7919) % 101) as f64 - 40.0)
        .collect();
    let model = fit_axis(&mut ws, &odd, 1000, &all).unwrap();
    assert_eq!(model.harmonics.len(), 31);
    for (j, &f) in odd.iter().enumerate() {
        assert!((model.eval(j as f64 / 63.0) - f).abs() < 1e-10 * 100.0);
    }
    assert!(model.fit_rms < 1e-10 * 100.0);
    // Even N, band-limited to k ≤ 31 (no Nyquist content).
    let bl: Axis = (
        5.0,
        (1..=31)
            .map(|k| (k, 1.0 + (k % 5) as f64, 0.1 * k as f64))
            .collect(),
    );
    let even: Vec<f64> = (0..64).map(|j| force(&bl, j as f64 / 64.0)).collect();
    let model = fit_axis(&mut ws, &even, 31, &all).unwrap();
    assert_eq!(ws.samples(), 64);
    assert!(model.fit_rms < 1e-10 * 100.0);
    // fit_rms by Parseval equals the direct residual RMS (1e-10 · scale, FFT roundoff),
    // for a truncated model on each N parity.
    for data in [&odd, &even] {
        let model = fit_axis(&mut ws, data, 4, &FitOptions::default()).unwrap();
        assert!(model.fit_rms > 1.0);
        assert!((model.fit_rms - rms_residual(data, &model)).abs() < 1e-10 * 100.0);
    }
    // Factor 2: a pure 3 N cosine at k = 5 has A_5 = 2|X_5|/N = 3, not 1.5.
    let pure: Vec<f64> = (0..64)
        .map(|j| 3.0 * (TAU * 5.0 * j as f64 / 64.0 + 0.4).cos())
        .collect();
    let model = fit_axis(&mut ws, &pure, 31, &FitOptions::default()).unwrap();
    assert_eq!(model.harmonics, vec![5.0]);
    assert!((model.amps[0] - 3.0).abs() < 1e-12 && (model.phases[0] - 0.4).abs() < 1e-12);
}

#[test]
fn j_cap_rule() {
    // 30 Hz, 0.22 s stance: n_st = 6 → j_cap 1; 7 → 2 (spec §4.1 step 5).
    let cases = [
        (0, 1),
        (2, 1),
        (3, 1),
        (5, 1),
        (6, 1),
        (7, 2),
        (9, 3),
        (30, 13),
    ];
    for (n_st, cap) in cases {
        assert_eq!(j_cap(n_st), cap, "n_st = {n_st}");
    }
    assert_eq!(
        (k_max(64, 1000), k_max(63, 1000), k_max(64, 6)),
        (31, 31, 1)
    );
    // A force with harmonics 1 and 2 fitted with n_st = 6 keeps only harmonic 1.
    let axes: [Axis; 3] = [
        (0.0, vec![]),
        (0.0, vec![]),
        (700.0, vec![(2, 300.0, 0.0), (1, 100.0, 0.5)]),
    ];
    let acc = splines(&axes, 0.5, 0.2, 70.0, yaw(0.0), 64);
    let mut ws = FitWorkspace::new(64);
    let fm = fit_stage_a(
        &mut ws,
        &acc,
        0.5,
        0.2,
        yaw(0.0),
        70.0,
        6,
        &FitOptions::default(),
    )
    .unwrap();
    assert_eq!(fm.axes[2].harmonics, vec![1.0]);
    assert!((fm.axes[2].fit_rms - 300.0 / 2f64.sqrt()).abs() < 1e-9); // RMS of the dropped cosine
    assert!(fm.axes[0].harmonics.is_empty() && fm.axes[0].c0.abs() < 1e-9);
}

#[test]
fn selection_follows_energy_cap_and_ties() {
    // Amplitudes 10, 5, 1 at k = 1, 2, 3: Σ = 126; 10² + 5² = 125 ≥ 0.99·126 = 124.74.
    let s: Vec<f64> = (0..64)
        .map(|j| {
            let t = j as f64 / 64.0;
            10.0 * (TAU * t).cos() + 5.0 * (2.0 * TAU * t).cos() + (3.0 * TAU * t).cos()
        })
        .collect();
    let mut ws = FitWorkspace::new(64);
    let fit = |ws: &mut FitWorkspace, max_harmonics, energy| {
        let o = FitOptions {
            max_harmonics,
            energy,
            ..Default::default()
        };
        fit_axis(ws, &s, 31, &o).unwrap().harmonics
    };
    assert_eq!(fit(&mut ws, 6, 0.99), vec![1.0, 2.0]);
    assert_eq!(fit(&mut ws, 6, 0.999), vec![1.0, 2.0, 3.0]);
    assert_eq!(fit(&mut ws, 1, 0.999), vec![1.0]);
    assert_eq!(fit(&mut ws, 6, 0.0), Vec::<f64>::new());
    // Exactly equal amplitudes (k = 2 and 4): the lower k comes first.
    let mut order = Vec::new();
    dominant_order(&[9.0, 1.0, 3.0, 0.5, 3.0, 3.5], &mut order);
    assert_eq!(order, vec![5, 2, 4, 1, 3]);
}

#[test]
fn degenerate_inputs_are_errors_not_panics() {
    let axes: [Axis; 3] = [(0.0, vec![]), (0.0, vec![]), (700.0, vec![])];
    let acc = splines(&axes, 0.0, 0.2, 70.0, yaw(0.0), 64);
    let mut ws = FitWorkspace::new(0);
    let d = FitOptions::default();
    let r = yaw(0.0);
    assert!(fit_stage_a(&mut ws, &acc, 0.0, 0.0, r, 70.0, 8, &d).is_err());
    assert!(fit_stage_a(&mut ws, &acc, 0.0, f64::NAN, r, 70.0, 8, &d).is_err());
    assert!(fit_stage_a(&mut ws, &acc, 0.0, 0.2, r, -1.0, 8, &d).is_err());
    assert!(fit_stage_a(&mut ws, &acc, f64::INFINITY, 0.2, r, 70.0, 8, &d).is_err());
    let mut bad_r = r;
    bad_r[1][1] = f64::NAN;
    assert!(fit_stage_a(&mut ws, &acc, 0.0, 0.2, bad_r, 70.0, 8, &d).is_err());
    let opts = |samples, energy| FitOptions {
        samples,
        energy,
        ..d
    };
    assert!(fit_stage_a(&mut ws, &acc, 0.0, 0.2, r, 70.0, 8, &opts(1, 0.99)).is_err());
    assert!(fit_stage_a(&mut ws, &acc, 0.0, 0.2, r, 70.0, 8, &opts(64, 1.5)).is_err());
    assert!(fit_stage_a(&mut ws, &acc, 0.0, 0.2, r, 70.0, 8, &opts(usize::MAX, 0.99)).is_err());
    assert_eq!(FitWorkspace::new(usize::MAX).samples(), MAX_SAMPLES);
    assert!(fit_stage_a(&mut ws, &acc, 0.0, 0.2, r, 70.0, 8, &opts(64, f64::NAN)).is_err());
    // n_st < 3 is fine (j_cap = 1), odd and tiny N too; far extrapolation stays finite.
    for (n_st, samples, t_td) in [(0, 64, 0.0), (2, 2, 0.0), (8, 3, 0.0), (8, 17, 100.0)] {
        let fm = fit_stage_a(
            &mut ws,
            &acc,
            t_td,
            0.2,
            r,
            70.0,
            n_st,
            &opts(samples, 0.99),
        )
        .unwrap();
        assert!(fm.j().iter().chain(&fm.p()).all(|v| v.is_finite()));
        assert!(fm.j_max() <= 1.0);
    }
}

#[test]
fn workspace_is_send() {
    fn send<T: Send>() {}
    send::<FitWorkspace>();
}

#[test]
#[ignore = "a timing printout, no assertion: 10,000 fits; run with --ignored --nocapture"]
fn timing_10000_stances() {
    // Not an assertion: prints the wall time of 10,000 fits plus the §4.3 flags on one
    // 60 s, 120 Hz clip (run with --nocapture; the dev profile is opt-level 1).
    let n_frames = 7200;
    let t: Vec<f64> = (0..n_frames).map(|i| i as f64 / 120.0).collect();
    let wave = |f: f64, p: f64| {
        t.iter()
            .map(|&x| 4.0 * (TAU * f * x + p).sin())
            .collect::<Vec<_>>()
    };
    let acc = [
        NaturalSpline::new(&t, &wave(1.3, 0.0)).unwrap(),
        NaturalSpline::new(&t, &wave(0.7, 1.0)).unwrap(),
        NaturalSpline::new(&t, &wave(2.9, 2.0)).unwrap(),
    ];
    let mut ws = FitWorkspace::new(crate::force_model::DEFAULT_SAMPLES);
    let start = std::time::Instant::now();
    let mut checksum = 0.0;
    for i in 0..10_000 {
        let t_td = 0.5 + 0.0059 * i as f64;
        let fm = fit_stage_a(
            &mut ws,
            &acc,
            t_td,
            0.22,
            yaw(0.001 * i as f64),
            70.0,
            26,
            &FitOptions::default(),
        )
        .unwrap();
        let g = fm.grid();
        checksum +=
            fm.j()[2] + fm.k()[0] + fm.min_f_v(&g) + f64::from(u8::from(fm.unilateral_ok(&g)));
    }
    let el = start.elapsed();
    println!(
        "10,000 Stage A fits + flags: {el:?} ({:.2} µs/stance), checksum {checksum:.3}",
        el.as_secs_f64() * 1e2
    );
    assert!(checksum.is_finite());
}
