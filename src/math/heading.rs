//! The stance frame's heading (spec stance-model §2): a horizontal unit vector `e_h` and
//! where it came from, with the rotation `R_s` (rows `e_h, e_p, e_v`) it defines. Chosen by
//! [`crate::stances::params::heading`]; here, below both the stances and the force models,
//! so that the force model's export takes it without depending on the stances.
//!
//! # Model
//! ```text
//! e_v = (0,0,1);  e_p = e_v × e_h;  R_s = [e_h; e_p; e_v] (rows): stance vector = R_s · world vector
//! ```

use crate::math::v3::V3;

/// Where a stance's heading came from.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum HeadingFrom {
    /// Horizontal COM velocity at touchdown.
    Velocity,
    /// Facing direction from the hip joint centres.
    Hips,
    /// The previous stance of the clip.
    Previous,
    /// World +X.
    WorldX,
}

impl HeadingFrom {
    /// Name used in `stances.parquet`.
    pub fn as_str(self) -> &'static str {
        match self {
            HeadingFrom::Velocity => "velocity",
            HeadingFrom::Hips => "hips",
            HeadingFrom::Previous => "previous",
            HeadingFrom::WorldX => "world_x",
        }
    }
}

/// The stance frame: heading `e_h` (unit, horizontal) and its source.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Heading {
    /// `e_h` in world coordinates.
    pub e_h: V3,
    /// Where it came from.
    pub from: HeadingFrom,
}

impl Heading {
    /// `R_s`, rows `e_h`, `e_p`, `e_v`.
    pub fn rotation(&self) -> [V3; 3] {
        let [hx, hy, _] = self.e_h;
        [[hx, hy, 0.0], [-hy, hx, 0.0], [0.0, 0.0, 1.0]]
    }

    /// A world vector in stance axes.
    pub fn to_stance(&self, v: V3) -> V3 {
        let r = self.rotation();
        std::array::from_fn(|i| r[i][0] * v[0] + r[i][1] * v[1] + r[i][2] * v[2])
    }
}
