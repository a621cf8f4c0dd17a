//! One output frame posed ([`pose_frame`]) and the whole edited motion ([`pose_motion`]):
//! the time-warped reference pose turned onto the planned heading, then feet, root and
//! posture iterated until the COM is the planned one.
//!
//! # Model
//! ```text
//! reference  stance k: t_src = td_k + (t − TD_k)·(lo_k − td_k)/(LO_k − TD_k)
//!            flight after k:   t_A = lo_k + (t − LO_k)·e_k⁺/E_k    (e, E: liftoff → apex,
//!            flight before k': t_B = td_k' − (TD_k' − t)·a_k'⁺/A_k' a, A: apex → touchdown;
//!            x⁺ = max(x, 0): a source apex inside its stance holds the edge pose;
//!            lower case source, upper case plan)
//!            q_j = slerp(q_j(t_A), q_j(t_B), w),  w = 3u² − 2u³,  u = (t − LO_k)/(TD_k' − LO_k)
//! heading    q_root ← yaw(Δψ)·q_root,  Δψ = ψ_plan − ψ_source (in flight each edge's root
//!            turned by its own Δψ, then slerped)
//! root       t_root ← t_root + to_file(c_plan − COM(q))  (COM is affine in t_root)
//!            repeat IK and root until |c_plan − COM| ≤ solve tol (10 µm), at most max_iterations
//! posture    a support leg short of its goal after the root shift: the pelvis turned under
//!            a still trunk by the damped least-squares step of edit::posture, inside the
//!            same iteration; pass 2 re-poses the frames whose ramped posture
//!            (posture::envelope) differs, with that posture and no further step
//! ```
//! Before the first touchdown (the lead-in) the frame is the recording's own pose at the
//! same time before its first stance's touchdown, placed as that stance is.
//!
//! # Frames and units
//! Plan times in s (output times from the first output frame in the result); COM and
//! reports in metres, internal Z-up frame; poses in file units and axes.

use super::goals::{anchored, foot_goal, smooth, FrameGoal};
use super::joints::{forward, up_file, write_angles, PoseWorkspace};
use super::reach::{place_feet, reach_update, ReachAt, ReachState};
use super::reference::{yaw_of, Reference, StanceSource};
use super::{EditedMotion, FramePose};
use crate::bvh::Motion;
use crate::edit::path::{ComPath, Phase};
use crate::edit::posture::{self, Kept, Posture, PostureFrame, POSTURE_ZERO};
use crate::edit::rotation as rot;
use crate::edit::EditOptions;
use crate::math::v3::{add, norm, sub, V3};

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
        // A jog's apex can lie inside its stance (`after_s < 0`): its pose then holds the
        // liftoff's instead of playing the stance backwards (the 2 m/s force-plate jog
        // edited to 5 m/s bent its landing knee from 20° to 81° and back in three frames
        // of flight, the root at 35 g).
        let rate = if e_new > 0.0 {
            s.after_s.max(0.0) / e_new
        } else {
            1.0
        };
        (lo, s.lo_clip_s + (t - lo) * rate)
    });
    let side_b = after.map(|a| {
        let (td, _) = st[a].contact_window();
        let b_new = td - st[a].t0;
        let s = src_of(a);
        let rate = if b_new > 0.0 {
            s.before_s.max(0.0) / b_new
        } else {
            1.0
        };
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

/// What one frame's root/IK iteration reached.
struct Solved {
    iterations: usize,
    err_m: f64,
    foot_err: f64,
    com_pose: V3,
    posture: Posture,
}

/// Poses one output time into `ws.pose` and returns the frame's outcome: with `fixed`
/// `None`, the posture ([`posture`]) is solved where a support leg falls short (the
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
        .then(|| posture_frame(r, ws, opts, &g.pulls));
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

/// The free pose's posture frame ([`PostureFrame`]): its hips, the world rotations of the
/// joints that keep them (the trunk; the hip of each leg by how little its foot is held,
/// `1 − pull`, from `pulls`) and the bound of `opts` (`ws` is left with FK of the free pose).
fn posture_frame(
    r: &Reference,
    ws: &mut PoseWorkspace,
    opts: &EditOptions,
    pulls: &[Option<(V3, rot::Quat, [f64; 2])>; 2],
) -> PostureFrame {
    ws.pose.q.copy_from_slice(&ws.free_q);
    forward(r, &ws.pose, &mut ws.world_q, &mut ws.file, &mut ws.pts);
    let kept = |joint: usize, weight: f64| {
        let parent = r.body.skeleton.parents[joint].map_or(rot::QUAT_IDENTITY, |p| ws.world_q[p]);
        Kept {
            joint,
            parent_world: parent,
            world: ws.world_q[joint],
            weight,
        }
    };
    let free_hip = |side: usize| {
        let held = pulls[side].map_or(0.0, |(_, _, pull)| pull[1].clamp(0.0, 1.0));
        (held < 1.0).then(|| kept(r.legs[side][0], 1.0 - held))
    };
    let kept = [r.trunk.map(|j| kept(j, 1.0)), free_hip(0), free_hip(1)];
    PostureFrame::new(
        [ws.file[r.legs[0][0]], ws.file[r.legs[1][0]]],
        up_file(&r.body),
        r.root,
        kept,
        opts.max_pelvis_turn_deg.to_radians(),
    )
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
