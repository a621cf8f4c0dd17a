//! Whole-body centre of mass from the de Leva (1996) segment table.
//!
//! # Model
//! ```text
//! p_seg = P_origin + (COM%/100)·(P_other − P_origin)
//! c     = Σ_seg m%_seg · p_seg / Σ_seg m%_seg           (fractions normalised by their sum)
//!
//! segment          origin → other   mass % M / F     COM % M / F
//! head + neck      VERT → CERV       6.94 / 6.68    50.02 / 48.41
//! trunk            CERV → MIDH      43.46 / 42.57   51.38 / 49.64
//! upper arm (×2)   SJC → EJC         2.71 / 2.55    57.72 / 57.54
//! forearm (×2)     EJC → WJC         1.62 / 1.38    45.74 / 45.59
//! hand (×2)        WJC → MET3        0.61 / 0.56    79.00 / 74.74
//! thigh (×2)       HJC → KJC        14.16 / 14.78   40.95 / 36.12
//! shank (×2)       KJC → AJC         4.33 / 4.81    43.95 / 43.52
//! foot (×2)        AJC → TTIP        1.37 / 1.29    44.15 / 40.14
//! ```
//! A side without an arm adds that arm's three mass fractions to the trunk.
//!
//! # Frames and units
//! Positions in metres, internal Z-up frame; mass does not change the COM.
//!
//! # References
//! de Leva, P. (1996) J Biomech 29(9), Table 4; spec com-from-bvh §5 (verified).
//!
//! # Examples
//! ```
//! use stancelib::skeleton::com::{com, BodyPoints, Sex};
//! let p = |z: f64| [0.0, 0.0, z];
//! let side = stancelib::skeleton::com::SidePoints {
//!     hjc: p(0.9), kjc: p(0.5), ajc: p(0.08), ttip: [0.2, 0.0, 0.0],
//!     arm: Some([p(1.45), p(1.15), p(0.9), p(0.8)]),
//! };
//! let b = BodyPoints { vert: p(1.75), cerv: p(1.5), left: side.clone(), right: side };
//! let c = com(&b, Sex::Male);
//! assert!(c[2] > 0.9 && c[2] < 1.05);
//! ```

/// Which de Leva column to use.
#[derive(serde::Serialize, Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Sex {
    /// Male column (default).
    #[default]
    Male,
    /// Female column.
    Female,
    /// Mean of the two columns.
    Average,
}

impl Sex {
    /// Parse `male`, `female` or `average`.
    pub fn parse(s: &str) -> Option<Sex> {
        match s.trim().to_ascii_lowercase().as_str() {
            "male" => Some(Sex::Male),
            "female" => Some(Sex::Female),
            "average" => Some(Sex::Average),
            _ => None,
        }
    }
}

/// One row of the table: (mass % male, mass % female, COM % male, COM % female).
type Row = (f64, f64, f64, f64);
const HEAD: Row = (6.94, 6.68, 50.02, 48.41);
const TRUNK: Row = (43.46, 42.57, 51.38, 49.64);
const UPPER_ARM: Row = (2.71, 2.55, 57.72, 57.54);
const FOREARM: Row = (1.62, 1.38, 45.74, 45.59);
const HAND: Row = (0.61, 0.56, 79.00, 74.74);
const THIGH: Row = (14.16, 14.78, 40.95, 36.12);
const SHANK: Row = (4.33, 4.81, 43.95, 43.52);
const FOOT: Row = (1.37, 1.29, 44.15, 40.14);

/// (mass fraction %, COM fraction 0–1) of a row for a sex.
fn pick(r: Row, s: Sex) -> (f64, f64) {
    match s {
        Sex::Male => (r.0, r.2 / 100.0),
        Sex::Female => (r.1, r.3 / 100.0),
        Sex::Average => ((r.0 + r.1) / 2.0, (r.2 + r.3) / 200.0),
    }
}

/// Landmark positions of one side of one frame.
#[derive(Debug, Clone, PartialEq)]
pub struct SidePoints {
    /// Hip joint centre.
    pub hjc: [f64; 3],
    /// Knee.
    pub kjc: [f64; 3],
    /// Ankle.
    pub ajc: [f64; 3],
    /// Toe tip.
    pub ttip: [f64; 3],
    /// SJC, EJC, WJC, MET3 when the side has an arm.
    pub arm: Option<[[f64; 3]; 4]>,
}

/// Landmark positions of one frame.
#[derive(Debug, Clone, PartialEq)]
pub struct BodyPoints {
    /// Head top.
    pub vert: [f64; 3],
    /// Neck base (C7).
    pub cerv: [f64; 3],
    /// Left side.
    pub left: SidePoints,
    /// Right side.
    pub right: SidePoints,
}

#[inline(always)]
fn seg(acc: &mut ([f64; 3], f64), (m, k): (f64, f64), a: [f64; 3], b: [f64; 3]) {
    for i in 0..3 {
        acc.0[i] += m * (a[i] + k * (b[i] - a[i]));
    }
    acc.1 += m;
}

/// Whole-body COM of one frame (metres, same frame as the inputs).
pub fn com(b: &BodyPoints, sex: Sex) -> [f64; 3] {
    let midh: [f64; 3] = std::array::from_fn(|i| 0.5 * (b.left.hjc[i] + b.right.hjc[i]));
    let mut acc = ([0.0; 3], 0.0);
    seg(&mut acc, pick(HEAD, sex), b.vert, b.cerv);
    let (mut trunk_m, trunk_k) = pick(TRUNK, sex);
    for s in [&b.left, &b.right] {
        seg(&mut acc, pick(THIGH, sex), s.hjc, s.kjc);
        seg(&mut acc, pick(SHANK, sex), s.kjc, s.ajc);
        seg(&mut acc, pick(FOOT, sex), s.ajc, s.ttip);
        match &s.arm {
            Some([sjc, ejc, wjc, met3]) => {
                seg(&mut acc, pick(UPPER_ARM, sex), *sjc, *ejc);
                seg(&mut acc, pick(FOREARM, sex), *ejc, *wjc);
                seg(&mut acc, pick(HAND, sex), *wjc, *met3);
            }
            None => trunk_m += pick(UPPER_ARM, sex).0 + pick(FOREARM, sex).0 + pick(HAND, sex).0,
        }
    }
    seg(&mut acc, (trunk_m, trunk_k), b.cerv, midh);
    acc.0.map(|v| v / acc.1)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fractions_sum_as_de_leva() {
        let rows = [
            HEAD, TRUNK, UPPER_ARM, UPPER_ARM, FOREARM, FOREARM, HAND, HAND, THIGH, THIGH, SHANK,
            SHANK, FOOT, FOOT,
        ];
        let m: f64 = rows.iter().map(|r| r.0).sum();
        let f: f64 = rows.iter().map(|r| r.1).sum();
        assert!((m - 100.0).abs() < 1e-9);
        assert!((f - 99.99).abs() < 1e-9);
    }

    #[test]
    fn a_point_body_has_its_com_there_and_translation_moves_it() {
        let p = [1.0, -2.0, 3.0];
        let side = SidePoints {
            hjc: p,
            kjc: p,
            ajc: p,
            ttip: p,
            arm: Some([p; 4]),
        };
        let b = BodyPoints {
            vert: p,
            cerv: p,
            left: side.clone(),
            right: SidePoints { arm: None, ..side },
        };
        for s in [Sex::Male, Sex::Female, Sex::Average] {
            let c = com(&b, s);
            assert!((0..3).all(|i| (c[i] - p[i]).abs() < 1e-12));
        }
    }
}
