//! Force-plate clips (`../shared/data/forceplate`): the stance force models against the
//! measured ground reaction force, stance by stance (CORRECTIONS issue 3 item 4).
//!
//! Each detected stance inside the clip's `window` is matched to the plate stances of its
//! feet (nearest plate touchdown within 0.15 s of `t_TD`, the matching radius of
//! `tests/forceplate.rs`; a plate stance open at the window edge is matched by its liftoff).
//! The model (spec stance-model §11, "Reconstructing the force") is evaluated in real time
//! over the detected stance [`t_TD`, `t_LO`] and is 0 outside it; it is compared with the
//! plate force at the plate samples in the union of the detected and the matched plate
//! stance: a single-foot stance (`L`, `R`) with that foot's force, a two-footed one (`LR`)
//! with the total.
//!
//! # Frames and units
//! `grf.csv` is in BVH world axes (+Y up, +X forward, +Z right); the project's Z-up world is
//! `(x, y, z) → (x, −z, y)` (SOURCES.md), so the vertical force is the `_fy_n` column.
//! Errors are in body weights (BW = `meta.body_weight_n`), impulses in BW·s.
//!
//! # References
//! CORRECTIONS issue 3 item 4; spec stance-model §1, §2, §4.3, §11; `data/forceplate/SOURCES.md`.

use serde_json::Value;
use stancelib::force_model::ratio::{DEFAULT_RATIO_DEGREE_H, DEFAULT_RATIO_DEGREE_P};
use stancelib::ingest::IngestOptions;
use stancelib::stances::{assemble_clip, Stance, StanceOptions};

/// (clip, mean vertical RMSE target in BW): issue 12 (the Fourier model's floor,
/// c0 + 3 harmonics fitted to the plate force itself, is 0.05 BW on the run and 0.17 on the
/// drop jump).
use crate::util::{self, outln};

/// The asserted bounds are the targets (measured: 0.126 BW on the run with
/// sub-frame stance edges and the soft position target, 0.285 BW on the drop jump).
const CLIPS: [(&str, f64); 2] = [
    ("hamner_s02_run_4ms", 0.13),
    ("opencap_s4_DJ1_dropjump", 0.35),
];

/// g of the data (meta.json `g_mps2`), m/s².
const G: f64 = 9.81;

/// Matching radius, s: about half a running stance, so a matched event belongs to the same
/// contact (as in `tests/forceplate.rs`).
const MATCH_TOL_S: f64 = 0.15;

/// Largest plate lag searched, s (the data's documented lags are 7–15 ms).
const MAX_PLATE_LAG_S: f64 = 0.03;

/// The candidate plate lags, s: −30 … 30 ms in 1 ms steps.
fn lag_candidates() -> impl Iterator<Item = f64> {
    let steps = (MAX_PLATE_LAG_S * 1e3).round() as i32;
    (-steps..=steps).map(|k| f64::from(k) * 1e-3)
}

/// How far the plates lag the kinematics, s: where the plates show at least
/// [`MIN_JOINED_FLIGHTS`] stances between two flights, the lag at which the plates join the
/// flights ([`flight_join_lag_s`]), else the lag that best matches the kinematic force's
/// shape ([`shape_lag_s`]). Estimated from the kinematics, never from a force model, so the
/// models are scored against plates on the motion's clock. `SOURCES.md` documents 7 ms
/// (2 m/s) and 12 ms (3 m/s) for the `hamner_multi_run` clips.
fn plate_lag_s(
    frames: &stancelib::ingest::ClipFrames,
    mass: f64,
    t_grf: &[f64],
    fy: &[f64],
    window: [f64; 2],
) -> f64 {
    flight_join_lag_s(frames, mass, t_grf, fy)
        .unwrap_or_else(|| shape_lag_s(frames, mass, t_grf, fy, window))
}

/// The plate force at `t` by linear interpolation; `None` outside the samples.
fn plate_at(t_grf: &[f64], fy: &[f64], t: f64) -> Option<f64> {
    let i = t_grf.partition_point(|&x| x <= t);
    (i > 0 && i < t_grf.len()).then(|| {
        let (t0, t1) = (t_grf[i - 1], t_grf[i]);
        fy[i - 1] + (fy[i] - fy[i - 1]) * (t - t0) / (t1 - t0)
    })
}

/// The shift `L` (±30 ms in 1 ms steps) that minimises the RMS difference between the
/// kinematic vertical force `m (a_z + g)` of the ingested COM and the plates' total vertical
/// force at `t + L`, over the window less the SG filter's edge (0.05 s each side).
fn shape_lag_s(
    frames: &stancelib::ingest::ClipFrames,
    mass: f64,
    t_grf: &[f64],
    fy: &[f64],
    window: [f64; 2],
) -> f64 {
    let rms = |lag: f64| {
        let (mut se, mut n) = (0.0, 0usize);
        for (t, a) in frames.time_s.iter().zip(&frames.com_a) {
            if *t < window[0] + 0.05 || *t > window[1] - 0.05 {
                continue;
            }
            if let Some(f) = plate_at(t_grf, fy, t + lag) {
                se += (mass * (a[2] + G) - f).powi(2);
                n += 1;
            }
        }
        (se / n.max(1) as f64).sqrt()
    };
    lag_candidates()
        .min_by(|a, b| rms(*a).total_cmp(&rms(*b)))
        .unwrap_or(0.0)
}

/// Plate threshold of a flight, N: the events' 20 N (`SOURCES.md`).
const FLIGHT_FORCE_N: f64 = 20.0;
/// Shortest plate flight used, s, and the margin kept from its events, s.
const FLIGHT_MIN_S: f64 = 0.04;
const FLIGHT_MARGIN_S: f64 = 0.004;
/// Fewest stances between two plate flights for [`flight_join_lag_s`].
const MIN_JOINED_FLIGHTS: usize = 2;

/// The plate flights: runs of total vertical force below [`FLIGHT_FORCE_N`] longer than
/// [`FLIGHT_MIN_S`], not at the ends of the record, (first, last sample time) on the plate
/// clock.
fn plate_flights(t_grf: &[f64], fy: &[f64]) -> Vec<(f64, f64)> {
    let mut out = Vec::new();
    let mut i = 0;
    while i < fy.len() {
        if fy[i] >= FLIGHT_FORCE_N {
            i += 1;
            continue;
        }
        let j = (i..fy.len())
            .take_while(|&k| fy[k] < FLIGHT_FORCE_N)
            .last()
            .unwrap_or(i);
        if i > 0 && j + 1 < fy.len() && t_grf[j] - t_grf[i] > FLIGHT_MIN_S {
            out.push((t_grf[i], t_grf[j]));
        }
        i = j + 1;
    }
    out
}

/// The −g parabola through the raw COM height over the frames inside `(a, b)` less
/// [`FLIGHT_MARGIN_S`] (least squares of `z + ½ g (t − t_m)² = z_m + v_m (t − t_m)`):
/// `(t_m, z_m, v_m)` at the midpoint; `None` with fewer than 2 frames.
fn flight_parabola(frames: &stancelib::ingest::ClipFrames, (a, b): (f64, f64)) -> Option<[f64; 3]> {
    let tm = 0.5 * (a + b);
    let pts: Vec<(f64, f64)> = frames
        .time_s
        .iter()
        .zip(&frames.com)
        .filter(|(t, _)| **t > a + FLIGHT_MARGIN_S && **t < b - FLIGHT_MARGIN_S)
        .map(|(t, c)| (t - tm, c[2] + 0.5 * G * (t - tm).powi(2)))
        .collect();
    if pts.len() < 2 {
        return None;
    }
    let n = pts.len() as f64;
    let (mx, my) = pts
        .iter()
        .fold((0.0, 0.0), |s, p| (s.0 + p.0 / n, s.1 + p.1 / n));
    let sxx: f64 = pts.iter().map(|p| (p.0 - mx).powi(2)).sum();
    let sxy: f64 = pts.iter().map(|p| (p.0 - mx) * (p.1 - my)).sum();
    let v = sxy / sxx;
    Some([tm, my - v * mx, v])
}

/// The lag at which the plates join the flights: for each stance between two plate flights,
/// the COM height reached by integrating `F_z/m − g` (plates at `t + L`, 1 ms trapezoid
/// steps) from the first flight's −g parabola at its midpoint to the next flight's midpoint,
/// minus that flight's parabola there; `L` (±30 ms, 1 ms steps) minimises the median |Δz|.
/// The velocities join on any clock (the impulse does not depend on `L`); the position
/// depends on the force's timing, `∂Δz/∂L ≈ J/m` (≈ 3.5 m/s on a 4 m/s run: 1 ms ≈ 3.5
/// mm). `None` with fewer than [`MIN_JOINED_FLIGHTS`] stances between parabolas.
fn flight_join_lag_s(
    frames: &stancelib::ingest::ClipFrames,
    mass: f64,
    t_grf: &[f64],
    fy: &[f64],
) -> Option<f64> {
    let flights = plate_flights(t_grf, fy);
    let miss = |lag: f64| -> Vec<f64> {
        let fits: Vec<Option<[f64; 3]>> = flights
            .iter()
            .map(|&(a, b)| flight_parabola(frames, (a - lag, b - lag)))
            .collect();
        fits.windows(2)
            .filter_map(|w| {
                let ([t0, mut z, mut v], [t1, z1, _]) = (w[0]?, w[1]?);
                let steps = ((t1 - t0) / 1e-3).ceil() as usize;
                let h = (t1 - t0) / steps as f64;
                let acc = |t: f64| plate_at(t_grf, fy, t + lag).map(|f| f / mass - G);
                for k in 0..steps {
                    let t = t0 + h * k as f64;
                    let (a0, a1) = (acc(t)?, acc(t + h)?);
                    z += v * h + h * h * (2.0 * a0 + a1) / 6.0;
                    v += 0.5 * h * (a0 + a1);
                }
                Some((z - z1).abs())
            })
            .collect()
    };
    if miss(0.0).len() < MIN_JOINED_FLIGHTS {
        return None;
    }
    lag_candidates().min_by(|a, b| {
        let m = |l: f64| quantile(&miss(l), 0.5);
        m(*a).total_cmp(&m(*b))
    })
}

/// Plate stances of one foot, (touchdown, liftoff) with the window edge for a missing event.
fn plate_stances(meta: &Value, side: &str, window: [f64; 2]) -> Vec<(f64, f64, bool, bool)> {
    meta["plate_events"][side]
        .as_array()
        .unwrap_or_else(|| panic!("plate_events.{side}"))
        .iter()
        .map(|e| {
            let (td, lo) = (e["touchdown_s"].as_f64(), e["liftoff_s"].as_f64());
            (
                td.unwrap_or(window[0]),
                lo.unwrap_or(window[1]),
                td.is_some(),
                lo.is_some(),
            )
        })
        .collect()
}

/// A plate stance of one foot: (touchdown, liftoff, touchdown inside, liftoff inside the window).
type PlateStance = (f64, f64, bool, bool);

/// The plate stance of one foot matched to a detected stance: the nearest plate touchdown
/// within the radius, else (a plate stance open at the window edge) the nearest liftoff.
/// Returns (touchdown, liftoff, complete: both events inside the window).
fn match_plate(s: &Stance, plate: &[PlateStance]) -> Option<(f64, f64, bool)> {
    let nearest = |key: &dyn Fn(&PlateStance) -> Option<f64>, t: f64| {
        plate
            .iter()
            .filter_map(|p| key(p).map(|x| ((x - t).abs(), (p.0, p.1, p.2 && p.3))))
            .filter(|(d, _)| *d <= MATCH_TOL_S)
            .min_by(|a, b| a.0.total_cmp(&b.0))
            .map(|(_, p)| p)
    };
    nearest(&|p| p.2.then_some(p.0), s.td_clip_s)
        .or_else(|| nearest(&|p| (!p.2 && p.3).then_some(p.1), s.lo_clip_s))
}

/// The model's applied force at clip time `t` in stance axes (h, p, v), N; 0 outside the
/// detected stance (spec §11).
fn model_at(s: &Stance, t: f64) -> [f64; 3] {
    if t < s.td_clip_s || t > s.lo_clip_s {
        return [0.0; 3];
    }
    let tau = (t - s.td_clip_s) / s.dt_s;
    std::array::from_fn(|a| s.model.axes[a].eval(tau))
}

/// One force-plate clip, ingested and segmented, with its plate forces in the Z-up world.
struct PlateClip {
    mass: f64,
    bw: f64,
    window: [f64; 2],
    frames: stancelib::ingest::ClipFrames,
    stances: Vec<Stance>,
    t_grf: Vec<f64>,
    /// Total, left and right plate force per sample (world, Z up), N.
    force: [Vec<[f64; 3]>; 3],
    plates: [Vec<PlateStance>; 2],
}

impl PlateClip {
    fn load(data: &std::path::Path, clip: &str, opts: &StanceOptions) -> PlateClip {
        let util::ForcePlateClip {
            dir,
            meta,
            mass,
            bw,
            window,
            bvh,
        } = util::forceplate_clip(data, clip);
        let ingest_opts = IngestOptions {
            mass_kg: mass,
            ..Default::default()
        };
        let (summary, frames, contacts) = util::ingest_body(&bvh, &ingest_opts, clip);
        // The force mapping below assumes the documented +Y-up file (SOURCES.md).
        assert_eq!(summary.up_axis.as_deref(), Some("+Y"), "{clip}: up axis");
        let (stances, _) = assemble_clip(clip, &frames, &summary, &contacts, mass, opts);
        let (h, cols) = util::read_csv(&dir.join("grf.csv"));
        // Plate time on the kinematics' clock: the plates' own lag removed.
        let lag = plate_lag_s(
            &frames,
            mass,
            util::csv_col(&h, &cols, "time_s"),
            util::csv_col(&h, &cols, "fy_n"),
            window,
        );
        let lag = std::env::var(format!("WT39_LAG_{clip}"))
            .map_or(lag, |v| v.parse::<f64>().unwrap() * 1e-3);
        eprintln!(
            "{clip}: plates lag the kinematics by {:.0} ms (removed)",
            1e3 * lag
        );
        let t_grf: Vec<f64> = util::csv_col(&h, &cols, "time_s")
            .iter()
            .map(|t| t - lag)
            .collect();
        // World Z-up force (x, −z, y) of the BVH-axes columns `<p>fx_n`, `<p>fy_n`, `<p>fz_n`.
        let world = |prefix: &str| -> Vec<[f64; 3]> {
            let (fx, fy, fz) = (
                util::csv_col(&h, &cols, &format!("{prefix}fx_n")),
                util::csv_col(&h, &cols, &format!("{prefix}fy_n")),
                util::csv_col(&h, &cols, &format!("{prefix}fz_n")),
            );
            (0..t_grf.len()).map(|i| [fx[i], -fz[i], fy[i]]).collect()
        };
        let force = [world(""), world("left_"), world("right_")];
        let shifted = |side: &str| -> Vec<PlateStance> {
            plate_stances(&meta, side, window)
                .into_iter()
                .map(|(td, lo, has_td, has_lo)| {
                    let at = |t: f64, has: bool| if has { t - lag } else { t };
                    (at(td, has_td), at(lo, has_lo), has_td, has_lo)
                })
                .collect()
        };
        let plates = [shifted("left"), shifted("right")];
        PlateClip {
            mass,
            bw,
            window,
            frames,
            stances,
            t_grf,
            force,
            plates,
        }
    }

    /// Whether a stance lies inside the clip's window (10 µs: meta.json rounds the ends).
    fn in_window(&self, s: &Stance) -> bool {
        s.td_clip_s >= self.window[0] - 1e-5 && s.lo_clip_s <= self.window[1] + 1e-5
    }

    /// The feet of a stance label (`L`, `R`, `LR`), `None` for any other label.
    fn feet(s: &Stance) -> Option<Vec<usize>> {
        match s.label.as_str() {
            "L" => Some(vec![0]),
            "R" => Some(vec![1]),
            "LR" => Some(vec![0, 1]),
            _ => None,
        }
    }

    /// The plate force series of a stance's label: that foot's, or the total for `LR`.
    fn series(&self, s: &Stance) -> &[[f64; 3]] {
        match s.label.as_str() {
            "L" => &self.force[1],
            "R" => &self.force[2],
            _ => &self.force[0],
        }
    }
}

#[test]
fn stance_force_models_match_the_force_plates() {
    let Some(data) = crate::util::shared_or_skip("stance_force_models_match_the_force_plates")
    else {
        return;
    };
    let mut out = String::new();
    let mut failures: Vec<String> = Vec::new();
    for (clip, target) in CLIPS {
        let pc = PlateClip::load(&data, clip, &StanceOptions::default());
        let PlateClip {
            mass,
            bw,
            window,
            ref frames,
            ref stances,
            ref plates,
            ..
        } = pc;
        outln!(
            out,
            "== {clip}: mass {mass} kg, BW {bw} N, window {window:?}, {} stances detected",
            stances.len()
        );
        outln!(
            out,
            "  {:<32} {:>15} {:>15}  {:>6} {:>6} {:>6} {:>6}  {:>7} {:>7} {:>7}\n  {:<32} {:>15} {:>15}  {:>27}  {:>23}",
            "stance",
            "detected",
            "plate",
            "h",
            "p",
            "v",
            "kin v",
            "J model",
            "J plate",
            "J err",
            "",
            "s",
            "s",
            "RMSE, BW (kin: m(a_z+g))",
            "vertical impulse, BW·s"
        );
        let mut rmse_v = Vec::new();
        let mut worst_imp = 0.0f64;
        for s in stances {
            // Only stances inside the window, where both data are valid (10 µs: the window
            // ends are rounded to 10 µs in meta.json).
            if !pc.in_window(s) {
                outln!(out, "  {:<32} outside the window: not scored", s.stance_id);
                continue;
            }
            let Some(feet) = PlateClip::feet(s) else {
                failures.push(format!("{}: unexpected label {}", s.stance_id, s.label));
                continue;
            };
            let matched: Vec<Option<(f64, f64, bool)>> =
                feet.iter().map(|&f| match_plate(s, &plates[f])).collect();
            let Some((p0, p1, complete)) = matched
                .iter()
                .try_fold((f64::INFINITY, f64::NEG_INFINITY, true), |acc, m| {
                    m.map(|(a, b, c)| (acc.0.min(a), acc.1.max(b), acc.2 && c))
                })
            else {
                failures.push(format!(
                    "{}: no plate stance within {MATCH_TOL_S} s for every foot (matches {matched:?})",
                    s.stance_id
                ));
                continue;
            };
            let plate_f = pc.series(s);
            let (u0, u1) = (s.td_clip_s.min(p0), s.lo_clip_s.max(p1));
            let r = s.heading.rotation();
            let (mut se, mut se_kin, mut n) = ([0.0; 3], 0.0, 0usize);
            let (mut samples_t, mut samples_v) = (Vec::new(), Vec::new());
            for (i, &t) in pc.t_grf.iter().enumerate() {
                if t < u0 || t > u1 {
                    continue;
                }
                let fw = plate_f[i];
                // The plate force in stance axes (R_s · world).
                let fp: [f64; 3] =
                    std::array::from_fn(|a| r[a][0] * fw[0] + r[a][1] * fw[1] + r[a][2] * fw[2]);
                let fm = model_at(s, t);
                (0..3).for_each(|a| se[a] += (fm[a] - fp[a]).powi(2));
                // Diagnostic: the kinematic vertical force m(a_z + g) the model is fitted to,
                // at the frame nearest the plate sample (same rate; the plate clock is
                // shifted by its lag, so within half a frame).
                let k = frames.time_s.partition_point(|x| *x < t);
                let k = match (k.checked_sub(1), frames.time_s.get(k)) {
                    (Some(j), Some(x)) if (t - frames.time_s[j]) < (x - t) => j,
                    (Some(j), None) => j,
                    _ => k,
                };
                se_kin += (mass * (frames.com_a[k][2] + G) - fp[2]).powi(2);
                n += 1;
                samples_t.push(t);
                samples_v.push(fp[2]);
            }
            assert!(
                n >= 3,
                "{}: only {n} plate samples in the union",
                s.stance_id
            );
            let rmse = se.map(|x| (x / n as f64).sqrt() / bw);
            let rmse_kin = (se_kin / n as f64).sqrt() / bw;
            // Vertical impulse: the model's over [t_TD, t_LO] in closed form (spec §5:
            // ∫f_v = c0_v Δt), the plate's by the trapezoid rule over the union's samples.
            let imp_model = s.model.axes[2].integral() * s.dt_s / bw;
            let imp_plate = samples_t
                .windows(2)
                .zip(samples_v.windows(2))
                .map(|(t, f)| 0.5 * (f[0] + f[1]) * (t[1] - t[0]))
                .sum::<f64>()
                / bw;
            outln!(
                out,
                "  {:<32} {:>7.4}-{:<7.4} {:>7.4}-{:<7.4}  {:>6.3} {:>6.3} {:>6.3} {:>6.3}  {:>7.4} {:>7.4} {:>+7.4} ({:+.1} %)",
                s.stance_id,
                s.td_clip_s,
                s.lo_clip_s,
                p0,
                p1,
                rmse[0],
                rmse[1],
                rmse[2],
                rmse_kin,
                imp_model,
                imp_plate,
                imp_model - imp_plate,
                100.0 * (imp_model - imp_plate) / imp_plate
            );
            // A plate stance open at the window edge (meta: no event there) continues beyond
            // the window, where neither the plate force nor its end is known: the union is
            // undefined, so the stance is reported above but not scored (SOURCES.md's plate
            // floor, "2 stances" on the drop jump, likewise counts only complete ones).
            if complete {
                rmse_v.push(rmse[2]);
                worst_imp = worst_imp.max((imp_model - imp_plate).abs());
            } else {
                outln!(
                    out,
                    "    ^ not scored: its plate stance is open at the window edge (contact continues past {:.4} s)",
                    window[1]
                );
            }
        }
        if rmse_v.is_empty() {
            failures.push(format!("{clip}: no stance scored"));
            continue;
        }
        let mean = rmse_v.iter().sum::<f64>() / rmse_v.len() as f64;
        let worst = rmse_v.iter().fold(0.0f64, |m, x| m.max(*x));
        outln!(
            out,
            "  {clip}: {} stances scored; vertical RMSE mean {mean:.3} BW (target ≤ {target}), worst {worst:.3} BW; worst |vertical impulse error| {worst_imp:.4} BW·s",
            rmse_v.len()
        );
        // CORRECTIONS issue 3 item 4: the mean over the clip's stances.
        if mean > target {
            failures.push(format!(
                "{clip}: mean vertical RMSE {mean:.3} BW > {target} BW"
            ));
        }
    }
    print!("{out}");
    assert!(
        failures.is_empty(),
        "stance force vs force plates:\n{}",
        failures.join("\n")
    );
}

/// `μ_req` of a force series at active fraction `λ`: `max |f_t|/f_v` where
/// `f_v ≥ λ · max f_v` (spec §7.1), stance axes (h, p, v), unit-free.
fn mu_req(forces: &[[f64; 3]], lambda: f64) -> f64 {
    let peak = forces
        .iter()
        .map(|f| f[2])
        .fold(f64::NEG_INFINITY, f64::max);
    forces
        .iter()
        .filter(|f| f[2] >= lambda * peak && f[2] > 0.0)
        .map(|f| f[0].hypot(f[1]) / f[2])
        .fold(0.0, f64::max)
}

/// The `q`-quantile (0…1) of `v` by the nearest rank.
fn quantile(v: &[f64], q: f64) -> f64 {
    let mut s = v.to_vec();
    s.sort_by(f64::total_cmp);
    s[((q * s.len() as f64).ceil() as usize).clamp(1, s.len()) - 1]
}

/// Asserted bound on the median |model − plate| `μ_req` (issue 12 target: 0.15).
const MU_MEDIAN_BOUND: f64 = 0.15;
/// Asserted bound on its 90th percentile (issue 12 target: 0.3).
const MU_P90_BOUND: f64 = 0.3;

#[test]
fn stance_friction_demand_matches_the_force_plates() {
    // See: issue 12 item 1 and targets — per running stance of the treadmill run, the
    // model's μ_req (5 % active set, spec §7.1) against the plate's over the plate stance.
    let Some(data) = crate::util::shared_or_skip("stance_friction_demand_matches_the_force_plates")
    else {
        return;
    };
    let clip = "hamner_s02_run_4ms";
    let pc = PlateClip::load(&data, clip, &StanceOptions::default());
    let mut out = String::new();
    outln!(
        out,
        "== {clip}: μ_req per single-foot stance (model | plate), active set 5 % and 20 %"
    );
    let (mut d5, mut model_ok, mut plate_ok, mut unilateral, mut n) =
        (Vec::new(), 0usize, 0usize, 0usize, 0usize);
    let mut d20 = Vec::new();
    for s in pc.stances.iter().filter(|s| pc.in_window(s)) {
        let Some(feet) = PlateClip::feet(s).filter(|f| f.len() == 1) else {
            continue;
        };
        let Some((p0, p1, true)) = match_plate(s, &pc.plates[feet[0]]) else {
            continue;
        };
        let r = s.heading.rotation();
        let plate: Vec<[f64; 3]> = pc
            .t_grf
            .iter()
            .zip(pc.series(s))
            .filter(|(t, _)| (p0..=p1).contains(*t))
            .map(|(_, fw)| {
                std::array::from_fn(|a| r[a][0] * fw[0] + r[a][1] * fw[1] + r[a][2] * fw[2])
            })
            .collect();
        let grid = s.model.grid();
        let model: Vec<[f64; 3]> = grid
            .iter()
            .map(|&t| std::array::from_fn(|a| s.model.axes[a].eval(t)))
            .collect();
        let (m5, p5) = (s.coef.mu_req, mu_req(&plate, 0.05));
        let (m20, p20) = (mu_req(&model, 0.2), mu_req(&plate, 0.2));
        // The stored μ_req is the same function of the model on its grid.
        assert!((m5 - mu_req(&model, 0.05)).abs() < 1e-9, "{}", s.stance_id);
        assert!((s.coef.mu_req_robust - m20).abs() < 1e-9, "{}", s.stance_id);
        outln!(
            out,
            "  {:<30} μ5 {m5:.3} | {p5:.3}   μ20 {m20:.3} | {p20:.3}   unilateral {}",
            s.stance_id,
            s.coef.unilateral_ok
        );
        d5.push((m5 - p5).abs());
        d20.push((m20 - p20).abs());
        model_ok += usize::from(m5 <= 0.7);
        plate_ok += usize::from(p5 <= 0.7);
        unilateral += usize::from(s.coef.unilateral_ok);
        n += 1;
    }
    assert!(n >= 20, "{clip}: only {n} stances matched");
    let share = |k: usize| 100.0 * k as f64 / n as f64;
    let (med, p90) = (quantile(&d5, 0.5), quantile(&d5, 0.9));
    outln!(
        out,
        "  {n} stances: |Δμ5| median {med:.3} (target ≤ 0.15), p90 {p90:.3} (≤ 0.3); |Δμ20| median {:.3}; ≤ 0.7: model {:.0} %, plates {:.0} % (within 10 points); unilateral {:.0} % (≥ 98 %)",
        quantile(&d20, 0.5),
        share(model_ok),
        share(plate_ok),
        share(unilateral)
    );
    print!("{out}");
    // Issue 12's targets, asserted as they are: median 0.15 (0.096 measured, 0.093 with the
    // travel targets of 2026-12-06) and 90th percentile 0.3 (0.260, now 0.251; the paper's
    // Fourier model gave 1.44 and 2.15).
    let mut failures = Vec::new();
    if med > MU_MEDIAN_BOUND {
        failures.push(format!("median |Δμ_req| {med:.3} > {MU_MEDIAN_BOUND}"));
    }
    if p90 > MU_P90_BOUND {
        failures.push(format!("p90 |Δμ_req| {p90:.3} > {MU_P90_BOUND}"));
    }
    if (share(model_ok) - share(plate_ok)).abs() > 10.0 {
        failures.push("share of stances with μ_req ≤ 0.7 differs by > 10 points".into());
    }
    if share(unilateral) < 98.0 {
        failures.push(format!(
            "unilateral_ok on {:.0} % < 98 %",
            share(unilateral)
        ));
    }
    assert!(failures.is_empty(), "{clip}: {}", failures.join("; "));
}

/// Per matched single-foot stance of a run clip: (|Δμ5|, |Δμ20|, model μ20, plate μ20).
fn friction_pairs(pc: &PlateClip) -> Vec<[f64; 4]> {
    let mut v = Vec::new();
    for s in pc.stances.iter().filter(|s| pc.in_window(s)) {
        let Some(feet) = PlateClip::feet(s).filter(|f| f.len() == 1) else {
            continue;
        };
        let Some((p0, p1, true)) = match_plate(s, &pc.plates[feet[0]]) else {
            continue;
        };
        let r = s.heading.rotation();
        let plate: Vec<[f64; 3]> = pc
            .t_grf
            .iter()
            .zip(pc.series(s))
            .filter(|(t, _)| (p0..=p1).contains(*t))
            .map(|(_, fw)| {
                std::array::from_fn(|a| r[a][0] * fw[0] + r[a][1] * fw[1] + r[a][2] * fw[2])
            })
            .collect();
        let model: Vec<[f64; 3]> = s
            .model
            .grid()
            .iter()
            .map(|&t| std::array::from_fn(|a| s.model.axes[a].eval(t)))
            .collect();
        let (m5, p5) = (mu_req(&model, 0.05), mu_req(&plate, 0.05));
        let (m20, p20) = (mu_req(&model, 0.2), mu_req(&plate, 0.2));
        v.push([(m5 - p5).abs(), (m20 - p20).abs(), m20, p20]);
    }
    v
}

/// Figures of one candidate friction form on one clip: median |Δμ20|, median and p90
/// |Δμ5|, model μ20 level (median model / median plate).
#[derive(Debug, Clone, Copy)]
struct FrictionScore {
    d20: f64,
    d5: f64,
    d5_p90: f64,
    level: f64,
}

fn friction_score(pc: &PlateClip) -> FrictionScore {
    let v = friction_pairs(pc);
    assert!(v.len() >= 5, "only {} stances matched", v.len());
    let col = |k: usize| v.iter().map(|x| x[k]).collect::<Vec<_>>();
    FrictionScore {
        d20: quantile(&col(1), 0.5),
        d5: quantile(&col(0), 0.5),
        d5_p90: quantile(&col(0), 0.9),
        level: quantile(&col(2), 0.5) / quantile(&col(3), 0.5),
    }
}

/// The plate runs the friction form is chosen on (issue 39 item 1).
const FRICTION_CLIPS: [&str; 3] = [
    "hamner_multi_run_2ms",
    "hamner_multi_run_3ms",
    "hamner_s02_run_4ms",
];

/// Issue 39's targets on a held-out run: median |Δμ20| ≤ 0.06, median |Δμ5| ≤ 0.15, p90 ≤ 0.3.
const HELD_OUT_MU20: f64 = 0.06;

/// A candidate form: (leg-line weight λ, roll fraction φ, degree of q_h, degree of q_p).
type Form = (f64, f64, usize, usize);

fn form_options(f: Form) -> StanceOptions {
    let mut o = StanceOptions::default();
    o.fit.ratio.leg_line_weight = f.0;
    o.fit.ratio.roll_fraction = f.1;
    o.fit.ratio.ratio_degree_h = f.2;
    o.fit.ratio.ratio_degree_p = f.3;
    o
}

#[test]
fn friction_model_form_is_chosen_by_leaving_one_run_out() {
    // See: issue 39 item 1 — the ratio model's form (leg-line weight, roll fraction, ratio
    // degrees) chosen on all plate runs but one and scored on that one; the library
    // defaults scored on every run.
    let Some(data) =
        crate::util::shared_or_skip("friction_model_form_is_chosen_by_leaving_one_run_out")
    else {
        return;
    };
    let mut forms: Vec<Form> = Vec::new();
    for lam in [0.0, 0.5, 1.0] {
        for roll in [0.5, 0.6, 0.7, 0.8, 1.0] {
            for (dh, dp) in [(1, 1), (1, 2), (2, 1), (2, 2)] {
                if lam > 0.0 || roll == 0.7 {
                    forms.push((lam, roll, dh, dp));
                }
            }
        }
    }
    // scores[form][clip]
    let scores: Vec<Vec<FrictionScore>> = forms
        .iter()
        .map(|&f| {
            let o = form_options(f);
            FRICTION_CLIPS
                .iter()
                .map(|c| friction_score(&PlateClip::load(&data, c, &o)))
                .collect()
        })
        .collect();
    let mut out = String::new();
    outln!(
        out,
        "== friction form by leaving one plate run out (|Δμ20| median; |Δμ5| median / p90)"
    );
    // The cost of a form on the kept runs: Σ |Δμ20| medians, then Σ |Δμ5| medians.
    let choose = |keep: &dyn Fn(usize) -> bool, degrees: Option<(usize, usize)>| -> usize {
        let cost = |k: usize| -> (f64, f64) {
            let s = scores[k].iter().enumerate().filter(|(c, _)| keep(*c));
            s.fold((0.0, 0.0), |a, (_, x)| (a.0 + x.d20, a.1 + x.d5))
        };
        (0..forms.len())
            .filter(|&k| degrees.is_none_or(|d| (forms[k].2, forms[k].3) == d))
            .min_by(|&a, &b| cost(a).partial_cmp(&cost(b)).expect("finite scores"))
            .expect("forms")
    };
    // The degrees also shape the stances without a leg line (walks, two-footed jumps),
    // which these runs do not score: the choice is λ and φ at the library's degrees, and
    // the free choice of degrees is printed beside it.
    let degrees = Some((DEFAULT_RATIO_DEGREE_H, DEFAULT_RATIO_DEGREE_P));
    let mut failures = Vec::new();
    for (held, clip) in FRICTION_CLIPS.iter().enumerate() {
        let (k, free) = (
            choose(&|c| c != held, degrees),
            choose(&|c| c != held, None),
        );
        let (s, f) = (scores[k][held], scores[free][held]);
        outln!(
            out,
            "  held out {clip}: chosen λ {} φ {} → |Δμ20| {:.3} (≤ {HELD_OUT_MU20}), |Δμ5| {:.3} / {:.3} (≤ {MU_MEDIAN_BOUND} / {MU_P90_BOUND}), μ20 level {:.2}; degrees free: {:?} → |Δμ20| {:.3}",
            forms[k].0, forms[k].1, s.d20, s.d5, s.d5_p90, s.level, forms[free], f.d20
        );
        if s.d20 > HELD_OUT_MU20 || s.d5 > MU_MEDIAN_BOUND || s.d5_p90 > MU_P90_BOUND {
            failures.push(format!("{clip} held out: {s:?}"));
        }
    }
    let all = choose(&|_| true, degrees);
    let defaults = StanceOptions::default().fit.ratio;
    let default_form: Form = (
        defaults.leg_line_weight,
        defaults.roll_fraction,
        defaults.ratio_degree_h,
        defaults.ratio_degree_p,
    );
    outln!(
        out,
        "  chosen on every run: {:?}; library defaults: {default_form:?}",
        forms[all]
    );
    let kinematic = forms
        .iter()
        .position(|f| f.0 == 0.0 && f.2 == 1 && f.3 == 2);
    for (name, k) in [
        ("kinematic ratio (λ 0, q_h 1, q_p 2)", kinematic),
        ("defaults", forms.iter().position(|f| *f == default_form)),
    ] {
        let Some(k) = k else { continue };
        let line: Vec<String> = FRICTION_CLIPS
            .iter()
            .zip(&scores[k])
            .map(|(c, s)| {
                format!(
                    "{c} {:.3} ({:.3}/{:.3}, level {:.2})",
                    s.d20, s.d5, s.d5_p90, s.level
                )
            })
            .collect();
        outln!(out, "  {name}: {}", line.join("; "));
    }
    print!("{out}");
    if forms[all] != default_form {
        failures.push(format!(
            "the library defaults {default_form:?} are not the form chosen on every run {:?}",
            forms[all]
        ));
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

/// Mean vertical RMSE (BW) over the clip's complete matched stances inside the window,
/// against the plate over the union of the detected and the plate stance (as in
/// `stance_force_models_match_the_force_plates`).
fn vertical_rmse(pc: &PlateClip) -> f64 {
    let mut v = Vec::new();
    for s in pc.stances.iter().filter(|s| pc.in_window(s)) {
        let Some(feet) = PlateClip::feet(s) else {
            continue;
        };
        let matched: Option<Vec<(f64, f64, bool)>> = feet
            .iter()
            .map(|&f| match_plate(s, &pc.plates[f]))
            .collect();
        let Some(m) = matched else { continue };
        if !m.iter().all(|x| x.2) {
            continue;
        }
        let u0 = m.iter().fold(s.td_clip_s, |a, x| a.min(x.0));
        let u1 = m.iter().fold(s.lo_clip_s, |a, x| a.max(x.1));
        let (mut se, mut n) = (0.0, 0usize);
        for (t, fw) in pc.t_grf.iter().zip(pc.series(s)) {
            if (u0..=u1).contains(t) {
                se += (model_at(s, *t)[2] - fw[2]).powi(2);
                n += 1;
            }
        }
        if n >= 3 {
            v.push((se / n as f64).sqrt() / pc.bw);
        }
    }
    assert!(!v.is_empty(), "no stance scored");
    v.iter().sum::<f64>() / v.len() as f64
}

/// Identity (share of single-foot stances with a flight on both sides feasible as recorded
/// at μ = 0.7, the queries' active set and absolute limits; as `tests/queries.rs`
/// `running_stances_are_feasible_as_recorded`) and the median apex mismatch across a
/// flight (height mm, velocity cm/s; as `consecutive_stances_describe_the_same_flight`).
fn identity_and_apex(pc: &PlateClip) -> (f64, usize, f64, f64) {
    use stancelib::library::codec::stances::PoolStance;
    use stancelib::library::readers::read::{ClipInfo, StanceLibrary};
    use stancelib::query::feasibility::{LimitForm, DEFAULT_QUERY_ACTIVE_FRACTION};
    use stancelib::query::limits::{absolute_limits, stance_limits};
    use stancelib::query::pool::Prepared;
    use stancelib::query::run::{policy_request, scale_and_check};
    use stancelib::query::solve::Refs;
    use stancelib::stances::segment::Boundary;
    let rows: Vec<PoolStance> = pc
        .stances
        .iter()
        .map(|s| PoolStance {
            stance_id: s.stance_id.clone(),
            clip: s.clip.clone(),
            character_id: s.character_id.clone(),
            label: s.label.clone(),
            first_frame: s.first_frame,
            boundary_start: s.boundary_start,
            boundary_end: s.boundary_end,
            z_c: s.z_c,
            params: s.params,
            model: s.model.clone(),
            cp: s.cp,
            coef: s.coef,
        })
        .collect();
    let clip = pc.stances[0].clip.clone();
    let lib = StanceLibrary {
        dir: Default::default(),
        stances: rows.clone(),
        clips: [(
            clip,
            ClipInfo {
                s_eff: None,
                leg_m: None,
                reach_m: None,
                mass_kg: pc.mass,
                content_sha256: String::new(),
            },
        )]
        .into(),
    };
    let limits = absolute_limits(&lib);
    let (mut n, mut ok) = (0usize, 0usize);
    for s in &rows {
        let flights = s.boundary_start == Boundary::Flight && s.boundary_end == Boundary::Flight;
        if !flights || !(s.label == "L" || s.label == "R") {
            continue;
        }
        n += 1;
        let p = Prepared::with_active_fraction(s.clone(), DEFAULT_QUERY_ACTIVE_FRACTION);
        let lim = stance_limits(&p, LimitForm::Absolute, &limits, Some(0.7));
        if let Ok(c) = scale_and_check(&p, &policy_request(&p.stance, 1.0), &Refs::run(1.0), &lim) {
            ok += usize::from(c.verdict.feasible);
        }
    }
    let (mut dz, mut dv) = (Vec::new(), Vec::new());
    for w in pc.stances.windows(2) {
        let (a, b) = (&w[0], &w[1]);
        if a.boundary_end != Boundary::Flight || b.boundary_start != Boundary::Flight {
            continue;
        }
        let (ha, hb) = (a.heading.e_h, b.heading.e_h);
        dz.push((a.z_c + a.params.ze - b.z_c - b.params.zs).abs());
        let after = [
            a.params.ve * ha[0] - a.params.vp * ha[1],
            a.params.ve * ha[1] + a.params.vp * ha[0],
        ];
        let before = [b.params.vs * hb[0], b.params.vs * hb[1]];
        dv.push((after[0] - before[0]).hypot(after[1] - before[1]));
    }
    // The 2 m/s jog has few flights (4 stances with one on both sides): reported as is.
    assert!(
        n >= 1 && !dz.is_empty(),
        "{n} stances, {} flights",
        dz.len()
    );
    (
        100.0 * ok as f64 / n as f64,
        n,
        1e3 * quantile(&dz, 0.5),
        1e2 * quantile(&dv, 0.5),
    )
}

/// Target figures not met when measured (issue 39 item 2), printed, not asserted:
/// (model, held-out run, figure). Empty since the Fourier model's ratios are low-degree
/// polynomials carried by their cosine series (`force_model::cosine::power_series`): with
/// free cosine terms its 5 % friction demand on the 4 m/s run missed by a median 0.166
/// (p90 0.301) and no choice of degrees leaving one run out met |Δμ5| on all three runs
/// (`docs/stance-model.md` §4.1). The apex mismatch (13 mm on the 4 m/s run with a soft
/// position target) closed when the position became exact; the 3 m/s run's vertical RMSE
/// (0.25 BW) was the plates' 13 ms lag: on the motion's clock ([`plate_lag_s`]) it is
/// 0.06 BW with either model.
const KNOWN_GAPS: [(&str, &str, &str); 0] = [];

#[test]
fn fourier_model_meets_the_ratio_models_targets() {
    // See: issue 39 item 2 — both force models on every plate run, each with its leg-line
    // knobs (λ, φ) chosen leaving the scored run out (on the other two: Σ |Δμ20| medians,
    // then Σ |Δμ5| medians); every target figure printed for both, the targets asserted for
    // both except the measured gaps of KNOWN_GAPS (printed).
    // `cargo test --test integration fourier_model_meets -- --nocapture`
    use stancelib::force_model::ForceModelKind;
    let Some(data) = crate::util::shared_or_skip("fourier_model_meets_the_ratio_models_targets")
    else {
        return;
    };
    let forms: Vec<Form> = [0.5, 1.0]
        .iter()
        .flat_map(|&lam| {
            [0.5, 0.6, 0.7].map(|roll| (lam, roll, DEFAULT_RATIO_DEGREE_H, DEFAULT_RATIO_DEGREE_P))
        })
        .collect();
    let mut out = String::new();
    let mut failures = Vec::new();
    outln!(
        out,
        "== issue 39 targets per plate run, knobs chosen leaving the run out (targets: |Δμ20| ≤ {HELD_OUT_MU20}, |Δμ5| ≤ {MU_MEDIAN_BOUND} / p90 ≤ {MU_P90_BOUND}, vertical RMSE ≤ 0.13 BW, identity ≥ 85 %, apex ≤ 5 mm)"
    );
    outln!(
        out,
        "  {:<8} {:<22} {:>9} {:>7} {:>11} {:>8} {:>7} {:>12} {:>10} {:>13}",
        "model",
        "held-out run",
        "λ, φ",
        "|Δμ20|",
        "|Δμ5| med",
        "|Δμ5| p90",
        "RMSE_v",
        "identity",
        "apex mm",
        "apex v cm/s"
    );
    for kind in [ForceModelKind::Ratio, ForceModelKind::Fourier] {
        let options = |f: Form| {
            let mut o = form_options(f);
            o.fit.model = kind;
            o
        };
        let clips: Vec<Vec<PlateClip>> = forms
            .iter()
            .map(|&f| {
                FRICTION_CLIPS
                    .iter()
                    .map(|c| PlateClip::load(&data, c, &options(f)))
                    .collect()
            })
            .collect();
        let scores: Vec<Vec<FrictionScore>> = clips
            .iter()
            .map(|row| row.iter().map(friction_score).collect())
            .collect();
        for (held, clip) in FRICTION_CLIPS.iter().enumerate() {
            let cost = |k: usize| -> (f64, f64) {
                let kept = scores[k].iter().enumerate().filter(|(c, _)| *c != held);
                kept.fold((0.0, 0.0), |a, (_, x)| (a.0 + x.d20, a.1 + x.d5))
            };
            let k = (0..forms.len())
                .min_by(|&a, &b| cost(a).partial_cmp(&cost(b)).expect("finite scores"))
                .expect("forms");
            let (s, pc) = (scores[k][held], &clips[k][held]);
            let rmse = vertical_rmse(pc);
            let (identity, n_id, apex_mm, apex_cms) = identity_and_apex(pc);
            outln!(
                out,
                "  {:<8} {:<22} {:>4}, {:<4} {:>7.3} {:>11.3} {:>8.3} {:>7.3} {:>5.0} % of {:<3} {:>10.1} {:>13.1}",
                kind.name(),
                clip,
                forms[k].0,
                forms[k].1,
                s.d20,
                s.d5,
                s.d5_p90,
                rmse,
                identity,
                n_id,
                apex_mm,
                apex_cms
            );
            let name = kind.name();
            let checks = [
                (
                    "mu20",
                    s.d20 <= HELD_OUT_MU20,
                    format!("|Δμ20| {:.3}", s.d20),
                ),
                (
                    "mu5",
                    s.d5 <= MU_MEDIAN_BOUND,
                    format!("|Δμ5| median {:.3}", s.d5),
                ),
                (
                    "mu5_p90",
                    s.d5_p90 <= MU_P90_BOUND,
                    format!("|Δμ5| p90 {:.3}", s.d5_p90),
                ),
                ("rmse", rmse <= 0.13, format!("vertical RMSE {rmse:.3} BW")),
                (
                    "identity",
                    identity >= 85.0,
                    format!("identity {identity:.0} %"),
                ),
                (
                    "apex",
                    apex_mm <= 5.0,
                    format!("apex mismatch {apex_mm:.1} mm"),
                ),
            ];
            for (key, met, what) in checks {
                let gap = KNOWN_GAPS.contains(&(name, *clip, key));
                match (met, gap) {
                    (false, false) => failures.push(format!("{name} on {clip} (held out): {what}")),
                    (false, true) => outln!(out, "    not met (known gap, not asserted): {what}"),
                    // The list stays true: a gap that closes must leave it.
                    (true, true) => failures.push(format!(
                        "{name} on {clip}: {what} now meets its target; drop it from KNOWN_GAPS"
                    )),
                    (true, false) => {}
                }
            }
        }
    }
    print!("{out}");
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}
