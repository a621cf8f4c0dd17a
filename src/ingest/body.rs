//! The body model of one clip, frozen: skeleton, landmarks, unit, up axis and toe-tip
//! rules, so that the COM of any new pose of the same skeleton is computed exactly as the
//! ingest computes it for the clip's own frames (the `edit` stage places poses with it).
//!
//! # Model
//! ```text
//! points(q) = scale · up(FK(q))                       metres, Z up (as the ingest)
//! COM(q)    = de Leva(landmarks(points(q)), toe tips)  toe rule chosen on the source clip
//! root translation t → t + d (file units)  ⇒  COM → COM + scale · up(d)   (affine)
//! ```
//!
//! # Frames and units
//! FK in file units and axes; [`BodyModel::points`] and [`BodyModel::com`] in metres,
//! internal Z-up frame.

use std::collections::BTreeMap;

use super::points::{choose_toe, facing, fk_frames, side_points, toe_tip};
use crate::bvh::Bvh;
use crate::error::{Error, Result};
use crate::skeleton::com::{com, BodyPoints, Sex};
use crate::skeleton::landmarks::{self, leg_length, Landmarks, Mapping};
use crate::skeleton::names::Side;
use crate::skeleton::units::UpAxis;
use crate::skeleton::{fk, leadin, Skeleton};

use crate::math::v3::V3;

/// One clip's body, frozen for posing (see the module docs).
#[derive(Debug, Clone)]
pub struct BodyModel {
    /// The joint tree.
    pub skeleton: Skeleton,
    /// Body landmarks (point indices).
    pub landmarks: Landmarks,
    /// Metres per file unit.
    pub unit_m: f64,
    /// The file's up axis.
    pub up: UpAxis,
    /// Toe-tip point per side (left, right); `None`: the fallback ahead of the ankle.
    pub toe: [Option<usize>; 2],
    /// Leg length, m.
    pub leg_m: f64,
    /// de Leva column.
    pub sex: Sex,
    /// Lead-in rows of the source clip (not poses).
    pub leadin: usize,
}

impl BodyModel {
    /// The body of a parsed clip with a known unit and up axis (as `clips.parquet` records
    /// them), de Leva column `sex` and landmark overrides `landmarks` (as the library's
    /// manifest records them); the toe rules are chosen on the clip's frames as the ingest
    /// chooses them.
    ///
    /// # Errors
    /// More point samples than [`super::MAX_POINT_SAMPLES`] (`ErrorKind::Cap`); the
    /// skeleton maps onto no body (`ErrorKind::Skeleton`).
    pub fn new(
        bvh: &Bvh,
        unit_m: f64,
        up: UpAxis,
        sex: Sex,
        landmarks: &BTreeMap<String, String>,
    ) -> Result<BodyModel> {
        let skel = Skeleton::from_bvh(bvh);
        super::check_point_samples(skel.n_points(), bvh.motion.n_frames())?;
        let rest_file = fk::rest_pose(&skel);
        let lm = match landmarks::map(&skel, &rest_file, landmarks)? {
            Mapping::Found(lm) => lm,
            Mapping::NotABody => return Err(Error::skeleton("no body landmark found")),
        };
        let skip = leadin::leadin_frames(&skel, &bvh.motion);
        let to_int = |p: V3| up.to_internal(p).map(|v| v * unit_m);
        let mut pts = fk_frames(&skel, bvh, skip);
        pts.iter_mut().for_each(|p| *p = to_int(*p));
        let rest: Vec<V3> = rest_file.iter().map(|p| to_int(*p)).collect();
        let np = skel.n_points();
        let frames: Vec<&[V3]> = pts.chunks_exact(np).collect();
        let fwd: Vec<V3> = frames
            .iter()
            .map(|fp| facing(fp[lm.left.hip], fp[lm.right.hip]))
            .collect();
        let toe = [Side::L, Side::R].map(|s| choose_toe(&lm, s, &rest, &frames, &fwd).1);
        let legs = [
            [lm.left.hip, lm.left.knee, lm.left.ankle],
            [lm.right.hip, lm.right.knee, lm.right.ankle],
        ];
        let leg_m = leg_length(&rest, legs);
        Ok(BodyModel {
            skeleton: skel,
            landmarks: lm,
            unit_m,
            up,
            toe,
            leg_m,
            sex,
            leadin: skip,
        })
    }

    /// A file-frame vector in metres, Z up.
    pub fn to_internal(&self, p: V3) -> V3 {
        self.up.to_internal(p).map(|v| v * self.unit_m)
    }

    /// An internal vector (metres, Z up) in file units and axes: the inverse of
    /// [`Self::to_internal`] (the axis map is a signed permutation).
    pub fn to_file(&self, v: V3) -> V3 {
        std::array::from_fn(|k| {
            let mut e = [0.0; 3];
            e[k] = 1.0;
            let c = self.up.to_internal(e);
            (c[0] * v[0] + c[1] * v[1] + c[2] * v[2]) / self.unit_m
        })
    }

    /// Every joint and End Site of a motion row: `file` in file units (FK), `out` in metres,
    /// Z up (both len = `skeleton.n_points()`).
    pub fn points(&self, ws: &mut fk::FkWorkspace, row: &[f64], file: &mut [V3], out: &mut [V3]) {
        fk::forward(&self.skeleton, ws, row, file);
        for (o, p) in out.iter_mut().zip(file.iter()) {
            *o = self.to_internal(*p);
        }
    }

    /// The toe tips (left, right) of a frame's points (metres, Z up).
    pub fn toe_tips(&self, pts: &[V3]) -> [V3; 2] {
        let lm = &self.landmarks;
        let fwd = facing(pts[lm.left.hip], pts[lm.right.hip]);
        [(0, &lm.left), (1, &lm.right)]
            .map(|(k, l)| toe_tip(self.toe[k], pts, l.ankle, fwd, self.leg_m))
    }

    /// Whole-body COM of a frame's points (metres, Z up), as the ingest computes it.
    pub fn com(&self, pts: &[V3]) -> V3 {
        let lm = &self.landmarks;
        let toe = self.toe_tips(pts);
        let b = BodyPoints {
            vert: lm.vert.at(pts),
            cerv: pts[lm.cerv],
            left: side_points(&lm.left, pts, toe[0]),
            right: side_points(&lm.right, pts, toe[1]),
        };
        com(&b, self.sex)
    }
}
