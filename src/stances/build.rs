//! All stances of one clip, from its ingest outputs (pure).

use super::params::{self, heading, model_consistent, Heading};
use super::segment::{segment, Boundary, Segment, SegmentInput, V_QUIET};
use super::{FlightRef, Stance};
use crate::constraints::{precompute, StanceContext};
use crate::contacts::flight::Flight;
use crate::contacts::EFFECTORS;
use crate::force_model::fit::j_cap;
use crate::force_model::stage_b::{
    fit_stage_b, to_stance_model, StageBFit, StageBInput, MAX_CONDITION,
};
use crate::force_model::{fit_stage_a, FitOptions, FitWorkspace, ForceModel};
use crate::ingest::{ClipFrames, ClipSummary};
use crate::math::savgol::{SavGol, DEFAULT_ORDER};
use crate::math::spline::NaturalSpline;
use crate::math::stats::median;

type V3 = [f64; 3];

/// Options of the stance stage.
#[derive(serde::Serialize, Debug, Clone, PartialEq, Default)]
pub struct StanceOptions {
    /// Force-model fit (Stage A).
    pub fit: FitOptions,
    /// Refit by least squares on the raw COM positions (Stage B, spec §4.2; off by default).
    pub stage_b: bool,
}

/// Natural cubic splines of the three coordinates of a per-frame vector series.
struct Splines([NaturalSpline; 3]);

impl Splines {
    fn new(t: &[f64], v: &[V3]) -> Option<Splines> {
        let axis = |i: usize| NaturalSpline::new(t, &v.iter().map(|p| p[i]).collect::<Vec<_>>());
        Some(Splines([axis(0)?, axis(1)?, axis(2)?]))
    }

    fn at(&self, t: f64) -> V3 {
        std::array::from_fn(|i| self.0[i].eval(t))
    }
}

/// The effectors that support a stance: a walking stance's single-support foot only
/// (stance-model §1 step 4, §8.1); otherwise every effector in contact on some frame.
fn supporting(seg: &Segment, contact: &[Vec<bool>; 4]) -> [bool; 4] {
    match seg.walking_foot {
        Some(f) => std::array::from_fn(|e| e == f),
        None => std::array::from_fn(|e| (seg.i0..=seg.i1).any(|k| contact[e][k])),
    }
}

fn label(seg: &Segment, contact: &[Vec<bool>; 4]) -> (String, Vec<String>) {
    let used = supporting(seg, contact);
    let effectors: Vec<String> = {
        let mut v: Vec<String> = (0..4)
            .filter(|&e| used[e])
            .map(|e| EFFECTORS[e].to_string())
            .collect();
        v.sort();
        v
    };
    let feet = match seg.walking_foot {
        Some(0) => "L",
        Some(_) => "R",
        None => match (used[0], used[1]) {
            (true, true) => "LR",
            (true, false) => "L",
            (false, true) => "R",
            _ => "",
        },
    };
    let mut parts: Vec<&str> = Vec::new();
    if !feet.is_empty() {
        parts.push(feet);
    }
    if seg.walking_foot.is_none() {
        if used[2] {
            parts.push("LH");
        }
        if used[3] {
            parts.push("RH");
        }
    }
    (parts.join("+"), effectors)
}

/// Mean ground point of the effectors in contact, over the stance frames (spec §8.1):
/// a foot is the ankle–toe-tip midpoint, a hand its wrist.
fn contact_point(seg: &Segment, fr: &ClipFrames) -> Option<V3> {
    let support = supporting(seg, &fr.contact);
    let mut acc = [0.0; 3];
    let mut n = 0.0;
    for k in seg.i0..=seg.i1 {
        let mut pts: Vec<V3> = Vec::new();
        for (e, _) in support.iter().enumerate().filter(|(_, s)| **s) {
            if !fr.contact[e][k] {
                continue;
            }
            let Some(pos) = &fr.effector_pos[e] else {
                continue;
            };
            pts.push(if e < 2 {
                std::array::from_fn(|i| 0.5 * (pos[k][i] + fr.toe[e][k][i]))
            } else {
                pos[k]
            });
        }
        if pts.is_empty() {
            continue;
        }
        for p in &pts {
            (0..3).for_each(|i| acc[i] += p[i] / pts.len() as f64);
        }
        n += 1.0;
    }
    (n > 0.0).then(|| acc.map(|v| v / n))
}

/// The adjacent flight of a `flight` boundary; without a fit (`n_int < 2`) its curvature
/// is the mean SG acceleration `ā_z` and its velocity is null.
fn flight_ref(f: &Flight, t: f64) -> FlightRef {
    FlightRef {
        first_frame: f.first_frame,
        last_frame: f.last_frame,
        n_int: (f.last_frame - f.first_frame - 3).max(0),
        free: f.tested,
        a_z: f
            .fit
            .as_ref()
            .map(|fit| fit.axes[2].curvature())
            .or(f.a_z_mean)
            .unwrap_or(f64::NAN),
        vel: f.fit.as_ref().map(|fit| fit.velocity(t)),
    }
}

/// `fit_rms` of a refitted model (spec §11): RMS over the Stage A samples (taken in the
/// frame `r_a`, rotated into the model's frame `r_b`) of sample − model.
fn set_fit_rms(model: &mut ForceModel, samples: &[Vec<f64>; 3], r_a: [V3; 3], r_b: [V3; 3]) {
    let n = samples[0].len();
    if n == 0 {
        return;
    }
    let mut ss = [0.0; 3];
    #[allow(clippy::needless_range_loop)] // j indexes three parallel sample columns
    for j in 0..n {
        let s_a: V3 = std::array::from_fn(|a| samples[a][j]);
        // world = R_aᵀ s_a, then s_b = R_b · world
        let world: V3 = std::array::from_fn(|i| (0..3).map(|a| r_a[a][i] * s_a[a]).sum());
        let tau = j as f64 / n as f64;
        for (b, acc) in ss.iter_mut().enumerate() {
            let s_b: f64 = (0..3).map(|i| r_b[b][i] * world[i]).sum();
            *acc += (s_b - model.axes[b].eval(tau)).powi(2);
        }
    }
    for (axis, acc) in model.axes.iter_mut().zip(ss) {
        axis.fit_rms = (acc / n as f64).sqrt();
    }
}

/// The inputs of one stance's Stage B refit (spec §4.2).
struct StageB<'a> {
    seg: &'a Segment,
    fr: &'a ClipFrames,
    summary: &'a ClipSummary,
    model: &'a ForceModel,
    t_td: f64,
    dt_s: f64,
    mass_kg: f64,
    state: (V3, V3),
}

impl StageB<'_> {
    /// Fit window: the stance frames, extended over an adjacent flight's frames (only where
    /// the boundary is a flight); harmonics: the union of Stage A's, capped at `j_cap`;
    /// touchdown state fixed to the SG one when neither side is a flight.
    fn fit(&self) -> crate::Result<StageBFit> {
        let (seg, fr) = (self.seg, self.fr);
        let frame0 = fr.frame[0];
        let kept = |f: i64| (f - frame0).max(0) as usize;
        let start = match seg.start {
            Boundary::Flight => self
                .summary
                .flights
                .iter()
                .find(|f| f.last_frame == fr.frame[seg.i0] - 1)
                .map_or(seg.i0, |f| kept(f.first_frame)),
            _ => seg.i0,
        };
        let end = match seg.end {
            Boundary::Flight => self
                .summary
                .flights
                .iter()
                .find(|f| f.first_frame == fr.frame[seg.i1] + 1)
                .map_or(seg.i1, |f| kept(f.last_frame)),
            _ => seg.i1,
        };
        let cap = j_cap(seg.i1 - seg.i0 + 1);
        let mut harmonics: Vec<u32> = self
            .model
            .axes
            .iter()
            .flat_map(|a| a.harmonics.iter().copied())
            .filter(|&j| j <= cap)
            .collect();
        harmonics.sort_unstable();
        harmonics.dedup();
        let no_flight = seg.start != Boundary::Flight && seg.end != Boundary::Flight;
        fit_stage_b(&StageBInput {
            t: &fr.time_s[start..=end],
            com: &fr.com[start..=end],
            t_td: self.t_td,
            dt: self.dt_s,
            mass_kg: self.mass_kg,
            harmonics: &harmonics,
            fixed_state: no_flight.then_some(self.state),
        })
    }
}

/// A clip-level message of the stance stage.
#[derive(Debug, Clone, PartialEq)]
pub struct StanceNote {
    /// What happened (frame and reason).
    pub message: String,
    /// A stance was lost to a failure (an `errors.parquet` row), not just reported.
    pub failed: bool,
}

impl From<String> for StanceNote {
    /// An advisory note (not a failure).
    fn from(message: String) -> Self {
        StanceNote {
            message,
            failed: false,
        }
    }
}

/// Build every stance of a clip. Returns the stances and clip-level notes.
///
/// A clip whose smoothing filter cannot be built (a frame time beyond
/// `MAX_SAVGOL_WINDOW`) or that is shorter than the window gives no stances and one
/// failed note (an `errors.parquet` row), never nothing silently.
pub fn build_clip(
    clip: &str,
    fr: &ClipFrames,
    summary: &ClipSummary,
    mass_kg: f64,
    opts: &StanceOptions,
) -> (Vec<Stance>, Vec<StanceNote>) {
    let n = fr.frame.len();
    let dt = summary.frame_time_s;
    let mut warnings = Vec::new();
    let failed = |message: String| StanceNote {
        message,
        failed: true,
    };
    let sg = match SavGol::for_frame_time(dt, DEFAULT_ORDER) {
        Ok(sg) => sg,
        Err(e) => {
            warnings.push(failed(format!("cannot build the smoothing filter: {e}")));
            return (Vec::new(), warnings);
        }
    };
    let smooth: Vec<V3> = {
        let cols: [Vec<f64>; 3] = std::array::from_fn(|i| {
            sg.apply(&fr.com.iter().map(|c| c[i]).collect::<Vec<_>>(), 0, dt)
        });
        if cols[0].len() != n {
            warnings.push(failed(format!(
                "{n} frames, fewer than the smoothing window of {} frames",
                sg.window()
            )));
            return (Vec::new(), warnings);
        }
        (0..n)
            .map(|k| [cols[0][k], cols[1][k], cols[2][k]])
            .collect()
    };
    let (Some(pos), Some(vel), Some(acc)) = (
        Splines::new(&fr.time_s, &smooth),
        Splines::new(&fr.time_s, &fr.com_v),
        Splines::new(&fr.time_s, &fr.com_a),
    ) else {
        warnings.push(StanceNote::from(
            "cannot build splines of the COM (too few frames)".to_string(),
        ));
        return (Vec::new(), warnings);
    };
    let speed: Vec<f64> = fr
        .com_v
        .iter()
        .map(|v| (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt())
        .collect();
    let frame0 = fr.frame[0];
    let flight_at = |a: usize| {
        summary
            .flights
            .iter()
            .find(|f| f.first_frame == frame0 + a as i64)
    };
    let ballistic = |a: usize, _b: usize| flight_at(a).is_some_and(|f| f.ballistic);
    let (segments, w) = segment(&SegmentInput {
        contact: &fr.contact,
        speed: &speed,
        ballistic: &ballistic,
        dt,
    });
    warnings.extend(w.into_iter().map(StanceNote::from));
    let mut ws = FitWorkspace::new(opts.fit.samples);
    let mut previous: Option<V3> = None;
    let mut out = Vec::with_capacity(segments.len());
    for seg in segments {
        let t_td = if seg.i0 == 0 {
            fr.time_s[0]
        } else {
            fr.time_s[seg.i0] - dt / 2.0
        };
        let t_lo = if seg.i1 + 1 == n {
            fr.time_s[n - 1]
        } else {
            fr.time_s[seg.i1] + dt / 2.0
        };
        let dt_s = t_lo - t_td;
        let (mut p_td, mut v_td) = (pos.at(t_td), vel.at(t_td));
        let facing_td: V3 = match seg.i0 {
            0 => fr.facing[0],
            i => std::array::from_fn(|a| 0.5 * (fr.facing[i - 1][a] + fr.facing[i][a])),
        };
        let mut h: Heading = heading(v_td, facing_td, previous);
        let z_c = median(&fr.ground_z[seg.i0..=seg.i1]).unwrap_or(0.0);
        let (label, effectors) = label(&seg, &fr.contact);
        let mut model = match fit_stage_a(
            &mut ws,
            &acc.0,
            t_td,
            dt_s,
            h.rotation(),
            mass_kg,
            seg.i1 - seg.i0 + 1,
            &opts.fit,
        ) {
            Ok(m) => m,
            Err(e) => {
                warnings.push(StanceNote {
                    message: format!(
                        "stance at frame {}: force fit failed: {e}",
                        fr.frame[seg.i0]
                    ),
                    failed: true,
                });
                continue;
            }
        };
        let mut sw = Vec::new();
        let (mut stage, mut fit_pos_rms_m) = ("A", None);
        if opts.stage_b {
            let refit = StageB {
                seg: &seg,
                fr,
                summary,
                model: &model,
                t_td,
                dt_s,
                mass_kg,
                state: (p_td, v_td),
            }
            .fit();
            match refit {
                Ok(fit) if fit.condition <= MAX_CONDITION => {
                    (p_td, v_td) = (fit.p_td, fit.v_td);
                    let r_a = h.rotation();
                    h = heading(v_td, facing_td, previous);
                    model = to_stance_model(&fit, h.rotation(), mass_kg, dt_s);
                    set_fit_rms(&mut model, ws.last_samples(), r_a, h.rotation());
                    (stage, fit_pos_rms_m) = ("B", Some(fit.pos_rms_m));
                }
                Ok(fit) => sw.push(format!(
                    "stage B fallback to A: condition {:.2e} above {MAX_CONDITION:e}",
                    fit.condition
                )),
                Err(e) => sw.push(format!("stage B fallback to A: {e}")),
            }
        }
        previous = Some(h.e_h);
        let (j, p) = (model.j(), model.p());
        let v_td_s = h.to_stance(v_td);
        let z_td = p_td[2] - z_c;
        let prm = model_consistent(v_td_s, z_td, j, p, dt_s);
        let (p_lo, v_lo) = (pos.at(t_lo), vel.at(t_lo));
        let dp = h.to_stance(std::array::from_fn(|i| p_lo[i] - p_td[i]));
        let measured = params::from_states(v_td_s, z_td, dp, h.to_stance(v_lo), dt_s);
        let cp = contact_point(&seg, fr).map_or([0.0, 0.0], |c| {
            let d = h.to_stance(std::array::from_fn(|i| c[i] - p_td[i]));
            [d[0], d[1]]
        });
        let ctx = StanceContext {
            vs: prm.vs,
            vps: prm.vps,
            t_td: prm.t_td,
            z_td,
            cp,
        };
        let coef = precompute(&model, &ctx);
        if !coef.unilateral_ok {
            sw.push("unilateral test failed: the model pulls on the ground (ringing)".to_string());
        }
        if !coef.support_ok {
            sw.push(
                "J_v ≤ 0: the stance cannot support the body; excluded from scaling".to_string(),
            );
        }
        let edge_rest = |k: usize| speed[k] < V_QUIET;
        let rest_at_edge = (seg.start == Boundary::ClipEdge && edge_rest(seg.i0))
            || (seg.end == Boundary::ClipEdge && edge_rest(seg.i1));
        let before = (seg.start == Boundary::Flight)
            .then(|| {
                summary
                    .flights
                    .iter()
                    .find(|f| f.last_frame == frame0 + seg.i0 as i64 - 1)
            })
            .flatten()
            .map(|f| flight_ref(f, t_td));
        let after = (seg.end == Boundary::Flight)
            .then(|| flight_at(seg.i1 + 1))
            .flatten()
            .map(|f| flight_ref(f, t_lo));
        out.push(Stance {
            stance_id: format!("{clip}:{label}:{}", fr.frame[seg.i0]),
            clip: clip.to_string(),
            character_id: summary.character_id.clone().unwrap_or_default(),
            label,
            effectors,
            first_frame: fr.frame[seg.i0],
            last_frame: fr.frame[seg.i1],
            td_clip_s: t_td,
            lo_clip_s: t_lo,
            dt_s,
            boundary_start: seg.start,
            boundary_end: seg.end,
            rest_at_edge,
            flight_before: before,
            flight_after: after,
            heading: h,
            z_c,
            params: prm,
            measured,
            mass_kg,
            model,
            cp,
            coef,
            stage,
            fit_pos_rms_m,
            warnings: sw,
        });
    }
    (out, warnings)
}
