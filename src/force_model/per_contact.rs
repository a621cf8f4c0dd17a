//! The whole body's force split between the contacts that share it (feet or hands), and
//! each contact's centre of pressure (COP) from its points: force per foot where no plates
//! exist.
//!
//! # Model
//! ```text
//! F(t) = m (a_COM(t) + g ẑ)                     total force on the body (SG acceleration)
//! one contact: it carries F.  none: no force.  three or more: F/n each ("even").
//! two contacts, a handover (walking double support: the trailing contact lifts off first,
//!   and the overlap t_to − t_hs ≤ T_max = 0.3 s), the leading one touching down at t_hs
//!   while the trailing one lifts off at t_to:   s = clamp((t − t_hs)/(t_to − t_hs), 0, 1)
//!   trailing:  f_v  = (1 − s) F_v(t)                      vertical
//!              f_lat = (1 − s) F_lat(t)                   lateral (⟂ heading, horizontal)
//!              f_fa = F_fa(t_hs) (1 − 3s² + 2s³)(1 + A s) fore-aft (along the heading)
//!   leading:   F(t) − trailing
//! heading: the horizontal COM velocity at t_hs (unit; fore-aft = lateral split when the
//!   body stands, |v| < 0.1 m/s); A = 2.5; t_hs within half an SG window (h frames, the
//!   COM filter's) of a clip end, or outside the clip: F_fa and the heading are read at
//!   the first (last) interior frame instead of the filter's edge values
//! an edge of the double support outside the clip (unknown t_hs or t_to): the other edge ∓
//!   the median duration of the clip's complete handovers (else 0.12 s); a handover is
//!   judged on what the clip shows (the overlap inside it, the liftoffs it has)
//! two contacts otherwise (both feet standing, a landing on both feet, a hand and a foot):
//!   the lever rule, the COM's horizontal projection between the two COPs p_a, p_b:
//!     u = clamp((c − p_a)·(p_b − p_a) / |p_b − p_a|², 0, 1)      (c: horizontal COM)
//!     a: (1 − u) F,   b: u F;   COPs closer than 1 cm: F/2 each ("even")
//! COP of a foot: the horizontal mean of its points (ankle, toe tip) weighted by
//!   w_p = max(0, H·s_leg − h_p),  h_p = z_p − ground_z − c_p·s_leg  (c_ankle 0.08 m,
//!   c_toe 0.01 m, the detector's clearances; H = 0.05 m; s_leg = L_leg/0.84 m), the lower
//!   point when neither weighs; a hand: its wrist. At the contact's surface height.
//! ```
//! This is the smooth-transition assumption (Ren et al. 2008; used with inertial motion
//! capture by Karatsidis et al. 2017): during double support the trailing foot's share
//! falls smoothly from everything at the leading foot's touchdown to nothing at its own
//! liftoff, and the leading foot takes the rest, so the two always sum to the measured
//! total. Two departures, each measured against the plates of three walks (per foot, BW
//! RMSE): the vertical and lateral shares are a linear share of the *current* total
//! (measured: 0.02–0.06 BW vertical, against 0.03–0.07 for Ren's `F(t_hs)·shape(s)` and
//! 0.15–0.20 for a Gaussian decay), which keeps both feet's vertical force non-negative;
//! the fore-aft share has a propulsive hump: the trailing foot keeps pushing harder for
//! the first half of double support (1.3–1.5 F_fa(t_hs) at s ≈ 0.4 on the plates) while
//! the leading foot brakes. `A` was chosen by leaving one walk out (2.0–3.5; 2.5 on all
//! three). Ren et al. model the same hump with a separate fore-aft function.
//! The COP rule rolls from the ankle (heel strike: the toe is high) over both points (flat
//! foot) to the toe tip (heel off). Against the plates: 3–6 cm RMSE.
//! The handover bound `T_max`: the walks' double supports measure 0.147–0.174 s; slow
//! walking reaches about 0.3 s. Two feet that stand together longer (the drop jump's
//! two-foot landing, 0.75 s) do not hand over; there the transition put 21 N on one foot
//! and 900 N on the other where the plates read 470 / 564 N (per-foot vertical RMSE over
//! the landing 0.46 BW), and the lever rule of statics (each contact's share inversely
//! proportional to its horizontal distance from the COM along the line joining the COPs)
//! gives 0.12.
//!
//! # Frames and units
//! World frame, Z up, metres, newtons, seconds; forces are the force *on the body*.
//!
//! # References
//! Ren, Jones & Howard (2008), J Biomech 41:2750, "Whole body inverse dynamics over a
//! complete gait cycle based only on measured kinematics" (smooth transition assumption);
//! Karatsidis et al. (2017), Sensors 17:75, "Estimation of ground reaction forces and
//! moments during gait using only inertial motion capture".
//!
//! # Examples
//! ```
//! use stancelib::force_model::per_contact::{
//!     split, ContactSpan, SplitInput, SplitOptions, SplitRule,
//! };
//! // Left foot on until 0.3 s, right foot from 0.2 s: double support 0.2–0.3 s.
//! let t: Vec<f64> = (0..5).map(|k| k as f64 * 0.1).collect();
//! let total = vec![[0.0, 0.0, 700.0]; 5];
//! let heading = vec![[1.0, 0.0, 0.0]; 5];
//! let spans = [
//!     ContactSpan { effector: 0, td_s: None, lo_s: Some(0.3) },
//!     ContactSpan { effector: 1, td_s: Some(0.2), lo_s: None },
//! ];
//! let input = SplitInput {
//!     time_s: &t,
//!     total: &total,
//!     heading: &heading,
//!     com: &[[0.0; 3]; 5],
//!     cop: &[[None; 4]; 5],
//! };
//! let out = split(&input, &spans, &SplitOptions::default());
//! assert_eq!(out[1].rule, SplitRule::Single);
//! assert_eq!(out[2].rule, SplitRule::Transition);
//! // At the touchdown everything is still on the trailing (left) foot.
//! assert_eq!(out[2].force[0], Some([0.0, 0.0, 700.0]));
//! assert_eq!(out[2].force[1], Some([0.0, 0.0, 0.0]));
//! assert_eq!(out[4].force[0], None);
//! ```

use crate::contacts::floor::{CLEARANCE_ANKLE, CLEARANCE_TTIP};
use crate::math::savgol::window_for_rate;
use crate::math::stats::median;
use crate::math::v3::{add, dot, norm, scale, sub, V3};

/// Fore-aft hump `A` of the trailing contact's share (chosen by leaving one walk out).
pub const DEFAULT_FORE_AFT_HUMP: f64 = 2.5;
/// Double-support duration when the clip has no complete one, s (a walk at ~1.2 m/s).
pub const DEFAULT_DOUBLE_SUPPORT_S: f64 = 0.12;
/// Least horizontal COM speed that gives a heading, m/s.
pub const MIN_HEADING_SPEED_MPS: f64 = 0.1;
/// COP weight height `H` above a point's contact height, m (scaled by `L_leg/0.84`).
pub const COP_HEIGHT_M: f64 = 0.05;
/// Longest overlap of two contacts that is a handover `T_max`, s: the walks' double
/// supports measure 0.147–0.174 s, slow walking about 0.3 s; a two-foot landing or stand
/// lasts longer.
pub const DEFAULT_MAX_HANDOVER_S: f64 = 0.3;
/// COPs closer than this share evenly instead of by the lever rule, m.
pub const MIN_LEVER_BASE_M: f64 = 0.01;

/// Options of [`split`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SplitOptions {
    /// `A` ([`DEFAULT_FORE_AFT_HUMP`]).
    pub fore_aft_hump: f64,
    /// Fallback double-support duration, s ([`DEFAULT_DOUBLE_SUPPORT_S`]).
    pub double_support_s: f64,
    /// Longest overlap that is a handover, s ([`DEFAULT_MAX_HANDOVER_S`]).
    pub max_handover_s: f64,
}

impl Default for SplitOptions {
    fn default() -> Self {
        SplitOptions {
            fore_aft_hump: DEFAULT_FORE_AFT_HUMP,
            double_support_s: DEFAULT_DOUBLE_SUPPORT_S,
            max_handover_s: DEFAULT_MAX_HANDOVER_S,
        }
    }
}

/// One contact of one effector: its touchdown and liftoff, `None` where it touches a clip
/// edge (it was in contact before the first, or after the last, frame).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ContactSpan {
    /// Effector index, [`crate::contacts::EFFECTORS`] order.
    pub effector: usize,
    /// Touchdown, clip time, s.
    pub td_s: Option<f64>,
    /// Liftoff, clip time, s.
    pub lo_s: Option<f64>,
}

impl ContactSpan {
    /// Whether the contact holds at clip time `t`, s (its edges included).
    pub fn holds(&self, t: f64) -> bool {
        self.td_s.is_none_or(|a| a <= t) && self.lo_s.is_none_or(|b| t <= b)
    }
}

/// How a frame's force was shared.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SplitRule {
    /// No contact: no force assigned.
    None,
    /// One contact carries the whole force.
    Single,
    /// Two contacts handing over (walking double support): the smooth transition.
    Transition,
    /// Two contacts that do not hand over: the lever rule (the COM between the COPs).
    Lever,
    /// Three or more contacts, or two whose COPs coincide (or are unknown): equal shares.
    Even,
}

impl SplitRule {
    /// The name written in the tables (`none`, `single`, `transition`, `lever`, `even`).
    pub fn as_str(self) -> &'static str {
        match self {
            SplitRule::None => "none",
            SplitRule::Single => "single",
            SplitRule::Transition => "transition",
            SplitRule::Lever => "lever",
            SplitRule::Even => "even",
        }
    }
}

/// One frame's forces per effector ([`crate::contacts::EFFECTORS`] order; `None` when not
/// in contact), N.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FrameSplit {
    /// How the force was shared.
    pub rule: SplitRule,
    /// Force on the body through each effector, world, N.
    pub force: [Option<V3>; 4],
}

/// The trailing share's shape of the fore-aft force: `(1 − 3s² + 2s³)(1 + A s)`.
pub fn fore_aft_shape(s: f64, hump: f64) -> f64 {
    let s = s.clamp(0.0, 1.0);
    (1.0 - s * s * (3.0 - 2.0 * s)) * (1.0 + hump * s)
}

/// Whether `trail` hands over to `lead` (a walking double support): `lead` touched down
/// while `trail` held, `trail` lifts off first, and the overlap is at most `max_s`. An
/// edge outside the clip (`None`) is judged on what the clip shows: the overlap inside
/// `[t_first, t_last]`, and a liftoff order only where both liftoffs are known or `lead`'s
/// alone is (then `trail` lifts off later: no handover).
pub fn is_handover(
    lead: &ContactSpan,
    trail: &ContactSpan,
    t_first: f64,
    t_last: f64,
    max_s: f64,
) -> bool {
    let lifts_first = match (trail.lo_s, lead.lo_s) {
        (Some(o), Some(l)) => o < l,
        (None, Some(_)) => false,
        _ => true,
    };
    let overlap = trail.lo_s.unwrap_or(t_last) - lead.td_s.unwrap_or(t_first);
    lifts_first && overlap <= max_s
}

/// Median duration of the complete handovers among `spans` (a touchdown while another
/// contact holds, to that contact's liftoff, at most `max_s` long and that contact
/// lifting off first), s.
pub fn double_support_duration(spans: &[ContactSpan], max_s: f64) -> Option<f64> {
    let mut d = Vec::new();
    for lead in spans {
        let Some(td) = lead.td_s else { continue };
        for trail in spans.iter().filter(|s| s.effector != lead.effector) {
            if let (Some(lo), true) = (trail.lo_s, trail.td_s.is_none_or(|a| a < td)) {
                let first = lead.lo_s.is_none_or(|l| lo < l);
                if lo > td && lo - td <= max_s && first {
                    d.push(lo - td);
                }
            }
        }
    }
    median(&d)
}

/// `v` at time `t`, linear between frames; `t` is first clamped to `[lo, hi]` (the
/// interior frames' times).
fn interp(time_s: &[f64], v: &[V3], t: f64, lo: f64, hi: f64) -> V3 {
    let t = t.max(lo).min(hi);
    let k = time_s.partition_point(|&x| x < t);
    if k == 0 {
        return v[0];
    }
    if k >= time_s.len() {
        return v[v.len() - 1];
    }
    let w = (t - time_s[k - 1]) / (time_s[k] - time_s[k - 1]);
    add(scale(1.0 - w, v[k - 1]), scale(w, v[k]))
}

/// The times of the first and last interior frames: half an SG window (the COM filter's,
/// [`window_for_rate`] of the frame rate) in from either end; the clip's ends when it is
/// shorter than a window.
pub fn interior_span(time_s: &[f64]) -> (f64, f64) {
    let n = time_s.len();
    if n < 2 {
        let t = time_s.first().copied().unwrap_or(0.0);
        return (t, t);
    }
    let dt = (time_s[n - 1] - time_s[0]) / (n - 1) as f64;
    let h = window_for_rate(1.0 / dt) / 2;
    if 2 * h >= n {
        return (time_s[0], time_s[n - 1]);
    }
    (time_s[h], time_s[n - 1 - h])
}

/// One clip's per-frame inputs of [`split`] (every slice as long as `time_s`).
#[derive(Debug, Clone, Copy)]
pub struct SplitInput<'a> {
    /// Clip time of each frame, s (evenly spaced).
    pub time_s: &'a [f64],
    /// Total force on the body m(a_COM + g ẑ), world, N.
    pub total: &'a [V3],
    /// Heading: unit horizontal, or zero ([`heading_from_velocity`]).
    pub heading: &'a [V3],
    /// COM position, world, m (only its horizontal part is used).
    pub com: &'a [V3],
    /// COP of each effector in contact ([`crate::contacts::EFFECTORS`] order), world, m.
    pub cop: &'a [[Option<V3>; 4]],
}

/// The force of every frame split between the contacts that hold at its time (see the
/// module docs); `spans` are every contact of the clip.
///
/// # Panics
/// A slice of `input` is not as long as `time_s` (a programmer error).
pub fn split(input: &SplitInput, spans: &[ContactSpan], opts: &SplitOptions) -> Vec<FrameSplit> {
    let n = input.time_s.len();
    assert!(
        [
            input.total.len(),
            input.heading.len(),
            input.com.len(),
            input.cop.len()
        ]
        .iter()
        .all(|&l| l == n),
        "split: per-frame inputs of unequal length"
    );
    let ds = double_support_duration(spans, opts.max_handover_s).unwrap_or(opts.double_support_s);
    let interior = interior_span(input.time_s);
    input
        .time_s
        .iter()
        .enumerate()
        .map(|(k, &t)| {
            let on: Vec<&ContactSpan> = spans.iter().filter(|s| s.holds(t)).collect();
            let mut force = [None; 4];
            let total = input.total[k];
            let rule = match on.len() {
                0 => SplitRule::None,
                1 => {
                    force[on[0].effector] = Some(total);
                    SplitRule::Single
                }
                2 => {
                    let (lead, trail) = lead_and_trail(on[0], on[1]);
                    let (t0, t1) = (input.time_s[0], input.time_s[n - 1]);
                    if is_handover(lead, trail, t0, t1, opts.max_handover_s) {
                        transition(input, k, lead, trail, ds, interior, opts, &mut force)
                    } else {
                        lever(input, k, on[0], on[1], &mut force)
                    }
                }
                n => {
                    for s in &on {
                        force[s.effector] = Some(scale(1.0 / n as f64, total));
                    }
                    SplitRule::Even
                }
            };
            FrameSplit { rule, force }
        })
        .collect()
}

/// The leading (touched down last; an unknown touchdown is earliest; between two unknown
/// touchdowns, the one that lifts off last) and the trailing contact.
fn lead_and_trail<'a>(
    a: &'a ContactSpan,
    b: &'a ContactSpan,
) -> (&'a ContactSpan, &'a ContactSpan) {
    let key = |s: &ContactSpan| {
        (
            s.td_s.unwrap_or(f64::NEG_INFINITY),
            s.lo_s.unwrap_or(f64::INFINITY),
        )
    };
    match key(a).partial_cmp(&key(b)) {
        Some(std::cmp::Ordering::Less) => (b, a),
        _ => (a, b),
    }
}

/// The lever rule at frame `k` between contacts `a` and `b` (even when their COPs are
/// unknown or closer than [`MIN_LEVER_BASE_M`]).
fn lever(
    input: &SplitInput,
    k: usize,
    a: &ContactSpan,
    b: &ContactSpan,
    force: &mut [Option<V3>; 4],
) -> SplitRule {
    let f = input.total[k];
    let cops = (input.cop[k][a.effector], input.cop[k][b.effector]);
    let (u, rule) = match cops {
        (Some(pa), Some(pb)) => {
            let d = [pb[0] - pa[0], pb[1] - pa[1], 0.0];
            let base2 = dot(d, d);
            if base2 < MIN_LEVER_BASE_M * MIN_LEVER_BASE_M {
                (0.5, SplitRule::Even)
            } else {
                let c = [input.com[k][0] - pa[0], input.com[k][1] - pa[1], 0.0];
                ((dot(c, d) / base2).clamp(0.0, 1.0), SplitRule::Lever)
            }
        }
        _ => (0.5, SplitRule::Even),
    };
    force[a.effector] = Some(scale(1.0 - u, f));
    force[b.effector] = Some(sub(f, scale(1.0 - u, f)));
    rule
}

/// The smooth transition from `trail` to `lead` at frame `k`; `interior` the first and last
/// interior frames' times (see [`interior_span`]).
#[allow(clippy::too_many_arguments)]
fn transition(
    input: &SplitInput,
    k: usize,
    lead: &ContactSpan,
    trail: &ContactSpan,
    ds: f64,
    interior: (f64, f64),
    opts: &SplitOptions,
    force: &mut [Option<V3>; 4],
) -> SplitRule {
    let f = input.total[k];
    let (t_hs, t_to) = match (lead.td_s, trail.lo_s) {
        (Some(h), Some(o)) if o > h => (h, o),
        (Some(h), None) => (h, h + ds),
        (None, Some(o)) => (o - ds, o),
        _ => {
            force[lead.effector] = Some(scale(0.5, f));
            force[trail.effector] = Some(scale(0.5, f));
            return SplitRule::Even;
        }
    };
    let time_s = input.time_s;
    let s = ((time_s[k] - t_hs) / (t_to - t_hs)).clamp(0.0, 1.0);
    // F_fa and the heading at t_hs, read no nearer a clip end than the first (last)
    // interior frame: the SG filter's edge values are no force.
    let (lo, hi) = interior;
    let e_fa = interp(time_s, input.heading, t_hs, lo, hi);
    let e_fa = if norm(e_fa) > 0.5 {
        scale(1.0 / norm(e_fa), [e_fa[0], e_fa[1], 0.0])
    } else {
        [0.0; 3]
    };
    let fa_now = dot(f, e_fa);
    let fa_hs = dot(interp(time_s, input.total, t_hs, lo, hi), e_fa);
    let share = 1.0 - s;
    // Everything but the fore-aft component goes by the linear share.
    let rest = sub(f, scale(fa_now, e_fa));
    let trail_f = add(
        scale(share, rest),
        scale(fa_hs * fore_aft_shape(s, opts.fore_aft_hump), e_fa),
    );
    force[trail.effector] = Some(trail_f);
    force[lead.effector] = Some(sub(f, trail_f));
    SplitRule::Transition
}

/// The heading per frame from the horizontal COM velocity: unit, or zero below
/// [`MIN_HEADING_SPEED_MPS`].
pub fn heading_from_velocity(com_v: &[V3]) -> Vec<V3> {
    com_v
        .iter()
        .map(|v| {
            let h = v[0].hypot(v[1]);
            if h >= MIN_HEADING_SPEED_MPS {
                [v[0] / h, v[1] / h, 0.0]
            } else {
                [0.0; 3]
            }
        })
        .collect()
}

/// A foot's COP (see the module docs): `ankle`, `toe` positions, `ground_z` the local
/// floor, `surface_z` the contact's height, `leg_scale` = `L_leg/0.84`, m.
pub fn foot_cop(ankle: V3, toe: V3, ground_z: f64, surface_z: f64, leg_scale: f64) -> V3 {
    let h = |p: V3, c: f64| p[2] - ground_z - c * leg_scale;
    let (ha, ht) = (h(ankle, CLEARANCE_ANKLE), h(toe, CLEARANCE_TTIP));
    let lim = COP_HEIGHT_M * leg_scale;
    let (wa, wt) = ((lim - ha).max(0.0), (lim - ht).max(0.0));
    let (x, y) = if wa + wt > 0.0 {
        (
            (wa * ankle[0] + wt * toe[0]) / (wa + wt),
            (wa * ankle[1] + wt * toe[1]) / (wa + wt),
        )
    } else if ha <= ht {
        (ankle[0], ankle[1])
    } else {
        (toe[0], toe[1])
    };
    [x, y, surface_z]
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sum(a: Option<V3>, b: Option<V3>) -> V3 {
        add(a.unwrap(), b.unwrap())
    }

    /// [`split`] with the COM at the origin and no COPs (the lever rule falls back to even).
    fn split_plain(
        t: &[f64],
        total: &[V3],
        heading: &[V3],
        spans: &[ContactSpan],
    ) -> Vec<FrameSplit> {
        let n = t.len();
        let input = SplitInput {
            time_s: t,
            total,
            heading,
            com: &vec![[0.0; 3]; n],
            cop: &vec![[None; 4]; n],
        };
        split(&input, spans, &SplitOptions::default())
    }

    #[test]
    fn the_two_shares_sum_to_the_total_and_hand_over_smoothly() {
        let t: Vec<f64> = (0..=20).map(|k| k as f64 * 0.01).collect();
        let total: Vec<V3> = t.iter().map(|&x| [100.0 - 300.0 * x, 5.0, 700.0]).collect();
        let heading = vec![[1.0, 0.0, 0.0]; t.len()];
        let spans = [
            ContactSpan {
                effector: 1,
                td_s: None,
                lo_s: Some(0.15),
            },
            ContactSpan {
                effector: 0,
                td_s: Some(0.05),
                lo_s: None,
            },
        ];
        let out = split_plain(&t, &total, &heading, &spans);
        for (k, f) in out.iter().enumerate() {
            if f.rule == SplitRule::Transition {
                let s = sum(f.force[0], f.force[1]);
                for i in 0..3 {
                    assert!((s[i] - total[k][i]).abs() < 1e-9);
                }
            }
        }
        // At t_hs the trailing (right) foot has everything; at t_to nothing.
        assert_eq!(out[5].force[1], Some(total[5]));
        let end = out[15].force[1].unwrap();
        assert!(end.iter().all(|v| v.abs() < 1e-9), "{end:?}");
        // Half-way (s = 0.5): vertical and lateral halve, fore-aft is F_fa(t_hs)·0.5·2.25.
        let mid = out[10].force[1].unwrap();
        assert!((mid[2] - 350.0).abs() < 1e-9 && (mid[1] - 2.5).abs() < 1e-9);
        assert!((mid[0] - 85.0 * 0.5 * 2.25).abs() < 1e-9, "{mid:?}");
        // Single support after the liftoff.
        assert_eq!(out[16].rule, SplitRule::Single);
        assert_eq!(out[16].force[0], Some(total[16]));
    }

    #[test]
    fn an_edge_outside_the_clip_takes_the_clips_double_support_duration() {
        let spans = [
            ContactSpan {
                effector: 0,
                td_s: None,
                lo_s: Some(0.1),
            },
            ContactSpan {
                effector: 1,
                td_s: None,
                lo_s: Some(0.8),
            },
            ContactSpan {
                effector: 0,
                td_s: Some(0.65),
                lo_s: None,
            },
        ];
        assert_eq!(double_support_duration(&spans, 0.3), Some(0.8 - 0.65));
        let t = [0.0, 0.05, 0.1];
        let total = vec![[0.0, 0.0, 600.0]; 3];
        let out = split_plain(&t, &total, &[[0.0; 3]; 3], &spans);
        // Left trails (lifts off first); t_hs = 0.1 − 0.15 = −0.05: s = 1/3 at 0 s.
        assert_eq!(out[0].rule, SplitRule::Transition);
        let left = out[0].force[0].unwrap()[2];
        assert!((left - 600.0 * (1.0 - 1.0 / 3.0)).abs() < 1e-9, "{left}");
        assert!(out[2].force[0].unwrap()[2].abs() < 1e-9);
    }

    #[test]
    fn the_cop_rolls_from_the_ankle_to_the_toe() {
        let s = 1.0;
        let ground = 0.0;
        // Heel strike: ankle at its clearance, toe 10 cm up → the ankle.
        let c = foot_cop([0.0, 0.0, 0.08], [0.2, 0.0, 0.11], ground, 0.0, s);
        assert_eq!(c, [0.0, 0.0, 0.0]);
        // Flat foot: both at clearance → the midpoint.
        let c = foot_cop([0.0, 0.0, 0.08], [0.2, 0.0, 0.01], ground, 0.0, s);
        assert!((c[0] - 0.1).abs() < 1e-12);
        // Heel off: the ankle 6 cm up → the toe.
        let c = foot_cop([0.0, 0.0, 0.14], [0.2, 0.0, 0.01], ground, 0.0, s);
        assert!((c[0] - 0.2).abs() < 1e-12);
    }

    #[test]
    fn three_contacts_share_evenly_and_none_carries_nothing() {
        let spans: Vec<ContactSpan> = (0..3)
            .map(|e| ContactSpan {
                effector: e,
                td_s: None,
                lo_s: Some(0.5),
            })
            .collect();
        let out = split_plain(&[0.0, 1.0], &[[0.0, 0.0, 900.0]; 2], &[[0.0; 3]; 2], &spans);
        assert_eq!(out[0].rule, SplitRule::Even);
        assert_eq!(out[0].force[2], Some([0.0, 0.0, 300.0]));
        assert_eq!(out[1].rule, SplitRule::None);
        assert_eq!(out[1].force, [None; 4]);
    }

    // See: issue 39 item 3 review — "feet that stand together are split as if handing
    // over": the drop jump's two-foot landing (both feet down within 4 ms, both up 0.75 s
    // later, the trailing one first) gave one foot 21 N and the other 900 N. Not a
    // handover (0.75 s > 0.3 s): the COM between the COPs shares the load.
    #[test]
    fn a_two_foot_landing_is_shared_by_the_lever_rule_not_handed_over() {
        let t: Vec<f64> = (0..100).map(|k| k as f64 * 0.01).collect();
        let n = t.len();
        let total = vec![[0.0, 0.0, 1000.0]; n];
        let heading = vec![[1.0, 0.0, 0.0]; n];
        let spans = [
            ContactSpan {
                effector: 0,
                td_s: Some(0.1035),
                lo_s: Some(0.85),
            },
            ContactSpan {
                effector: 1,
                td_s: Some(0.0996),
                lo_s: Some(0.8486),
            },
        ];
        // Left COP at y = +0.2, right at y = −0.2; the COM 0.1 m towards the left.
        let mut cop = vec![[None; 4]; n];
        for c in cop.iter_mut() {
            c[0] = Some([0.0, 0.2, 0.0]);
            c[1] = Some([0.0, -0.2, 0.0]);
        }
        let com = vec![[0.05, 0.1, 0.9]; n];
        let input = SplitInput {
            time_s: &t,
            total: &total,
            heading: &heading,
            com: &com,
            cop: &cop,
        };
        let out = split(&input, &spans, &SplitOptions::default());
        let k = 12; // 0.12 s, 17 ms after the landing
        assert_eq!(out[k].rule, SplitRule::Lever);
        // u = (c − p_l)·(p_r − p_l)/|p_r − p_l|² = (−0.1)(−0.4)/0.16 = 0.25: right 250 N.
        let (l, r) = (out[k].force[0].unwrap(), out[k].force[1].unwrap());
        assert!(
            (l[2] - 750.0).abs() < 1e-9 && (r[2] - 250.0).abs() < 1e-9,
            "{l:?} {r:?}"
        );
        // The COM beyond a COP: that contact carries everything (clamped).
        let com = vec![[0.0, 0.5, 0.9]; n];
        let input = SplitInput { com: &com, ..input };
        let out = split(&input, &spans, &SplitOptions::default());
        assert_eq!(out[k].force[0], Some(total[k]));
        // Coinciding COPs: even.
        let cop = vec![[Some([0.0, 0.0, 0.0]), Some([0.0, 0.005, 0.0]), None, None]; n];
        let input = SplitInput { cop: &cop, ..input };
        let out = split(&input, &spans, &SplitOptions::default());
        assert_eq!(out[k].rule, SplitRule::Even);
        assert_eq!(out[k].force[1], Some([0.0, 0.0, 500.0]));
    }

    #[test]
    fn only_a_short_overlap_whose_trailing_contact_lifts_off_first_hands_over() {
        let span = |e, td, lo| ContactSpan {
            effector: e,
            td_s: td,
            lo_s: lo,
        };
        let lead = span(1, Some(1.0), Some(1.8));
        // A walking double support (0.15 s, the trailing foot up first).
        assert!(is_handover(
            &lead,
            &span(0, Some(0.3), Some(1.15)),
            0.0,
            2.0,
            0.3
        ));
        // Too long (0.4 s).
        assert!(!is_handover(
            &lead,
            &span(0, Some(0.3), Some(1.4)),
            0.0,
            2.0,
            0.3
        ));
        // The trailing contact lifts off after the leading one.
        assert!(!is_handover(
            &span(1, Some(1.0), Some(1.1)),
            &span(0, Some(0.3), Some(1.15)),
            0.0,
            2.0,
            0.3
        ));
        // Unknown edges: judged on the clip's part (a clip that starts in double support).
        assert!(is_handover(
            &span(1, None, Some(1.8)),
            &span(0, None, Some(0.1)),
            0.0,
            2.0,
            0.3
        ));
        assert!(!is_handover(
            &span(1, None, Some(1.8)),
            &span(0, None, Some(0.5)),
            0.0,
            2.0,
            0.3
        ));
        // The trailing contact outlasts the clip while the leading one lifts off in it.
        assert!(!is_handover(
            &lead,
            &span(0, Some(0.3), None),
            0.0,
            1.2,
            0.3
        ));
        // Long overlaps do not set the fallback duration.
        let spans = [
            lead,
            span(0, Some(0.3), Some(1.15)),
            span(0, Some(1.7), None),
            span(1, None, Some(0.8)),
        ];
        // Handovers 0.15 s and 0.10 s; the 0.5 s overlaps (left 0.3–1.15 s with the right
        // foot's 0.8 s liftoff) are left out: the median is 0.125 s, not 0.15 s.
        let d = double_support_duration(&spans, 0.3).unwrap();
        assert!((d - 0.125).abs() < 1e-9, "{d}");
    }

    // See: issue 39 item 3 review — "clip-edge fore-aft": a touchdown before the first
    // frame read F_fa at frame 0, the SG filter's edge value (the overground walk's left
    // foot: 205 N fore-aft at 0.06 s where the total was −10 N).
    #[test]
    fn a_touchdown_before_the_interior_reads_the_fore_aft_force_at_the_first_interior_frame() {
        let t: Vec<f64> = (0..40).map(|k| k as f64 * 0.01).collect(); // 100 Hz: h = 5
        assert_eq!(interior_span(&t), (0.05, 0.34));
        // The total's fore-aft: 400 N at frame 0 falling to −50 N at frame 5 (the edge),
        // −50 N from there on.
        let total: Vec<V3> = (0..40)
            .map(|k| {
                [
                    if k < 5 {
                        400.0 - 90.0 * k as f64
                    } else {
                        -50.0
                    },
                    0.0,
                    700.0,
                ]
            })
            .collect();
        let heading = vec![[1.0, 0.0, 0.0]; 40];
        // Left trails, lifting off at 0.10 s; right leads, down before the clip.
        let spans = [
            ContactSpan {
                effector: 0,
                td_s: None,
                lo_s: Some(0.10),
            },
            ContactSpan {
                effector: 1,
                td_s: None,
                lo_s: Some(0.35),
            },
            ContactSpan {
                effector: 0,
                td_s: Some(0.25),
                lo_s: None,
            },
        ];
        let out = split_plain(&t, &total, &heading, &spans);
        let ds = 0.35 - 0.25; // the clip's one complete handover
        for k in 5..=10 {
            assert_eq!(out[k].rule, SplitRule::Transition, "frame {k}");
            let s = (t[k] - (0.10 - ds)) / ds;
            let want = -50.0 * fore_aft_shape(s, DEFAULT_FORE_AFT_HUMP);
            let left = out[k].force[0].unwrap()[0];
            assert!(
                (left - want).abs() < 1e-9,
                "frame {k}: {left} N, want {want}"
            );
        }
    }
}
