//! `FILE.png` of `edit`: a side view (x–z) and a top view (x–y) of the planned COM path,
//! the footprints (planned contact points) and a stick figure every 0.1 s, equal scales.

use std::path::Path;

use plotters::coord::Shift;
use plotters::prelude::*;

use super::{draw_legend, err, register_font, PlotError};

/// What the edit plot shows (world frame, m).
#[derive(Debug, Clone, PartialEq, Default)]
pub struct EditPlot {
    /// Title.
    pub title: String,
    /// Planned COM per output frame.
    pub com: Vec<[f64; 3]>,
    /// Planned contact point of each stance.
    pub footprints: Vec<[f64; 3]>,
    /// Stick-figure bones (parent, child) of the sampled poses.
    pub bones: Vec<[[f64; 3]; 2]>,
}

/// Pixel size of one view.
const VIEW_PX: (u32, u32) = (900, 420);

fn view(
    area: &DrawingArea<BitMapBackend<'_>, Shift>,
    path: &Path,
    d: &EditPlot,
    caption: &str,
    k: usize,
) -> Result<(), PlotError> {
    let pr = |p: &[f64; 3]| (p[0], p[k]);
    let pts = d
        .com
        .iter()
        .chain(&d.footprints)
        .chain(d.bones.iter().flatten());
    let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
    for p in pts.filter(|p| p.iter().all(|v| v.is_finite())) {
        let q = pr(p);
        lo = [lo[0].min(q.0), lo[1].min(q.1)];
        hi = [hi[0].max(q.0), hi[1].max(q.1)];
    }
    if !lo[0].is_finite() {
        (lo, hi) = ([-1.0; 2], [1.0; 2]);
    }
    // Equal metres per pixel on both axes.
    let (w, h) = (f64::from(VIEW_PX.0 - 90), f64::from(VIEW_PX.1 - 90));
    let per_px = ((hi[0] - lo[0]).max(0.2) * 1.1 / w).max((hi[1] - lo[1]).max(0.2) * 1.1 / h);
    let mid = [0.5 * (lo[0] + hi[0]), 0.5 * (lo[1] + hi[1])];
    let (hw, hh) = (0.5 * per_px * w, 0.5 * per_px * h);
    let mut chart = ChartBuilder::on(area)
        .caption(caption, ("sans-serif", 18))
        .margin(10)
        .x_label_area_size(40)
        .y_label_area_size(50)
        .build_cartesian_2d((mid[0] - hw)..(mid[0] + hw), (mid[1] - hh)..(mid[1] + hh))
        .map_err(|e| err(path, e))?;
    let y_desc = if k == 2 { "z (m)" } else { "y (m)" };
    chart
        .configure_mesh()
        .x_desc("x (m)")
        .y_desc(y_desc)
        .label_style(("sans-serif", 13))
        .draw()
        .map_err(|e| err(path, e))?;
    let grey = RGBColor(150, 150, 150);
    chart
        .draw_series(
            d.bones
                .iter()
                .map(|b| PathElement::new(vec![pr(&b[0]), pr(&b[1])], grey.stroke_width(1))),
        )
        .map_err(|e| err(path, e))?;
    let blue = RGBColor(30, 90, 200);
    chart
        .draw_series(LineSeries::new(d.com.iter().map(pr), blue.stroke_width(2)))
        .map_err(|e| err(path, e))?
        .label("planned COM")
        .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 16, y)], blue.stroke_width(2)));
    chart
        .draw_series(
            d.footprints
                .iter()
                .map(|p| Cross::new(pr(p), 6, RED.stroke_width(2))),
        )
        .map_err(|e| err(path, e))?
        .label("footprints (planned contact points)")
        .legend(|(x, y)| Cross::new((x + 8, y), 6, RED.stroke_width(2)));
    draw_legend(&mut chart, path)?;
    Ok(())
}

/// Draws the edit plot: side view (x–z) above, top view (x–y) below.
///
/// # Errors
/// The file cannot be written or the font cannot be used.
pub fn edit_png(path: &Path, d: &EditPlot) -> Result<(), PlotError> {
    register_font();
    let root = BitMapBackend::new(path, (VIEW_PX.0, 2 * VIEW_PX.1 + 40)).into_drawing_area();
    root.fill(&WHITE).map_err(|e| err(path, e))?;
    let root = root
        .titled(&d.title, ("sans-serif", 20))
        .map_err(|e| err(path, e))?;
    let (top, bottom) = root.split_vertically(VIEW_PX.1);
    view(&top, path, d, "Side view (x–z)", 2)?;
    view(&bottom, path, d, "Top view (x–y)", 1)?;
    root.present().map_err(|e| err(path, e))?;
    Ok(())
}
