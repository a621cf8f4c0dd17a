//! A full-body pose per output frame: the time-warped reference, the new heading, the
//! support feet planted by analytic two-bone IK and the root placed so the COM is the
//! planned one.
//!
//! # Model
//! ```text
//! reference  stance k: t_src = td_k + (t − TD_k)·(lo_k − td_k)/(LO_k − TD_k)
//!            flight after k:   t_A = lo_k + (t − LO_k)·e_k/E_k     (e, E: liftoff → apex,
//!            flight before k': t_B = td_k' − (TD_k' − t)·a_k'/A_k'  a, A: apex → touchdown;
//!            lower case source, upper case plan)
//!            q_j = slerp(q_j(t_A), q_j(t_B), w),  w = 3u² − 2u³,  u = (t − LO_k)/(TD_k' − LO_k)
//! heading    q_root ← yaw(Δψ)·q_root,  Δψ = ψ_plan − ψ_source (in flight each edge's root
//!            turned by its own Δψ, then slerped)
//! feet       ankle* = c_plan + yaw(Δψ)(ankle_src − c_src − D),  foot orientation = yaw(Δψ)·src
//!            D: the source foot's slide while resting (Reference::foot_drift)
//!            swinging: ankle* ← ankle* + z·Δz_COM (the planned COM's rise above the
//!            source's since the liftoff or until the touchdown), then
//!            goal = ankle*_h + (A_ref + h·(ankle* − A_ref))_z,  h = 1 − smoothstep(τ / T_hold)
//!            (horizontally on the planted paths' blend, vertically following the body
//!            away from the contacts; before a foot's first or after its last stance
//!            A_ref + h·(ankle* − A_ref) in full)
//!            (A_ref: where the reference pose puts the ankle, τ: time to the foot's nearest
//!            own touchdown or liftoff; ankle* between two stances: their smoothstep blend)
//!            beyond the soft reach ρ(|ankle* − H|): turn the foot about its toe tip T,
//!            heel up, by the smallest φ ≤ φ_max with |ankle*(φ) − H| = ρ (pivot_angle)
//!            ρ(d) = d for d ≤ d₀, else d₀ + (R − d₀)·tanh((d − d₀)/(R − d₀)),
//!            R = max_reach·(l₁ + l₂),  d₀ = min(R, max(soft_reach·(l₁ + l₂), |A_ref − H|))
//!            knee: rotate the shank about n = (H − K) × (A − K) to |A − H| = |ankle* − H|
//!            hip:  the smallest rotation taking A − H onto ankle* − H
//! root       t_root ← t_root + to_file(c_plan − COM(q))  (COM is affine in t_root)
//!            repeat IK and root until |c_plan − COM| ≤ solve tol (10 µm), at most max_iterations
//! posture    a support leg short of its goal after the root shift: the pelvis turned under
//!            a still trunk by the damped least-squares step of super::posture, inside the
//!            same iteration; pass 2 re-poses the frames whose ramped posture
//!            (posture::envelope) differs, with that posture and no further step
//! ```
//! `c` is the contact point (COM at touchdown plus the stance's contact point `cp`), so the
//! reference foot's motion about its contact point, heel–toe roll included, is kept and
//! only moved to the planned point.
//!
//! # Frames and units
//! FK and IK in file units and axes (rotations as unit quaternions); COM, targets and
//! reports in metres, internal Z-up frame.

use super::path::{ComPath, Phase};
use super::posture::{self, Posture, PostureFrame, Row, N_DOF, POSTURE_ZERO};
use super::rotation::{self as rot, Quat};
use super::EditOptions;
use crate::bvh::Motion;
use crate::error::{Error, Result};
use crate::ingest::body::BodyModel;
use crate::skeleton::fk::local_translation;

use crate::math::v3::{add, cross, dot, norm, sub, V3};

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
    /// [`super::posture`].
    pub trunk: Option<usize>,
    /// Toe-tip point of each leg (left, right) when it moves with the ankle (a point below
    /// it in the tree): the pivot of [`DEFAULT_MAX_TOE_PIVOT_DEG`](super::DEFAULT_MAX_TOE_PIVOT_DEG).
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
            for (j, ch) in sk.channels.iter().enumerate() {
                let deg: Vec<f64> = ch.rotations.iter().map(|&(_, i)| row[i]).collect();
                quats.push(rot::from_euler(&axes[j], &deg));
            }
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
    /// scaled by `L`): a step inside a stance is then `L ·` [`super::FOOT_STEP_M`], and a
    /// detail's edge window `√L ·` [`super::detail::EDGE_WINDOW_S`] (times scale by √L under
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
            let step = super::FOOT_STEP_M * self.length_scale;
            let slides = tracks
                .each_ref()
                .map(|p| sliding_frames(p, super::FOOT_REST_BAND_M, step));
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
    fn sample(&self, t: f64, pose: &mut Pose) {
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

/// A pose being built: local rotations and the row of every channel.
#[derive(Debug, Clone, PartialEq)]
pub struct Pose {
    /// Local rotation per joint.
    pub q: Vec<Quat>,
    /// Every channel (translations used; rotation values are rewritten from `q`).
    pub row: Vec<f64>,
    /// Nearest source frame (Euler branch reference for the first output frame).
    pub ref_frame: usize,
}

/// Per-thread scratch of the pose stage.
#[derive(Debug, Clone)]
pub struct PoseWorkspace {
    pose: Pose,
    other: Pose,
    world_q: Vec<Quat>,
    file: Vec<V3>,
    pts: Vec<V3>,
    knee_axis: [Option<V3>; 2],
    prev_angles: Option<Vec<f64>>,
    free_q: Vec<Quat>,
}

impl PoseWorkspace {
    /// Scratch for a reference's skeleton.
    pub fn new(r: &Reference) -> PoseWorkspace {
        let sk = &r.body.skeleton;
        let pose = Pose {
            q: vec![rot::QUAT_IDENTITY; sk.n_joints()],
            row: vec![0.0; sk.n_channels],
            ref_frame: 0,
        };
        PoseWorkspace {
            other: pose.clone(),
            pose,
            world_q: vec![rot::QUAT_IDENTITY; sk.n_joints()],
            file: vec![[0.0; 3]; sk.n_points()],
            pts: vec![[0.0; 3]; sk.n_points()],
            knee_axis: [None; 2],
            prev_angles: None,
            free_q: vec![rot::QUAT_IDENTITY; sk.n_joints()],
        }
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

/// World rotations of one frame's local rotations (parents before children).
fn world_quats(sk: &crate::skeleton::Skeleton, local: &[Quat]) -> Vec<Quat> {
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

/// FK of a quaternion pose: world rotations and file-frame points, then metres Z up.
fn forward(r: &Reference, pose: &Pose, wq: &mut [Quat], file: &mut [V3], pts: &mut [V3]) {
    let sk = &r.body.skeleton;
    for j in 0..sk.n_joints() {
        let t = local_translation(sk, j, &pose.row);
        match sk.parents[j] {
            None => {
                wq[j] = pose.q[j];
                file[j] = t;
            }
            Some(p) => {
                wq[j] = rot::mul(wq[p], pose.q[j]);
                file[j] = add(file[p], rot::rotate(wq[p], t));
            }
        }
    }
    let nj = sk.n_joints();
    for (e, (j, off)) in sk.end_sites.iter().enumerate() {
        file[nj + e] = add(file[*j], rot::rotate(wq[*j], *off));
    }
    for (o, p) in pts.iter_mut().zip(file.iter()) {
        *o = r.body.to_internal(*p);
    }
}

/// Sets joint `j`'s world rotation to `delta · world` (its parent unchanged).
fn turn_world(r: &Reference, pose: &mut Pose, wq: &[Quat], j: usize, delta: Quat) {
    let parent = r.body.skeleton.parents[j].map_or(rot::QUAT_IDENTITY, |p| wq[p]);
    let world = rot::mul(delta, wq[j]);
    pose.q[j] = rot::normalize(rot::mul(rot::conj(parent), world));
}

/// One output frame's outcome.
#[derive(Debug, Clone, PartialEq)]
pub struct FramePose {
    /// Output time (s from the first output frame; [`pose_frame`] gives the plan time).
    pub time_s: f64,
    /// The phase.
    pub phase: Phase,
    /// Planned COM (m).
    pub com_plan: V3,
    /// COM of the written pose (m).
    pub com_pose: V3,
    /// Planned contact point, in stance (m).
    pub contact: Option<V3>,
    /// Planned touchdown and liftoff of the stance, in stance (s, output time;
    /// [`pose_frame`] gives plan times).
    pub window: Option<(f64, f64)>,
    /// Support ankle (left when both), in stance (m).
    pub foot: Option<V3>,
    /// Largest distance of a support ankle from its target (m).
    pub foot_error_m: f64,
    /// Root/IK iterations used.
    pub iterations: usize,
    /// COM within tolerance and feet on their targets.
    pub converged: bool,
    /// The posture change that let the support legs reach ([`super::posture`]; zero
    /// where they reach with the reference's posture).
    pub posture: Posture,
    /// Clip time of the source pose the frame is taken from, s (in a flight between two
    /// stances, that of the edge weighing more in the blend).
    pub source_time_s: f64,
}

/// The whole edited motion.
#[derive(Debug, Clone, PartialEq)]
pub struct EditedMotion {
    /// Rows in the source's channel layout.
    pub motion: Motion,
    /// Per frame: plan, pose COM and convergence.
    pub frames: Vec<FramePose>,
}

fn smooth(u: f64) -> f64 {
    let u = u.clamp(0.0, 1.0);
    u * u * (3.0 - 2.0 * u)
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
fn yaw_of(path: &ComPath, src: &[StanceSource], k: usize) -> f64 {
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

/// Foot `side` anchored to planned stance `k`, from the source foot at clip time `t_src`:
/// ankle position (file) and world orientation.
fn anchored(
    r: &Reference,
    c_plan: V3,
    s: &StanceSource,
    yaw: f64,
    t_src: f64,
    side: usize,
) -> (V3, Quat) {
    let body = &r.body;
    let (p, q) = r.foot_at(t_src, side);
    let [dx, dy] = s.drift_at(side, t_src, r.motion.frame_time_s);
    let planted = sub(p, [s.anchor[0] + dx, s.anchor[1] + dy, s.anchor[2]]);
    let rel = rot::rotate(rot::axis_angle([0.0, 0.0, 1.0], yaw), planted);
    (
        body.to_file(add(c_plan, rel)),
        rot::mul(rot::axis_angle(up_file(body), yaw), q),
    )
}

fn up_file(body: &BodyModel) -> V3 {
    let u = body.to_file([0.0, 0.0, 1.0]);
    let n = norm(u);
    u.map(|v| v / n)
}

/// Where foot `side` goes at `t` and how strongly it is held there ([`Pull`], [`hold`]):
/// anchored to its stance
/// while in one (held fully); in a swing, the blend (smooth weight over the swing) of its
/// motion after the last liftoff, anchored to that stance, and before the next
/// touchdown, anchored to that one, each raised by the planned COM's vertical departure
/// from the source COM since that liftoff (until that touchdown), held vertically only
/// near those contacts (horizontally throughout: following the body horizontally, a run
/// slower than recorded dragged the lifted foot backwards, its re-ingested liftoffs 1.6–1.9
/// frames late at 2 m/s); before its first or after its last stance, held near that
/// contact only. The foot leaves and reaches the floor exactly as the source foot does, and
/// moves off it with the body: a jump higher than recorded rises faster than the recorded
/// foot leaves the floor, and held at the recorded foot's height the straight legs pointed
/// at goals beyond their reach (the vertical jump 1.1 × higher: the root at 11 g in the
/// frames after liftoff). `None`: no stance of this foot.
fn foot_goal(
    r: &Reference,
    path: &ComPath,
    src: &[StanceSource],
    t: f64,
    side: usize,
    hold_s: f64,
) -> Option<(V3, Quat, Pull)> {
    let st = &path.stances;
    let has = |k: usize| src[st[k].source].feet[side];
    let yaw_of = |k: usize| yaw_of(path, src, k);
    let rate = |k: usize| {
        let (td, lo) = st[k].contact_window();
        let s = &src[st[k].source];
        if lo > td {
            (s.lo_clip_s - s.td_clip_s) / (lo - td)
        } else {
            1.0
        }
    };
    for k in (0..st.len()).filter(|&k| has(k)) {
        let (td, lo) = st[k].contact_window();
        if t >= td && t <= lo {
            let s = &src[st[k].source];
            let (p, q) = anchored(
                r,
                st[k].contact_point(),
                s,
                yaw_of(k),
                s.td_clip_s + (t - td) * rate(k),
                side,
            );
            return Some((p, q, [1.0; 2]));
        }
    }
    let b = (0..st.len())
        .rev()
        .find(|&k| has(k) && st[k].contact_window().1 <= t);
    let a = (0..st.len()).find(|&k| has(k) && st[k].contact_window().0 >= t);
    // A run is periodic: after a foot's last stance it swings towards that stance one
    // cycle (two stances of one source) on: (stance, time shift s, horizontal shift m).
    // Held near its liftoff and then following the body instead, a run slower than
    // recorded dragged the lifted foot backwards (the last liftoffs re-ingested 1.8 frames
    // late at 2 m/s). Before a foot's first stance the source's swing after that stance's
    // liftoff is not the swing before it (on `cmu_09_01` it lies at the clip's end, and
    // the leg straightened and the foot turned 25° in a frame), so the foot is held only.
    let edge_b = b.map(|k| (k, 0.0, [0.0; 2]));
    let edge_a = match (a, b) {
        (Some(k), _) => Some((k, 0.0, [0.0; 2])),
        (None, Some(k)) => k
            .checked_sub(2)
            .filter(|&j| st[j].source == st[k].source)
            .map(|j| {
                (
                    k,
                    st[k].t0 - st[j].t0,
                    [0, 1].map(|i| st[k].origin[i] - st[j].origin[i]),
                )
            }),
        _ => None,
    };
    // The source foot's motion about the contact it left (b) or meets (a), plus the
    // planned COM's vertical departure from the source COM's since (until) that contact
    // (horizontally the footprints' blend below carries the new distance: the horizontal
    // departure too dragged a run slower than recorded's lifted foot backwards at the
    // speed difference, its re-ingested liftoffs 1.6–1.9 frames late at 2 m/s).
    let swing_from = |(k, dt, o): (usize, f64, [f64; 2]), end: usize| {
        let s = &src[st[k].source];
        let (td, lo) = st[k].contact_window();
        let (edge, edge_src) = if end == 1 {
            (lo + dt, s.lo_clip_s)
        } else {
            (td + dt, s.td_clip_s)
        };
        let t_src = edge_src + (t - edge) * rate(k);
        let c = st[k].contact_point();
        let (p, q) = anchored(
            r,
            [c[0] + o[0], c[1] + o[1], c[2]],
            s,
            yaw_of(k),
            t_src,
            side,
        );
        // A cycle away the planned and source paths rise alike (periodic).
        let rise = if dt == 0.0 {
            let planned = sub(path.com(t).0, path.com(edge).0);
            let recorded = sub(r.com_at(t_src), r.com_at(edge_src));
            let yaw = rot::axis_angle([0.0, 0.0, 1.0], yaw_of(k));
            sub(planned, rot::rotate(yaw, recorded))[2]
        } else {
            0.0
        };
        (add(p, r.body.to_file([0.0, 0.0, rise])), q, edge)
    };
    let from_b = edge_b.map(|e| swing_from(e, 1));
    let from_a = edge_a.map(|e| swing_from(e, 0));
    let lo = from_b.map(|f| f.2);
    let td = from_a.map(|f| f.2);
    let held = hold(
        lo.map_or(f64::INFINITY, |lo| t - lo)
            .min(td.map_or(f64::INFINITY, |td| td - t)),
        hold_s,
    );
    match (from_b, from_a) {
        (Some(pb), Some(pa)) => {
            let (lo, td) = (pb.2, pa.2);
            let w = smooth(if td > lo { (t - lo) / (td - lo) } else { 1.0 });
            let p = std::array::from_fn(|i| pb.0[i] + w * (pa.0[i] - pb.0[i]));
            Some((p, rot::slerp(pb.1, pa.1, w), [1.0, held]))
        }
        // Before the first or after the last stance of a foot with no stance a cycle on
        // (a jump, a single cycle): held near that contact, horizontally too (the source
        // foot's path far from its only contact, time-warped, stretched the leg).
        (Some(p), None) | (None, Some(p)) => Some((p.0, p.1, [held; 2])),
        _ => None,
    }
}

/// How strongly a swinging foot is held on its planted path `τ` (s) from its nearest own
/// touchdown or liftoff: `1 − smoothstep(τ / hold_s)`, 1 at the contact, 0 from `hold_s`
/// on (where the foot follows the body); always 1 when `hold_s ≤ 0`.
fn hold(tau: f64, hold_s: f64) -> f64 {
    if hold_s > 0.0 {
        1.0 - smooth(tau / hold_s)
    } else {
        1.0
    }
}

/// Step 1 of [`pose_frame`]: the reference pose of output time `t` into `ws.pose` (the
/// source stance's pose at the same fraction of its contact, or in a flight the source
/// flight edges' poses, blended across a flight between two stances) and the yaw that
/// turns it onto the planned heading (0 in a flight between two stances: the edges' roots
/// are turned before the blend). Returns the yaw, the stance `t` lies in and the clip time
/// of the source pose (in a flight between two stances, that of the edge weighing more).
fn reference_pose(
    r: &Reference,
    path: &ComPath,
    src: &[StanceSource],
    t: f64,
    ws: &mut PoseWorkspace,
) -> (f64, Option<usize>, f64) {
    let st = &path.stances;
    let src_of = |k: usize| &src[st[k].source];
    let yaw_of = |k: usize| yaw_of(path, src, k);
    let (before, after) = match path.phase(t) {
        Phase::Stance(k) => {
            let (td, lo) = st[k].contact_window();
            let s = src_of(k);
            let u = if lo > td { (t - td) / (lo - td) } else { 0.0 };
            let t_src = s.td_clip_s + u * (s.lo_clip_s - s.td_clip_s);
            r.sample(t_src, &mut ws.pose);
            return (yaw_of(k), Some(k), t_src);
        }
        Phase::Flight { before, after } => (before, after),
        Phase::Rest => (None, None),
    };
    let side_a = before.map(|b| {
        let (_, lo) = st[b].contact_window();
        let e_new = st[b].end() - lo;
        let s = src_of(b);
        let rate = if e_new > 0.0 { s.after_s / e_new } else { 1.0 };
        (lo, s.lo_clip_s + (t - lo) * rate)
    });
    let side_b = after.map(|a| {
        let (td, _) = st[a].contact_window();
        let b_new = td - st[a].t0;
        let s = src_of(a);
        let rate = if b_new > 0.0 { s.before_s / b_new } else { 1.0 };
        (td, s.td_clip_s - (td - t) * rate)
    });
    match (side_a, side_b, before, after) {
        (Some((lo, ta)), Some((td, tb)), Some(b), Some(a)) => {
            let w = smooth(if td > lo { (t - lo) / (td - lo) } else { 1.0 });
            let up = up_file(&r.body);
            r.sample(tb, &mut ws.pose);
            ws.pose.q[r.root] = rot::mul(rot::axis_angle(up, yaw_of(a)), ws.pose.q[r.root]);
            std::mem::swap(&mut ws.pose, &mut ws.other);
            r.sample(ta, &mut ws.pose);
            ws.pose.q[r.root] = rot::mul(rot::axis_angle(up, yaw_of(b)), ws.pose.q[r.root]);
            // Both roots already turned onto their planned headings: the slerp takes the
            // shortest way between the orientations the body has at either edge. Blending
            // the source roots and the yaws apart spun a landing recorded 180° from its
            // liftoff (a paired jump) a full turn in the flight.
            for (qa, qb) in ws.pose.q.iter_mut().zip(&ws.other.q) {
                *qa = rot::slerp(*qa, *qb, w);
            }
            for (va, vb) in ws.pose.row.iter_mut().zip(&ws.other.row) {
                *va += w * (vb - *va);
            }
            (0.0, None, if w < 0.5 { ta } else { tb })
        }
        (Some((_, ta)), _, Some(b), _) => {
            r.sample(ta, &mut ws.pose);
            (yaw_of(b), None, ta)
        }
        (_, Some((_, tb)), _, Some(a)) => {
            r.sample(tb, &mut ws.pose);
            (yaw_of(a), None, tb)
        }
        _ => {
            r.sample(0.0, &mut ws.pose);
            (0.0, None, 0.0)
        }
    }
}

/// One IK pass of the feet (step 2 of [`pose_frame`]): each pulled ankle goes part way
/// ([`Pull`]) from where FK puts it towards its goal, by two-bone IK and the goal
/// orientation;
/// `ws` is left with FK of the result. Returns the largest distance of a planted (support)
/// foot from its goal (m) and each pulled ankle's goal after the toe pivot (file).
fn place_feet(
    r: &Reference,
    ws: &mut PoseWorkspace,
    pulls: &[Option<(V3, Quat, Pull)>; 2],
    planted: [bool; 2],
    opts: &EditOptions,
) -> (f64, [Option<V3>; 2]) {
    let body = &r.body;
    let max_reach = opts.max_reach;
    let up = up_file(body);
    let goal: [Option<(V3, Quat)>; 2] = std::array::from_fn(|side| {
        pulls[side].map(|(p, q, [wh, wv])| {
            let ankle = r.legs[side][2];
            let (fp, fq) = (ws.file[ankle], ws.world_q[ankle]);
            // Part way from the reference foot: `wh` horizontally, `wv` vertically and in
            // orientation.
            let d = sub(p, fp);
            let dv = dot(d, up);
            let pos = std::array::from_fn(|i| fp[i] + wh * (d[i] - dv * up[i]) + wv * dv * up[i]);
            toe_pivot(r, ws, side, (pos, rot::slerp(fq, q, wv)), opts)
        })
    });
    for (side, g) in goal.iter().enumerate() {
        if let Some((p, _)) = *g {
            two_bone(r, ws, side, p, max_reach);
            forward(r, &ws.pose, &mut ws.world_q, &mut ws.file, &mut ws.pts);
        }
    }
    for (side, g) in goal.iter().enumerate() {
        if let Some((_, o)) = *g {
            let ankle = r.legs[side][2];
            let parent = body.skeleton.parents[ankle].map_or(rot::QUAT_IDENTITY, |p| ws.world_q[p]);
            ws.pose.q[ankle] = rot::normalize(rot::mul(rot::conj(parent), o));
        }
    }
    forward(r, &ws.pose, &mut ws.world_q, &mut ws.file, &mut ws.pts);
    // Support feet only: a swing foot may be out of reach and is not planted.
    let err = (0..2)
        .filter(|&side| planted[side])
        .filter_map(|side| goal[side].map(|(p, _)| norm(sub(ws.file[r.legs[side][2]], p))))
        .fold(0.0, f64::max)
        * body.unit_m;
    (err, goal.map(|g| g.map(|(p, _)| p)))
}

/// How far a foot is pulled from the reference pose's towards its goal: horizontally,
/// vertically (and in orientation); 1 is onto it.
type Pull = [f64; 2];

/// What one frame's root/IK iteration aims at: the planned COM (m), the foot pulls
/// ([`foot_goal`]) and which legs are planted (support).
struct FrameGoal {
    com: V3,
    pulls: [Option<(V3, Quat, Pull)>; 2],
    planted: [bool; 2],
}

/// What one frame's root/IK iteration reached.
struct Solved {
    iterations: usize,
    err_m: f64,
    foot_err: f64,
    com_pose: V3,
    posture: Posture,
}

/// Poses one output time into `ws.pose` and returns the frame's outcome: with `fixed`
/// `None`, the posture ([`super::posture`]) is solved where a support leg falls short (the
/// first pass); with `Some(x)` the pelvis takes posture `x` and no reach step is taken
/// (the second pass, from the ramped postures).
pub fn pose_frame(
    r: &Reference,
    path: &ComPath,
    src: &[StanceSource],
    opts: &EditOptions,
    t: f64,
    ws: &mut PoseWorkspace,
    fixed: Option<&Posture>,
) -> FramePose {
    let phase = path.phase(t);
    if phase == Phase::Rest {
        return lead_in_frame(r, path, src, opts, t, ws, fixed);
    }
    let st = &path.stances;
    let src_of = |k: usize| &src[st[k].source];
    // 1. Reference pose, foot anchors and yaw.
    let (yaw, stance, source_time_s) = reference_pose(r, path, src, t, ws);
    let q_yaw = rot::axis_angle(up_file(&r.body), yaw);
    let (com_plan, _) = path.com(t);
    let contact = stance.map(|k| st[k].contact_point());
    ws.pose.q[r.root] = rot::mul(q_yaw, ws.pose.q[r.root]);
    ws.free_q.clone_from(&ws.pose.q);
    // 2. Root, posture and IK until the COM is on the plan.
    let goal = FrameGoal {
        com: com_plan,
        pulls: [0, 1].map(|side| foot_goal(r, path, src, t, side, opts.swing_hold_s)),
        planted: [0, 1].map(|side| stance.is_some_and(|k| src_of(k).feet[side])),
    };
    let s = solve_frame(r, opts, &goal, fixed, ws);
    let support = stance.and_then(|k| src_of(k).feet.iter().position(|&f| f));
    let foot = support.map(|side| ws.pts[r.legs[side][2]]);
    FramePose {
        time_s: t,
        phase,
        com_plan,
        com_pose: s.com_pose,
        contact,
        window: stance.map(|k| st[k].contact_window()),
        foot,
        foot_error_m: s.foot_err,
        iterations: s.iterations,
        converged: s.err_m <= opts.com_tol_m && s.foot_err <= opts.com_tol_m,
        posture: s.posture,
        source_time_s,
    }
}

/// A lead-in frame ([`Phase::Rest`], plan time `t` before the first touchdown): the
/// recording's own pose at the same time before the first stance's source touchdown, turned
/// onto that stance's planned heading, with the root putting the COM on the recording's COM
/// moved as the stance is placed, and the feet of the first stance on its planned
/// footprints ([`anchored`], as from its touchdown on). A jump's first stance keeps its
/// recorded heading and touchdown COM, so the recorded jump's lead-in is its recording; a
/// request whose solved contact point moved stands on the moved footprints from the first
/// frame (written with the recording's feet, they jumped by that move, up to 5.4 cm, at the
/// touchdown: found by review). The jump edits play the source's own size (`L = 1`): the
/// clip times here are not scaled.
fn lead_in_frame(
    r: &Reference,
    path: &ComPath,
    src: &[StanceSource],
    opts: &EditOptions,
    t: f64,
    ws: &mut PoseWorkspace,
    fixed: Option<&Posture>,
) -> FramePose {
    let s = &src[path.stances[0].source];
    let (td, _) = path.stances[0].contact_window();
    let clip_t = s.td_clip_s + (t - td);
    r.sample(clip_t, &mut ws.pose);
    let yaw = yaw_of(path, src, 0);
    ws.pose.q[r.root] = rot::mul(rot::axis_angle(up_file(&r.body), yaw), ws.pose.q[r.root]);
    ws.free_q.clone_from(&ws.pose.q);
    let moved = rot::rotate(
        rot::axis_angle([0.0, 0.0, 1.0], yaw),
        sub(r.com_at(clip_t), r.com_at(s.td_clip_s)),
    );
    let com_plan = add(path.com(td).0, moved);
    let planted = s.feet;
    let goal = FrameGoal {
        com: com_plan,
        pulls: [0, 1].map(|side| {
            planted[side].then(|| {
                let (p, q) = anchored(r, path.stances[0].contact_point(), s, yaw, clip_t, side);
                (p, q, [1.0; 2])
            })
        }),
        planted,
    };
    let s = solve_frame(r, opts, &goal, fixed, ws);
    FramePose {
        time_s: t,
        phase: Phase::Rest,
        com_plan,
        com_pose: s.com_pose,
        contact: None,
        window: None,
        foot: None,
        foot_error_m: s.foot_err,
        iterations: s.iterations,
        converged: s.err_m <= opts.com_tol_m && s.foot_err <= opts.com_tol_m,
        posture: s.posture,
        source_time_s: clip_t,
    }
}

/// Step 2 of [`pose_frame`]: from the free pose in `ws.free_q`, alternate posture (the
/// `fixed` one, or the reach step of [`reach_update`]), foot IK and the root shift that
/// puts the COM on the plan, until the COM error is below the solve tolerance and the
/// posture settled.
fn solve_frame(
    r: &Reference,
    opts: &EditOptions,
    g: &FrameGoal,
    fixed: Option<&Posture>,
    ws: &mut PoseWorkspace,
) -> Solved {
    let body = &r.body;
    let root_ch = body.skeleton.channels[r.root].translations;
    let solve = fixed.is_none();
    let base = fixed.copied().unwrap_or(POSTURE_ZERO);
    let frame = ((solve && g.planted.iter().any(|&p| p)) || base != POSTURE_ZERO)
        .then(|| posture_frame(r, ws, opts));
    let mut reach = ReachState {
        y: POSTURE_ZERO,
        jac: None,
    };
    let mut iterations = 0;
    let (mut err_m, mut foot_err) = (f64::INFINITY, 0.0);
    let mut com_pose = [0.0; 3];
    let mut settled = false;
    let mut x_used = base;
    while iterations < opts.max_iterations {
        iterations += 1;
        let x: Posture = if solve { reach.y } else { base };
        x_used = x;
        ws.pose.q.copy_from_slice(&ws.free_q);
        if let Some(fr) = &frame {
            fr.apply(&x, &mut ws.pose.q);
        }
        forward(r, &ws.pose, &mut ws.world_q, &mut ws.file, &mut ws.pts);
        let mut goals = [None; 2];
        if g.pulls.iter().any(Option::is_some) {
            (foot_err, goals) = place_feet(r, ws, &g.pulls, g.planted, opts);
        }
        com_pose = body.com(&ws.pts);
        let e = sub(g.com, com_pose);
        err_m = norm(e);
        let moved = solve
            && frame.as_ref().is_some_and(|fr| {
                let at = ReachAt {
                    frame: fr,
                    x: &x,
                    goals: &goals,
                    com_pose,
                };
                reach_update(r, opts, g, &at, &mut reach, ws)
            });
        if err_m <= opts.com_solve_tol_m && !moved {
            settled = true;
            break;
        }
        let d = body.to_file(e);
        for a in 0..3 {
            if let Some(i) = root_ch[a] {
                ws.pose.row[i] += d[a];
            }
        }
    }
    if !settled {
        // The last root shift is not yet seen by FK: measure the pose as written.
        forward(r, &ws.pose, &mut ws.world_q, &mut ws.file, &mut ws.pts);
        com_pose = body.com(&ws.pts);
        err_m = norm(sub(g.com, com_pose));
    }
    Solved {
        iterations,
        err_m,
        foot_err,
        com_pose,
        posture: x_used,
    }
}

/// The free pose's posture frame ([`PostureFrame`]): its hips, the trunk joint's world
/// rotations and the bound of `opts` (`ws` is left with FK of the free pose).
fn posture_frame(r: &Reference, ws: &mut PoseWorkspace, opts: &EditOptions) -> PostureFrame {
    ws.pose.q.copy_from_slice(&ws.free_q);
    forward(r, &ws.pose, &mut ws.world_q, &mut ws.file, &mut ws.pts);
    let trunk = r.trunk.map(|j| {
        let parent = r.body.skeleton.parents[j].map_or(rot::QUAT_IDENTITY, |p| ws.world_q[p]);
        (j, parent, ws.world_q[j])
    });
    PostureFrame::new(
        [ws.file[r.legs[0][0]], ws.file[r.legs[1][0]]],
        up_file(&r.body),
        r.root,
        trunk,
        opts.max_pelvis_turn_deg.to_radians(),
    )
}

/// The reach step's state within one frame: the posture on top of the base, and the
/// Jacobian of the support legs' shortfalls (computed once, when a shortfall first shows).
struct ReachState {
    y: Posture,
    jac: Option<[Posture; 2]>,
}

/// Where the current iteration stands: its posture frame, posture `x`, the pivoted ankle
/// goals (file) and the pose's COM (m).
struct ReachAt<'a> {
    frame: &'a PostureFrame,
    x: &'a Posture,
    goals: &'a [Option<V3>; 2],
    com_pose: V3,
}

/// One reach step ([`super::posture`]): the support legs' shortfalls after the coming root
/// shift, `s_k = |G_k − H_k − (c_plan − c)| − R_k` (m), and when one is positive the damped
/// least-squares posture that brings them to `−tol` (Jacobian by finite differences, once
/// per frame). Returns whether the posture moved (a support ankle by more than the solve
/// tolerance); `ws` keeps FK of the current pose.
fn reach_update(
    r: &Reference,
    opts: &EditOptions,
    g: &FrameGoal,
    at: &ReachAt,
    st: &mut ReachState,
    ws: &mut PoseWorkspace,
) -> bool {
    let body = &r.body;
    let shift = sub(g.com, at.com_pose);
    let rows: [Option<(f64, V3, V3)>; 2] = std::array::from_fn(|k| {
        let goal = at.goals[k].filter(|_| g.planted[k])?;
        let [hip, knee, ankle] = r.legs[k];
        let (h, kn, a) = (ws.file[hip], ws.file[knee], ws.file[ankle]);
        let reach = opts.max_reach * (norm(sub(h, kn)) + norm(sub(a, kn))) * body.unit_m;
        let hip_m = ws.pts[hip];
        let v = sub(sub(body.to_internal(goal), hip_m), shift);
        let d = norm(v);
        (d > 0.0).then(|| (d - reach, v.map(|c| c / d), hip_m))
    });
    let tol = opts.com_solve_tol_m;
    if st.jac.is_none() {
        if !rows.iter().flatten().any(|row| row.0 > tol) {
            return false;
        }
        st.jac = Some(reach_jacobian(r, opts, g, at, &rows, ws));
    }
    let Some(jac) = st.jac else { return false };
    let active: Vec<Row> = (0..2)
        .filter_map(|k| {
            let s0 = rows[k]?.0 - dot_dof(&jac[k], &st.y);
            (s0 > 0.0).then_some((jac[k], -tol - s0))
        })
        .collect();
    let y = if active.is_empty() {
        POSTURE_ZERO
    } else {
        posture::dls_step(&active, posture::DAMPING_M, &[-1.0; N_DOF], &[1.0; N_DOF])
    };
    let dy: Posture = std::array::from_fn(|d| y[d] - st.y[d]);
    let change = (0..2)
        .filter(|&k| rows[k].is_some())
        .map(|k| dot_dof(&jac[k], &dy).abs())
        .fold(0.0, f64::max);
    let moved = change > tol;
    if moved {
        st.y = y;
    }
    moved
}

fn dot_dof(a: &Posture, b: &Posture) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}

/// `∂s_k/∂x_d` of the support legs' shortfalls at posture `at.x` (m per unit of `x`):
/// each DOF stepped by [`posture::FD_STEP`], FK, foot IK and COM again, and the hip's move
/// after the root shift, `ΔH − Δc`, projected on the leg's direction `u_k` (`rows`:
/// shortfall, `u_k`, hip in m). `ws` is left with the pose it was given.
fn reach_jacobian(
    r: &Reference,
    opts: &EditOptions,
    g: &FrameGoal,
    at: &ReachAt,
    rows: &[Option<(f64, V3, V3)>; 2],
    ws: &mut PoseWorkspace,
) -> [Posture; 2] {
    ws.other.q.copy_from_slice(&ws.pose.q);
    let mut jac = [POSTURE_ZERO; 2];
    for d in 0..posture::N_DOF {
        let mut xd = *at.x;
        xd[d] += posture::FD_STEP;
        ws.pose.q.copy_from_slice(&ws.free_q);
        at.frame.apply(&xd, &mut ws.pose.q);
        forward(r, &ws.pose, &mut ws.world_q, &mut ws.file, &mut ws.pts);
        place_feet(r, ws, &g.pulls, g.planted, opts);
        let dc = sub(r.body.com(&ws.pts), at.com_pose);
        for (k, row) in rows.iter().enumerate() {
            if let Some((_, u, h)) = *row {
                let dh = sub(sub(ws.pts[r.legs[k][0]], h), dc);
                jac[k][d] = -dot(u, dh) / posture::FD_STEP;
            }
        }
    }
    ws.pose.q.copy_from_slice(&ws.other.q);
    forward(r, &ws.pose, &mut ws.world_q, &mut ws.file, &mut ws.pts);
    jac
}

/// Leg `side` as FK left it in `ws` (the reference leg, before IK): its hip (file) and
/// where its soft reach starts and ends (file units; [`soft_reach`]): from
/// `opts.soft_reach` of thigh plus shank, or the leg's own extension if longer, to the
/// knee's reach `R = min(max_reach·(l₁ + l₂), √(l₁² + l₂² + 2 l₁ l₂ cos κ_min))`
/// (`κ_min = opts.min_knee_flexion_deg`; the toe pivot takes the rest).
fn leg_reach(r: &Reference, ws: &PoseWorkspace, side: usize, opts: &EditOptions) -> (V3, f64, f64) {
    let [hip, knee, ankle] = r.legs[side];
    let (h, k, a) = (ws.file[hip], ws.file[knee], ws.file[ankle]);
    let (l1, l2) = (norm(sub(h, k)), norm(sub(a, k)));
    let full = l1 + l2;
    let bent = (l1 * l1 + l2 * l2 + 2.0 * l1 * l2 * opts.min_knee_flexion_deg.to_radians().cos())
        .max(0.0)
        .sqrt();
    let hard = (opts.max_reach * full).min(bent);
    (
        h,
        (opts.soft_reach * full).max(norm(sub(a, h))).min(hard),
        hard,
    )
}

/// The foot goal `(ankle, orientation)` (file frame) of leg `side`, turned about its
/// toe tip (heel up, [`pivot_angle`]) when the ankle is beyond the leg's soft reach
/// ([`leg_reach`]) from the hip; unchanged when it is within it or the leg has no toe
/// below its ankle.
fn toe_pivot(
    r: &Reference,
    ws: &PoseWorkspace,
    side: usize,
    goal: (V3, Quat),
    opts: &EditOptions,
) -> (V3, Quat) {
    let Some(tp) = r.toes[side] else { return goal };
    let ankle = r.legs[side][2];
    let (h, start, hard) = leg_reach(r, ws, side, opts);
    let a = ws.file[ankle];
    let (p, q) = goal;
    let d = norm(sub(p, h));
    let reach = soft_reach(d, start, hard);
    if d <= reach {
        return goal;
    }
    let toe_ankle = rot::rotate(rot::conj(ws.world_q[ankle]), sub(ws.file[tp], a));
    let toe = add(p, rot::rotate(q, toe_ankle));
    let axis = cross(up_file(&r.body), sub(toe, p));
    let n = norm(axis);
    if n == 0.0 {
        return goal;
    }
    let axis = axis.map(|v| v / n);
    let u = sub(p, toe);
    let phi = pivot_angle(toe, u, axis, h, reach, opts.max_toe_pivot_deg.to_radians());
    let turn = rot::axis_angle(axis, phi);
    (add(toe, rot::rotate(turn, u)), rot::mul(turn, q))
}

/// The leg's share `ρ(d)` of a hip-to-ankle distance `d` (any unit): `d` up to `start`,
/// then approaching `hard` smoothly, `start + (hard − start)·tanh((d − start)/(hard − start))`
/// (slope 1 and no curvature at `start`); `min(d, hard)` when `start ≥ hard`.
fn soft_reach(d: f64, start: f64, hard: f64) -> f64 {
    if d <= start {
        d
    } else if hard > start {
        start + (hard - start) * ((d - start) / (hard - start)).tanh()
    } else {
        d.min(hard)
    }
}

/// The smallest turn `φ ∈ [0, φ_max]` (rad) about `axis` (unit, ⟂ `u`) through the toe
/// tip `toe` that brings the ankle `toe + u` within `reach` of the hip `hip`:
/// ```text
/// ankle(φ) = T + u cos φ + (n × u) sin φ,   |ankle(φ) − H|² = R²
///   ⇔ A cos φ + B sin φ = C,  A = 2(T − H)·u,  B = 2(T − H)·(n × u),  C = R² − |T − H|² − |u|²
/// ```
/// the first root above 0; without one (the hip too far even from the nearest ankle
/// position) the turn to that nearest position; both capped at `φ_max`.
fn pivot_angle(toe: V3, u: V3, axis: V3, hip: V3, reach: f64, max_rad: f64) -> f64 {
    use std::f64::consts::{PI, TAU};
    let th = sub(toe, hip);
    let w = cross(axis, u);
    let (a, b) = (2.0 * dot(th, u), 2.0 * dot(th, w));
    let c = reach * reach - dot(th, th) - dot(u, u);
    let m = a.hypot(b);
    if m == 0.0 {
        return 0.0;
    }
    let psi = b.atan2(a);
    let phi = if c / m >= -1.0 {
        let d = (c / m).min(1.0).acos();
        [psi - d, psi + d]
            .map(|x| x.rem_euclid(TAU))
            .into_iter()
            .fold(f64::INFINITY, f64::min)
    } else {
        (psi + PI).rem_euclid(TAU)
    };
    if phi > PI {
        0.0
    } else {
        phi.min(max_rad)
    }
}

/// Analytic two-bone IK of one leg towards `target` (file frame): knee about its hinge,
/// then the hip by the smallest rotation. Reach is clamped to `max_reach` of the leg.
fn two_bone(r: &Reference, ws: &mut PoseWorkspace, side: usize, target: V3, max_reach: f64) {
    let [hip, knee, ankle] = r.legs[side];
    let (h, k, a) = (ws.file[hip], ws.file[knee], ws.file[ankle]);
    let (v1, v2) = (sub(h, k), sub(a, k));
    let (l1, l2) = (norm(v1), norm(v2));
    if l1 == 0.0 || l2 == 0.0 {
        return;
    }
    let lo = (l1 - l2).abs() * 1.001;
    let d = norm(sub(target, h)).clamp(lo, max_reach * (l1 + l2));
    let cur = (dot(v1, v2) / (l1 * l2)).clamp(-1.0, 1.0).acos();
    let want = ((l1 * l1 + l2 * l2 - d * d) / (2.0 * l1 * l2))
        .clamp(-1.0, 1.0)
        .acos();
    let c = cross(v1, v2);
    let n = if norm(c) > 1e-6 * l1 * l2 {
        let n = c.map(|v| v / norm(c));
        ws.knee_axis[side] = Some(n);
        n
    } else {
        ws.knee_axis[side].unwrap_or_else(|| rot::rotate(ws.world_q[knee], [1.0, 0.0, 0.0]))
    };
    let dk = rot::axis_angle(n, want - cur);
    turn_world(r, &mut ws.pose, &ws.world_q, knee, dk);
    let a2 = add(k, rot::rotate(dk, v2));
    let dh = rot::between(sub(a2, h), sub(target, h));
    turn_world(r, &mut ws.pose, &ws.world_q, hip, dh);
}

/// Writes the rotation channels of `ws.pose` into its row (Euler angles nearest the
/// previous frame's, or the reference frame's for the first).
fn write_angles(r: &Reference, ws: &mut PoseWorkspace) {
    let sk = &r.body.skeleton;
    let prev = ws
        .prev_angles
        .get_or_insert_with(|| r.motion.row(ws.pose.ref_frame).to_vec());
    for j in 0..sk.n_joints() {
        let ch = &sk.channels[j].rotations;
        if ch.len() == 3 && rot::is_tait_bryan(&r.axes[j]) {
            let axes = [r.axes[j][0], r.axes[j][1], r.axes[j][2]];
            let reference = [prev[ch[0].1], prev[ch[1].1], prev[ch[2].1]];
            let e = rot::to_euler(ws.pose.q[j], axes, reference);
            for n in 0..3 {
                ws.pose.row[ch[n].1] = e[n];
            }
        }
    }
    prev.copy_from_slice(&ws.pose.row);
}

/// The frames [`pose_motion`] writes for `path` at `frame_time_s`: the lead-in, then
/// `t_start..=t_end` (as a float: no overflow for any path or rate).
pub fn frame_count_f64(path: &ComPath, frame_time_s: f64) -> f64 {
    let dt = frame_time_s;
    (path.lead_in_s / dt + 1e-9).floor() + ((path.t_end - path.t_start) / dt + 1e-9).floor() + 1.0
}

fn frame_count(path: &ComPath, frame_time_s: f64) -> usize {
    frame_count_f64(path, frame_time_s) as usize
}

/// Poses every output frame `t = t_start + (i − n_lead)·Δt` of the plan (`frame_time_s` =
/// Δt, s: the source clip's own value unless `--fps`, so that the written `Frame Time` is
/// the source's; `n_lead = ⌊lead_in_s / Δt⌋` frames of lead-in: the recording before the first touchdown, [`Phase::Rest`]).
/// Two passes: every frame from the reference's posture (the posture solved where a support
/// leg falls short), then the frames whose solved posture, ramped in and out over
/// `opts.posture_ramp_s` ([`posture::envelope`]), differs, posed again with the ramped
/// posture and no further reach step. (A step on top of the ramped posture, where a leg was
/// still short, threw the least effective turn to its bound for single frames: root spikes
/// of 30–60 g on the CMU run at 4 m/s and the fixture jump 1.2 × higher.)
pub fn pose_motion(
    r: &Reference,
    path: &ComPath,
    src: &[StanceSource],
    opts: &EditOptions,
    frame_time_s: f64,
) -> EditedMotion {
    let dt = frame_time_s;
    let n_lead = (path.lead_in_s / dt + 1e-9).floor() as usize;
    let n = frame_count(path, dt);
    let nc = r.body.skeleton.n_channels;
    let mut ws = PoseWorkspace::new(r);
    let time = |i: usize| path.t_start + (i as f64 - n_lead as f64) * dt;
    let t_first = time(0);
    let mut poses = Vec::with_capacity(n);
    let mut frames = Vec::with_capacity(n);
    for i in 0..n {
        frames.push(pose_frame(r, path, src, opts, time(i), &mut ws, None));
        poses.push(ws.pose.clone());
    }
    let solved: Vec<Posture> = frames.iter().map(|f: &FramePose| f.posture).collect();
    let base = posture::envelope(&solved, dt, opts.posture_ramp_s);
    for i in (0..n).filter(|&i| base[i] != solved[i]) {
        frames[i] = pose_frame(r, path, src, opts, time(i), &mut ws, Some(&base[i]));
        poses[i].clone_from(&ws.pose);
    }
    let mut values = Vec::with_capacity(n * nc);
    for (i, (f, p)) in frames.iter_mut().zip(&poses).enumerate() {
        f.time_s = i as f64 * dt;
        f.window = f.window.map(|(td, lo)| (td - t_first, lo - t_first));
        ws.pose.clone_from(p);
        write_angles(r, &mut ws);
        values.extend_from_slice(&ws.pose.row);
    }
    EditedMotion {
        motion: Motion {
            frames_header: Some(n as u64),
            frame_time_s: dt,
            n_channels: nc,
            values,
        },
        frames,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Ankle 8 cm above the floor, toe tip 19 cm ahead on it, Z up, pivot axis +y.
    const TOE: V3 = [0.19, 0.0, 0.0];
    const U: V3 = [-0.19, 0.0, 0.08];
    const AXIS: V3 = [0.0, 1.0, 0.0];

    fn ankle_at(phi: f64) -> V3 {
        add(TOE, rot::rotate(rot::axis_angle(AXIS, phi), U))
    }

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

    #[test]
    fn toe_pivot_puts_the_ankle_at_the_reach_with_the_heel_up() {
        let hip = [0.0, 0.0, 0.98];
        for reach in [0.88, 0.85, 0.8] {
            let phi = pivot_angle(TOE, U, AXIS, hip, reach, 50f64.to_radians());
            let a = ankle_at(phi);
            // Closed form against the quaternion rotation: roundoff (1e-12 m).
            assert!((norm(sub(a, hip)) - reach).abs() < 1e-12, "reach {reach}");
            assert!(phi > 0.0 && a[2] > U[2], "heel up: φ {phi}, ankle {a:?}");
            // The first root: every smaller turn leaves the ankle out of reach.
            assert!(norm(sub(ankle_at(0.999 * phi), hip)) > reach);
        }
    }

    #[test]
    fn toe_pivot_out_of_range_turns_to_the_nearest_ankle_or_the_cap() {
        let hip = [0.0, 0.0, 0.98];
        let cap = 50f64.to_radians();
        // 0.3 m: no turn reaches; the nearest ankle position lies past the cap.
        assert_eq!(pivot_angle(TOE, U, AXIS, hip, 0.3, cap), cap);
        let phi = pivot_angle(TOE, U, AXIS, hip, 0.3, std::f64::consts::PI);
        let d = |p: f64| norm(sub(ankle_at(p), hip));
        // The nearest point of the circle (sampled at 0.001 rad around it).
        assert!(
            d(phi) <= d(phi - 1e-3) && d(phi) <= d(phi + 1e-3),
            "φ {phi}"
        );
    }
}
