//! The immutable skeleton model: flat arrays in topological order (`parent[i] < i`), with
//! each joint's rotation channels and translation rule.
//!
//! # Model
//! ```text
//! R_j^local = R_a1(θ1) · R_a2(θ2) · R_a3(θ3)     rotation channels in the order listed
//! t_j^local = OFFSET_j                           no position channels
//!           = channels (per coordinate)          root: position channels replace OFFSET
//!           = OFFSET_j + channels                non-root "delta" joints
//!           = channels (OFFSET where absent)     non-root "replace" joints
//! non-root rule, decided once per clip: delta  ⇔  median_f |channel translation| < ½·|OFFSET|
//! ```
//! Points are the joints `0..n_joints` followed by the End Sites in joint order.
//!
//! # References
//! spec com-from-bvh §2 (conventions, root replacement, delta/replace rule, rest pose).

use crate::bvh::Bvh;
use crate::math::stats::median;

/// How a joint's position channels combine with its OFFSET.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum TranslationMode {
    /// No position channels: `t = OFFSET`.
    Offset,
    /// Channels replace the OFFSET per coordinate that has a channel.
    Replace,
    /// Channels are added to the OFFSET.
    Delta,
}

/// Channel layout of one joint.
#[derive(Debug, Clone, PartialEq)]
pub struct JointChannels {
    /// Rotation channels in the order listed: (axis 0/1/2, index in the motion row).
    pub rotations: Vec<(usize, usize)>,
    /// Position channel index per file axis, when present.
    pub translations: [Option<usize>; 3],
    /// How the position channels are applied.
    pub mode: TranslationMode,
}

/// The skeleton: immutable, shared by reference across threads.
#[derive(Debug, Clone, PartialEq)]
pub struct Skeleton {
    /// Joint names as written in the file.
    pub names: Vec<String>,
    /// Parent index per joint (`None` for the root); `parents[i] < i`.
    pub parents: Vec<Option<usize>>,
    /// OFFSET per joint, file units.
    pub offsets: Vec<[f64; 3]>,
    /// Channel layout per joint.
    pub channels: Vec<JointChannels>,
    /// End Sites: (joint, OFFSET in file units), in joint order.
    pub end_sites: Vec<(usize, [f64; 3])>,
    /// Values per motion row.
    pub n_channels: usize,
}

impl Skeleton {
    /// Build the model from a parsed file, deciding each joint's translation rule from
    /// the motion (spec com-from-bvh §2).
    pub fn from_bvh(bvh: &Bvh) -> Skeleton {
        let h = &bvh.hierarchy;
        let mut s = Skeleton {
            names: h.joints.iter().map(|j| j.name.clone()).collect(),
            parents: h.joints.iter().map(|j| j.parent).collect(),
            offsets: h.joints.iter().map(|j| j.offset).collect(),
            channels: Vec::with_capacity(h.joints.len()),
            end_sites: h
                .joints
                .iter()
                .enumerate()
                .filter_map(|(i, j)| j.end_site.map(|e| (i, e)))
                .collect(),
            n_channels: h.n_channels(),
        };
        for j in &h.joints {
            let mut rotations = Vec::new();
            let mut translations = [None; 3];
            for (k, c) in j.channels.iter().enumerate() {
                let idx = j.first_channel + k;
                if c.is_rotation() {
                    rotations.push((c.axis(), idx));
                } else {
                    translations[c.axis()] = Some(idx);
                }
            }
            let has_t = translations.iter().any(Option::is_some);
            let mode = match (has_t, j.parent) {
                (false, _) => TranslationMode::Offset,
                (true, None) => TranslationMode::Replace,
                (true, Some(_)) => delta_or_replace(bvh, &translations, j.offset),
            };
            s.channels.push(JointChannels {
                rotations,
                translations,
                mode,
            });
        }
        s
    }

    /// Number of joints.
    pub fn n_joints(&self) -> usize {
        self.names.len()
    }

    /// Number of points FK produces: joints then End Sites.
    pub fn n_points(&self) -> usize {
        self.names.len() + self.end_sites.len()
    }

    /// Point name: the joint's name, or `<parent>/End` for an End Site.
    pub fn point_name(&self, p: usize) -> String {
        if p < self.n_joints() {
            self.names[p].clone()
        } else {
            format!("{}/End", self.names[self.end_sites[p - self.n_joints()].0])
        }
    }

    /// Point index of joint `j`'s End Site, if any.
    pub fn end_site_point(&self, j: usize) -> Option<usize> {
        self.end_sites
            .iter()
            .position(|(k, _)| *k == j)
            .map(|e| self.n_joints() + e)
    }

    /// Children of joint `j`, in file order.
    pub fn children(&self, j: usize) -> impl Iterator<Item = usize> + '_ {
        (j + 1..self.n_joints()).filter(move |&c| self.parents[c] == Some(j))
    }

    /// The channel kind at row index `idx` (for diagnostics).
    pub fn is_rotation_channel(&self, idx: usize) -> bool {
        self.channels
            .iter()
            .any(|c| c.rotations.iter().any(|&(_, i)| i == idx))
    }
}

fn delta_or_replace(bvh: &Bvh, tr: &[Option<usize>; 3], offset: [f64; 3]) -> TranslationMode {
    let m = &bvh.motion;
    let norms: Vec<f64> = (0..m.n_frames())
        .map(|f| {
            let row = m.row(f);
            tr.iter()
                .map(|c| c.map_or(0.0, |i| row[i] * row[i]))
                .sum::<f64>()
                .sqrt()
        })
        .collect();
    let off = offset.iter().map(|v| v * v).sum::<f64>().sqrt();
    match median(&norms) {
        Some(med) if med < 0.5 * off => TranslationMode::Delta,
        _ => TranslationMode::Replace,
    }
}
