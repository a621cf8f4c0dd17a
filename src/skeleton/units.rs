//! File length unit (metres per file unit, from leg length) and up axis, and the map from
//! file coordinates to the internal right-handed Z-up frame in metres.
//!
//! # Model
//! ```text
//! unit: argmin_u |ln(u·L_leg/0.84)| over {m, dm, cm, mm, in, ft, cmu}, accepted when
//!       u·L_leg/0.84 ∈ [1/1.5, 1.5]; otherwise u = 0.84/L_leg ("estimated", warning)
//! up:   v = mean_f(head − ½(ankle_L + ankle_R)); the signed axis with the largest |component|
//!       when that is ≥ 0.7·|v|; else the same test on the rest pose; else +Y (warning)
//! p_internal = u · M_up · p_file      (M_up a proper rotation, det = +1)
//! ```
//!
//! # Frames and units
//! Output: metres, right-handed, Z up.
//!
//! # References
//! spec com-from-bvh §3.1, §3.2 (verified).

/// Nominal leg length (hip–knee–ankle) of a 1.75 m adult, metres.
pub const NOMINAL_LEG_M: f64 = 0.84;
/// Nominal stature for [`NOMINAL_LEG_M`], metres.
pub const NOMINAL_HEIGHT_M: f64 = 1.75;
/// A candidate unit is accepted when `u·L_leg/0.84` lies within this factor of 1.
pub const UNIT_ACCEPT_FACTOR: f64 = 1.5;
/// Minimum share of the dominant axis in the head-above-ankles vector.
pub const UP_AXIS_MIN_SHARE: f64 = 0.7;
/// The CMU unit: (1/0.45) inch in metres.
pub const CMU_UNIT_M: f64 = 0.056444;

/// Candidate units (name, metres per unit) of spec §3.1.
pub const UNITS: [(&str, f64); 7] = [
    ("m", 1.0),
    ("dm", 0.1),
    ("cm", 0.01),
    ("mm", 0.001),
    ("in", 0.0254),
    ("ft", 0.3048),
    ("cmu", CMU_UNIT_M),
];

/// The unit used for a clip.
#[derive(Debug, Clone, PartialEq)]
pub struct Unit {
    /// Metres per file unit.
    pub scale: f64,
    /// Candidate name, `estimated` or `override`.
    pub name: String,
}

/// Parse a unit given by name (`m`, `cm`, `mm`, `in`, `cmu`, …) or as metres per unit.
pub fn parse_unit(s: &str) -> Option<f64> {
    let s = s.trim();
    UNITS
        .iter()
        .find(|(n, _)| n.eq_ignore_ascii_case(s))
        .map(|u| u.1)
        .or_else(|| s.parse::<f64>().ok().filter(|v| v.is_finite() && *v > 0.0))
}

/// Detect the unit from the rest-pose leg length in file units; the second value is a
/// warning when no candidate fits.
pub fn detect_unit(leg_file: f64) -> (Unit, Option<String>) {
    let best = UNITS
        .iter()
        .min_by(|a, b| {
            (a.1 * leg_file / NOMINAL_LEG_M)
                .ln()
                .abs()
                .total_cmp(&(b.1 * leg_file / NOMINAL_LEG_M).ln().abs())
        })
        .copied()
        .unwrap_or(("m", 1.0));
    let ratio = best.1 * leg_file / NOMINAL_LEG_M;
    // A non-finite leg length (OFFSETs overflowing f64) fits no unit; callers refuse it.
    let usable = leg_file > 0.0 && leg_file.is_finite();
    if usable && (1.0 / UNIT_ACCEPT_FACTOR..=UNIT_ACCEPT_FACTOR).contains(&ratio) {
        (
            Unit {
                scale: best.1,
                name: best.0.to_string(),
            },
            None,
        )
    } else {
        let scale = if usable {
            NOMINAL_LEG_M / leg_file
        } else {
            1.0
        };
        (
            Unit { scale, name: "estimated".into() },
            Some(format!("unit not detected (leg length {leg_file:.4} file units): estimated {scale:.6} m per unit")),
        )
    }
}

/// A signed file axis that points up.
#[derive(serde::Serialize, Debug, Clone, Copy, PartialEq, Eq)]
pub enum UpAxis {
    /// +X up.
    PosX,
    /// −X up.
    NegX,
    /// +Y up (CMU, Mixamo, most files).
    PosY,
    /// −Y up.
    NegY,
    /// +Z up.
    PosZ,
    /// −Z up.
    NegZ,
}

impl UpAxis {
    /// Name as written in `clips.parquet` and configuration files.
    pub fn as_str(self) -> &'static str {
        match self {
            UpAxis::PosX => "+X",
            UpAxis::NegX => "-X",
            UpAxis::PosY => "+Y",
            UpAxis::NegY => "-Y",
            UpAxis::PosZ => "+Z",
            UpAxis::NegZ => "-Z",
        }
    }

    /// Parse `+X` … `-Z` (a missing sign means `+`).
    pub fn parse(s: &str) -> Option<UpAxis> {
        Some(match s.trim().to_ascii_uppercase().as_str() {
            "+X" | "X" => UpAxis::PosX,
            "-X" => UpAxis::NegX,
            "+Y" | "Y" => UpAxis::PosY,
            "-Y" => UpAxis::NegY,
            "+Z" | "Z" => UpAxis::PosZ,
            "-Z" => UpAxis::NegZ,
            _ => return None,
        })
    }

    /// Rotate a file-frame vector to internal Z-up (spec §3.2 table).
    #[inline(always)]
    pub fn to_internal(self, [x, y, z]: [f64; 3]) -> [f64; 3] {
        match self {
            UpAxis::PosY => [x, -z, y],
            UpAxis::NegY => [x, z, -y],
            UpAxis::PosZ => [x, y, z],
            UpAxis::NegZ => [x, -y, -z],
            UpAxis::PosX => [-z, y, x],
            UpAxis::NegX => [z, y, -x],
        }
    }
}

/// The dominant signed axis of `v` when it holds at least [`UP_AXIS_MIN_SHARE`] of |v|.
pub fn dominant_axis(v: [f64; 3]) -> Option<UpAxis> {
    let n = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
    let (k, c) = v
        .iter()
        .copied()
        .enumerate()
        .max_by(|a, b| a.1.abs().total_cmp(&b.1.abs()))?;
    if n.is_nan() || n <= 0.0 || c.abs() < UP_AXIS_MIN_SHARE * n {
        return None;
    }
    Some(match (k, c > 0.0) {
        (0, true) => UpAxis::PosX,
        (0, false) => UpAxis::NegX,
        (1, true) => UpAxis::PosY,
        (1, false) => UpAxis::NegY,
        (_, true) => UpAxis::PosZ,
        (_, false) => UpAxis::NegZ,
    })
}

/// Up axis from the motion's and the rest pose's head-above-ankles vectors, with a warning
/// when both fail and `+Y` is assumed.
pub fn detect_up(motion: [f64; 3], rest: [f64; 3]) -> (UpAxis, Option<String>) {
    match dominant_axis(motion).or_else(|| dominant_axis(rest)) {
        Some(a) => (a, None),
        None => (
            UpAxis::PosY,
            Some("up axis not detected: +Y assumed".into()),
        ),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn spec_examples_pick_their_units() {
        assert_eq!(detect_unit(14.4).0.name, "cmu");
        assert_eq!(detect_unit(86.0).0.name, "cm");
        assert_eq!(detect_unit(34.0).0.name, "in");
        assert_eq!(detect_unit(0.9).0.name, "m");
        let (u, w) = detect_unit(3.0e5);
        assert_eq!(u.name, "estimated");
        assert!(w.is_some());
        assert!((u.scale * 3.0e5 - NOMINAL_LEG_M).abs() < 1e-12);
    }

    #[test]
    fn up_maps_are_proper_rotations_taking_up_to_z() {
        for (a, up) in [
            (UpAxis::PosX, [1.0, 0.0, 0.0]),
            (UpAxis::NegX, [-1.0, 0.0, 0.0]),
            (UpAxis::PosY, [0.0, 1.0, 0.0]),
            (UpAxis::NegY, [0.0, -1.0, 0.0]),
            (UpAxis::PosZ, [0.0, 0.0, 1.0]),
            (UpAxis::NegZ, [0.0, 0.0, -1.0]),
        ] {
            assert_eq!(a.to_internal(up), [0.0, 0.0, 1.0]);
            let cols = [
                a.to_internal([1.0, 0.0, 0.0]),
                a.to_internal([0.0, 1.0, 0.0]),
                a.to_internal([0.0, 0.0, 1.0]),
            ];
            let det = cols[0][0] * (cols[1][1] * cols[2][2] - cols[2][1] * cols[1][2])
                - cols[1][0] * (cols[0][1] * cols[2][2] - cols[2][1] * cols[0][2])
                + cols[2][0] * (cols[0][1] * cols[1][2] - cols[1][1] * cols[0][2]);
            assert_eq!(det, 1.0, "{a:?}");
            assert_eq!(UpAxis::parse(a.as_str()), Some(a));
            assert_eq!(dominant_axis(up), Some(a));
        }
        // share 1/1.5 = 0.67 < 0.7 in both: +Y assumed with a warning
        assert_eq!(detect_up([1.0, 1.0, 0.5], [0.0, 0.0, 0.0]).0, UpAxis::PosY);
        assert!(detect_up([1.0, 1.0, 0.5], [0.0, 0.0, 0.0]).1.is_some());
        assert_eq!(detect_up([1.0, 1.0, 0.5], [0.0, 0.0, -2.0]).0, UpAxis::NegZ);
    }
}
