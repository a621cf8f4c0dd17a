//! Measured figures for the report (spec §8.1): run with
//! `cargo test --release --lib twopac::tests::timing -- --ignored --nocapture`.
//! Not a pass/fail test: timings depend on the machine.

use super::{flat_foot, point_set, r3_box, ring_scene, R1_COM, R1_POINTS};
use crate::twopac::bezier::ComState;
use crate::twopac::contact::contact_points;
use crate::twopac::equilibrium::EqualityForm;
use crate::twopac::region::{static_region, RegionOptions};
use crate::twopac::trajectory::{plan, Phase, PlanOptions};
use crate::twopac::transition::{transition_eq13, transition_eq6, QpForm, TransitionOptions};
use crate::twopac::validate::{validate, DEFAULT_STEP_S};
use std::time::Instant;

fn stats(mut v: Vec<f64>) -> (f64, f64) {
    v.sort_by(f64::total_cmp);
    (v[v.len() / 2], v[(v.len() * 95) / 100])
}

fn time<F: FnMut()>(n: usize, mut f: F) -> (f64, f64) {
    let mut v = Vec::with_capacity(n);
    for _ in 0..n {
        let t = Instant::now();
        f();
        v.push(t.elapsed().as_secs_f64());
    }
    stats(v)
}

fn ten_phases() -> Vec<Phase> {
    let ph = |feet: &[(&str, f64, f64)], d: f64| Phase {
        contacts: feet
            .iter()
            .map(|&(n, x, y)| flat_foot(n, [x, y, 0.0], 0.2172, 0.138, 0.5))
            .collect(),
        kinematics: feet.iter().map(|&(_, x, y)| r3_box(x, y)).collect(),
        duration_s: Some(d),
        com: Some([
            feet.iter().map(|f| f.1).sum::<f64>() / feet.len() as f64,
            0.0,
            0.8,
        ]),
    };
    let mut out = vec![ph(&[("l", 0.0, 0.1), ("r", 0.0, -0.1)], 0.3)];
    let (mut xl, mut xr) = (0.0, 0.0);
    for k in 0..9 {
        if k % 4 == 0 {
            out.push(ph(&[("r", xr, -0.1)], 0.6));
        } else if k % 4 == 1 {
            xl += 0.3;
            out.push(ph(&[("l", xl, 0.1), ("r", xr, -0.1)], 0.3));
        } else if k % 4 == 2 {
            out.push(ph(&[("l", xl, 0.1)], 0.6));
        } else {
            xr += 0.3;
            out.push(ph(&[("l", xl, 0.1), ("r", xr, -0.1)], 0.3));
        }
    }
    out
}

#[test]
#[ignore = "timing report, run by hand in release mode"]
fn report_measured_figures() {
    report_margins();
    report_region_and_transitions();
    report_plans();
}

/// Equilibrium margins of the reference scenes R1 and R2 (§8.1).
fn report_margins() {
    let r1 = EqualityForm::new(&[point_set(&R1_POINTS, [0.0, 0.0, 1.0], 0.5)], 55.8836).unwrap();
    println!("R1 margin: {:?}", r1.verdict(R1_COM, [0.0; 3]).margin_n);
    let r2_pts = [
        [0.05, 0.1, 0.0],
        [0.05, -0.1, 0.0],
        [-0.05, -0.1, 0.0],
        [-0.05, 0.1, 0.0],
    ];
    let r2 = EqualityForm::new(&[point_set(&r2_pts, [0.0, 0.0, 1.0], 0.3)], 54.0).unwrap();
    println!(
        "R2 margin: {:?}",
        r2.verdict([0.0, 0.0, 1.0], [0.0; 3]).margin_n
    );
    println!(
        "R2 margin, acc 1000: {:?}",
        r2.verdict([0.0, 0.0, 1.0], [1000.0, 0.0, 0.0]).margin_n
    );
}

/// The static region of the ring scene and the two transition QP forms, timed.
fn report_region_and_transitions() {
    let ring = contact_points(&ring_scene());
    let opts = RegionOptions::default();
    let region = static_region(&ring, &opts).unwrap();
    println!(
        "ring scene H-rep: {} rows, {} vertices, {} LPs",
        region.polytope.len(),
        region.vertices.len(),
        region.n_lps
    );
    let (med, p95) = time(2000, || {
        std::hint::black_box(static_region(&ring, &opts).unwrap());
    });
    println!(
        "H-rep build, ring scene (24 points): median {:.1} us, p95 {:.1} us",
        med * 1e6,
        p95 * 1e6
    );

    let feet = [
        flat_foot("l", [0.0, 0.1, 0.0], 0.2172, 0.138, 0.5),
        flat_foot("r", [0.0, -0.1, 0.0], 0.2172, 0.138, 0.5),
    ];
    let form = EqualityForm::new(&feet[1..], 50.0).unwrap();
    let reg = static_region(&form.points, &opts).unwrap();
    let kin = r3_box(0.0, 0.1).stacked(&r3_box(0.0, -0.1));
    let o = TransitionOptions::default();
    let (med, p95) = time(20000, || {
        std::hint::black_box(transition_eq6(&reg, false, &kin, [0.0; 3], &o).unwrap());
    });
    println!(
        "transition QP eq 6 ({} + {} rows): median {:.2} us, p95 {:.2} us",
        reg.polytope.len(),
        kin.len(),
        med * 1e6,
        p95 * 1e6
    );
    let (med, p95) = time(2000, || {
        std::hint::black_box(transition_eq13(&form, &kin, [0.0; 3], &o).unwrap());
    });
    println!(
        "transition QP eq 13 (4 points): median {:.1} us, p95 {:.1} us",
        med * 1e6,
        p95 * 1e6
    );
}

/// The 10-phase trajectory under both QP forms, timed, and its validation.
fn report_plans() {
    let phases = ten_phases();
    for (name, form) in [("eq 13", QpForm::Eq13), ("eq 6", QpForm::Eq6)] {
        let po = PlanOptions {
            form,
            ..PlanOptions::default()
        };
        let (med, p95) = time(200, || {
            std::hint::black_box(plan(&phases, 50.0, &ComState::default(), &po).unwrap());
        });
        println!(
            "10-phase trajectory ({name}): median {:.3} ms, p95 {:.3} ms",
            med * 1e3,
            p95 * 1e3
        );
    }
    let p = plan(&phases, 50.0, &ComState::default(), &PlanOptions::default()).unwrap();
    let t = Instant::now();
    let v = validate(&p, &p.forms, DEFAULT_STEP_S);
    println!(
        "validation: {} samples in {:.1} ms, point_valid_rate {:.3}, trajectory_valid {}, max s* {:.2} N",
        v.samples.len(),
        t.elapsed().as_secs_f64() * 1e3,
        v.point_valid_rate,
        v.trajectory_valid,
        v.max_slack_n
    );
    println!(
        "windows: {:?}",
        p.windows
            .iter()
            .map(|w| (w.first_phase, w.last_phase, w.u_end, w.violations.len()))
            .collect::<Vec<_>>()
    );
    println!(
        "transition slacks: {:?}",
        p.transitions
            .iter()
            .map(|t| t.point.slack)
            .collect::<Vec<_>>()
    );
}
