//! Polytopes `A c ≤ b` in COM space: kinematic constraints (two-pac §3) and their frame
//! changes.
//!
//! # Model
//!
//! ```text
//! P = { c ∈ ℝ³ : A_i · c ≤ b_i  for every row i }            (A_i unit outward normals, b in m)
//! world rows of a contact at (p, R):   K_w = K_e Rᵀ ,   k_w = k_e + K_e Rᵀ p      (§3)
//! phase polytope K^(j): the world rows of all active contacts stacked (§3)
//! ```
//!
//! # Frames and units
//!
//! Rows are unit vectors (so violations are in metres); offsets in metres.
//!
//! # References
//!
//! Tonneau et al., 2PAC, eq 3–4; spec two-pac §3, §5.4.

use super::v3::{dot, norm, scale};

/// Most rows of one inline kinematic polytope of a phases file (count); a phase stacks
/// those of its contacts into each transition QP.
pub const MAX_ROWS: usize = 1_024;

/// A convex polytope `{c : a[i]·c ≤ b[i]}`; an empty row list is all of `ℝ³`.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Polytope {
    /// Row normals `A_i` (unit length when built by this crate).
    pub a: Vec<[f64; 3]>,
    /// Offsets `b_i`, m.
    pub b: Vec<f64>,
}

impl Polytope {
    /// A polytope from rows `a[i]·c ≤ b[i]`, each row scaled to unit `‖a[i]‖`; rows with
    /// `‖a[i]‖ = 0` are dropped (they do not depend on `c`).
    ///
    /// # Panics
    ///
    /// If `a` and `b` differ in length (a programmer error).
    pub fn new(a: Vec<[f64; 3]>, b: Vec<f64>) -> Polytope {
        assert_eq!(a.len(), b.len(), "Polytope::new: rows and offsets differ");
        let mut out = Polytope::default();
        for (ai, bi) in a.into_iter().zip(b) {
            let n = norm(ai);
            if n > 0.0 {
                out.a.push(scale(1.0 / n, ai));
                out.b.push(bi / n);
            }
        }
        out
    }

    /// The box `lo ≤ c ≤ hi` (6 rows).
    pub fn aabb(lo: [f64; 3], hi: [f64; 3]) -> Polytope {
        let mut a = Vec::with_capacity(6);
        let mut b = Vec::with_capacity(6);
        for k in 0..3 {
            let mut e = [0.0; 3];
            e[k] = 1.0;
            a.push(e);
            b.push(hi[k]);
            e[k] = -1.0;
            a.push(e);
            b.push(-lo[k]);
        }
        Polytope { a, b }
    }

    /// Number of rows.
    pub fn len(&self) -> usize {
        self.a.len()
    }

    /// True when there are no rows (all of `ℝ³`).
    pub fn is_empty(&self) -> bool {
        self.a.is_empty()
    }

    /// `max_i (a_i·c − b_i)`, m; `−∞` without rows. `≤ 0` means inside.
    pub fn max_violation(&self, c: [f64; 3]) -> f64 {
        self.a
            .iter()
            .zip(&self.b)
            .map(|(ai, bi)| dot(*ai, c) - bi)
            .fold(f64::NEG_INFINITY, f64::max)
    }

    /// Whether `c` satisfies every row within `tol_m`.
    pub fn contains(&self, c: [f64; 3], tol_m: f64) -> bool {
        self.max_violation(c) <= tol_m
    }

    /// The world-frame rows of a polytope given in a contact frame at `(p, R)` (§3):
    /// `K_w = K_e Rᵀ`, `k_w = k_e + K_e Rᵀ p`. `r` is `world_from_contact` by columns
    /// (`r[k]` is the frame's `k`-th axis in world coordinates).
    pub fn to_world(&self, p_world: [f64; 3], r: [[f64; 3]; 3]) -> Polytope {
        let mut out = Polytope::default();
        for (ke, &be) in self.a.iter().zip(&self.b) {
            // K_e Rᵀ: row ke rotated into world = Σ_k ke[k] · r[k].
            let kw = [
                ke[0] * r[0][0] + ke[1] * r[1][0] + ke[2] * r[2][0],
                ke[0] * r[0][1] + ke[1] * r[1][1] + ke[2] * r[2][1],
                ke[0] * r[0][2] + ke[1] * r[1][2] + ke[2] * r[2][2],
            ];
            out.a.push(kw);
            out.b.push(be + dot(kw, p_world));
        }
        out
    }

    /// [`Polytope::to_world`] for a yaw-only frame with `z` up (the §3 effector frame).
    pub fn to_world_yaw(&self, p_world: [f64; 3], yaw_rad: f64) -> Polytope {
        let (s, c) = yaw_rad.sin_cos();
        self.to_world(p_world, [[c, s, 0.0], [-s, c, 0.0], [0.0, 0.0, 1.0]])
    }

    /// The rows of `self` and `other` stacked (an intersection).
    pub fn stacked(&self, other: &Polytope) -> Polytope {
        let mut out = self.clone();
        out.a.extend_from_slice(&other.a);
        out.b.extend_from_slice(&other.b);
        out
    }
}
