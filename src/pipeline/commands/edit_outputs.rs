//! What an edit writes besides the BVH: the plan table `FILE.plan.parquet` (one row per
//! output frame, columns in [`crate::library::codec::schema::edit_plan`]) and the plot data of
//! `FILE.png` (planned COM path, footprints, [`PLOT_POSES`] sampled poses, the body's
//! facing and the verdicts).

use std::path::{Path, PathBuf};

use polars::prelude::{Column, DataFrame, PolarsResult};

use crate::bvh::Bvh;
use crate::edit::fidelity::{Fidelity, Gauge};
use crate::edit::path::Phase;
use crate::edit::plan::EditStance;
use crate::edit::pose::{EditedMotion, Reference};
use crate::library::codec::schema::edit_plan as col;
use crate::plot::edit::{EditPlot, Pose};
use crate::skeleton::fk::FkWorkspace;

/// Stick figures in the plot: this many poses, evenly spread over the output frames
/// (first and last included), so that they stand apart along the direction of travel.
pub const PLOT_POSES: usize = 6;

/// Everything an edit computes before anything is written.
pub struct EditOutputs {
    /// The source clip (scaled to the character), whose hierarchy is written.
    pub bvh: Bvh,
    /// The posed frames.
    pub edited: EditedMotion,
    /// The reference the poses came from.
    pub reference: Reference,
    /// The solved stances.
    pub stances: Vec<EditStance>,
    /// The stances in play order (indices into `stances`).
    pub order: Vec<usize>,
    /// Planned contact point of every placed stance, m.
    pub footprints: Vec<[f64; 3]>,
    /// `<stance_id>: <constraint> <value> > <limit> (by <margin>)` of every stance that
    /// breaks one (`query::tables::violation_detail`).
    pub violated: Vec<String>,
    /// Posture and smoothness against the source ([`crate::edit::fidelity`]), its swing
    /// knees folded by the speed law.
    pub fidelity: Fidelity,
    /// The swing knee fold of a run ([`crate::edit::swing`]; nothing for a jump).
    pub swing: crate::edit::swing::FoldReport,
    /// The contacts a run moved for its legs to reach ([`crate::edit::footing`]; none for
    /// a jump).
    pub footing: crate::edit::footing::Footing,
}

/// The sidecar paths of `FILE.bvh`: `FILE.plan.parquet`, `FILE.png`.
pub fn sidecars(out: &Path) -> (PathBuf, PathBuf) {
    (
        out.with_extension(col::EXTENSION),
        out.with_extension(col::PLOT_EXTENSION),
    )
}

/// The three columns of the 3-vector `prefix`, each frame's value from `g` (null: `None`).
fn v3_columns(prefix: &str, n: usize, g: impl Fn(usize) -> Option<[f64; 3]>) -> Vec<Column> {
    (0..3)
        .map(|a| {
            let v: Vec<Option<f64>> = (0..n).map(|i| g(i).map(|p| p[a])).collect();
            Column::new(col::axis_column(prefix, a).into(), v)
        })
        .collect()
}

/// The plan table: one row per output frame (see the module docs).
///
/// # Errors
/// A column cannot be built.
pub fn plan_table(e: &EditOutputs) -> PolarsResult<DataFrame> {
    let f = &e.edited.frames;
    let stance = |p: &Phase| match p {
        Phase::Stance(k) => Some(&e.stances[e.order[*k]]),
        Phase::Flight { .. } | Phase::Rest => None,
    };
    let dt = e.edited.motion.frame_time_s;
    let phase = |p: &Phase| match p {
        Phase::Stance(_) => "stance",
        Phase::Flight { .. } => "flight",
        Phase::Rest => "rest",
    };
    let mut cols = vec![
        Column::new(
            col::TIME.into(),
            (0..f.len()).map(|i| i as f64 * dt).collect::<Vec<_>>(),
        ),
        Column::new(
            col::PHASE.into(),
            f.iter().map(|x| phase(&x.phase)).collect::<Vec<_>>(),
        ),
        Column::new(
            col::STANCE_ID.into(),
            f.iter()
                .map(|x| stance(&x.phase).map(|s| s.source.stance_id.clone()))
                .collect::<Vec<_>>(),
        ),
    ];
    cols.extend(v3_columns(col::COM, f.len(), |i| Some(f[i].com_plan)));
    cols.extend(v3_columns(col::POSE_COM, f.len(), |i| Some(f[i].com_pose)));
    cols.extend(v3_columns(col::CONTACT, f.len(), |i| f[i].contact));
    cols.extend(v3_columns(col::FOOT, f.len(), |i| f[i].foot));
    for (name, end) in [(col::STANCE_TD, 0), (col::STANCE_LO, 1)] {
        let v: Vec<Option<f64>> = f
            .iter()
            .map(|x| x.window.map(|w| if end == 0 { w.0 } else { w.1 }))
            .collect();
        cols.push(Column::new(name.into(), v));
    }
    cols.push(Column::new(
        col::CONVERGED.into(),
        f.iter().map(|x| x.converged).collect::<Vec<_>>(),
    ));
    cols.push(Column::new(
        col::FOOT_ERROR.into(),
        f.iter().map(|x| x.foot_error_m).collect::<Vec<_>>(),
    ));
    cols.push(Column::new(
        col::ITERATIONS.into(),
        f.iter().map(|x| x.iterations as i64).collect::<Vec<_>>(),
    ));
    cols.push(Column::new(
        col::VIOLATED.into(),
        f.iter()
            .map(|x| stance(&x.phase).and_then(EditStance::violated))
            .collect::<Vec<_>>(),
    ));
    let bound = crate::edit::DEFAULT_MAX_PELVIS_TURN_DEG;
    for (d, name) in col::PELVIS_TURN.iter().enumerate() {
        cols.push(Column::new(
            (*name).into(),
            f.iter().map(|x| x.posture[d] * bound).collect::<Vec<_>>(),
        ));
    }
    cols.push(Column::new(
        col::SOURCE_TIME.into(),
        f.iter().map(|x| x.source_time_s).collect::<Vec<_>>(),
    ));
    let g = &e.fidelity.frames;
    let gauge = |name: &str, v: &dyn Fn(&Gauge) -> f64| {
        Column::new(name.into(), g.iter().map(v).collect::<Vec<_>>())
    };
    cols.push(gauge(col::TRUNK_LEAN, &|g| g.lean_deg));
    cols.push(gauge(col::KNEE_LEFT, &|g| g.knee_deg[0]));
    cols.push(gauge(col::KNEE_RIGHT, &|g| g.knee_deg[1]));
    cols.push(gauge(col::ROOT_ACCEL, &|g| g.root_accel_mps2));
    DataFrame::new_infer_height(cols)
}

/// The plot of an edit: the planned COM, the footprints, [`PLOT_POSES`] sampled poses,
/// the body's mean facing (from the hips) and the verdicts.
pub fn plot_of(e: &EditOutputs, title: String) -> EditPlot {
    let body = &e.reference.body;
    let sk = &body.skeleton;
    let m = &e.edited.motion;
    let n = m.n_frames();
    let mut ws = FkWorkspace::new(sk);
    let (mut file, mut pts) = (vec![[0.0; 3]; sk.n_points()], vec![[0.0; 3]; sk.n_points()]);
    let mut frames: Vec<usize> = (0..PLOT_POSES.min(n))
        .map(|k| (k * n.saturating_sub(1)) / (PLOT_POSES - 1).max(1))
        .collect();
    frames.dedup();
    let mut poses = Vec::with_capacity(frames.len());
    let mut facing = [0.0; 2];
    for fr in frames {
        body.points(&mut ws, m.row(fr), &mut file, &mut pts);
        let mut bones = Vec::new();
        for j in 0..sk.n_joints() {
            if let Some(p) = sk.parents[j] {
                bones.push([pts[p], pts[j]]);
            }
        }
        for (e_i, (j, _)) in sk.end_sites.iter().enumerate() {
            bones.push([pts[*j], pts[sk.n_joints() + e_i]]);
        }
        // Forward = (left hip − right hip) × up, horizontal.
        let (l, r) = (pts[body.landmarks.left.hip], pts[body.landmarks.right.hip]);
        facing = [facing[0] + (l[1] - r[1]), facing[1] - (l[0] - r[0])];
        poses.push(Pose {
            time_s: fr as f64 * m.frame_time_s,
            bones,
        });
    }
    let norm = facing[0].hypot(facing[1]);
    EditPlot {
        title,
        com: e.edited.frames.iter().map(|f| f.com_plan).collect(),
        footprints: e.footprints.clone(),
        poses,
        facing: (norm > 1e-9).then(|| [facing[0] / norm, facing[1] / norm]),
        violated: e.violated.clone(),
        n_frames: e.edited.frames.len(),
        frame_time_s: m.frame_time_s,
        unconverged: e.edited.frames.iter().filter(|f| !f.converged).count(),
    }
}
