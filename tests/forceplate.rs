//! Force-plate clips (`../shared/data/forceplate`): contact events against the plate
//! events, and the kinematic vertical force m(a_com,z + g) against the measured force.
//!
//! # References
//! spec com-from-bvh §7.3 (timing requirement); CORRECTIONS issue 2 item 4;
//! `data/forceplate/SOURCES.md`.

use serde_json::Value;
use stancelib::ingest::IngestOptions;
use stancelib::math::savgol::{window_for_rate, SavGol};

use crate::util::{self, outln};

const CLIPS: [&str; 2] = ["hamner_s02_run_4ms", "opencap_s4_DJ1_dropjump"];
/// g used by the data (meta.json `g_mps2`) and by the flight fits, m/s².
const G: f64 = 9.81;

/// Pearson's correlation coefficient of two equally long series.
pub fn pearson(a: &[f64], b: &[f64]) -> f64 {
    let n = a.len() as f64;
    let (ma, mb) = (a.iter().sum::<f64>() / n, b.iter().sum::<f64>() / n);
    let cov: f64 = a.iter().zip(b).map(|(x, y)| (x - ma) * (y - mb)).sum();
    let va: f64 = a.iter().map(|x| (x - ma).powi(2)).sum();
    let vb: f64 = b.iter().map(|y| (y - mb).powi(2)).sum();
    cov / (va * vb).sqrt()
}

/// One plate stance of a foot: (touchdown, liftoff), `None` at the window edge.
type PlateStance = (Option<f64>, Option<f64>);

fn plate_stances(meta: &Value, side: &str) -> Vec<PlateStance> {
    meta["plate_events"][side]
        .as_array()
        .unwrap_or_else(|| panic!("plate_events.{side}"))
        .iter()
        .map(|e| (e["touchdown_s"].as_f64(), e["liftoff_s"].as_f64()))
        .collect()
}

#[test]
fn contact_events_and_kinematic_force_match_the_force_plates() {
    let Some(data) =
        util::shared_or_skip("contact_events_and_kinematic_force_match_the_force_plates")
    else {
        return;
    };
    let mut failures: Vec<String> = Vec::new();
    let mut out = String::new();
    for clip in CLIPS {
        let util::ForcePlateClip {
            dir,
            meta,
            mass,
            bw,
            window,
            bvh,
        } = util::forceplate_clip(&data, clip);
        let grf_rate = meta["grf_rate_hz"].as_f64().expect("grf_rate_hz");
        let opts = IngestOptions {
            mass_kg: mass,
            ..Default::default()
        };
        let (summary, frames, contacts) = util::ingest_body(&bvh, &opts, clip);
        let dt = summary.frame_time_s;
        let n = frames.time_s.len();
        let (t_first, t_last) = (frames.time_s[0], frames.time_s[n - 1]);
        outln!(
            out,
            "== {clip}: {n} kept frames at {:.1} Hz, mass {mass} kg (BW {bw} N), unit {:?}, leg {:.3} m, window {window:?}",
            1.0 / dt,
            summary.unit,
            summary.leg_length_m.unwrap_or(f64::NAN)
        );

        // ---- Events (CORRECTIONS issue 2 item 4, spec §7.3) ----
        // Targets of spec §7.3 / CORRECTIONS item 4: mean ≤ max(1 frame + 10 ms, 20 ms),
        // worst ≤ max(2 frames + 10 ms, 30 ms): a kinematic edge is quantised to the frame
        // and the plate's 20 N threshold is not the kinematic contact instant.
        let mean_tol = (dt + 0.010).max(0.020);
        let worst_tol = (2.0 * dt + 0.010).max(0.030);
        // Matching radius 0.15 s (CORRECTIONS item 4): about half a running stance, so a
        // matched event belongs to the same contact.
        let match_tol = 0.15;
        // Plate events within 2 frames of a clip end are not scored (a detector starts out of
        // contact at the first kept frame and has no event at the last).
        let near_end = |t: f64| t - t_first <= 2.0 * dt || t_last - t <= 2.0 * dt;
        for (side, effector) in [("left", "left_foot"), ("right", "right_foot")] {
            let plate = plate_stances(&meta, side);
            let runs: Vec<_> = contacts.iter().filter(|r| r.effector == effector).collect();
            outln!(
                out,
                "  {side}: plate stances {:?}",
                plate
                    .iter()
                    .map(|p| format!(
                        "{:.4}-{:.4}",
                        p.0.unwrap_or(f64::NAN),
                        p.1.unwrap_or(f64::NAN)
                    ))
                    .collect::<Vec<_>>()
            );
            outln!(
                out,
                "  {side}: detected runs  {:?}",
                runs.iter()
                    .map(|r| format!(
                        "{}-{} ({:.4}-{:.4})",
                        r.first_frame,
                        r.last_frame,
                        r.t_td_s.unwrap_or(f64::NAN),
                        r.t_lo_s.unwrap_or(f64::NAN)
                    ))
                    .collect::<Vec<_>>()
            );
            for (kind, plate_t, det_t) in [
                (
                    "touchdown",
                    plate.iter().filter_map(|p| p.0).collect::<Vec<f64>>(),
                    runs.iter().filter_map(|r| r.t_td_s).collect::<Vec<f64>>(),
                ),
                (
                    "liftoff",
                    plate.iter().filter_map(|p| p.1).collect(),
                    runs.iter().filter_map(|r| r.t_lo_s).collect(),
                ),
            ] {
                let mut errs = Vec::new();
                let mut skipped = 0;
                for &tp in &plate_t {
                    if near_end(tp) {
                        skipped += 1;
                        continue;
                    }
                    let nearest = det_t
                        .iter()
                        .copied()
                        .min_by(|a, b| (a - tp).abs().total_cmp(&(b - tp).abs()));
                    match nearest {
                        Some(td) if (td - tp).abs() <= match_tol => errs.push(td - tp),
                        _ => failures.push(format!("{clip} {side} {kind}: plate event at {tp:.4} s has no detected {kind} within {match_tol} s (nearest {nearest:?})")),
                    }
                }
                let mean_abs = errs.iter().map(|e| e.abs()).sum::<f64>() / errs.len().max(1) as f64;
                let signed = errs.iter().sum::<f64>() / errs.len().max(1) as f64;
                let worst = errs.iter().fold(0.0f64, |m, e| m.max(e.abs()));
                outln!(out,
                    "  {side} {kind:<9}: scored {:>2} (not scored near a clip end: {skipped}), |err| mean {:5.1} ms worst {:5.1} ms (targets {:.1} / {:.1}), signed mean {:+5.1} ms; errors ms {:?}",
                    errs.len(),
                    mean_abs * 1e3,
                    worst * 1e3,
                    mean_tol * 1e3,
                    worst_tol * 1e3,
                    signed * 1e3,
                    errs.iter().map(|e| (e * 1e4).round() / 10.0).collect::<Vec<_>>()
                );
                if errs.is_empty() {
                    failures.push(format!("{clip} {side} {kind}: no scored plate event"));
                }
                // + 1e-12 s: round-off of the frame-time arithmetic only.
                if mean_abs > mean_tol + 1e-12 {
                    failures.push(format!(
                        "{clip} {side} {kind}: mean |error| {:.1} ms > {:.1} ms",
                        mean_abs * 1e3,
                        mean_tol * 1e3
                    ));
                }
                if worst > worst_tol + 1e-12 {
                    failures.push(format!(
                        "{clip} {side} {kind}: worst |error| {:.1} ms > {:.1} ms",
                        worst * 1e3,
                        worst_tol * 1e3
                    ));
                }
            }
            // A detected stance (inside the window) must overlap some plate stance of that foot.
            for r in &runs {
                let a = r.t_td_s.unwrap_or(t_first - dt / 2.0).max(window[0]);
                let b = r.t_lo_s.unwrap_or(t_last + dt / 2.0).min(window[1]);
                if b <= a {
                    continue; // outside the window
                }
                let overlaps = plate.iter().any(|p| {
                    let (pa, pb) = (p.0.unwrap_or(window[0]), p.1.unwrap_or(window[1]));
                    a.max(pa) < b.min(pb)
                });
                if !overlaps {
                    failures.push(format!(
                        "{clip} {side}: detected stance {}-{} ({a:.4}-{b:.4} s) overlaps no plate stance",
                        r.first_frame, r.last_frame
                    ));
                }
            }
        }

        // ---- Kinematic vertical force (CORRECTIONS issue 2 item 4) ----
        let (h, cols) = util::read_csv(&dir.join("grf.csv"));
        let t_grf = util::csv_col(&h, &cols, "time_s");
        let fvert = util::csv_col(&h, &cols, "fvert_n");
        assert!(
            fvert.iter().all(|f| f.is_finite()),
            "{clip}: fvert_n has empty cells"
        );
        // The same SG low-pass as the COM: cubic, 2·round(0.05 s·F)+1 samples.
        let w = window_for_rate(grf_rate);
        let f_sg = SavGol::new(w, 3)
            .expect("SG window")
            .apply(fvert, 0, 1.0 / grf_rate);
        let half_s = (window_for_rate(1.0 / dt) / 2) as f64 * dt; // half an SG window of the kinematics
        let half_k = window_for_rate(1.0 / dt) / 2;
        let (mut kin, mut meas, mut meas_raw) = (Vec::new(), Vec::new(), Vec::new());
        for k in half_k..n - half_k {
            let t = frames.time_s[k];
            // 10 µs: frame times are k·dt with a rounded dt; the window ends are rounded to 10 µs.
            if t < window[0] + half_s - 1e-5 || t > window[1] - half_s + 1e-5 {
                continue;
            }
            let i = (t * grf_rate).round() as usize;
            // Plate samples and frames share the clock (SOURCES.md: same rate, time 0 = frame 0);
            // the CSV rounds times to 0.1 ms.
            assert!(
                i < f_sg.len() && (t_grf[i] - t).abs() < 1e-4,
                "{clip}: no plate sample at frame time {t}"
            );
            kin.push(mass * (frames.com_a[k][2] + G));
            meas.push(f_sg[i]);
            meas_raw.push(fvert[i]);
        }
        assert!(
            kin.len() > n / 2,
            "{clip}: only {} frames compared",
            kin.len()
        );
        let rmse = (kin
            .iter()
            .zip(&meas)
            .map(|(a, b)| (a - b).powi(2))
            .sum::<f64>()
            / kin.len() as f64)
            .sqrt()
            / bw;
        let r = pearson(&kin, &meas);
        let rmse_raw = (kin
            .iter()
            .zip(&meas_raw)
            .map(|(a, b)| (a - b).powi(2))
            .sum::<f64>()
            / kin.len() as f64)
            .sqrt()
            / bw;
        outln!(out,
            "  kinematic vertical force vs plate (SG {w}), {} frames: RMSE {rmse:.3} BW (target ≤ 0.15), r {r:.4} (target ≥ 0.98); unfiltered plate (reported): RMSE {rmse_raw:.3} BW, r {:.4}",
            kin.len(),
            pearson(&kin, &meas_raw)
        );
        // CORRECTIONS issue 2 item 4: 0.15 BW and r ≥ 0.98 (measured 0.114 / 0.993 and
        // 0.128 / 0.989 in SOURCES.md; the margin covers the de Leva vs OpenSim COM).
        if rmse > 0.15 {
            failures.push(format!("{clip}: vertical force RMSE {rmse:.3} BW > 0.15"));
        }
        if r < 0.98 {
            failures.push(format!("{clip}: vertical force r {r:.4} < 0.98"));
        }
    }
    print!("{out}");
    assert!(
        failures.is_empty(),
        "force-plate failures:\n{}",
        failures.join("\n")
    );
}
