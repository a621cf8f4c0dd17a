//! The crate's one 3-vector type, `[f64; 3]` ([`V3`]), and its few operations (the
//! stages share these instead of each writing its own).

/// A 3-vector: a position (m), velocity (m/s), direction or force (N), by context.
pub type V3 = [f64; 3];

/// `a + b`.
#[inline]
pub fn add(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] + b[0], a[1] + b[1], a[2] + b[2]]
}

/// `a − b`.
#[inline]
pub fn sub(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

/// `s · a`.
#[inline]
pub fn scale(s: f64, a: [f64; 3]) -> [f64; 3] {
    [s * a[0], s * a[1], s * a[2]]
}

/// `a · b`.
#[inline]
pub fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

/// `a × b`.
#[inline]
pub fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

/// `‖a‖`.
#[inline]
pub fn norm(a: [f64; 3]) -> f64 {
    dot(a, a).sqrt()
}

/// `a / ‖a‖` (NaN for the zero vector).
#[inline]
pub fn unit(a: [f64; 3]) -> [f64; 3] {
    scale(1.0 / norm(a), a)
}

/// Flexion at a joint, degrees: `180° − ∠(proximal, joint, distal)` (0 for a straight
/// limb, and for a degenerate one with a zero-length segment). The knee's: hip, knee, ankle.
pub fn flexion_deg(proximal: [f64; 3], joint: [f64; 3], distal: [f64; 3]) -> f64 {
    let (u, v) = (sub(proximal, joint), sub(distal, joint));
    let n = norm(u) * norm(v);
    if n == 0.0 {
        return 0.0;
    }
    180.0 - (dot(u, v) / n).clamp(-1.0, 1.0).acos().to_degrees()
}
