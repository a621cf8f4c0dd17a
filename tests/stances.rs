//! Stances on real clips (issue 3 checks as corrected by CORRECTIONS.md): flights on both
//! sides, impulse–momentum against the flight fits, walking splits, running forces.

use std::collections::BTreeMap;

use stancelib::ingest::{ClipFrames, ClipSummary, IngestOptions};
use stancelib::stances::segment::Boundary;
use stancelib::stances::{assemble_clip, Stance, StanceOptions};

use crate::util;

const G: f64 = 9.81;

/// Stances of one shared clip (relative to `data/bvh`) and its number of ballistic flights.
fn stances_and_flights(rel: &str) -> Option<(Vec<Stance>, usize)> {
    stances_and_summary(rel).map(|(st, summary, _)| {
        let flights = summary.flights.iter().filter(|f| f.ballistic).count();
        (st, flights)
    })
}

/// Stances of one shared clip with its ingest summary (its flights) and frames.
fn stances_and_summary(rel: &str) -> Option<(Vec<Stance>, ClipSummary, ClipFrames)> {
    let data = util::shared_or_skip("stances")?;
    let bvh = stancelib::bvh::parse_file(&data.join("bvh").join(rel)).unwrap();
    let (summary, frames, contacts) = util::ingest_body(&bvh, &IngestOptions::default(), rel);
    let clip = std::path::Path::new(rel)
        .file_stem()
        .unwrap()
        .to_string_lossy()
        .into_owned();
    let st = assemble_clip(
        &clip,
        &frames,
        &summary,
        &contacts,
        70.0,
        &StanceOptions::default(),
    )
    .0;
    Some((st, summary, frames))
}

/// Stances of one shared clip.
fn stances_of(rel: &str) -> Option<Vec<Stance>> {
    stances_and_summary(rel).map(|s| s.0)
}

const RUNS_AND_JUMPS: [&str; 8] = [
    "run/cmu_09_01_run_mb.bvh",
    "run/cmu_16_36_runjog_daz.bvh",
    "run/mass_run_fast.bvh",
    "jump/cmu_01_01_forward_jumps_mb.bvh",
    "jump/cmu_02_04_vertical_jump_mb.bvh",
    "jump/cmu_13_32_forward_jump_daz.bvh",
    "jump/cmu_131_03_hop_3dsmax_meters.bvh",
    "jump/mass_backflip.bvh",
];

#[test]
fn runs_and_jumps_have_stances_between_flights() {
    for rel in RUNS_AND_JUMPS {
        let Some((st, flights)) = stances_and_flights(rel) else {
            return;
        };
        let both = st
            .iter()
            .filter(|s| s.boundary_start == Boundary::Flight && s.boundary_end == Boundary::Flight)
            .count();
        let before = st
            .iter()
            .filter(|s| s.boundary_start == Boundary::Flight)
            .count();
        let after = st
            .iter()
            .filter(|s| s.boundary_end == Boundary::Flight)
            .count();
        println!("{rel}: {flights} flights, {} stances, flight both sides {both}, before {before}, after {after}", st.len());
        match flights {
            // The backflip's airborne intervals are not ballistic (time base ≈ 2× off).
            0 => assert_eq!((both, before, after), (0, 0, 0), "{rel}"),
            // Exactly one flight (CORRECTIONS issue 3 item 1): one stance before it, one after.
            1 => assert_eq!((after, before), (1, 1), "{rel}"),
            // Every flight between two stances bounds both of them.
            n => {
                assert!(both >= 1, "{rel}: no stance between two flights");
                assert_eq!((after, before), (n, n), "{rel}");
            }
        }
    }
}

/// The velocity at `t` of a −g ballistic fit of the raw COM over a flight's frames, less two
/// at each end: straight lines horizontally, a parabola of curvature −g vertically, by least
/// squares (written here independently of the stance build's own fit).
fn gravity_fit_velocity(
    fr: &ClipFrames,
    first_frame: i64,
    last_frame: i64,
    t: f64,
) -> Option<[f64; 3]> {
    let ks: Vec<usize> = (0..fr.frame.len())
        .filter(|&k| fr.frame[k] >= first_frame + 2 && fr.frame[k] <= last_frame - 2)
        .collect();
    if ks.len() < 3 {
        return None;
    }
    let slope = |ys: Vec<f64>| {
        let n = ks.len() as f64;
        let ts: Vec<f64> = ks.iter().map(|&k| fr.time_s[k]).collect();
        let (mt, my) = (ts.iter().sum::<f64>() / n, ys.iter().sum::<f64>() / n);
        let sxy: f64 = ts.iter().zip(&ys).map(|(t, y)| (t - mt) * (y - my)).sum();
        let sxx: f64 = ts.iter().map(|t| (t - mt) * (t - mt)).sum();
        sxy / sxx
    };
    let axis = |i: usize| -> Vec<f64> {
        ks.iter()
            .map(|&k| {
                let lift = if i == 2 {
                    0.5 * G * fr.time_s[k] * fr.time_s[k]
                } else {
                    0.0
                };
                fr.com[k][i] + lift
            })
            .collect()
    };
    Some([slope(axis(0)), slope(axis(1)), slope(axis(2)) - G * t])
}

#[test]
fn impulse_momentum_matches_the_flight_fits() {
    // CORRECTIONS issue 3 item 2, for stances whose flights on both sides have a free fit.
    // The velocity change is taken between −g fits of the flights' raw COM made here, not
    // from the stance's edge states (the force fit meets those by construction) nor from
    // the free-curvature fits (a 0.1 s flight's free curvature is noise: −5.6 m/s² on one
    // flight of cmu_09_01, which is why the build uses −g; docs/stance-model.md).
    let mut checked = 0;
    let mut skipped = 0;
    let mut worst: BTreeMap<&str, f64> = BTreeMap::new();
    let mut failures: Vec<String> = Vec::new();
    for rel in RUNS_AND_JUMPS {
        let Some((st, _, frames)) = stances_and_summary(rel) else {
            return;
        };
        for s in &st {
            let (Some(b), Some(a)) = (&s.flight_before, &s.flight_after) else {
                continue;
            };
            if !(b.free && a.free) {
                skipped += 1;
                continue;
            }
            let (Some(va), Some(vb)) = (
                gravity_fit_velocity(&frames, a.first_frame, a.last_frame, s.lo_clip_s),
                gravity_fit_velocity(&frames, b.first_frame, b.last_frame, s.td_clip_s),
            ) else {
                skipped += 1;
                continue;
            };
            let dv_world: Vec<f64> = (0..3).map(|i| va[i] - vb[i]).collect();
            let dv = s.heading.to_stance([dv_world[0], dv_world[1], dv_world[2]]);
            let j = s.model.j();
            for ax in 0..3 {
                let model = j[ax] - if ax == 2 { G * s.dt_s } else { 0.0 };
                let err = (model - dv[ax]).abs();
                // Tolerance from CORRECTIONS: max(5 % of |Δv_a|, 0.15 m/s).
                let tol = (0.05 * dv[ax].abs()).max(0.15);
                println!(
                    "{}: axis {ax} J−gΔt {model:.3} Δv {:.3} err {err:.3} (tol {tol:.3})",
                    s.stance_id, dv[ax]
                );
                if err > tol {
                    failures.push(format!(
                        "{}: axis {ax}: model {model:.4} vs flights {:.4}",
                        s.stance_id, dv[ax]
                    ));
                }
                let w = worst.entry(["h", "p", "v"][ax]).or_insert(0.0);
                *w = w.max(err);
            }
            checked += 1;
        }
    }
    println!("impulse-momentum: {checked} stances checked, {skipped} skipped (a flight without a free fit); worst {worst:?}");
    if util::shared_data().is_some() {
        // cmu_09_01 (2), cmu_16_36 (1 of 3: the others border untested short flights) and
        // the between-jump stances of cmu_01_01 (3).
        assert!(checked >= 5, "only {checked} stances checked");
    }
    assert!(
        failures.is_empty(),
        "{} axis checks failed:\n{}",
        failures.len(),
        failures.join("\n")
    );
}

#[test]
fn walks_split_without_flight() {
    for rel in [
        "walk/cmu_07_01_walk_mb.bvh",
        "walk/cmu_07_04_slow_walk_mb.bvh",
        "walk/cmu_16_15_walk_daz.bvh",
        "walk/cmu_131_01_walk_3dsmax.bvh",
    ] {
        let Some(st) = stances_of(rel) else { return };
        let walking = st
            .iter()
            .filter(|s| {
                s.boundary_start == Boundary::NoFlight || s.boundary_end == Boundary::NoFlight
            })
            .count();
        println!(
            "{rel}: {} stances, {walking} walking: {:?}",
            st.len(),
            st.iter().map(|s| s.label.as_str()).collect::<Vec<_>>()
        );
        assert!(st.iter().all(|s| s.boundary_start != Boundary::Flight && s.boundary_end != Boundary::Flight), "{rel}");
        assert!(walking >= 3, "{rel}: {walking} walking stances");
        for s in st.iter().filter(|s| s.boundary_start == Boundary::NoFlight) {
            assert!(
                s.label == "L" || s.label == "R",
                "{rel}: walking stance labelled {}",
                s.label
            );
        }
    }
}

#[test]
fn running_stances_carry_more_than_body_weight() {
    // CORRECTIONS issue 3 item 3: mean vertical applied force over a running stance > 1.1 BW.
    for rel in [
        "run/cmu_09_01_run_mb.bvh",
        "odd/cmu_09_10_run_zero_frames_mb.bvh",
    ] {
        let Some(st) = stances_of(rel) else { return };
        for s in st
            .iter()
            .filter(|s| s.boundary_start == Boundary::Flight && s.boundary_end == Boundary::Flight)
        {
            let bw = s.model.axes[2].integral() / (s.mass_kg * G);
            println!("{}: mean vertical force {bw:.2} BW", s.stance_id);
            assert!(bw > 1.1, "{}: {bw:.3} BW", s.stance_id);
        }
    }
}
