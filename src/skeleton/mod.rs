//! The skeleton: an immutable joint tree built once per clip, forward kinematics over it,
//! its body landmarks, lead-in frames, units and up axis, and the whole-body COM.
//!
//! Data flow: `bvh::Bvh` → [`model::Skeleton`] → [`fk`] (file-frame points) →
//! [`units`] (metres, Z up) → [`landmarks`] → [`com`].

pub mod com;
pub mod fk;
pub mod landmarks;
pub mod leadin;
pub mod model;
pub mod names;
pub mod plausibility;
pub mod units;

pub use model::Skeleton;
