//! `equilibrium --png`: where does this contact set hold the COM at rest, and are the
//! evaluated COM states in equilibrium? A horizontal slice of the static-equilibrium
//! region of one contact set (spec two-pac §2.2) with its outline (eq 2), its contact
//! points and the evaluated COM states; the verdict line counts the states in equilibrium.
//!
//! # Model
//! ```text
//! grid: n × n COM positions (x, y) at height z over a square around the contacts and the
//!       evaluated states (at most SLICE_REACH_M beyond the contacts) ± PAD, c̈ = 0;
//! each cell coloured by the robustness margin (N) where in equilibrium, grey elsewhere
//! ```
//! Both axes have the same metres per pixel, so the region keeps its shape.
//! With zero acceleration the region is a vertical prism, so the slice's height does not
//! change it; the evaluated states (with their own accelerations) are drawn over it,
//! blue where in equilibrium and red elsewhere (a state with an acceleration can be out of
//! equilibrium inside the static region, and in it outside).
//!
//! # Frames and units
//! World frame, Z up, metres; margins in newtons.

use std::path::Path;

use plotters::prelude::*;

use super::{draw_legend, err, register_font, tick_label, titled, PlotError, Verdict};

/// Cells per axis of the slice.
pub const DEFAULT_SLICE_CELLS: usize = 80;
/// Margin around the slice's box, m.
pub const SLICE_PAD_M: f64 = 0.3;
/// Farthest an evaluated COM state widens the slice beyond the contacts' box, m (a state
/// farther away is counted in the verdict but drawn at the edge of the picture).
pub const SLICE_REACH_M: f64 = 2.0;

/// What the slice shows.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct EquilibriumPlot {
    /// Title.
    pub title: String,
    /// The verdict line: how many evaluated states are in equilibrium.
    pub verdict: Verdict,
    /// Cell centres along x, m.
    pub xs: Vec<f64>,
    /// Cell centres along y, m.
    pub ys: Vec<f64>,
    /// Per cell (row-major over `ys`, then `xs`): the margin (N) when in equilibrium
    /// (`f64::INFINITY` for force closure), else `None`.
    pub margin_n: Vec<Option<f64>>,
    /// The static region's polygon `(x, y)`, m, counter-clockwise (empty when unbounded,
    /// empty or not found).
    pub region: Vec<[f64; 2]>,
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

/// The square `(x range, y range)` of the slice, before [`SLICE_PAD_M`]: the contacts' box
/// widened to the evaluated states (each clamped to [`SLICE_REACH_M`] beyond it), then to
/// a square about its centre, so the grid's cells are square.
pub fn square_box(contacts: &[[f64; 3]], states: &[[f64; 3]]) -> ([f64; 2], [f64; 2]) {
    let mut lo = [f64::INFINITY; 2];
    let mut hi = [f64::NEG_INFINITY; 2];
    for p in contacts.iter().filter(|p| p.iter().all(|v| v.is_finite())) {
        for k in 0..2 {
            lo[k] = lo[k].min(p[k]);
            hi[k] = hi[k].max(p[k]);
        }
    }
    if !lo[0].is_finite() {
        return ([-1.0, 1.0], [-1.0, 1.0]);
    }
    let (c_lo, c_hi) = (lo, hi);
    for p in states.iter().filter(|p| p.iter().all(|v| v.is_finite())) {
        for k in 0..2 {
            let v = p[k].clamp(c_lo[k] - SLICE_REACH_M, c_hi[k] + SLICE_REACH_M);
            lo[k] = lo[k].min(v);
            hi[k] = hi[k].max(v);
        }
    }
    let half = 0.5 * (hi[0] - lo[0]).max(hi[1] - lo[1]);
    let mid = [0.5 * (lo[0] + hi[0]), 0.5 * (lo[1] + hi[1])];
    (
        [mid[0] - half, mid[0] + half],
        [mid[1] - half, mid[1] + half],
    )
}

/// Margins of the chart inside the picture, px: outer margin, x and y label areas.
const CHART_PX: (u32, u32, u32) = (14, 45, 60);

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
    let root = titled(&root, path, &d.title, &d.verdict)?;
    // Equal metres per pixel on both axes: widen the shorter range about its centre.
    let (w_px, h_px) = root.dim_in_pixel();
    let (m, xl, yl) = CHART_PX;
    let plot_w = f64::from(w_px.saturating_sub(2 * m + yl).max(1));
    let plot_h = f64::from(h_px.saturating_sub(2 * m + xl).max(1));
    let per_px = ((x1 - x0) / plot_w).max((y1 - y0) / plot_h);
    let (cx, cy) = (0.5 * (x0 + x1), 0.5 * (y0 + y1));
    let (hx, hy) = (0.5 * per_px * plot_w, 0.5 * per_px * plot_h);
    let mut chart = ChartBuilder::on(&root)
        .margin(m)
        .x_label_area_size(xl)
        .y_label_area_size(yl)
        .build_cartesian_2d((cx - hx)..(cx + hx), (cy - hy)..(cy + hy))
        .map_err(|e| err(path, e))?;
    chart
        .configure_mesh()
        .x_desc("x (m)")
        .y_desc("y (m)")
        .x_label_formatter(&tick_label)
        .y_label_formatter(&tick_label)
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
            "COM held at rest here (darker = larger robustness margin, up to {finite_max:.0} N)"
        ))
        .legend(move |(x, y)| Rectangle::new([(x, y - 5), (x + 12, y + 5)], green.filled()));
    if !d.region.is_empty() {
        let outline: Vec<(f64, f64)> = d
            .region
            .iter()
            .chain(d.region.first())
            .map(|v| (v[0], v[1]))
            .collect();
        let dark = RGBColor(20, 80, 40);
        chart
            .draw_series(std::iter::once(PathElement::new(
                outline,
                dark.stroke_width(2),
            )))
            .map_err(|e| err(path, e))?
            .label("edge of the static region (eq 2)")
            .legend(move |(x, y)| {
                PathElement::new(vec![(x, y), (x + 16, y)], dark.stroke_width(2))
            });
    }
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
    let (xr, yr) = ((cx - hx, cx + hx), (cy - hy, cy + hy));
    let clamp = |p: &[f64; 3]| (p[0].clamp(xr.0, xr.1), p[1].clamp(yr.0, yr.1));
    chart
        .draw_series(
            d.points
                .iter()
                .filter(|(_, ok)| *ok)
                .map(|(p, _)| Circle::new(clamp(p), 3, blue.filled())),
        )
        .map_err(|e| err(path, e))?
        .label("evaluated COM state: in equilibrium")
        .legend(move |(x, y)| Circle::new((x + 6, y), 3, blue.filled()));
    chart
        .draw_series(
            d.points
                .iter()
                .filter(|(_, ok)| !*ok)
                .map(|(p, _)| Circle::new(clamp(p), 3, RED.filled())),
        )
        .map_err(|e| err(path, e))?
        .label("evaluated COM state: not in equilibrium")
        .legend(|(x, y)| Circle::new((x + 6, y), 3, RED.filled()));
    draw_legend(&mut chart, path)?;
    root.present().map_err(|e| err(path, e))?;
    Ok(())
}
