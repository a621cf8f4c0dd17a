//! The time-warped source reference: the source clip's joint rotations, COM and feet per
//! frame ([`Reference`]), sampled at any clip time, and what the pose stage needs of each
//! planned stance's source stance ([`StanceSource`]).
//!
//! # Model
//! ```text
//! sample     x = t/Δt clamped to the kept frames,  f₀ = ⌊x⌋,  f₁ = f₀ + 1,  w = x − f₀
//!            q_j = slerp(q_j(f₀), q_j(f₁), w),  other channels, COM and feet linear
//! drift      D: the source foot's slide while resting (Reference::foot_drift)
//! heading    Δψ = ψ_plan − ψ_source wrapped to ±π,  ψ = atan2(e_h,y, e_h,x)   (yaw_of)
//! ```
//!
//! # Frames and units
//! Clip times in s; rotations in the file's axes; COM, feet and drift in metres, internal
//! Z-up frame.

use super::Pose;
use crate::bvh::Motion;
use crate::edit::path::ComPath;
use crate::edit::rotation::{self as rot, Quat};
use crate::error::{Error, Result};
use crate::ingest::body::BodyModel;
use crate::math::v3::V3;

/// What the pose stage needs of each planned stance's source stance.
#[derive(Debug, Clone, PartialEq)]
pub struct StanceSource {
    /// `<clip>:<label>:<first frame>`.
    pub stance_id: String,
    /// Source touchdown and liftoff, clip time (s).
    pub td_clip_s: f64,
    /// Source liftoff, clip time (s).
    pub lo_clip_s: f64,
    /// Source start apex → touchdown (s).
    pub before_s: f64,
    /// Source liftoff → end apex (s).
    pub after_s: f64,
    /// Source heading angle `atan2(e_h,y, e_h,x)` (rad).
    pub heading_rad: f64,
    /// Source contact point, world (m).
    pub anchor: V3,
    /// Feet in contact: left, right.
    pub feet: [bool; 2],
    /// Horizontal drift of each source foot's resting points from touchdown, one entry per
    /// source frame from `floor(td / Δt)` ([`Reference::foot_drift`]; m, Z up).
    pub drift: [Vec<[f64; 2]>; 2],
}

impl StanceSource {
    /// The drift of foot `side` at clip time `t` (s), linear between frames; 0 before the
    /// stance, its last value after it.
    pub fn drift_at(&self, side: usize, t: f64, frame_time_s: f64) -> [f64; 2] {
        let d = &self.drift[side];
        let Some(last) = d.last() else {
            return [0.0; 2];
        };
        let f0 = (self.td_clip_s / frame_time_s).floor();
        let x = (t / frame_time_s - f0).max(0.0);
        let i = x.floor() as usize;
        if i + 1 >= d.len() {
            return *last;
        }
        let w = x - i as f64;
        [0, 1].map(|a| d[i][a] + w * (d[i + 1][a] - d[i][a]))
    }
}

/// The reference motion: the source clip's joint rotations per frame.
#[derive(Debug, Clone)]
pub struct Reference {
    /// The (character-scaled) body.
    pub body: BodyModel,
    /// Source rows (character-scaled translations), row-major.
    pub motion: Motion,
    /// Local rotation per frame and joint (`frame · n_joints + joint`).
    pub quats: Vec<Quat>,
    /// Rotation axes per joint (file axes, in channel order).
    pub axes: Vec<Vec<usize>>,
    /// Hip, knee, ankle joints of the left and right legs.
    pub legs: [[usize; 3]; 2],
    /// Root joint.
    pub root: usize,
    /// First joint of the trunk (the child of the root on the way to the neck base), when
    /// it has three rotation channels and no leg below it: the trunk lean of
    /// [`posture`](crate::edit::posture).
    pub trunk: Option<usize>,
    /// Toe-tip point of each leg (left, right) when it moves with the ankle (a point below
    /// it in the tree): the pivot of [`DEFAULT_MAX_TOE_PIVOT_DEG`](crate::edit::DEFAULT_MAX_TOE_PIVOT_DEG).
    pub toes: [Option<usize>; 2],
    /// Source COM per frame (m, Z up).
    pub com: Vec<V3>,
    /// Source ankles per frame (left, right): position (m, Z up), world rotation (file).
    pub feet: Vec<[(V3, Quat); 2]>,
    /// Source toe tips per frame (left, right; m, Z up), as the ingest places them.
    pub toe_tips: Vec<[V3; 2]>,
    /// The character's length scale `L` against its source (1 for the recorded character;
    /// [`Reference::with_length_scale`]): body-size thresholds scale by it.
    pub length_scale: f64,
}

impl Reference {
    /// Prepares a reference from a body and its clip's motion.
    ///
    /// # Errors
    /// `ErrorKind::Skeleton` when the root has no three translation and three distinct
    /// rotation channels, or a hip, knee or ankle has no three distinct rotation channels
    /// or is not below the one before (the edit cannot place or bend them).
    pub fn new(body: BodyModel, motion: Motion) -> Result<Reference> {
        let sk = &body.skeleton;
        let nj = sk.n_joints();
        let axes: Vec<Vec<usize>> = sk
            .channels
            .iter()
            .map(|c| c.rotations.iter().map(|&(a, _)| a).collect())
            .collect();
        let root = (0..nj).find(|&j| sk.parents[j].is_none()).unwrap_or(0);
        let name = |j: usize| sk.names.get(j).cloned().unwrap_or_else(|| format!("#{j}"));
        if sk.channels[root].translations.iter().any(Option::is_none)
            || !rot::is_tait_bryan(&axes[root])
        {
            return Err(Error::skeleton(format!(
                "root '{}' needs 3 position and 3 distinct rotation channels to be placed",
                name(root)
            )));
        }
        let lm = &body.landmarks;
        let legs = [
            [lm.left.hip, lm.left.knee, lm.left.ankle],
            [lm.right.hip, lm.right.knee, lm.right.ankle],
        ];
        let below = |a: usize, b: usize| {
            let mut p = sk.parents.get(b).copied().flatten();
            while let Some(q) = p {
                if q == a {
                    return true;
                }
                p = sk.parents[q];
            }
            false
        };
        for leg in legs {
            for (k, &j) in leg.iter().enumerate() {
                if j >= nj || !rot::is_tait_bryan(&axes[j]) || (k > 0 && !below(leg[k - 1], j)) {
                    return Err(Error::skeleton(format!(
                        "leg joint '{}' needs 3 distinct rotation channels below the joint \
                         before it for the foot IK",
                        if j < nj {
                            name(j)
                        } else {
                            format!("point {j}")
                        }
                    )));
                }
            }
        }
        let toes = [0, 1].map(|k| {
            body.toe[k].filter(|&p| {
                let j = if p < nj { p } else { sk.end_sites[p - nj].0 };
                j == legs[k][2] || below(legs[k][2], j)
            })
        });
        let trunk = trunk_joint(sk, root, lm.cerv, &axes, &legs);
        let n = motion.n_frames();
        let mut quats = Vec::with_capacity(n * nj);
        let mut com = Vec::with_capacity(n);
        let mut feet = Vec::with_capacity(n);
        let mut toe_tips = Vec::with_capacity(n);
        let mut ws = crate::skeleton::fk::FkWorkspace::new(sk);
        let np = sk.n_points();
        let (mut file, mut pts) = (vec![[0.0; 3]; np], vec![[0.0; 3]; np]);
        for f in 0..n {
            let row = motion.row(f);
            quats.extend((0..nj).map(|j| local_quat(sk, &axes[j], j, row)));
            body.points(&mut ws, row, &mut file, &mut pts);
            com.push(body.com(&pts));
            let wq = world_quats(sk, &quats[f * nj..(f + 1) * nj]);
            feet.push([0, 1].map(|k| (pts[legs[k][2]], wq[legs[k][2]])));
            toe_tips.push(body.toe_tips(&pts));
        }
        Ok(Reference {
            body,
            motion,
            quats,
            axes,
            legs,
            root,
            trunk,
            toes,
            com,
            feet,
            toe_tips,
            length_scale: 1.0,
        })
    }

    /// The same reference for a character `L` times the source's size (its motion already
    /// scaled by `L`): a step inside a stance is then `L ·` [`FOOT_STEP_M`](crate::edit::FOOT_STEP_M), and a
    /// detail's edge window `√L ·` [`detail::EDGE_WINDOW_S`](crate::edit::detail::EDGE_WINDOW_S) (times scale by √L under
    /// dynamic similarity). A scale that is not finite and positive is ignored.
    pub fn with_length_scale(mut self, l: f64) -> Reference {
        if l.is_finite() && l > 0.0 {
            self.length_scale = l;
        }
        self
    }

    /// Horizontal drift of the source feet over a stance from clip time `td` to `lo` (s),
    /// per foot (left, right) and source frame from `floor(td / Δt)` to `ceil(lo / Δt)`:
    /// ```text
    /// h_p(f) = z_p(f) − min over the stance of z_p,    p ∈ {ankle, toe tip}
    /// I_p = [first, last frame with h_p ≤ b],           b = FOOT_REST_BAND_M
    /// S_p: the frames of a run off the band (h_p > b) inside I_p whose rests before and
    ///      after lie more than L · FOOT_STEP_M apart horizontally (a step, not a slide)
    /// D(f) = D(f−1) + Σ_{p: f−1, f ∈ I_p \ S_p} Δx_p(f) / #{p: …}   (0 when none),  D(first) = 0
    /// ```
    /// (`Δx_p`: the point's horizontal step.) Between the first and the last frame where a
    /// foot point rests on the floor (within `b` of its lowest height) its horizontal motion
    /// is the capture's slide, so removing `D` holds it in place: the heel while the foot
    /// lands and rests, the toe tip until it rolls off (heel up), their mean while both
    /// rest. A point on its way down or up does not count, nor one stepping to a new rest
    /// inside the stance; `D` is a sum of steps, so the foot's position stays continuous.
    pub fn foot_drift(&self, td: f64, lo: f64) -> [Vec<[f64; 2]>; 2] {
        let n = self.motion.n_frames();
        let dt = self.motion.frame_time_s;
        let f0 = ((td / dt).floor().max(0.0) as usize).min(n - 1);
        let f1 = ((lo / dt).ceil().max(0.0) as usize).clamp(f0, n - 1);
        [0, 1].map(|side| {
            let tracks: [Vec<V3>; 2] = [
                (f0..=f1).map(|f| self.feet[f][side].0).collect(),
                (f0..=f1).map(|f| self.toe_tips[f][side]).collect(),
            ];
            let step = crate::edit::FOOT_STEP_M * self.length_scale;
            let slides = tracks
                .each_ref()
                .map(|p| sliding_frames(p, crate::edit::FOOT_REST_BAND_M, step));
            let mut d = vec![[0.0; 2]];
            for i in 1..tracks[0].len() {
                let (mut step, mut count) = ([0.0; 2], 0.0);
                for (p, slide) in tracks.iter().zip(&slides) {
                    if slide[i - 1] && slide[i] {
                        count += 1.0;
                        for (a, st) in step.iter_mut().enumerate() {
                            *st += p[i][a] - p[i - 1][a];
                        }
                    }
                }
                let prev = d[i - 1];
                let k = if count > 0.0 { 1.0 / count } else { 0.0 };
                d.push([0, 1].map(|a| prev[a] + step[a] * k));
            }
            d
        })
    }

    /// Source ankle of `side` at clip time `t`: position (m, Z up) and world rotation (file).
    pub fn foot_at(&self, t: f64, side: usize) -> (V3, Quat) {
        let (a, b, w) = self.at(t);
        let ((pa, qa), (pb, qb)) = (self.feet[a][side], self.feet[b][side]);
        (
            std::array::from_fn(|i| pa[i] + w * (pb[i] - pa[i])),
            rot::slerp(qa, qb, w),
        )
    }

    /// Clip time of the first kept frame (s): the reference holds no pose before it.
    pub fn first_time_s(&self) -> f64 {
        let n = self.motion.n_frames();
        self.body.leadin.min(n.saturating_sub(1)) as f64 * self.motion.frame_time_s
    }

    /// Frame position of clip time `t` (s): `(f0, f1, w)`, clamped to the kept frames.
    fn at(&self, t: f64) -> (usize, usize, f64) {
        let n = self.motion.n_frames();
        let first = self.body.leadin.min(n - 1);
        let x = (t / self.motion.frame_time_s).clamp(first as f64, (n - 1) as f64);
        let f0 = x.floor() as usize;
        let f1 = (f0 + 1).min(n - 1);
        (f0, f1, x - f0 as f64)
    }

    /// Source COM at clip time `t` (m), linear between frames.
    pub fn com_at(&self, t: f64) -> V3 {
        let (a, b, w) = self.at(t);
        std::array::from_fn(|i| self.com[a][i] + w * (self.com[b][i] - self.com[a][i]))
    }

    /// The reference pose at clip time `t` into `pose` (rotations slerped, other channels
    /// linear between the two frames).
    pub(super) fn sample(&self, t: f64, pose: &mut Pose) {
        let (a, b, w) = self.at(t);
        let nj = self.body.skeleton.n_joints();
        let (ra, rb) = (self.motion.row(a), self.motion.row(b));
        for (i, v) in pose.row.iter_mut().enumerate() {
            *v = ra[i] + w * (rb[i] - ra[i]);
        }
        for j in 0..nj {
            pose.q[j] = rot::slerp(self.quats[a * nj + j], self.quats[b * nj + j], w);
        }
        pose.ref_frame = if w < 0.5 { a } else { b };
    }
}

/// The child of `root` on the way from it to point `cerv` (the neck base), when it has
/// three distinct rotation channels and no hip below it (`None` otherwise).
fn trunk_joint(
    sk: &crate::skeleton::Skeleton,
    root: usize,
    cerv: usize,
    axes: &[Vec<usize>],
    legs: &[[usize; 3]; 2],
) -> Option<usize> {
    let nj = sk.n_joints();
    let mut j = if cerv < nj {
        cerv
    } else {
        sk.end_sites.get(cerv - nj)?.0
    };
    while sk.parents[j]? != root {
        j = sk.parents[j]?;
    }
    let above = |a: usize, mut b: usize| loop {
        match sk.parents[b] {
            Some(p) if p == a => return true,
            Some(p) => b = p,
            None => return false,
        }
    };
    let ok = rot::is_tait_bryan(&axes[j]) && legs.iter().all(|l| !above(j, l[0]));
    ok.then_some(j)
}

/// The local rotation of joint `j` in `row`: its rotation channels (axes `axes`) as
/// Euler angles.
pub(crate) fn local_quat(
    sk: &crate::skeleton::Skeleton,
    axes: &[usize],
    j: usize,
    row: &[f64],
) -> Quat {
    let deg: Vec<f64> = sk.channels[j]
        .rotations
        .iter()
        .map(|&(_, i)| row[i])
        .collect();
    rot::from_euler(axes, &deg)
}

/// World rotations of one frame's local rotations (parents before children).
pub(crate) fn world_quats(sk: &crate::skeleton::Skeleton, local: &[Quat]) -> Vec<Quat> {
    let mut w: Vec<Quat> = Vec::with_capacity(local.len());
    for (j, q) in local.iter().enumerate() {
        let v = match sk.parents[j] {
            None => *q,
            Some(p) => rot::mul(w[p], *q),
        };
        w.push(v);
    }
    w
}

/// The frames of one foot point's track whose horizontal motion is the capture's slide
/// ([`Reference::foot_drift`]): from the first to the last frame within `band` of the
/// track's lowest height, except the runs off the band whose rests before and after lie
/// more than `step` apart horizontally (m).
fn sliding_frames(p: &[V3], band: f64, step: f64) -> Vec<bool> {
    let zmin = p.iter().map(|v| v[2]).fold(f64::INFINITY, f64::min);
    let on: Vec<bool> = p.iter().map(|v| v[2] - zmin <= band).collect();
    let (Some(first), Some(last)) = (on.iter().position(|&x| x), on.iter().rposition(|&x| x))
    else {
        return vec![false; p.len()];
    };
    let mut slide: Vec<bool> = (0..p.len()).map(|i| first <= i && i <= last).collect();
    let mut i = first;
    while i < last {
        if on[i + 1] {
            i += 1;
            continue;
        }
        // Frames i+1 ..= j−1 are off the band, i and j rest.
        let j = (i + 1..=last).find(|&j| on[j]).unwrap_or(last);
        let moved = (p[j][0] - p[i][0]).hypot(p[j][1] - p[i][1]);
        if moved > step {
            slide[i + 1..j].iter_mut().for_each(|s| *s = false);
        }
        i = j;
    }
    slide
}

/// The turn of planned stance `k` from its source's recorded heading, rad, in `(−π, π]`.
pub(super) fn yaw_of(path: &ComPath, src: &[StanceSource], k: usize) -> f64 {
    wrap_pi(heading_of(path, k) - src[path.stances[k].source].heading_rad)
}

fn heading_of(path: &ComPath, k: usize) -> f64 {
    let h = path.stances[k].heading;
    h[1].atan2(h[0])
}

fn wrap_pi(a: f64) -> f64 {
    let t = std::f64::consts::TAU;
    a - t * (a / t).round()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A foot point resting at `x = 0`, lifted by `rise` while it moves to `x = moved`, and
    /// resting there: 5 + 6 + 5 frames, 2 mm of slide on each rest.
    fn rest_lift_rest(rise: f64, moved: f64) -> Vec<V3> {
        let mut p: Vec<V3> = (0..5).map(|i| [0.002 * i as f64 / 4.0, 0.0, 0.0]).collect();
        p.extend((1..=6).map(|i| {
            let u = i as f64 / 7.0;
            [
                0.002 + moved * u,
                0.0,
                rise * (std::f64::consts::PI * u).sin(),
            ]
        }));
        p.extend((0..5).map(|i| [0.002 + moved + 0.002 * i as f64 / 4.0, 0.0, 0.0]));
        p
    }

    #[test]
    fn a_rise_between_two_rests_is_held_unless_the_point_steps() {
        let (band, step) = (crate::edit::FOOT_REST_BAND_M, crate::edit::FOOT_STEP_M);
        // The CMU run's toe: flat, up 2.9 cm, rests again 0.5 cm on: all slide (held).
        let held = sliding_frames(&rest_lift_rest(0.029, 0.005), band, step);
        assert!(held.iter().all(|&s| s), "{held:?}");
        // The vertical jump's shuffle: up 5 cm, rests again 15 cm on: the lift is kept.
        let shuffle = sliding_frames(&rest_lift_rest(0.05, 0.15), band, step);
        let want: Vec<bool> = (0..16).map(|i| !(5..11).contains(&i)).collect();
        assert_eq!(shuffle, want);
        // Before the first and after the last rest: the foot is on its way down or up.
        let mut p = rest_lift_rest(0.029, 0.005);
        p.insert(0, [0.0, 0.0, 0.05]);
        p.push([0.0, 0.0, 0.05]);
        let s = sliding_frames(&p, band, step);
        assert!(!s[0] && !s[p.len() - 1] && s[1..p.len() - 1].iter().all(|&x| x));
        assert!(sliding_frames(&[], band, step).is_empty());
        // The threshold itself: a rest 4.9 cm on is held, 5.1 cm on is a step; a character
        // twice the size (the caller passes 2 · FOOT_STEP_M) holds the 5.1 cm one.
        let kept =
            |moved: f64, step: f64| !sliding_frames(&rest_lift_rest(0.04, moved), band, step)[7];
        assert!(!kept(0.049, step) && kept(0.051, step) && !kept(0.051, 2.0 * step));
    }
}
