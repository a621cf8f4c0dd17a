//! Plots (PNG) of query results, drawn with plotters and an embedded font, so they render
//! on a machine without fontconfig or system fonts.
//!
//! The font is DejaVu Sans (Bitstream Vera licence, see `DejaVuSans-LICENSE.txt`).

use std::path::Path;
use std::sync::Once;

use plotters::coord::types::RangedCoordf64;
use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::FontStyle;

use crate::query::map::JumpMap;

pub mod clip;
pub mod edit;
pub mod equilibrium;
pub mod runs;
pub mod stance;
pub mod trajectory;

/// DejaVu Sans, registered as the `sans-serif` family on first use.
static FONT: &[u8] = include_bytes!("DejaVuSans.ttf");
static REGISTER: Once = Once::new();

fn register_font() {
    REGISTER.call_once(|| {
        // The bytes are a valid TTF (checked by the plot test); a failure leaves plotters
        // without a font and its text calls return an error, not a panic.
        let _ = plotters::style::register_font("sans-serif", FontStyle::Normal, FONT);
    });
}

/// Errors of the plot writers.
#[derive(Debug, thiserror::Error)]
#[error("{path}: cannot draw plot: {msg}")]
pub struct PlotError {
    /// The output file.
    pub path: String,
    /// What failed.
    pub msg: String,
}

/// Draws a PNG with `draw` under a temporary name beside `path`, then renames it into
/// place, so a failed draw leaves no file and an earlier one survives
/// ([`crate::library::atomic::write_file_atomic`]).
///
/// # Errors
/// The drawing fails or the rename does.
pub fn write_png(
    path: &Path,
    draw: impl FnOnce(&Path) -> Result<(), PlotError>,
) -> anyhow::Result<()> {
    crate::library::atomic::write_file_atomic(path, |tmp| draw(tmp).map_err(anyhow::Error::from))
}

/// A picture's answer to its question, drawn as the line under its title: dark green when
/// the answer is good news (feasible, valid, ballistic), dark red when it is not.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Verdict {
    /// The answer in words, with numbers and units.
    pub text: String,
    /// Good news.
    pub ok: bool,
}

impl Verdict {
    /// A verdict `text`, good news when `ok`.
    pub fn new(text: impl Into<String>, ok: bool) -> Verdict {
        Verdict {
            text: text.into(),
            ok,
        }
    }
}

/// Font size of a picture's title line, px (the largest; shrunk to fit the width).
pub const TITLE_FONT_PX: u32 = 22;
/// Font size of a picture's verdict line, px (the largest; shrunk to fit the width).
pub const VERDICT_FONT_PX: u32 = 18;
/// Smallest font a title or verdict line is shrunk to, px.
const MIN_FONT_PX: u32 = 11;
const GOOD: RGBColor = RGBColor(0, 110, 50);
const BAD: RGBColor = RGBColor(190, 0, 0);

/// The largest font size from `size` down to [`MIN_FONT_PX`] at which `text` fits the
/// width of `area` with 10 px either side.
fn fitted_font(area: &DrawingArea<BitMapBackend<'_>, Shift>, text: &str, size: u32) -> u32 {
    let width = area.dim_in_pixel().0;
    (MIN_FONT_PX..=size)
        .rev()
        .find(|&s| {
            let style: TextStyle = ("sans-serif", s).into();
            area.estimate_text_size(text, &style)
                .is_ok_and(|(w, _)| w + 20 <= width)
        })
        .unwrap_or(MIN_FONT_PX)
}

/// Draws `title` and, under it, the `verdict` (coloured) across the top of `area`, each
/// shrunk to fit the width; returns the area below them.
///
/// # Errors
/// The font cannot be used.
fn titled<'a>(
    area: &DrawingArea<BitMapBackend<'a>, Shift>,
    path: &Path,
    title: &str,
    verdict: &Verdict,
) -> Result<DrawingArea<BitMapBackend<'a>, Shift>, PlotError> {
    let size = fitted_font(area, title, TITLE_FONT_PX);
    let rest = area
        .titled(title, ("sans-serif", size))
        .map_err(|e| err(path, e))?;
    let size = fitted_font(&rest, &verdict.text, VERDICT_FONT_PX);
    let colour = if verdict.ok { GOOD } else { BAD };
    rest.titled(
        &verdict.text,
        ("sans-serif", size).into_font().color(&colour),
    )
    .map_err(|e| err(path, e))
}

/// The unit horizontal direction of travel of a path of points (world x, y): from its
/// first point to its last when they are at least `min_travel_m` apart, else `None`.
pub fn travel_direction(path: &[[f64; 3]], min_travel_m: f64) -> Option<[f64; 2]> {
    let (a, b) = (path.first()?, path.last()?);
    let d = [b[0] - a[0], b[1] - a[1]];
    let n = d[0].hypot(d[1]);
    (n >= min_travel_m && n.is_finite()).then(|| [d[0] / n, d[1] / n])
}

fn err(path: &Path, e: impl std::fmt::Display) -> PlotError {
    PlotError {
        path: path.display().to_string(),
        msg: e.to_string(),
    }
}

/// The series legend of a chart, in its upper-right corner on a light box.
fn draw_legend<'a, 'b: 'a>(
    chart: &mut ChartContext<'a, BitMapBackend<'b>, Cartesian2d<RangedCoordf64, RangedCoordf64>>,
    path: &Path,
) -> Result<(), PlotError> {
    chart
        .configure_series_labels()
        .background_style(WHITE.mix(0.85))
        .border_style(BLACK)
        .label_font(("sans-serif", 13))
        .position(SeriesLabelPosition::UpperRight)
        .draw()
        .map_err(|e| err(path, e))
}

/// The mesh of a value panel: `x_desc` against `y_desc`, no light grid lines, 13 px labels.
fn value_mesh(
    chart: &mut Chart<'_, '_>,
    path: &Path,
    x_desc: &str,
    y_desc: &str,
) -> Result<(), PlotError> {
    chart
        .configure_mesh()
        .x_desc(x_desc)
        .y_desc(y_desc)
        .light_line_style(WHITE.mix(0.0))
        .label_style(("sans-serif", 13))
        .draw()
        .map_err(|e| err(path, e))
}

/// Per (distance bin, height row): pairs feasible by both, approx only, exact only.
struct Binned {
    d0: f64,
    width: f64,
    n_d: usize,
    cells: Vec<[u32; 3]>,
    max_exact: u32,
}

fn bin(map: &JumpMap, width: f64) -> Option<Binned> {
    let n_u = map.speeds.len();
    let mut range = (f64::INFINITY, f64::NEG_INFINITY);
    let each = |f: &mut dyn FnMut(usize, f64, bool, bool)| {
        for p in &map.pairs {
            for (r, row) in p.rows.iter().enumerate() {
                let Some((d, c, _)) = row else { continue };
                for (q, &u) in map.speeds.iter().enumerate() {
                    let (a, e) = (p.approx[r * n_u + q], p.exact[r * n_u + q]);
                    if a || e {
                        f(r, u * d + c, a, e);
                    }
                }
            }
        }
    };
    each(&mut |_, d, _, _| range = (range.0.min(d), range.1.max(d)));
    if !range.0.is_finite() {
        return None;
    }
    let d0 = (range.0 / width).floor() * width;
    let n_d = ((range.1 - d0) / width).floor() as usize + 1;
    let mut cells = vec![[0u32; 3]; n_d * map.heights.len()];
    each(&mut |r, d, a, e| {
        let k = (((d - d0) / width) as usize).min(n_d - 1);
        let kind = match (a, e) {
            (true, true) => 0,
            (true, false) => 1,
            _ => 2,
        };
        cells[r * n_d + k][kind] += 1;
    });
    let max_exact = cells.iter().map(|c| c[0] + c[2]).max().unwrap_or(0);
    Some(Binned {
        d0,
        width,
        n_d,
        cells,
        max_exact,
    })
}

type Chart<'a, 'b> =
    ChartContext<'a, BitMapBackend<'b>, Cartesian2d<RangedCoordf64, RangedCoordf64>>;

/// One panel: distance (m) against apex height (m), with a mesh and axis names.
fn panel<'a, 'b>(
    area: &'a DrawingArea<BitMapBackend<'b>, Shift>,
    path: &Path,
    caption: &str,
    (x, y): (std::ops::Range<f64>, std::ops::Range<f64>),
) -> Result<Chart<'a, 'b>, PlotError> {
    let mut chart = ChartBuilder::on(area)
        .caption(caption, ("sans-serif", 18))
        .margin(12)
        .x_label_area_size(45)
        .y_label_area_size(60)
        .build_cartesian_2d(x, y)
        .map_err(|e| err(path, e))?;
    chart
        .configure_mesh()
        .x_desc("jump distance d_jump (m)")
        .y_desc("apex height above the liftoff contact (m)")
        .label_style(("sans-serif", 14))
        .draw()
        .map_err(|e| err(path, e))?;
    Ok(chart)
}

/// The shade of a cell holding `n` of at most `max` feasible (pair, cell)s.
fn shade(n: u32, max: u32) -> f64 {
    0.15 + 0.85 * f64::from(n) / f64::from(max.max(1))
}

/// `jump_map.png`: left, how many liftoff/landing pairs can make each (distance, height)
/// by the exact check (Figure 4 over the pool), with a colour bar and the `recorded`
/// jumps (distance, height; m) marked ×; right, where the fast filters and the exact
/// check agree (Figure 5). `scope` names the pool in the title (`all characters`, a
/// `character_id`).
///
/// # Errors
/// The file cannot be written or the font cannot be used.
pub fn jump_map_png(
    path: &Path,
    map: &JumpMap,
    scope: &str,
    recorded: &[(f64, f64)],
) -> Result<(), PlotError> {
    register_font();
    let root = BitMapBackend::new(path, (1500, 650)).into_drawing_area();
    root.fill(&WHITE).map_err(|e| err(path, e))?;
    let title = format!(
        "Jump feasibility map ({scope}): {} liftoff × landing pairs, IoU(approx, exact) = {:.3}",
        map.pairs.len(),
        map.agreement.iou()
    );
    let root = root
        .titled(&title, ("sans-serif", 22))
        .map_err(|e| err(path, e))?;
    let (left, right) = root.split_horizontally(750);
    let (left, bar) = left.split_horizontally(670);
    let (h0, h1) = (
        map.heights.first().copied().unwrap_or(0.0),
        map.heights.last().copied().unwrap_or(1.0),
    );
    let dh = map.heights.get(1).map_or(0.02, |h| h - h0);
    let b = bin(map, 0.05);
    let (x0, x1) = b
        .as_ref()
        .map_or((0.0, 1.0), |b| (b.d0, b.d0 + b.n_d as f64 * b.width));
    let ranges = (x0..x1, (h0 - dh / 2.0)..(h1 + dh / 2.0));
    let mut l = panel(
        &left,
        path,
        "Exact check: feasible pairs per cell",
        ranges.clone(),
    )?;
    let mut r = panel(
        &right,
        path,
        "Fast filters (eq 10, 12) vs exact check (§7.4)",
        ranges,
    )?;
    if let Some(b) = &b {
        draw_cells(&mut l, &mut r, path, b, map.heights.len(), (h0, dh))?;
    }
    if !recorded.is_empty() {
        draw_recorded(&mut l, path, recorded)?;
    }
    colour_bar(&bar, path, b.as_ref().map_or(0, |b| b.max_exact))?;
    for chart in [&mut l, &mut r] {
        chart
            .configure_series_labels()
            .background_style(WHITE.mix(0.85))
            .border_style(BLACK)
            .label_font(("sans-serif", 14))
            .position(SeriesLabelPosition::UpperRight)
            .draw()
            .map_err(|e| err(path, e))?;
    }
    root.present().map_err(|e| err(path, e))?;
    Ok(())
}

/// The binned cells: shaded by exact-feasible count on the left panel, by agreement of
/// the fast filters and the exact check on the right; `(h0, dh)` is the first height row
/// and the row spacing (m).
fn draw_cells(
    l: &mut Chart<'_, '_>,
    r: &mut Chart<'_, '_>,
    path: &Path,
    b: &Binned,
    n_heights: usize,
    (h0, dh): (f64, f64),
) -> Result<(), PlotError> {
    let rect = |k: usize, row: usize| {
        let x = b.d0 + k as f64 * b.width;
        let y = h0 + row as f64 * dh;
        [(x, y - dh / 2.0), (x + b.width, y + dh / 2.0)]
    };
    let colours = [
        RGBColor(46, 139, 87),
        RGBColor(255, 140, 0),
        RGBColor(65, 105, 225),
    ];
    let mut exact = Vec::new();
    let mut agree = Vec::new();
    for row in 0..n_heights {
        for k in 0..b.n_d {
            let c = b.cells[row * b.n_d + k];
            let n_exact = c[0] + c[2];
            if n_exact > 0 {
                let mix = shade(n_exact, b.max_exact);
                exact.push(Rectangle::new(rect(k, row), BLUE.mix(mix).filled()));
            }
            let kind = (0..3).max_by_key(|&i| (c[i], 3 - i)).unwrap_or(0);
            if c.iter().any(|&n| n > 0) {
                agree.push((kind, rect(k, row)));
            }
        }
    }
    l.draw_series(exact)
        .map_err(|e| err(path, e))?
        .label(format!(
            "darker = more feasible (pair, cell)s, max {}",
            b.max_exact
        ))
        .legend(|(x, y)| Rectangle::new([(x, y - 5), (x + 12, y + 5)], BLUE.filled()));
    let names = ["both feasible", "approx only", "exact only"];
    for (kind, name) in names.iter().enumerate() {
        let rects = agree
            .iter()
            .filter(|(k, _)| *k == kind)
            .map(|(_, c)| Rectangle::new(*c, colours[kind].filled()));
        let colour = colours[kind];
        r.draw_series(rects)
            .map_err(|e| err(path, e))?
            .label(*name)
            .legend(move |(x, y)| Rectangle::new([(x, y - 5), (x + 12, y + 5)], colour.filled()));
    }
    Ok(())
}

/// The recorded jumps (distance, height; m) inside the panel, marked ×.
fn draw_recorded(
    l: &mut Chart<'_, '_>,
    path: &Path,
    recorded: &[(f64, f64)],
) -> Result<(), PlotError> {
    let (x, y) = (l.x_range(), l.y_range());
    let inside: Vec<(f64, f64)> = recorded
        .iter()
        .copied()
        .filter(|(d, h)| x.contains(d) && y.contains(h))
        .collect();
    l.draw_series(
        inside
            .iter()
            .map(|&p| Cross::new(p, 7, BLACK.stroke_width(2))),
    )
    .map_err(|e| err(path, e))?
    .label(format!(
        "recorded jump ({} of {})",
        inside.len(),
        recorded.len()
    ))
    .legend(|(x, y)| Cross::new((x + 6, y), 5, BLACK.stroke_width(2)));
    Ok(())
}

/// The colour bar of the exact panel: feasible (pair, cell)s per cell, 1 … `max`.
fn colour_bar(
    area: &DrawingArea<BitMapBackend<'_>, Shift>,
    path: &Path,
    max: u32,
) -> Result<(), PlotError> {
    let top = max.max(1);
    let mut chart = ChartBuilder::on(area)
        .margin_top(50)
        .margin_bottom(57)
        .margin_right(8)
        .y_label_area_size(45)
        .build_cartesian_2d(0.0..1.0, 0.5..(f64::from(top) + 0.5))
        .map_err(|e| err(path, e))?;
    chart
        .configure_mesh()
        .disable_x_mesh()
        .disable_x_axis()
        .disable_y_mesh()
        .y_labels(6)
        .y_label_formatter(&|v| format!("{v:.0}"))
        .y_desc("pairs per cell")
        .label_style(("sans-serif", 12))
        .draw()
        .map_err(|e| err(path, e))?;
    chart
        .draw_series((1..=top).map(|n| {
            let y = f64::from(n);
            Rectangle::new(
                [(0.0, y - 0.5), (1.0, y + 0.5)],
                BLUE.mix(shade(n, top)).filled(),
            )
        }))
        .map_err(|e| err(path, e))?;
    Ok(())
}
