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
/// ([`crate::library::storage::atomic::write_file_atomic`]).
///
/// # Errors
/// The drawing fails or the rename does.
pub fn write_png(
    path: &Path,
    draw: impl FnOnce(&Path) -> Result<(), PlotError>,
) -> anyhow::Result<()> {
    crate::library::storage::atomic::write_file_atomic(path, |tmp| {
        draw(tmp).map_err(anyhow::Error::from)
    })
}

/// A picture's answer to its question, drawn as the line under its title: dark green when
/// the answer is good news (feasible, valid, ballistic), dark red when it is not.
#[derive(Debug, Clone, PartialEq, Eq, Default)]
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

/// A tick label of a decimal axis: at most three decimals, trailing zeros dropped
/// (`2400`, not `2400.0`), and never `-0` (plotters prints `-0.0` at a rounded zero).
fn tick_label(v: &f64) -> String {
    let v = if v.abs() < 5e-4 { 0.0 } else { *v };
    let s = format!("{v:.3}");
    let s = s.trim_end_matches('0').trim_end_matches('.');
    s.to_string()
}

/// The mesh of a value panel: `x_desc` against `y_desc`, no light grid lines, 13 px labels
/// ([`tick_label`]).
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
        .x_label_formatter(&tick_label)
        .y_label_formatter(&tick_label)
        .light_line_style(WHITE.mix(0.0))
        .label_style(("sans-serif", 13))
        .draw()
        .map_err(|e| err(path, e))
}

/// Per (distance bin, height row): the pairs with a cell there feasible by both, approx
/// only, exact only; the pairs with any cell there; the pairs feasible there (exact).
struct Binned {
    d0: f64,
    width: f64,
    n_d: usize,
    cells: Vec<[u32; 5]>,
    max_exact: u32,
}

/// The distance bins of a map, at least `width` wide, wider when the grid's speeds are
/// farther apart than that: a cell's distance is `d = u · D + C` (per pair and height
/// row), so consecutive speeds land `Δu · |D|` apart, and bins narrower than that left
/// empty stripes inside the feasible area that read as "no pair makes this jump". The
/// spacing is taken over the rows that have a feasible cell (other rows' `|D|` reach
/// 66 s on the demo, where the stance times stretch with speed), rounded up to a
/// multiple of `width`, and capped at [`MAX_BIN_WIDENING`] × `width`.
fn bin(map: &JumpMap, width: f64) -> Option<Binned> {
    let n_u = map.speeds.len();
    let du = map
        .speeds
        .windows(2)
        .map(|w| (w[1] - w[0]).abs())
        .fold(0.0, f64::max);
    let mut spread = 0.0f64;
    for p in &map.pairs {
        for (r, row) in p.rows.iter().enumerate() {
            let feasible = (0..n_u).any(|q| p.approx[r * n_u + q] || p.exact[r * n_u + q]);
            if let (Some((d, _, _)), true) = (row, feasible) {
                if (d.abs() * du).is_finite() {
                    spread = spread.max(d.abs() * du);
                }
            }
        }
    }
    let widening = (spread / width - 1e-9).ceil().clamp(1.0, MAX_BIN_WIDENING);
    let width = width * widening;
    let mut range = (f64::INFINITY, f64::NEG_INFINITY);
    let each = |f: &mut dyn FnMut(usize, usize, f64, bool, bool)| {
        for (i, p) in map.pairs.iter().enumerate() {
            for (r, row) in p.rows.iter().enumerate() {
                let Some((d, c, _)) = row else { continue };
                for (q, &u) in map.speeds.iter().enumerate() {
                    let (a, e) = (p.approx[r * n_u + q], p.exact[r * n_u + q]);
                    f(i, r, u * d + c, a, e);
                }
            }
        }
    };
    each(&mut |_, _, d, a, e| {
        if a || e {
            range = (range.0.min(d), range.1.max(d));
        }
    });
    if !range.0.is_finite() {
        return None;
    }
    let d0 = (range.0 / width).floor() * width;
    let n_d = ((range.1 - d0) / width).floor() as usize + 1;
    // Each pair counts once per bin and kind, however many of its speeds land there.
    let mut cells = vec![[0u32; 5]; n_d * map.heights.len()];
    let mut counted = vec![[usize::MAX; 5]; cells.len()];
    each(&mut |i, r, d, a, e| {
        let k = (d - d0) / width;
        if !(k >= 0.0 && k < n_d as f64) {
            return;
        }
        let at = r * n_d + k as usize;
        let kinds: &[usize] = match (a, e) {
            (true, true) => &[0, 3, 4],
            (true, false) => &[1, 3],
            (false, true) => &[2, 3, 4],
            (false, false) => &[3],
        };
        for &kind in kinds {
            if counted[at][kind] != i {
                counted[at][kind] = i;
                cells[at][kind] += 1;
            }
        }
    });
    let max_exact = cells.iter().map(|c| c[4]).max().unwrap_or(0);
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

/// Pixel size of `jump_map.png` (and of the `--diagnostics` agreement picture).
pub const JUMP_MAP_PX: (u32, u32) = (1100, 760);
/// Narrowest distance bin of the jump map, m (wider when the speeds are coarser, see `bin`).
pub const JUMP_MAP_BIN_M: f64 = 0.05;
/// Most a distance bin is widened beyond [`JUMP_MAP_BIN_M`] to close the gaps between
/// the distances of consecutive speeds (factor).
pub const MAX_BIN_WIDENING: f64 = 4.0;
/// Most shades the jump map's legend lists (more pair counts share shades).
const MAX_LEGEND_SHADES: u32 = 6;

/// One panel: distance (m) against apex height (m), with a mesh and axis names.
fn panel<'a, 'b>(
    area: &'a DrawingArea<BitMapBackend<'b>, Shift>,
    path: &Path,
    caption: &str,
    (x, y): (std::ops::Range<f64>, std::ops::Range<f64>),
) -> Result<Chart<'a, 'b>, PlotError> {
    let mut chart = ChartBuilder::on(area)
        .caption(caption, ("sans-serif", 17))
        .margin(12)
        .x_label_area_size(45)
        .y_label_area_size(60)
        .build_cartesian_2d(x, y)
        .map_err(|e| err(path, e))?;
    chart
        .configure_mesh()
        .x_desc("jump distance d_jump (m)")
        .y_desc("apex height above the liftoff contact (m)")
        .light_line_style(WHITE.mix(0.0))
        .label_style(("sans-serif", 14))
        .draw()
        .map_err(|e| err(path, e))?;
    Ok(chart)
}

/// The shade of a cell holding `n` of at most `max` feasible (pair, cell)s.
fn shade(n: u32, max: u32) -> f64 {
    0.15 + 0.85 * f64::from(n) / f64::from(max.max(1))
}

/// The pair counts the legend shows: every count up to [`MAX_LEGEND_SHADES`], else that
/// many spread from 1 to `max`.
fn legend_counts(max: u32) -> Vec<u32> {
    if max <= MAX_LEGEND_SHADES {
        return (1..=max).collect();
    }
    let k = MAX_LEGEND_SHADES - 1;
    let mut v: Vec<u32> = (0..=k).map(|i| 1 + (i * (max - 1) + k / 2) / k).collect();
    v.dedup();
    v
}

/// The recorded jumps of a jump map as the picture places them: `(shown, outside,
/// infeasible)` — inside the grid, outside it, and inside it in a cell no pair makes.
fn recorded_counts(
    b: Option<&Binned>,
    map: &JumpMap,
    recorded: &[(f64, f64)],
) -> (usize, usize, usize) {
    let (h0, dh) = height_rows(map);
    let n_h = map.heights.len();
    let mut counts = (0, 0, 0);
    for &(d, h) in recorded {
        let row = ((h - h0) / dh + 0.5).floor();
        let cell = b.and_then(|b| {
            let k = ((d - b.d0) / b.width).floor();
            let inside = k >= 0.0 && (k as usize) < b.n_d && row >= 0.0 && (row as usize) < n_h;
            inside.then(|| b.cells[row as usize * b.n_d + k as usize])
        });
        match cell {
            None => counts.1 += 1,
            Some(c) if c[4] == 0 => {
                counts.0 += 1;
                counts.2 += 1;
            }
            Some(_) => counts.0 += 1,
        }
    }
    counts
}

/// The first height row and the row spacing of a map, m.
fn height_rows(map: &JumpMap) -> (f64, f64) {
    let h0 = map.heights.first().copied().unwrap_or(0.0);
    (h0, map.heights.get(1).map_or(0.02, |h| h - h0))
}

/// The verdict of the jump map: the highest and farthest jump some pair makes (exact
/// check), and whether the recorded jumps lie in the feasible area.
pub fn jump_map_verdict(map: &JumpMap, recorded: &[(f64, f64)]) -> Verdict {
    let b = bin(map, JUMP_MAP_BIN_M);
    let (h0, dh) = height_rows(map);
    let feasible = b.as_ref().map(|b| {
        let mut top = (f64::NEG_INFINITY, f64::NEG_INFINITY);
        for (i, c) in b.cells.iter().enumerate() {
            if c[4] > 0 {
                let (row, k) = (i / b.n_d, i % b.n_d);
                top.0 = top.0.max(h0 + row as f64 * dh);
                top.1 = top.1.max(b.d0 + (k + 1) as f64 * b.width);
            }
        }
        top
    });
    let (shown, outside, infeasible) = recorded_counts(b.as_ref(), map, recorded);
    let rec = match (recorded.len(), infeasible, outside) {
        (0, _, _) => String::new(),
        (_, 0, 0) => format!("; all {shown} recorded jump(s) in the feasible area"),
        (n, i, o) => {
            format!("; of {n} recorded jump(s), {i} in no pair's area, {o} outside the grid")
        }
    };
    match feasible {
        Some((h, d)) if h.is_finite() => {
            let h_top = map.heights.last().copied().unwrap_or(h);
            let at_least = if h >= h_top - 1e-9 { "at least " } else { "" };
            Verdict::new(
                format!(
                    "some pair makes jumps up to {at_least}{h:.2} m high and {d:.2} m far{rec}"
                ),
                true,
            )
        }
        _ => Verdict::new(format!("no pair makes any jump of the grid{rec}"), false),
    }
}

/// `jump_map.png`: which jumps (distance, apex height) can the library make? Each cell is
/// shaded by how many liftoff/landing pairs make it by the exact check (Figure 4 over the
/// pool), with the shades listed in the legend and the `recorded` jumps (distance,
/// height; m) marked ×. `scope` names the pool in the title (`all characters`, a
/// `character_id`). The fast filters' agreement with the exact check (Figure 5) is a
/// developer diagnostic: [`jump_map_agreement_png`].
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
    let root = BitMapBackend::new(path, JUMP_MAP_PX).into_drawing_area();
    root.fill(&WHITE).map_err(|e| err(path, e))?;
    let title = format!(
        "Which jumps can the library make? ({scope}: {} liftoff × landing pairs)",
        map.pairs.len()
    );
    let root = titled(&root, path, &title, &jump_map_verdict(map, recorded))?;
    let b = bin(map, JUMP_MAP_BIN_M);
    let mut chart = panel(
        &root,
        path,
        "shade: how many liftoff × landing pairs make the jump (exact check)",
        map_ranges(map, b.as_ref()),
    )?;
    if let Some(b) = &b {
        draw_exact_cells(&mut chart, path, b, map)?;
    }
    draw_recorded(&mut chart, path, map, b.as_ref(), recorded)?;
    draw_legend(&mut chart, path)?;
    root.present().map_err(|e| err(path, e))?;
    Ok(())
}

/// `jump_map_agreement.png` (`map jumps --diagnostics`): where the fast filters (eq 10,
/// 12 of the paper) and the exact check (§7.4) agree, per cell, with their IoU.
///
/// # Errors
/// The file cannot be written or the font cannot be used.
pub fn jump_map_agreement_png(path: &Path, map: &JumpMap, scope: &str) -> Result<(), PlotError> {
    register_font();
    let root = BitMapBackend::new(path, JUMP_MAP_PX).into_drawing_area();
    root.fill(&WHITE).map_err(|e| err(path, e))?;
    let iou = map.agreement.iou();
    let title = format!(
        "Diagnostic: do the fast filters (paper eq 10, 12) agree with the exact check? ({scope})"
    );
    let verdict = Verdict::new(
        format!(
            "IoU of the feasible cells = {iou:.3} (approx {}, exact {}, both {})",
            map.agreement.approx, map.agreement.exact, map.agreement.both
        ),
        iou >= AGREEMENT_OK_IOU,
    );
    let root = titled(&root, path, &title, &verdict)?;
    let b = bin(map, JUMP_MAP_BIN_M);
    let mut chart = panel(
        &root,
        path,
        "per cell, the verdict most (pair, cell)s give",
        map_ranges(map, b.as_ref()),
    )?;
    if let Some(b) = &b {
        draw_agreement_cells(&mut chart, path, b, map)?;
    }
    draw_legend(&mut chart, path)?;
    root.present().map_err(|e| err(path, e))?;
    Ok(())
}

/// The agreement picture's verdict is good news at or above this IoU.
pub const AGREEMENT_OK_IOU: f64 = 0.95;

/// The axes of a map's panels: the binned distances and the height rows (m).
fn map_ranges(map: &JumpMap, b: Option<&Binned>) -> (std::ops::Range<f64>, std::ops::Range<f64>) {
    let (h0, dh) = height_rows(map);
    let h1 = map.heights.last().copied().unwrap_or(1.0);
    let (x0, x1) = b.map_or((0.0, 1.0), |b| (b.d0, b.d0 + b.n_d as f64 * b.width));
    (x0..x1, (h0 - dh / 2.0)..(h1 + dh / 2.0))
}

/// The rectangle of distance bin `k`, height row `row`.
fn cell_rect(b: &Binned, map: &JumpMap, k: usize, row: usize) -> [(f64, f64); 2] {
    let (h0, dh) = height_rows(map);
    let x = b.d0 + k as f64 * b.width;
    let y = h0 + row as f64 * dh;
    [(x, y - dh / 2.0), (x + b.width, y + dh / 2.0)]
}

/// The cells shaded by their exact-feasible pair count, with one legend entry per shade.
fn draw_exact_cells(
    chart: &mut Chart<'_, '_>,
    path: &Path,
    b: &Binned,
    map: &JumpMap,
) -> Result<(), PlotError> {
    let grey = RGBColor(215, 215, 215);
    let checked = (0..b.cells.len()).filter_map(|i| {
        let c = b.cells[i];
        (c[3] > 0 && c[4] == 0).then(|| {
            let r = cell_rect(b, map, i % b.n_d, i / b.n_d);
            Rectangle::new(r, grey.filled())
        })
    });
    chart
        .draw_series(checked)
        .map_err(|e| err(path, e))?
        .label("checked: no pair makes the jump (white: not on the grid)")
        .legend(move |(x, y)| Rectangle::new([(x, y - 6), (x + 14, y + 6)], grey.filled()));
    let cells = (0..b.cells.len()).filter_map(|i| {
        let c = b.cells[i];
        let n = c[4];
        (n > 0).then(|| {
            let r = cell_rect(b, map, i % b.n_d, i / b.n_d);
            Rectangle::new(r, BLUE.mix(shade(n, b.max_exact)).filled())
        })
    });
    chart.draw_series(cells).map_err(|e| err(path, e))?;
    let counts = legend_counts(b.max_exact);
    let approx = counts.len() < b.max_exact as usize;
    for n in counts {
        let colour = BLUE.mix(shade(n, b.max_exact));
        let label = match (n, approx) {
            (1, _) => "1 pair makes the jump".to_string(),
            (n, false) => format!("{n} pairs make the jump"),
            (n, true) => format!("about {n} pairs make the jump"),
        };
        chart
            .draw_series(std::iter::empty::<Rectangle<(f64, f64)>>())
            .map_err(|e| err(path, e))?
            .label(label)
            .legend(move |(x, y)| Rectangle::new([(x, y - 6), (x + 14, y + 6)], colour.filled()));
    }
    Ok(())
}

/// The cells coloured by the verdict most of their (pair, cell)s give.
fn draw_agreement_cells(
    chart: &mut Chart<'_, '_>,
    path: &Path,
    b: &Binned,
    map: &JumpMap,
) -> Result<(), PlotError> {
    let colours = [
        RGBColor(46, 139, 87),
        RGBColor(255, 140, 0),
        RGBColor(65, 105, 225),
    ];
    let names = [
        "both feasible",
        "fast filters only (false positive)",
        "exact check only (false negative)",
    ];
    for (kind, name) in names.iter().enumerate() {
        let rects = (0..b.cells.len()).filter_map(|i| {
            let c = b.cells[i];
            let most = (0..3).max_by_key(|&j| (c[j], 3 - j)).unwrap_or(0);
            (c[..3].iter().any(|&n| n > 0) && most == kind).then(|| {
                Rectangle::new(
                    cell_rect(b, map, i % b.n_d, i / b.n_d),
                    colours[kind].filled(),
                )
            })
        });
        let colour = colours[kind];
        chart
            .draw_series(rects)
            .map_err(|e| err(path, e))?
            .label(*name)
            .legend(move |(x, y)| Rectangle::new([(x, y - 6), (x + 14, y + 6)], colour.filled()));
    }
    Ok(())
}

/// The recorded jumps (distance, height; m) inside the panel, marked ×, with a legend
/// entry that says what they are and how many fall outside the grid.
fn draw_recorded(
    chart: &mut Chart<'_, '_>,
    path: &Path,
    map: &JumpMap,
    b: Option<&Binned>,
    recorded: &[(f64, f64)],
) -> Result<(), PlotError> {
    if recorded.is_empty() {
        return Ok(());
    }
    let (x, y) = (chart.x_range(), chart.y_range());
    let inside = recorded
        .iter()
        .copied()
        .filter(|(d, h)| x.contains(d) && y.contains(h));
    let (_, outside, _) = recorded_counts(b, map, recorded);
    let more = if outside > 0 {
        format!(", {outside} more outside the grid")
    } else {
        String::new()
    };
    chart
        .draw_series(inside.map(|p| Cross::new(p, 7, BLACK.stroke_width(2))))
        .map_err(|e| err(path, e))?
        .label(format!(
            "a jump as recorded (its distance, apex height){more}"
        ))
        .legend(|(x, y)| Cross::new((x + 7, y), 5, BLACK.stroke_width(2)));
    Ok(())
}
