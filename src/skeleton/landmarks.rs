//! Body landmarks found structurally from the joint tree (spec com-from-bvh §4.2).
//!
//! # Model
//! ```text
//! AJC   sided joint with key "foot" or "ankle"          KJC = parent(AJC)   HJC = parent(KJC)
//! toe   first non-helper child of AJC keyed toebase/toe/toes/ball
//! WJC   sided joint keyed "wrist" or "hand" (nearer the root)   EJC = parent(WJC)  SJC = parent(EJC)
//! MET3  child keyed handmiddle1/middle1 → child with "finger" → end(WJC) → WJC + 0.32·(WJC − EJC)
//! head  unsided joint keyed "head";  CERV first root→head joint keyed neck*, else lowerneck, else parent(head)
//! VERT  end(head) or child keyed headtop, else head + (head − CERV)
//! no head joint: CERV = the neck joint nearest the root (keyed neck*, else lowerneck);
//!       VERT = CERV + 0.2907·L_leg·û, û = unit(top of the neck chain − CERV)
//!       (else unit(CERV − MIDH)); a warning, not an error
//! parent(·) skips helper joints and zero-length OFFSETs; end(·) is a non-degenerate End Site
//! (|OFFSET| ≥ 0.02·L_leg) or a child whose key ends in "end".
//! ```
//! The toe tip needs positions to be validated and is chosen in `ingest`, from the
//! candidates returned by [`Landmarks::toe_candidates`].
//!
//! # References
//! spec com-from-bvh §4.2, §4.3; README "Configuration files" (`[landmarks]` overrides).

use std::collections::BTreeMap;

use super::model::Skeleton;
use super::names::{normalise_all, NormName, Side};
use crate::error::{echo, Error, Result};

/// The landmark names a body file's `[landmarks]` table may map (README "Configuration
/// files"); any other key would be ignored, so the body file refuses it.
pub const LANDMARK_KEYS: [&str; 19] = [
    "AJC_L", "AJC_R", "KJC_L", "KJC_R", "HJC_L", "HJC_R", "toe_L", "toe_R", "WJC_L", "WJC_R",
    "EJC_L", "EJC_R", "SJC_L", "SJC_R", "MET3_L", "MET3_R", "head", "VERT", "CERV",
];

/// An End Site shorter than this fraction of `L_leg` counts as absent (spec §4.2).
pub const DEGENERATE_END_SITE_FRACTION: f64 = 0.02;
/// An End Site longer than this fraction of `L_leg` counts as absent too: no hand, toe or
/// head segment is that long. The MASS files' right hand has a 161.8-unit (1.6 m) End Site
/// where spec §4.2 assumed 0.9 units like the left hand's.
pub const IMPLAUSIBLE_END_SITE_FRACTION: f64 = 0.5;
/// MET3 extrapolation beyond the wrist along the forearm (spec §4.2).
pub const MET3_EXTRAPOLATION: f64 = 0.32;
/// Head length (vertex to the cervicale, C7) per metre of leg (`L_leg`, hip to ankle), for
/// a skeleton without a head joint. De Leva (1996) measured the head-and-neck segment from
/// the top of the head to C7 as 242.9 mm on his male reference subject of 1741 mm stature
/// (his trunk, C7 to the hip-joint midpoint, is 603.3 mm: the head is 0.40 of it); with the
/// stature from the leg as in spec com-from-bvh §4.3 (`H = 1.75 m·L_leg/0.84 m`) the head is
/// 0.1395·H = 0.2907·L_leg. The leg, not the trunk, sets the scale: skeletons put their
/// neck joint at different heights (the CMU neck joint sits at the top of its two spine
/// bones, so its "trunk" is half of de Leva's), while hip, knee and ankle centres are the
/// same anatomical points in every convention. Dimensionless.
pub const HEAD_PER_LEG_LENGTH: f64 = 242.9 / 1741.0 * 1.75 / 0.84;

/// A landmark position rule: a point, or a point extrapolated beyond another.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Landmark {
    /// FK point index (joint or End Site).
    Point(usize),
    /// `through + k·(through − from)`.
    Beyond {
        /// Start of the direction.
        from: usize,
        /// Point extrapolated beyond.
        through: usize,
        /// Extrapolation factor.
        k: f64,
    },
    /// A head top built from the neck chain (no head joint):
    /// `cerv + HEAD_PER_LEG_LENGTH·L_leg·û`, `û` = unit(`top` − `cerv`), or
    /// unit(`cerv` − `midh`) when `top` is `cerv` or coincides with it; `midh` is the
    /// midpoint of the two hip joints and `L_leg` the mean of the two legs' hip–knee plus
    /// knee–ankle lengths in the same frame (rigid bones: a constant).
    FromNeck {
        /// CERV.
        cerv: usize,
        /// Last joint of the neck chain above CERV (CERV itself when there is none).
        top: usize,
        /// Hip, knee and ankle of the left and the right leg.
        legs: [[usize; 3]; 2],
    },
}

impl Landmark {
    /// Position from a frame's points.
    pub fn at(&self, pts: &[[f64; 3]]) -> [f64; 3] {
        match *self {
            Landmark::Point(p) => pts[p],
            Landmark::Beyond { from, through, k } => {
                std::array::from_fn(|a| pts[through][a] + k * (pts[through][a] - pts[from][a]))
            }
            Landmark::FromNeck { cerv, top, legs } => {
                let c = pts[cerv];
                let [hl, hr] = [legs[0][0], legs[1][0]];
                let midh: [f64; 3] = std::array::from_fn(|a| 0.5 * (pts[hl][a] + pts[hr][a]));
                let trunk: [f64; 3] = std::array::from_fn(|a| c[a] - midh[a]);
                let neck: [f64; 3] = std::array::from_fn(|a| pts[top][a] - c[a]);
                let len = HEAD_PER_LEG_LENGTH * leg_length(pts, legs);
                let dir = if len3(&neck) > 0.0 { neck } else { trunk };
                let d = len3(&dir);
                if d > 0.0 {
                    std::array::from_fn(|a| c[a] + len * dir[a] / d)
                } else {
                    c
                }
            }
        }
    }
}

/// Arm landmarks of one side.
#[derive(Debug, Clone, PartialEq)]
pub struct Arm {
    /// SJC joint.
    pub shoulder: usize,
    /// EJC joint.
    pub elbow: usize,
    /// WJC joint.
    pub wrist: usize,
    /// MET3 rule.
    pub met3: Landmark,
}

/// Leg and arm landmarks of one side.
#[derive(Debug, Clone, PartialEq)]
pub struct Limb {
    /// HJC joint.
    pub hip: usize,
    /// KJC joint.
    pub knee: usize,
    /// AJC joint.
    pub ankle: usize,
    /// Toe joint, when the foot has one.
    pub toe_joint: Option<usize>,
    /// The toe joint's "end" (live End Site or `*end` child), when it has one.
    pub toe_end: Option<usize>,
    /// The ankle's "end", when the ankle has no toe joint.
    pub ankle_end: Option<usize>,
    /// Arm, when the skeleton has one on this side.
    pub arm: Option<Arm>,
}

/// Every landmark the COM model and the contact detector need.
#[derive(Debug, Clone, PartialEq)]
pub struct Landmarks {
    /// Left limbs.
    pub left: Limb,
    /// Right limbs.
    pub right: Limb,
    /// Head joint.
    pub head: usize,
    /// CERV (neck base) joint.
    pub cerv: usize,
    /// VERT (head top) rule.
    pub vert: Landmark,
    /// The skeleton has no head joint: `head` is the top of the neck chain and `vert` is
    /// [`Landmark::FromNeck`] (a warning in `clips.parquet`).
    pub head_from_neck: bool,
}

/// Which toe-tip candidate a foot uses (spec §4.3).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ToeTipRule {
    /// The toe joint's End Site.
    ToeEnd,
    /// The toe joint itself.
    ToeJoint,
    /// The ankle's End Site.
    AnkleEnd,
    /// A virtual point ahead of and below the ankle.
    Fallback,
}

impl ToeTipRule {
    /// Name used in `clips.parquet`.
    pub fn as_str(self) -> &'static str {
        match self {
            ToeTipRule::ToeEnd => "toe_end",
            ToeTipRule::ToeJoint => "toe_joint",
            ToeTipRule::AnkleEnd => "ankle_end",
            ToeTipRule::Fallback => "fallback",
        }
    }
}

impl Landmarks {
    /// The limb of a side.
    pub fn limb(&self, s: Side) -> &Limb {
        match s {
            Side::L => &self.left,
            Side::R => &self.right,
        }
    }

    /// Ordered toe-tip point candidates of a foot (rows 1–3 of spec §4.3; the fallback is
    /// implicit). `min_end_len` is the degenerate End Site length in file units.
    pub fn toe_candidates(&self, s: Side) -> Vec<(ToeTipRule, usize)> {
        let limb = self.limb(s);
        let mut c = Vec::new();
        if let Some(t) = limb.toe_joint {
            if let Some(e) = limb.toe_end {
                c.push((ToeTipRule::ToeEnd, e));
            }
            c.push((ToeTipRule::ToeJoint, t));
        } else if let Some(e) = limb.ankle_end {
            c.push((ToeTipRule::AnkleEnd, e));
        }
        c
    }

    /// `landmark=joint` pairs, `;`-separated (the `skeleton` column of `clips.parquet`).
    pub fn describe(&self, skel: &Skeleton) -> String {
        let n = |p: usize| skel.point_name(p);
        let lm = |l: &Landmark| match *l {
            Landmark::Point(p) => n(p),
            Landmark::Beyond { from, through, k } => {
                format!("{}+{k}*({}-{})", n(through), n(through), n(from))
            }
            Landmark::FromNeck { cerv, top, .. } => {
                format!(
                    "{}+{HEAD_PER_LEG_LENGTH:.4}*L_leg*dir({}-{})",
                    n(cerv),
                    n(top),
                    n(cerv)
                )
            }
        };
        let mut parts = Vec::new();
        for (tag, limb) in [("L", &self.left), ("R", &self.right)] {
            parts.push(format!("HJC_{tag}={}", n(limb.hip)));
            parts.push(format!("KJC_{tag}={}", n(limb.knee)));
            parts.push(format!("AJC_{tag}={}", n(limb.ankle)));
            if let Some(t) = limb.toe_joint {
                parts.push(format!("toe_{tag}={}", n(t)));
            }
            if let Some(a) = &limb.arm {
                parts.push(format!("SJC_{tag}={}", n(a.shoulder)));
                parts.push(format!("EJC_{tag}={}", n(a.elbow)));
                parts.push(format!("WJC_{tag}={}", n(a.wrist)));
                parts.push(format!("MET3_{tag}={}", lm(&a.met3)));
            }
        }
        if self.head_from_neck {
            parts.push("head=none".to_string());
        } else {
            parts.push(format!("head={}", n(self.head)));
        }
        parts.push(format!("CERV={}", n(self.cerv)));
        parts.push(format!("VERT={}", lm(&self.vert)));
        parts.join(";")
    }
}

fn len3(v: &[f64; 3]) -> f64 {
    (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt()
}

/// Point index of joint `j`'s End Site when it is not degenerate.
fn live_end_site(skel: &Skeleton, j: usize, min_len: f64) -> Option<usize> {
    let e = skel.end_sites.iter().position(|(k, _)| *k == j)?;
    let len = len3(&skel.end_sites[e].1);
    let max_len = min_len * IMPLAUSIBLE_END_SITE_FRACTION / DEGENERATE_END_SITE_FRACTION;
    (len >= min_len && len <= max_len).then_some(skel.n_joints() + e)
}

/// Result of the structural mapping.
// Built once per clip; boxing the large variant buys nothing.
#[allow(clippy::large_enum_variant)]
#[derive(Debug, Clone, PartialEq)]
pub enum Mapping {
    /// Every required landmark was found.
    Found(Landmarks),
    /// No landmark at all: the file is not a body (`skipped`).
    NotABody,
}

struct Finder<'a> {
    skel: &'a Skeleton,
    names: Vec<NormName>,
    /// Depth of each joint (root 1), computed once: parents come before children.
    depths: Vec<usize>,
    overrides: &'a BTreeMap<String, String>,
}

impl Finder<'_> {
    fn is_helper(&self, j: usize) -> bool {
        self.names[j].is_helper()
    }

    /// Parent that skips helper joints and zero-length OFFSETs.
    fn parent(&self, j: usize) -> Option<usize> {
        let mut p = self.skel.parents[j]?;
        while self.is_helper(p) || len3(&self.skel.offsets[p]) == 0.0 {
            match self.skel.parents[p] {
                Some(pp) => p = pp,
                None => break,
            }
        }
        Some(p)
    }

    fn depth(&self, j: usize) -> usize {
        self.depths[j]
    }

    fn overridden(&self, key: &str) -> Result<Option<usize>> {
        let Some(name) = self.overrides.get(key) else {
            return Ok(None);
        };
        (0..self.skel.n_points())
            .find(|&p| self.skel.point_name(p) == *name)
            .map(Some)
            .ok_or_else(|| {
                Error::skeleton(format!(
                    "[landmarks] {key} = '{}': no such joint",
                    echo(name)
                ))
            })
    }

    fn sided(&self, side: Side, keys: &[&str]) -> Vec<usize> {
        (0..self.skel.n_joints())
            .filter(|&j| {
                !self.is_helper(j)
                    && self.names[j].side == Some(side)
                    && keys.contains(&self.names[j].key.as_str())
            })
            .collect()
    }

    /// The joint's "end": a non-degenerate End Site, or a child keyed `*end`.
    fn end_of(&self, j: usize, min_len: f64) -> Option<usize> {
        live_end_site(self.skel, j, min_len).or_else(|| {
            self.skel
                .children(j)
                .find(|&c| self.names[c].key.ends_with("end"))
        })
    }

    fn pick(&self, key: String, default: Option<usize>) -> Result<Option<usize>> {
        Ok(self.overridden(&key)?.or(default))
    }

    fn leg(&self, s: Side, tag: &str) -> Result<[Option<usize>; 3]> {
        let ankle = self.pick(
            format!("AJC_{tag}"),
            self.sided(s, &["foot", "ankle"]).first().copied(),
        )?;
        let knee = self.pick(format!("KJC_{tag}"), ankle.and_then(|a| self.parent(a)))?;
        let hip = self.pick(format!("HJC_{tag}"), knee.and_then(|k| self.parent(k)))?;
        Ok([hip, knee, ankle])
    }

    fn toe(&self, ankle: usize, tag: &str) -> Result<Option<usize>> {
        let keys = ["toebase", "toe", "toes", "ball"];
        let default = self
            .skel
            .children(ankle)
            .find(|&c| !self.is_helper(c) && keys.contains(&self.names[c].key.as_str()));
        self.pick(format!("toe_{tag}"), default)
    }

    fn arm(&self, s: Side, tag: &str, min_len: f64) -> Result<Option<Arm>> {
        let mut wrists = self.sided(s, &["wrist", "hand"]);
        wrists.sort_by_key(|&w| self.depth(w));
        let Some(wrist) = self.pick(format!("WJC_{tag}"), wrists.first().copied())? else {
            return Ok(None);
        };
        let Some(elbow) = self.pick(format!("EJC_{tag}"), self.parent(wrist))? else {
            return Ok(None);
        };
        let Some(shoulder) = self.pick(format!("SJC_{tag}"), self.parent(elbow))? else {
            return Ok(None);
        };
        let child = |pred: &dyn Fn(&str) -> bool| {
            self.skel
                .children(wrist)
                .find(|&c| pred(&self.names[c].key))
        };
        let met3 = match self.overridden(&format!("MET3_{tag}"))? {
            Some(p) => Landmark::Point(p),
            None => child(&|k| k == "handmiddle1" || k == "middle1")
                .or_else(|| child(&|k| k.contains("finger")))
                .or_else(|| self.end_of(wrist, min_len))
                .map(Landmark::Point)
                .unwrap_or(Landmark::Beyond {
                    from: elbow,
                    through: wrist,
                    k: MET3_EXTRAPOLATION,
                }),
        };
        Ok(Some(Arm {
            shoulder,
            elbow,
            wrist,
            met3,
        }))
    }

    fn head(&self) -> Result<Option<usize>> {
        let default = (0..self.skel.n_joints()).find(|&j| {
            self.names[j].side.is_none() && self.names[j].key == "head" && !self.is_helper(j)
        });
        self.pick("head".into(), default)
    }

    fn cerv(&self, head: usize) -> Result<usize> {
        let mut path: Vec<usize> =
            std::iter::successors(Some(head), |&k| self.skel.parents[k]).collect();
        path.reverse();
        // A `neck*` joint wins over `lowerneck`: the CMU 3dsmax chain has both
        // (`lowerneck` → `Neck` → `Head`), and the spec's convention table and measured
        // figures (cmu_131_01 ā_z = −4.8, cmu_131_03 a_z = −8.68) use `Neck`; ASF files
        // have only `lowerneck`.
        let first =
            |pred: &dyn Fn(&str) -> bool| path.iter().copied().find(|&j| pred(&self.names[j].key));
        let default = first(&|k| k.starts_with("neck"))
            .or_else(|| first(&|k| k == "lowerneck"))
            .or_else(|| self.parent(head))
            .unwrap_or(head);
        Ok(self.overridden("CERV")?.unwrap_or(default))
    }
}

/// Joint names shown in a mapping error: at most this many, then a count of the rest.
const MAX_LISTED_JOINTS: usize = 40;

/// The joint names, escaped, the first [`MAX_LISTED_JOINTS`] of them and a count of the rest.
fn joint_list(names: &[String]) -> String {
    let mut shown: Vec<String> = names
        .iter()
        .take(MAX_LISTED_JOINTS)
        .map(|n| echo(n))
        .collect();
    if names.len() > MAX_LISTED_JOINTS {
        shown.push(format!("… and {} more", names.len() - MAX_LISTED_JOINTS));
    }
    shown.join(", ")
}

impl Finder<'_> {
    /// Without a head joint: the neck chain, from its base (CERV: the unsided joint keyed
    /// `neck*`, else `lowerneck`, nearest the root; a `[landmarks]` CERV wins) up through
    /// unsided non-helper children whose key contains `neck`. `(CERV, top of the chain)`.
    fn neck_chain(&self) -> Result<Option<(usize, usize)>> {
        let unsided = |j: usize, pred: &dyn Fn(&str) -> bool| {
            self.names[j].side.is_none() && !self.is_helper(j) && pred(&self.names[j].key)
        };
        let nearest = |pred: &dyn Fn(&str) -> bool| {
            (0..self.skel.n_joints())
                .filter(|&j| unsided(j, pred))
                .min_by_key(|&j| self.depth(j))
        };
        let default =
            nearest(&|k| k.starts_with("neck")).or_else(|| nearest(&|k| k == "lowerneck"));
        let Some(cerv) = self.overridden("CERV")?.or(default) else {
            return Ok(None);
        };
        // A [landmarks] CERV may name an End Site, which has no children.
        let mut top = cerv;
        while top < self.skel.n_joints() {
            match self
                .skel
                .children(top)
                .find(|&c| unsided(c, &|k| k.contains("neck")))
            {
                Some(c) => top = c,
                None => break,
            }
        }
        Ok(Some((cerv, top)))
    }
}

/// Leg length in the rest pose, file units: `|KJC − HJC| + |AJC − KJC|`, averaged over the
/// two sides (spec com-from-bvh §3.1).
pub fn leg_length(rest: &[[f64; 3]], legs: [[usize; 3]; 2]) -> f64 {
    let d = |a: usize, b: usize| len3(&std::array::from_fn(|k| rest[a][k] - rest[b][k]));
    legs.iter()
        .map(|[h, k, a]| d(*k, *h) + d(*a, *k))
        .sum::<f64>()
        / 2.0
}

/// Map a skeleton onto landmarks. `rest` is the rest pose (file units), used for the leg
/// length that sets the degenerate End Site length. `overrides` maps landmark names
/// (`AJC_L`, …, `head`, `VERT`, `CERV`) to point names and wins over the rules.
///
/// # Errors
/// A partial mapping: the message lists the required landmarks not found and the joints
/// tried.
pub fn map(
    skel: &Skeleton,
    rest: &[[f64; 3]],
    overrides: &BTreeMap<String, String>,
) -> Result<Mapping> {
    let mut depths: Vec<usize> = Vec::with_capacity(skel.n_joints());
    for p in &skel.parents {
        // parents[j] < j (file order), so the parent's depth is known.
        let d = p.and_then(|p| depths.get(p)).map_or(1, |d| d + 1);
        depths.push(d);
    }
    let f = Finder {
        skel,
        names: normalise_all(&skel.names),
        depths,
        overrides,
    };
    let legs = [f.leg(Side::L, "L")?, f.leg(Side::R, "R")?];
    let head = f.head()?;
    // No head joint: the neck chain stands in for it (a warning, not an error).
    let neck = if head.is_none() {
        f.neck_chain()?
    } else {
        None
    };
    let mut missing = Vec::new();
    for (tag, leg) in ["L", "R"].iter().zip(&legs) {
        for (name, v) in ["HJC", "KJC", "AJC"].iter().zip(leg) {
            if v.is_none() {
                missing.push(format!("{name}_{tag}"));
            }
        }
    }
    if head.is_none() && neck.is_none() {
        missing.push("head".to_string());
    }
    if missing.len() == 7 {
        return Ok(Mapping::NotABody);
    }
    if !missing.is_empty() {
        return Err(Error::skeleton(format!(
            "could not map landmarks {} (joints tried: {})",
            missing.join(", "),
            joint_list(&skel.names)
        )));
    }
    let leg_idx = legs.map(|l| l.map(|v| v.unwrap_or(0)));
    let min_len = DEGENERATE_END_SITE_FRACTION * leg_length(rest, leg_idx);
    let (head, cerv, vert_default) = match (head, neck) {
        (Some(h), _) => (h, f.cerv(h)?, None),
        (None, Some((cerv, top))) => (
            top,
            cerv,
            Some(Landmark::FromNeck {
                cerv,
                top,
                legs: leg_idx,
            }),
        ),
        (None, None) => (0, 0, None), // unreachable: reported as missing above
    };
    let head_from_neck = vert_default.is_some();
    let vert = match f.overridden("VERT")? {
        Some(p) => Landmark::Point(p),
        None if head_from_neck => vert_default.unwrap_or(Landmark::Point(cerv)),
        None => f
            .end_of(head, min_len)
            .or_else(|| skel.children(head).find(|&c| f.names[c].key == "headtop"))
            .map(Landmark::Point)
            .unwrap_or(Landmark::Beyond {
                from: cerv,
                through: head,
                k: 1.0,
            }),
    };
    let limb = |s: Side, tag: &str, [hip, knee, ankle]: [usize; 3]| -> Result<Limb> {
        let toe_joint = f.toe(ankle, tag)?;
        Ok(Limb {
            hip,
            knee,
            ankle,
            toe_joint,
            toe_end: toe_joint.and_then(|t| f.end_of(t, min_len)),
            ankle_end: toe_joint
                .is_none()
                .then(|| f.end_of(ankle, min_len))
                .flatten(),
            arm: f.arm(s, tag, min_len)?,
        })
    };
    Ok(Mapping::Found(Landmarks {
        left: limb(Side::L, "L", leg_idx[0])?,
        right: limb(Side::R, "R", leg_idx[1])?,
        head,
        cerv,
        vert,
        head_from_neck,
    }))
}
