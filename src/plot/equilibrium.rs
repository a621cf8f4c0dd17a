//! `equilibrium --png`: a horizontal slice of the static-equilibrium region of one contact
//! set (spec two-pac §2.2) with its contact points and the evaluated COM states.
//!
//! # Model
//! ```text
//! grid: n × n COM positions (x, y) at height z over the contacts' box ± PAD, c̈ = 0;
//! each cell coloured by the robustness margin (N) where in equilibrium, grey elsewhere
//! ```
//! With zero acceleration the region is a vertical prism, so the slice's height does not
//! change it; the evaluated states (with their own accelerations) are drawn over it,
//! green where in equilibrium and red elsewhere.
//!
//! # Frames and units
//! World frame, Z up, metres; margins in newtons.

use std::path::Path;

use plotters::prelude::*;

use super::{draw_legend, err, register_font, PlotError};

/// Cells per axis of the slice.
pub const DEFAULT_SLICE_CELLS: usize = 80;
/// Margin around the contacts' horizontal bounding box, m.
pub const SLICE_PAD_M: f64 = 0.3;

/// What the slice shows.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct EquilibriumPlot {
    /// Title.
    pub title: String,
    /// Cell centres along x and y, m.
    pub xs: Vec<f64>,
    /// Cell centres along y, m.
    pub ys: Vec<f64>,
    /// Per cell (row-major over `ys`, then `xs`): the margin (N) when in equilibrium
    /// (`f64::INFINITY` for force closure), else `None`.
    pub margin_n: Vec<Option<f64>>,
    /// Contact points, world m.
    pub contacts: Vec<[f64; 3]>,
    /// The evaluated COM states and their verdicts.
    pub points: Vec<([f64; 3], bool)>,
}

/// Cell centres of `n` cells over `[lo − pad, hi + pad]`.
pub fn axis(lo: f64, hi: f64, n: usize) -> Vec<f64> {
    let (a, b) = (lo - SLICE_PAD_M, hi + SLICE_PAD_M);
    let w = (b - a) / n as f64;
    (0..n).map(|i| a + (i as f64 + 0.5) * w).collect()
}

/// Writes the slice to `path` (PNG, 900 × 820 px).
///
/// # Errors
/// The file cannot be written or the font cannot be used.
pub fn equilibrium_png(path: &Path, d: &EquilibriumPlot) -> Result<(), PlotError> {
    register_font();
    let root = BitMapBackend::new(path, (900, 820)).into_drawing_area();
    root.fill(&WHITE).map_err(|e| err(path, e))?;
    let (nx, ny) = (d.xs.len().max(1), d.ys.len().max(1));
    let step = |v: &[f64]| v.get(1).zip(v.first()).map_or(0.1, |(b, a)| b - a);
    let (wx, wy) = (step(&d.xs), step(&d.ys));
    let x0 = d.xs.first().copied().unwrap_or(0.0) - wx / 2.0;
    let y0 = d.ys.first().copied().unwrap_or(0.0) - wy / 2.0;
    let (x1, y1) = (x0 + wx * nx as f64, y0 + wy * ny as f64);
    let mut chart = ChartBuilder::on(&root)
        .caption(&d.title, ("sans-serif", 18))
        .margin(14)
        .x_label_area_size(45)
        .y_label_area_size(60)
        .build_cartesian_2d(x0..x1, y0..y1)
        .map_err(|e| err(path, e))?;
    chart
        .configure_mesh()
        .x_desc("x (m)")
        .y_desc("y (m)")
        .light_line_style(WHITE.mix(0.0))
        .label_style(("sans-serif", 13))
        .draw()
        .map_err(|e| err(path, e))?;
    let finite_max = d
        .margin_n
        .iter()
        .flatten()
        .filter(|m| m.is_finite())
        .fold(0.0f64, |a, &m| a.max(m));
    let green = RGBColor(46, 139, 87);
    let cells = d.margin_n.iter().enumerate().map(|(k, m)| {
        let (i, j) = (k % nx, k / nx);
        let (cx, cy) = (x0 + i as f64 * wx, y0 + j as f64 * wy);
        let style = match m {
            Some(v) => {
                let t = if v.is_finite() && finite_max > 0.0 {
                    0.2 + 0.8 * (v / finite_max).clamp(0.0, 1.0)
                } else {
                    1.0
                };
                green.mix(t).filled()
            }
            None => RGBColor(225, 225, 225).filled(),
        };
        Rectangle::new([(cx, cy), (cx + wx, cy + wy)], style)
    });
    chart
        .draw_series(cells)
        .map_err(|e| err(path, e))?
        .label(format!(
            "in equilibrium (darker = larger margin, max {finite_max:.0} N)"
        ))
        .legend(move |(x, y)| Rectangle::new([(x, y - 5), (x + 12, y + 5)], green.filled()));
    chart
        .draw_series(
            d.contacts
                .iter()
                .map(|p| Cross::new((p[0], p[1]), 6, BLACK.stroke_width(2))),
        )
        .map_err(|e| err(path, e))?
        .label("contact points")
        .legend(|(x, y)| Cross::new((x + 6, y), 5, BLACK.stroke_width(2)));
    let blue = RGBColor(30, 90, 200);
    chart
        .draw_series(
            d.points
                .iter()
                .filter(|(_, ok)| *ok)
                .map(|(p, _)| Circle::new((p[0], p[1]), 3, blue.filled())),
        )
        .map_err(|e| err(path, e))?
        .label("COM state in equilibrium")
        .legend(move |(x, y)| Circle::new((x + 6, y), 3, blue.filled()));
    chart
        .draw_series(
            d.points
                .iter()
                .filter(|(_, ok)| !*ok)
                .map(|(p, _)| Circle::new((p[0], p[1]), 3, RED.filled())),
        )
        .map_err(|e| err(path, e))?
        .label("COM state not in equilibrium")
        .legend(|(x, y)| Circle::new((x + 6, y), 3, RED.filled()));
    draw_legend(&mut chart, path)?;
    root.present().map_err(|e| err(path, e))?;
    Ok(())
}
