//! Force-plate CSV files (`stancelib plot stance --plates`): the measured ground-reaction
//! force on the body, per foot and in total, mapped to the world frame.
//!
//! # Model
//! ```text
//! header: time_s, fx_n, fy_n, fz_n, left_fx_n, left_fy_n, left_fz_n,
//!         right_fx_n, right_fy_n, right_fz_n   (any order; other columns ignored)
//! f_world(t) = M_up · (f?x_n, f?y_n, f?z_n)   (the clip's up-axis map, no length scale)
//! ```
//! Only the time column and the three columns of the chosen foot ([`PlateFoot`]) are
//! required; an empty cell there is an error.
//!
//! # Frames and units
//! File: the BVH file's own axes, newtons (force on the body), seconds of clip time
//! (frame 0 at t = 0). Output: world axes, right-handed, Z up, newtons.

use crate::error::{Error, Result};
use crate::skeleton::units::UpAxis;

/// Which of the file's forces a stance is compared with.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum PlateFoot {
    /// `left_f{x,y,z}_n`.
    Left,
    /// `right_f{x,y,z}_n`.
    Right,
    /// The total `f{x,y,z}_n`.
    Total,
}

impl PlateFoot {
    /// The foot of a stance label: `L` → left, `R` → right, anything else (`LR`, hands) → total.
    pub fn from_label(label: &str) -> PlateFoot {
        match label {
            "L" => PlateFoot::Left,
            "R" => PlateFoot::Right,
            _ => PlateFoot::Total,
        }
    }

    /// The column prefix: `left_`, `right_` or empty.
    pub fn prefix(self) -> &'static str {
        match self {
            PlateFoot::Left => "left_",
            PlateFoot::Right => "right_",
            PlateFoot::Total => "",
        }
    }
}

/// One plate sample: clip time (s) and force (N, world axes, Z up).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PlateSample {
    /// Clip time, s.
    pub time_s: f64,
    /// Force on the body, world axes (Z up), N.
    pub f_world: [f64; 3],
}

/// Parses plate CSV text: `foot`'s force at each row, mapped by `up` to the world frame.
///
/// # Errors
/// [`crate::ErrorKind::Config`] with the 1-based line: no header, a required column
/// missing, a row with another number of cells, an empty or non-numeric value in a
/// required column, or times that do not increase.
pub fn parse_plates(text: &str, foot: PlateFoot, up: UpAxis) -> Result<Vec<PlateSample>> {
    let bad = |line: usize, msg: String| Error::config(None, Some(line), msg);
    let mut lines = text
        .lines()
        .enumerate()
        .map(|(i, l)| (i + 1, l.trim()))
        .filter(|(_, l)| !l.is_empty());
    let (_, head) = lines
        .next()
        .ok_or_else(|| bad(1, "empty file: expected a header line".into()))?;
    let header: Vec<&str> = head.split(',').map(str::trim).collect();
    let p = foot.prefix();
    let wanted = [
        "time_s".to_string(),
        format!("{p}fx_n"),
        format!("{p}fy_n"),
        format!("{p}fz_n"),
    ];
    let mut idx = [0usize; 4];
    for (k, name) in wanted.iter().enumerate() {
        idx[k] = header
            .iter()
            .position(|h| h == name)
            .ok_or_else(|| bad(1, format!("missing column '{name}'")))?;
    }
    let mut out: Vec<PlateSample> = Vec::new();
    for (line, l) in lines {
        let cells: Vec<&str> = l.split(',').map(str::trim).collect();
        if cells.len() != header.len() {
            let msg = format!("{} cells, the header has {}", cells.len(), header.len());
            return Err(bad(line, msg));
        }
        let mut v = [0.0; 4];
        for (k, &i) in idx.iter().enumerate() {
            v[k] = cells[i]
                .parse::<f64>()
                .ok()
                .filter(|x| x.is_finite())
                .ok_or_else(|| {
                    let msg = format!("column '{}': '{}' is not a number", wanted[k], cells[i]);
                    bad(line, msg)
                })?;
        }
        if let Some(prev) = out.last() {
            if v[0] <= prev.time_s {
                let msg = format!(
                    "time_s {} does not increase (previous {})",
                    v[0], prev.time_s
                );
                return Err(bad(line, msg));
            }
        }
        out.push(PlateSample {
            time_s: v[0],
            f_world: up.to_internal([v[1], v[2], v[3]]),
        });
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::path::Path;

    const CSV: &str = "time_s,fx_n,fy_n,fz_n,left_fx_n,left_fy_n,left_fz_n,left_copx_m,\
right_fx_n,right_fy_n,right_fz_n\n\
0.0,1,700,3,1,700,3,,0,0,0\n\
0.01,-5,900,-2,0,0,0,,-5,900,-2\n";

    #[test]
    fn each_foot_is_mapped_to_z_up() {
        // +Y up file: (x, y, z) → (x, −z, y), so the file's vertical y becomes world z.
        let left = parse_plates(CSV, PlateFoot::Left, UpAxis::PosY).unwrap();
        assert_eq!(left[0].f_world, [1.0, -3.0, 700.0]);
        assert_eq!(left[1].f_world, [0.0, 0.0, 0.0]);
        let right = parse_plates(CSV, PlateFoot::Right, UpAxis::PosY).unwrap();
        assert_eq!(right[1].f_world, [-5.0, 2.0, 900.0]);
        let total = parse_plates(CSV, PlateFoot::Total, UpAxis::PosZ).unwrap();
        assert_eq!(
            total.iter().map(|s| s.time_s).collect::<Vec<_>>(),
            [0.0, 0.01]
        );
        assert_eq!(total[1].f_world, [-5.0, 900.0, -2.0]);
        assert_eq!(PlateFoot::from_label("LR+LH"), PlateFoot::Total);
        assert_eq!(PlateFoot::from_label("R"), PlateFoot::Right);
    }

    #[test]
    fn bad_files_name_their_line_and_column() {
        let msg = |text: &str, foot| {
            parse_plates(text, foot, UpAxis::PosY)
                .unwrap_err()
                .with_path(Path::new("grf.csv"))
                .to_string()
        };
        assert_eq!(
            msg("time_s,fx_n,fy_n\n0,1,2\n", PlateFoot::Total),
            "grf.csv:1: missing column 'fz_n'"
        );
        let gap = CSV.replace("0.01,-5,900", "0.01,,900");
        assert_eq!(
            msg(&gap, PlateFoot::Total),
            "grf.csv:3: column 'fx_n': '' is not a number"
        );
        // The left foot's columns are intact on that row: it parses.
        assert!(parse_plates(&gap, PlateFoot::Left, UpAxis::PosY).is_ok());
        let back = CSV.replace("0.01,", "0.0,");
        assert!(msg(&back, PlateFoot::Left).starts_with("grf.csv:3: time_s 0 does not increase"));
        assert_eq!(
            msg("", PlateFoot::Left),
            "grf.csv:1: empty file: expected a header line"
        );
        let short = format!("{CSV}0.02,1,2\n");
        assert_eq!(
            msg(&short, PlateFoot::Left),
            "grf.csv:4: 3 cells, the header has 11"
        );
    }
}
