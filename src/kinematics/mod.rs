//! The contact frame of the kinematic samples (spec two-pac §3, eq 3): where the COM is
//! relative to an effector in contact.
//!
//! # Model
//! ```text
//! point:    ʳc = R_eᵀ (c − p_e)        COM in the effector's contact frame (m);
//!           R_e = Rz(yaw), p_e = contact-frame origin (com-from-bvh §7.5)
//! ```
//! The outlier rules and the hull that turn these points into kinematic polytopes are in
//! [`crate::twopac::kinematic`].
//!
//! # References
//! spec two-pac §3; com-from-bvh §7.5 (contact frames).

/// The COM in a yaw-only contact frame: `Rz(yaw)ᵀ (c − origin)`, m.
pub fn com_in_contact_frame(com: [f64; 3], origin: [f64; 3], yaw_rad: f64) -> [f64; 3] {
    let (s, c) = yaw_rad.sin_cos();
    let d = [com[0] - origin[0], com[1] - origin[1], com[2] - origin[2]];
    [c * d[0] + s * d[1], -s * d[0] + c * d[1], d[2]]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn contact_frame_undoes_yaw_and_origin() {
        let origin = [1.0, 2.0, 0.1];
        let yaw = 0.7f64;
        // A point 0.3 m ahead, 0.1 m left, 0.9 m up in the contact frame.
        let local = [0.3, 0.1, 0.9];
        let (s, c) = yaw.sin_cos();
        let world = [
            origin[0] + c * local[0] - s * local[1],
            origin[1] + s * local[0] + c * local[1],
            origin[2] + local[2],
        ];
        let back = com_in_contact_frame(world, origin, yaw);
        for k in 0..3 {
            assert!((back[k] - local[k]).abs() < 1e-12, "{back:?}");
        }
    }
}
