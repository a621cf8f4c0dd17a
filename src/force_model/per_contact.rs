//! The whole body's force split between the contacts that share it (feet or hands), and
//! each contact's centre of pressure (COP) from its points: force per foot where no plates
//! exist.
//!
//! # Model
//! ```text
//! F(t) = m (a_COM(t) + g ẑ)                     total force on the body (SG acceleration)
//! one contact: it carries F.  none: no force.  three or more: F/n each ("even").
//! two contacts (double support), the leading one touching down at t_hs while the trailing
//! one lifts off at t_to:   s = clamp((t − t_hs)/(t_to − t_hs), 0, 1)
//!   trailing:  f_v  = (1 − s) F_v(t)                      vertical
//!              f_lat = (1 − s) F_lat(t)                   lateral (⟂ heading, horizontal)
//!              f_fa = F_fa(t_hs) (1 − 3s² + 2s³)(1 + A s) fore-aft (along the heading)
//!   leading:   F(t) − trailing
//! heading: the horizontal COM velocity at t_hs (unit; fore-aft = lateral split when the
//!   body stands, |v| < 0.1 m/s); A = 2.5
//! an edge of the double support outside the clip (unknown t_hs or t_to): the other edge ∓
//!   the median duration of the clip's complete double supports (else 0.12 s); both
//!   unknown: "even"
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
//! use stancelib::force_model::per_contact::{split, ContactSpan, SplitOptions, SplitRule};
//! // Left foot on until 0.3 s, right foot from 0.2 s: double support 0.2–0.3 s.
//! let t: Vec<f64> = (0..5).map(|k| k as f64 * 0.1).collect();
//! let total = vec![[0.0, 0.0, 700.0]; 5];
//! let heading = vec![[1.0, 0.0, 0.0]; 5];
//! let spans = [
//!     ContactSpan { effector: 0, td_s: None, lo_s: Some(0.3) },
//!     ContactSpan { effector: 1, td_s: Some(0.2), lo_s: None },
//! ];
//! let out = split(&t, &total, &heading, &spans, &SplitOptions::default());
//! assert_eq!(out[1].rule, SplitRule::Single);
//! assert_eq!(out[2].rule, SplitRule::Transition);
//! // At the touchdown everything is still on the trailing (left) foot.
//! assert_eq!(out[2].force[0], Some([0.0, 0.0, 700.0]));
//! assert_eq!(out[2].force[1], Some([0.0, 0.0, 0.0]));
//! assert_eq!(out[4].force[0], None);
//! ```

use crate::contacts::floor::{CLEARANCE_ANKLE, CLEARANCE_TTIP};
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

/// Options of [`split`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SplitOptions {
    /// `A` ([`DEFAULT_FORE_AFT_HUMP`]).
    pub fore_aft_hump: f64,
    /// Fallback double-support duration, s ([`DEFAULT_DOUBLE_SUPPORT_S`]).
    pub double_support_s: f64,
}

impl Default for SplitOptions {
    fn default() -> Self {
        SplitOptions {
            fore_aft_hump: DEFAULT_FORE_AFT_HUMP,
            double_support_s: DEFAULT_DOUBLE_SUPPORT_S,
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
    fn holds(&self, t: f64) -> bool {
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
    /// Two contacts: the smooth transition.
    Transition,
    /// Three or more contacts, or a double support with neither edge in the clip: equal
    /// shares.
    Even,
}

impl SplitRule {
    /// The name written in the tables (`none`, `single`, `transition`, `even`).
    pub fn as_str(self) -> &'static str {
        match self {
            SplitRule::None => "none",
            SplitRule::Single => "single",
            SplitRule::Transition => "transition",
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

/// Median duration of the complete double supports among `spans` (a touchdown while
/// another contact holds, to that contact's liftoff), s.
pub fn double_support_duration(spans: &[ContactSpan]) -> Option<f64> {
    let mut d = Vec::new();
    for lead in spans {
        let Some(td) = lead.td_s else { continue };
        for trail in spans.iter().filter(|s| s.effector != lead.effector) {
            if let (Some(lo), true) = (trail.lo_s, trail.td_s.is_none_or(|a| a < td)) {
                if lo > td {
                    d.push(lo - td);
                }
            }
        }
    }
    median(&d)
}

fn interp(time_s: &[f64], v: &[V3], t: f64) -> V3 {
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

/// The force of every frame split between the contacts that hold at its time (see the
/// module docs). `total` and `heading` (unit horizontal, or zero) are per frame; `spans`
/// are every contact of the clip.
///
/// # Panics
/// `total` or `heading` is not as long as `time_s` (a programmer error).
pub fn split(
    time_s: &[f64],
    total: &[V3],
    heading: &[V3],
    spans: &[ContactSpan],
    opts: &SplitOptions,
) -> Vec<FrameSplit> {
    assert!(total.len() == time_s.len() && heading.len() == time_s.len());
    let ds = double_support_duration(spans).unwrap_or(opts.double_support_s);
    time_s
        .iter()
        .enumerate()
        .map(|(k, &t)| {
            let on: Vec<&ContactSpan> = spans.iter().filter(|s| s.holds(t)).collect();
            let mut force = [None; 4];
            let rule = match on.len() {
                0 => SplitRule::None,
                1 => {
                    force[on[0].effector] = Some(total[k]);
                    SplitRule::Single
                }
                2 => transition(
                    time_s, total, heading, k, on[0], on[1], ds, opts, &mut force,
                ),
                n => {
                    for s in &on {
                        force[s.effector] = Some(scale(1.0 / n as f64, total[k]));
                    }
                    SplitRule::Even
                }
            };
            FrameSplit { rule, force }
        })
        .collect()
}

/// The smooth transition between two contacts at frame `k`.
#[allow(clippy::too_many_arguments)]
fn transition(
    time_s: &[f64],
    total: &[V3],
    heading: &[V3],
    k: usize,
    a: &ContactSpan,
    b: &ContactSpan,
    ds: f64,
    opts: &SplitOptions,
    force: &mut [Option<V3>; 4],
) -> SplitRule {
    // The leading contact touched down last (an unknown touchdown is earliest); between
    // two unknown touchdowns, the one that lifts off last leads.
    let key = |s: &ContactSpan| {
        (
            s.td_s.unwrap_or(f64::NEG_INFINITY),
            s.lo_s.unwrap_or(f64::INFINITY),
        )
    };
    let (ka, kb) = (key(a), key(b));
    let (lead, trail) = match ka.partial_cmp(&kb) {
        Some(std::cmp::Ordering::Greater) => (a, b),
        Some(std::cmp::Ordering::Less) => (b, a),
        _ => (a, b),
    };
    let (t_hs, t_to) = match (lead.td_s, trail.lo_s) {
        (Some(h), Some(o)) if o > h => (h, o),
        (Some(h), None) => (h, h + ds),
        (None, Some(o)) => (o - ds, o),
        _ => {
            force[a.effector] = Some(scale(0.5, total[k]));
            force[b.effector] = Some(scale(0.5, total[k]));
            return SplitRule::Even;
        }
    };
    let s = ((time_s[k] - t_hs) / (t_to - t_hs)).clamp(0.0, 1.0);
    let f = total[k];
    let e_fa = interp(time_s, heading, t_hs);
    let e_fa = if norm(e_fa) > 0.5 {
        scale(1.0 / norm(e_fa), [e_fa[0], e_fa[1], 0.0])
    } else {
        [0.0; 3]
    };
    let fa_now = dot(f, e_fa);
    let fa_hs = dot(interp(time_s, total, t_hs), e_fa);
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
        let out = split(&t, &total, &heading, &spans, &SplitOptions::default());
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
        assert_eq!(double_support_duration(&spans), Some(0.8 - 0.65));
        let t = [0.0, 0.05, 0.1];
        let total = vec![[0.0, 0.0, 600.0]; 3];
        let out = split(&t, &total, &[[0.0; 3]; 3], &spans, &SplitOptions::default());
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
        let out = split(
            &[0.0, 1.0],
            &[[0.0, 0.0, 900.0]; 2],
            &[[0.0; 3]; 2],
            &spans,
            &SplitOptions::default(),
        );
        assert_eq!(out[0].rule, SplitRule::Even);
        assert_eq!(out[0].force[2], Some([0.0, 0.0, 300.0]));
        assert_eq!(out[1].rule, SplitRule::None);
        assert_eq!(out[1].force, [None; 4]);
    }
}
