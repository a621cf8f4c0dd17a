//! All stances of one clip, from its ingest outputs (pure).

use super::params::{self, heading, model_consistent, Heading};
use super::segment::{segment, Boundary, Segment, SegmentInput, V_QUIET};
use super::{FlightRef, Stance};
use crate::constraints::{precompute, StanceContext};
use crate::contacts::flight::Flight;
use crate::contacts::flight::FlightFit;
use crate::contacts::timing::EVENT_MAX_SHIFT_S;
use crate::contacts::EFFECTORS;
use crate::force_model::ratio::POSITION_TOLERANCE_M;
use crate::force_model::{
    fit_stance, EdgeTargets, FitOptions, FitWorkspace, LegLine, StanceFit, StanceForce, GRAVITY,
};
use crate::ingest::{ClipFrames, ClipSummary, ContactRun};
use crate::math::polyfit::{fit as poly_fit, fit_fixed_curvature};
use crate::math::savgol::{SavGol, DEFAULT_ORDER};
use crate::math::spline::NaturalSpline;
use crate::math::stats::median;

use crate::math::v3::V3;

/// Options of the stance stage.
#[derive(serde::Serialize, Debug, Clone, PartialEq, Default)]
pub struct StanceOptions {
    /// Force-model fit (model and its knobs).
    pub fit: FitOptions,
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

/// The adjacent flight of a `flight` boundary: its own curvature (free fit, else the
/// fixed one; without a fit, `n_int < 2`, the mean SG acceleration `ā_z`) and the velocity
/// at the stance edge `t`: `edge_vel`, the stance's edge state when it came from the
/// flight's −g parabola ([`ballistic_fit`]), else the flight's own fit (null without one).
fn flight_ref(f: &Flight, t: f64, edge_vel: Option<V3>) -> FlightRef {
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
        vel: edge_vel.or_else(|| f.fit.as_ref().map(|fit| fit.velocity(t))),
    }
}

/// A stance edge.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Edge {
    Touchdown,
    Liftoff,
}

/// The sub-frame time of a stance edge: over the supporting effectors' runs that start
/// (touchdown) or end (liftoff) on the stance's first or last frame, the earliest
/// touchdown or the latest liftoff; `None` when no run edge is there. A time must lie
/// within [`EVENT_MAX_SHIFT_S`] + one frame of the frame edge (the event search's own
/// reach): at 60 Hz a running touchdown is often 1.5 frames before the detector's frame.
fn event_time(contacts: &[ContactRun], seg: &Segment, fr: &ClipFrames, edge: Edge) -> Option<f64> {
    let support = supporting(seg, &fr.contact);
    let dt = fr
        .time_s
        .get(1)
        .zip(fr.time_s.first())
        .map(|(b, a)| b - a)?;
    let (frame, edge_t) = match edge {
        Edge::Touchdown => (fr.frame[seg.i0], fr.time_s[seg.i0] - dt / 2.0),
        Edge::Liftoff => (fr.frame[seg.i1], fr.time_s[seg.i1] + dt / 2.0),
    };
    let times = contacts.iter().filter_map(|r| {
        let e = EFFECTORS.iter().position(|&e| e == r.effector)?;
        if !support[e] {
            return None;
        }
        match edge {
            Edge::Touchdown => (r.first_frame == frame).then_some(r.td_time_s).flatten(),
            Edge::Liftoff => (r.last_frame == frame).then_some(r.lo_time_s).flatten(),
        }
    });
    let t = match edge {
        Edge::Touchdown => times.fold(None, |m: Option<f64>, t| Some(m.map_or(t, |m| m.min(t)))),
        Edge::Liftoff => times.fold(None, |m: Option<f64>, t| Some(m.map_or(t, |m| m.max(t)))),
    }?;
    (t.is_finite() && (t - edge_t).abs() <= EVENT_MAX_SHIFT_S + dt).then_some(t)
}

/// Frames dropped at each end of a flight before its ballistic fit: the contact edges are
/// about one frame uncertain, and SG-free raw positions still carry the transition there.
pub const BALLISTIC_EDGE_FRAMES: usize = 2;
/// Fewest interior frames of a flight for a ballistic edge state.
pub const BALLISTIC_MIN_FRAMES: usize = 2;

/// Largest distance of a flight's own free curvature `a_z` from −g, m/s², at which the
/// stance beside it meets its edge position exactly ([`EdgeTargets::position_tolerance_m`]
/// `None`; beyond it the position is a soft target of [`POSITION_TOLERANCE_M`]). The edge
/// states come from a −g parabola (`ballistic_fit`); where the flight's COM itself curves
/// far from −g that parabola is not its path, and forcing the stance through it bends the
/// stance's force: on `cmu_09_01_run_mb` the 102 ms flight curves at −5.6 m/s² (4.2 m/s²
/// from −g; the clip's other flights −8.9 and −9.6) and, held exactly, the stances beside it
/// planned a COM beyond the leg's reach in the edit (a frame that did not converge, a
/// 31.6° joint step; soft there: every frame converged, 16.5° at most). 3 m/s² is the
/// scatter of the interior fit `a_z` on a 0.1 s flight ([`Flight::a_z_all`]): beyond it the
/// flight's COM does not follow the −g parabola to the millimetre, whatever the cause. The
/// all-frames curvature `a_z_all` does not tell the flights apart (−8.2 m/s² for that flight,
/// −9.3 to −12.3 m/s² on the 4 m/s plate run, whose flights the plates join). A flight too
/// short for a free fit (`tested` false: every flight of the three plate runs, 20–100 ms at
/// 60–100 Hz) has no evidence against −g and keeps the exact position, on which the plates
/// join the flights (docs `stance-model.md` §4.1, "Edge position").
pub const EXACT_POSITION_MAX_CURVATURE_MISS_MPS2: f64 = 3.0;

/// Whether a flight's own curvature allows the exact edge position
/// ([`EXACT_POSITION_MAX_CURVATURE_MISS_MPS2`]): untested, or tested with `|a_z + g|` within it.
fn curves_like_gravity(f: &Flight) -> bool {
    match (f.tested, f.a_z) {
        (false, _) => true,
        (true, Some(a_z)) => (a_z + GRAVITY).abs() <= EXACT_POSITION_MAX_CURVATURE_MISS_MPS2,
        (true, None) => false,
    }
}

/// The flight whose last frame is `last_frame`.
fn flight_ending_at(summary: &ClipSummary, last_frame: i64) -> Option<&Flight> {
    summary.flights.iter().find(|f| f.last_frame == last_frame)
}

/// The ballistic fit of a flight that a stance takes its edge state from: the raw COM
/// with `x(t)`, `y(t)` lines and `z(t)` a parabola of curvature −g over the frames strictly
/// between the flight's sub-frame liftoff and touchdown ([`Flight::events_s`]; every such
/// frame is airborne, and a 60 Hz running flight keeps 4–5 of its frames), or, without
/// events, over the flight's frames less [`BALLISTIC_EDGE_FRAMES`] at each end. Both
/// stances beside one flight use the same parabola, so they agree on its state. `None` for
/// a non-ballistic flight or fewer than [`BALLISTIC_MIN_FRAMES`] frames.
///
/// The curvature is −g even where the flight has its own free-curvature fit (a departure
/// from spec com-from-bvh §7.7, which takes the free fit's state): a 0.1 s flight at
/// 120 Hz leaves 8 interior frames, and their free curvature is as noisy as the COM
/// estimate. A wrong curvature joins the liftoff and touchdown velocities of a flight of
/// length `T` by other than `g·T`, which moves the apexes of the stances beside it and the
/// touchdowns of an edit at the recorded speed (the measured case is in
/// `docs/decisions.md`, "Measurements moved from module docs"). The free fit still gives
/// the flight's `a_z`, the ballistic test and the clip's time scale `s_eff`; a clip whose
/// flights say it is time-scaled is not eligible for queries (`stances::limits`), so −g
/// is the physics of every stance used.
fn ballistic_fit(fr: &ClipFrames, f: &Flight) -> Option<FlightFit> {
    if !f.ballistic {
        return None;
    }
    let frame0 = fr.frame[0];
    let (first, last) = (
        usize::try_from(f.first_frame - frame0).ok()?,
        usize::try_from(f.last_frame - frame0).ok()?,
    );
    if last >= fr.com.len() {
        return None;
    }
    let ks: Vec<usize> = match f.events_s {
        Some((lo, td)) => (first.saturating_sub(BALLISTIC_EDGE_FRAMES)
            ..=(last + BALLISTIC_EDGE_FRAMES).min(fr.com.len() - 1))
            .filter(|&k| fr.time_s[k] > lo && fr.time_s[k] < td)
            .collect(),
        None => {
            (first + BALLISTIC_EDGE_FRAMES..=last.saturating_sub(BALLISTIC_EDGE_FRAMES)).collect()
        }
    };
    if ks.len() < BALLISTIC_MIN_FRAMES {
        return None;
    }
    let t: Vec<f64> = ks.iter().map(|&k| fr.time_s[k]).collect();
    let axis = |i: usize| -> Vec<f64> { ks.iter().map(|&k| fr.com[k][i]).collect() };
    Some(FlightFit {
        axes: [
            poly_fit(&t, &axis(0), 1)?,
            poly_fit(&t, &axis(1), 1)?,
            fit_fixed_curvature(&t, &axis(2), -GRAVITY)?,
        ],
    })
}

/// The force integrals that join the touchdown state `(p, v)_TD` to the liftoff state
/// `(p, v)_LO` over `Δt` (world states, stance frame `h`), see [`EdgeTargets`].
/// `exact`: the position is met exactly, else softly ([`POSITION_TOLERANCE_M`]).
fn edge_targets(
    h: &Heading,
    (td, lo): ((V3, V3), (V3, V3)),
    dt: f64,
    m: f64,
    exact: bool,
) -> EdgeTargets {
    let dv = h.to_stance(std::array::from_fn(|i| lo.1[i] - td.1[i]));
    let impulse = std::array::from_fn(|a| {
        let g = if a == 2 { GRAVITY * dt } else { 0.0 };
        m * (dv[a] + g) / dt
    });
    let dz = lo.0[2] - td.0[2];
    let dp = h.to_stance(std::array::from_fn(|i| lo.0[i] - td.0[i]));
    let v_td = h.to_stance(td.1);
    EdgeTargets {
        impulse,
        vertical_double: m * (dz - td.1[2] * dt + 0.5 * GRAVITY * dt * dt) / (dt * dt),
        travel_double: [0, 1].map(|a| m * (dp[a] - v_td[a] * dt) / (dt * dt)),
        position_tolerance_m: (!exact).then_some(POSITION_TOLERANCE_M),
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
/// `contacts` are the clip's contact runs: a stance edge that is a run's first or last
/// frame takes that run's sub-frame event time ([`ContactRun::td_time_s`],
/// [`ContactRun::lo_time_s`]); other edges, and an empty slice, use the frame edges
/// (half a frame outside the stance's first and last frame).
///
/// A clip whose smoothing filter cannot be built (a frame time beyond
/// `MAX_SAVGOL_WINDOW`) or that is shorter than the window gives no stances and one
/// failed note (an `errors.parquet` row), never nothing silently.
pub fn assemble_clip(
    clip: &str,
    fr: &ClipFrames,
    summary: &ClipSummary,
    contacts: &[ContactRun],
    mass_kg: f64,
    opts: &StanceOptions,
) -> (Vec<Stance>, Vec<StanceNote>) {
    let data = match ClipData::new(clip, fr, summary, contacts, mass_kg) {
        Ok(data) => data,
        Err(note) => return (Vec::new(), vec![note]),
    };
    let ballistic = |a: usize, _b: usize| data.flight_at(a).is_some_and(|f| f.ballistic);
    let (segments, w) = segment(&SegmentInput {
        contact: &fr.contact,
        speed: &data.speed,
        ballistic: &ballistic,
        dt: data.dt,
    });
    let mut notes: Vec<StanceNote> = w.into_iter().map(StanceNote::from).collect();
    let mut ws = FitWorkspace::new(opts.fit.samples);
    let mut previous: Option<V3> = None;
    let mut out = Vec::with_capacity(segments.len());
    for seg in segments {
        match data.stance(&seg, &mut previous, &mut ws, opts) {
            Ok(stance) => out.push(stance),
            Err(note) => notes.push(note),
        }
    }
    (out, notes)
}

/// One clip's inputs to the stance stage, with its smoothed COM splines.
struct ClipData<'a> {
    clip: &'a str,
    fr: &'a ClipFrames,
    summary: &'a ClipSummary,
    contacts: &'a [ContactRun],
    mass_kg: f64,
    /// Frame time, s.
    dt: f64,
    /// `|v_COM|` per frame, m/s.
    speed: Vec<f64>,
    /// SG-smoothed COM position, m.
    pos: Splines,
    /// SG COM velocity, m/s.
    vel: Splines,
    /// SG COM acceleration, m/s².
    acc: Splines,
}

/// The state `(position m, velocity m/s)` at each edge of a stance, from the ballistic fit
/// of the adjacent flight when there is one, else from the COM splines.
struct EdgeStates {
    td: (V3, V3),
    lo: (V3, V3),
    fit_before: bool,
    fit_after: bool,
    /// Every flight that gave an edge state curves like −g ([`curves_like_gravity`]).
    position_exact: bool,
}

/// The SG-smoothed COM of a clip; a failed note when the filter cannot be built or the
/// clip is shorter than its window.
fn smoothed_com(fr: &ClipFrames, dt: f64) -> Result<Vec<V3>, StanceNote> {
    let n = fr.frame.len();
    let failed = |message: String| StanceNote {
        message,
        failed: true,
    };
    let sg = SavGol::for_frame_time(dt, DEFAULT_ORDER)
        .map_err(|e| failed(format!("cannot build the smoothing filter: {e}")))?;
    let cols: [Vec<f64>; 3] =
        std::array::from_fn(|i| sg.apply(&fr.com.iter().map(|c| c[i]).collect::<Vec<_>>(), 0, dt));
    if cols[0].len() != n {
        return Err(failed(format!(
            "{n} frames, fewer than the smoothing window of {} frames",
            sg.window()
        )));
    }
    Ok((0..n)
        .map(|k| [cols[0][k], cols[1][k], cols[2][k]])
        .collect())
}

impl<'a> ClipData<'a> {
    fn new(
        clip: &'a str,
        fr: &'a ClipFrames,
        summary: &'a ClipSummary,
        contacts: &'a [ContactRun],
        mass_kg: f64,
    ) -> Result<ClipData<'a>, StanceNote> {
        let dt = summary.frame_time_s;
        let smooth = smoothed_com(fr, dt)?;
        let (Some(pos), Some(vel), Some(acc)) = (
            Splines::new(&fr.time_s, &smooth),
            Splines::new(&fr.time_s, &fr.com_v),
            Splines::new(&fr.time_s, &fr.com_a),
        ) else {
            return Err(StanceNote::from(
                "cannot build splines of the COM (too few frames)".to_string(),
            ));
        };
        let speed: Vec<f64> = fr
            .com_v
            .iter()
            .map(|v| (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt())
            .collect();
        Ok(ClipData {
            clip,
            fr,
            summary,
            contacts,
            mass_kg,
            dt,
            speed,
            pos,
            vel,
            acc,
        })
    }

    /// The flight that starts at kept frame `a`.
    fn flight_at(&self, a: usize) -> Option<&'a Flight> {
        let frame0 = self.fr.frame[0];
        self.summary
            .flights
            .iter()
            .find(|f| f.first_frame == frame0 + a as i64)
    }

    /// The flight before a stance that starts at a flight boundary.
    fn flight_before(&self, seg: &Segment) -> Option<&'a Flight> {
        (seg.start == Boundary::Flight)
            .then(|| flight_ending_at(self.summary, self.fr.frame[0] + seg.i0 as i64 - 1))
            .flatten()
    }

    /// The flight after a stance that ends at a flight boundary.
    fn flight_after(&self, seg: &Segment) -> Option<&'a Flight> {
        (seg.end == Boundary::Flight)
            .then(|| self.flight_at(seg.i1 + 1))
            .flatten()
    }

    /// Touchdown and liftoff time of a stance, s: the clip's first (last) frame when the
    /// stance starts (ends) on it, else the sub-frame event, else half a frame outside the
    /// stance's frames (a `clip_edge` stance cut at a settled end, `segment::settled_end`,
    /// ends half a frame after its last frame, as one cut at a rest does).
    fn stance_times(&self, seg: &Segment) -> (f64, f64) {
        let (fr, dt, n) = (self.fr, self.dt, self.fr.frame.len());
        let t_td = if seg.i0 == 0 {
            fr.time_s[0]
        } else {
            event_time(self.contacts, seg, fr, Edge::Touchdown)
                .unwrap_or(fr.time_s[seg.i0] - dt / 2.0)
        };
        let t_lo = if seg.i1 + 1 == n {
            fr.time_s[n - 1]
        } else {
            event_time(self.contacts, seg, fr, Edge::Liftoff)
                .unwrap_or(fr.time_s[seg.i1] + dt / 2.0)
        };
        (t_td, t_lo)
    }

    /// The edge states of a stance (adjacent flights' ballistic fits, else the splines).
    fn edge_states(&self, seg: &Segment, t_td: f64, t_lo: f64) -> EdgeStates {
        let fit = |f: Option<&Flight>| {
            f.and_then(|f| Some((ballistic_fit(self.fr, f)?, curves_like_gravity(f))))
        };
        let (before, after) = (fit(self.flight_before(seg)), fit(self.flight_after(seg)));
        let position_exact = [&before, &after]
            .iter()
            .all(|f| f.as_ref().is_none_or(|(_, exact)| *exact));
        let (fit_before, fit_after) = (before.map(|f| f.0), after.map(|f| f.0));
        let td = fit_before
            .as_ref()
            .map_or((self.pos.at(t_td), self.vel.at(t_td)), |f| {
                (f.position(t_td), f.velocity(t_td))
            });
        let lo = fit_after
            .as_ref()
            .map_or((self.pos.at(t_lo), self.vel.at(t_lo)), |f| {
                (f.position(t_lo), f.velocity(t_lo))
            });
        EdgeStates {
            td,
            lo,
            fit_before: fit_before.is_some(),
            fit_after: fit_after.is_some(),
            position_exact,
        }
    }

    /// The stance heading (§2): from the touchdown velocity, or the liftoff velocity of a
    /// standing liftoff (no flight before, a flight after: it heads where it leaves to).
    fn heading(&self, seg: &Segment, edges: &EdgeStates, previous: Option<V3>) -> Heading {
        let fr = self.fr;
        let facing_td: V3 = match seg.i0 {
            0 => fr.facing[0],
            i => std::array::from_fn(|a| 0.5 * (fr.facing[i - 1][a] + fr.facing[i][a])),
        };
        let v_heading = if !edges.fit_before && edges.fit_after {
            edges.lo.1
        } else {
            edges.td.1
        };
        heading(v_heading, facing_td, previous)
    }

    /// The leg line of a running stance on one foot ([`LegLine`]): none for a walking
    /// stance (its double support shares the force), several effectors, or a foot without
    /// an ankle.
    fn leg_line(&self, seg: &Segment) -> Option<LegLine<'_>> {
        if seg.walking_foot.is_some() {
            return None;
        }
        let support = supporting(seg, &self.fr.contact);
        let mut used = support
            .iter()
            .enumerate()
            .filter(|(_, s)| **s)
            .map(|(e, _)| e);
        let (Some(foot), None) = (used.next(), used.next()) else {
            return None;
        };
        let ankle = self.fr.effector_pos.get(foot)?.as_ref()?;
        Some(LegLine {
            time_s: &self.fr.time_s,
            ankle,
            toe: self.fr.toe.get(foot)?,
            com: &self.pos.0,
        })
    }

    /// The force fit of a stance (§4), with the adjacent flights' edge targets when it has
    /// a ballistic neighbour; a failed note when the fit fails.
    fn fit_force(
        &self,
        ws: &mut FitWorkspace,
        seg: &Segment,
        times: (f64, f64),
        h: &Heading,
        edges: &EdgeStates,
        opts: &StanceOptions,
    ) -> Result<(StanceFit, Option<EdgeTargets>), StanceNote> {
        let (t_td, t_lo) = times;
        let dt_s = t_lo - t_td;
        let targets = (edges.fit_before || edges.fit_after).then(|| {
            let states = (edges.td, edges.lo);
            edge_targets(h, states, dt_s, self.mass_kg, edges.position_exact)
        });
        let force = StanceForce {
            acc: &self.acc.0,
            t_td,
            dt: dt_s,
            r_s: h.rotation(),
            mass_kg: self.mass_kg,
            leg: self.leg_line(seg),
        };
        match fit_stance(ws, &force, seg.i1 - seg.i0 + 1, targets.as_ref(), &opts.fit) {
            Ok(fit) => Ok((fit, targets)),
            Err(e) => Err(StanceNote {
                message: format!(
                    "stance at frame {}: force fit failed: {e}",
                    self.fr.frame[seg.i0]
                ),
                failed: true,
            }),
        }
    }

    /// One stance of the clip: times, edge states, heading, force fit, then its row.
    /// `previous` is the heading of the last stance built (updated on success).
    fn stance(
        &self,
        seg: &Segment,
        previous: &mut Option<V3>,
        ws: &mut FitWorkspace,
        opts: &StanceOptions,
    ) -> Result<Stance, StanceNote> {
        let times = self.stance_times(seg);
        let edges = self.edge_states(seg, times.0, times.1);
        let h = self.heading(seg, &edges, *previous);
        let (fit, targets) = self.fit_force(ws, seg, times, &h, &edges, opts)?;
        *previous = Some(h.e_h);
        Ok(self.stance_row(seg, times, &edges, h, fit, targets.is_some()))
    }

    /// The stance's row: parameters, contact point, constraint coefficients, adjacent
    /// flights and warnings.
    fn stance_row(
        &self,
        seg: &Segment,
        (t_td, t_lo): (f64, f64),
        edges: &EdgeStates,
        h: Heading,
        fit: StanceFit,
        targeted: bool,
    ) -> Stance {
        let (fr, clip, mass_kg) = (self.fr, self.clip, self.mass_kg);
        let ((p_td, v_td), (p_lo, v_lo)) = (edges.td, edges.lo);
        let dt_s = t_lo - t_td;
        let StanceFit {
            model,
            kind: force_model,
            ratio,
            targets_met,
        } = fit;
        let mut sw = Vec::new();
        if targeted && targets_met < 2 {
            sw.push(format!(
                "the force model meets {targets_met} of 2 vertical edge targets of the adjacent flight(s)"
            ));
        }
        let z_c = median(&fr.ground_z[seg.i0..=seg.i1]).unwrap_or(0.0);
        let (label, effectors) = label(seg, &fr.contact);
        let (j, p) = (model.j(), model.p());
        let v_td_s = h.to_stance(v_td);
        let z_td = p_td[2] - z_c;
        let prm = model_consistent(v_td_s, z_td, j, p, dt_s);
        let dp = h.to_stance(std::array::from_fn(|i| p_lo[i] - p_td[i]));
        let measured = params::from_states(v_td_s, z_td, dp, h.to_stance(v_lo), dt_s);
        let cp = contact_point(seg, fr).map_or([0.0, 0.0], |c| {
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
        let edge_rest = |k: usize| self.speed[k] < V_QUIET;
        let rest_at_edge = (seg.start == Boundary::ClipEdge && edge_rest(seg.i0))
            || (seg.end == Boundary::ClipEdge && edge_rest(seg.i1));
        Stance {
            stance_id: format!("{clip}:{label}:{}", fr.frame[seg.i0]),
            clip: clip.to_string(),
            character_id: self.summary.character_id.clone().unwrap_or_default(),
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
            flight_before: self
                .flight_before(seg)
                .map(|f| flight_ref(f, t_td, edges.fit_before.then_some(edges.td.1))),
            flight_after: self
                .flight_after(seg)
                .map(|f| flight_ref(f, t_lo, edges.fit_after.then_some(edges.lo.1))),
            heading: h,
            z_c,
            params: prm,
            measured,
            mass_kg,
            model,
            cp,
            coef,
            force_model,
            ratio,
            warnings: sw,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::stances::params::HeadingFrom;

    #[test]
    fn edge_targets_are_the_integrals_of_a_constant_force() {
        // A constant world acceleration `a` over Δt from (p0, v0): every target is the
        // closed form of a constant stance force `m (a − g⃗)` turned into the stance axes.
        let (m, dt) = (70.0, 0.8);
        let (p0, v0, a) = ([0.3, -0.2, 1.0], [1.2, 0.4, -0.5], [2.0, -1.5, 3.0]);
        let lo = (
            std::array::from_fn(|i| p0[i] + v0[i] * dt + 0.5 * a[i] * dt * dt),
            std::array::from_fn(|i| v0[i] + a[i] * dt),
        );
        let (c, s) = (0.6f64, 0.8f64);
        let h = Heading {
            e_h: [c, s, 0.0],
            from: HeadingFrom::Velocity,
        };
        let t = edge_targets(&h, ((p0, v0), lo), dt, m, true);
        assert_eq!(t.position_tolerance_m, None);
        let soft = edge_targets(&h, ((p0, v0), lo), dt, m, false);
        assert_eq!(soft.position_tolerance_m, Some(POSITION_TOLERANCE_M));
        let f = h.to_stance(std::array::from_fn(|i| {
            m * (a[i] + if i == 2 { GRAVITY } else { 0.0 })
        }));
        // ∫₀¹ f dτ = f and ∫₀¹∫₀ˢ f = f / 2 for a constant force.
        for (got, want) in t.impulse.iter().zip(f) {
            assert!((got - want).abs() < 1e-9, "impulse {got} against {want}");
        }
        assert!((t.vertical_double - f[2] / 2.0).abs() < 1e-9);
        for (got, want) in t.travel_double.iter().zip(f) {
            assert!(
                (got - want / 2.0).abs() < 1e-9,
                "travel {got} against {want} / 2"
            );
        }
    }

    #[test]
    fn the_edge_position_is_exact_beside_a_flight_that_curves_like_gravity() {
        // The flights of `cmu_09_01_run_mb` (free a_z −8.9, −5.6, −9.6 m/s²) and an
        // untested plate-run flight.
        let flight = |tested: bool, a_z: Option<f64>| Flight {
            first_frame: 0,
            last_frame: 12,
            duration_s: 0.1,
            a_z,
            a_x: None,
            a_y: None,
            rms_m: None,
            s_eff: None,
            a_z_all: None,
            events_duration_s: None,
            events_s: None,
            a_z_mean: None,
            ballistic: true,
            tested,
            airborne: tested,
            fit: None,
        };
        assert!(curves_like_gravity(&flight(true, Some(-8.92))));
        assert!(curves_like_gravity(&flight(true, Some(-9.61))));
        assert!(!curves_like_gravity(&flight(true, Some(-5.60))));
        assert!(!curves_like_gravity(&flight(true, Some(-13.0))));
        assert!(curves_like_gravity(&flight(false, None)));
    }
}
