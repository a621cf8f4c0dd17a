//! `query run --png`: at which speeds can the library's run cycles run, and which limit
//! stops them? Table 1 of the paper, with the gait law's times, over the target speed:
//! (a) each stance's contact time and step period, (b) the cycle's peak force against
//! `F_max`, (c) the friction the cycle needs, `mu_min`, against the friction limit μ, and
//! (d) the leg extension extremes `ext_min`, `ext_max` against `χ_min`, `χ_max`. One colour
//! per cycle, named in the legend row, each with its own marker; a later cycle is drawn
//! thinner on top of an earlier one, so cycles whose lines coincide (two stances of one
//! clip) both stay visible; limits dashed in the cycle's colour. An infeasible
//! (cycle, speed) is marked with a red cross and the violated limit's name on the panel of
//! that limit only; the verdict line says up to which speed every cycle is feasible.

use std::path::Path;

use plotters::coord::types::RangedCoordf64;
use plotters::prelude::*;

use plotters::coord::Shift;
use plotters::style::text_anchor::{HPos, Pos, VPos};

use super::{err, register_font, titled, value_mesh, PlotError, Verdict};

/// One cycle at one speed, as the figure needs it.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct RunPoint {
    /// Index of the cycle (one colour each).
    pub cycle: usize,
    /// The cycle's name in the legend (its first stance id).
    pub cycle_name: String,
    /// Target speed, m/s.
    pub speed_mps: f64,
    /// Contact time of each solved stance, s.
    pub contact_s: Vec<f64>,
    /// Step period (apex to apex) of each solved stance, s.
    pub step_s: Vec<f64>,
    /// The cycle's peak force (both stances solved), N.
    pub peak_n: Option<f64>,
    /// The force limit `F_max` of the cycle's first stance, N.
    pub f_max_n: f64,
    /// Friction the cycle needs (both stances solved), –.
    pub mu_min: Option<f64>,
    /// Shortest and longest COM–contact distance, m.
    pub ext_min_m: Option<f64>,
    /// Longest COM–contact distance, m.
    pub ext_max_m: Option<f64>,
    /// The limits `(μ, χ_min, χ_max)` of the cycle's first stance (–, m, m).
    pub limits: (f64, f64, f64),
    /// Feasible by the exact check.
    pub feasible: bool,
    /// The violated constraint (`friction`, `extension_max`, …) when infeasible.
    pub violated: Option<String>,
}

/// One colour per cycle (no red: red marks infeasible answers); more cycles repeat them.
const PALETTE: [RGBColor; 8] = [
    RGBColor(31, 119, 180),
    RGBColor(44, 160, 44),
    RGBColor(148, 103, 189),
    RGBColor(140, 86, 75),
    RGBColor(23, 190, 207),
    RGBColor(188, 189, 34),
    RGBColor(255, 127, 14),
    RGBColor(127, 127, 127),
];

/// Pixel size of the figure.
pub const RUNS_PLOT_PX: (u32, u32) = (1100, 1450);
/// Height of the legend row under the title, px.
const LEGEND_ROW_PX: u32 = 60;
/// Panels of the figure, in order: (a) times, (b) peak force, (c) friction, (d) extension
/// (`query run --help` names them).
pub const N_PANELS: usize = 4;

/// The panel that shows the limit a violation names (`<stance_id>: friction`): (b) for
/// `force`, (c) for `friction`, (d) for `extension_min`/`extension_max`, (a) for anything
/// else (a stance without a solution, a negative β).
pub fn panel_of(violated: &str) -> usize {
    match violated.rsplit(": ").next().unwrap_or(violated) {
        "force" => 1,
        "friction" => 2,
        "extension_min" | "extension_max" => 3,
        _ => 0,
    }
}

/// The violated limit's name of an infeasible point (`friction`, …; `no solution` when a
/// stance did not solve).
fn violation_name(p: &RunPoint) -> &str {
    let why = p.violated.as_deref().unwrap_or("infeasible");
    let name = why.rsplit(": ").next().unwrap_or(why);
    if panel_of(why) == 0 && !matches!(name, "beta_negative" | "unilateral") {
        "no solution"
    } else {
        name
    }
}

/// Speeds as text: a list of up to 3, else their range (m/s).
fn speeds_text(mut v: Vec<f64>) -> String {
    v.sort_by(f64::total_cmp);
    v.dedup();
    match v.as_slice() {
        [] => String::new(),
        [a, .., b] if v.len() > 3 => format!("{a:.1}–{b:.1} m/s"),
        _ => {
            let list: Vec<String> = v.iter().map(|x| format!("{x:.1}")).collect();
            format!("{} m/s", list.join(", "))
        }
    }
}

/// The figure's verdict: up to which speed every cycle is feasible, and which limits stop
/// the others at which speeds.
pub fn runs_verdict(points: &[RunPoint]) -> Verdict {
    let bad: Vec<&RunPoint> = points.iter().filter(|p| !p.feasible).collect();
    let speeds = || points.iter().map(|p| p.speed_mps).collect::<Vec<f64>>();
    if points.is_empty() {
        return Verdict::new("no answer to draw", false);
    }
    if bad.is_empty() {
        return Verdict::new(
            format!(
                "every cycle feasible at every speed ({})",
                speeds_text(speeds())
            ),
            true,
        );
    }
    let first_bad = bad
        .iter()
        .map(|p| p.speed_mps)
        .fold(f64::INFINITY, f64::min);
    let all_ok: Vec<f64> = speeds().into_iter().filter(|&v| v < first_bad).collect();
    let head = match all_ok.iter().copied().reduce(f64::max) {
        Some(v) => format!("every cycle feasible up to {v:.1} m/s"),
        None => "no speed at which every cycle is feasible".to_string(),
    };
    let mut names: Vec<&str> = bad.iter().map(|p| violation_name(p)).collect();
    names.sort_unstable();
    names.dedup();
    let why: Vec<String> = names
        .iter()
        .map(|n| {
            let at: Vec<&&RunPoint> = bad.iter().filter(|p| violation_name(p) == *n).collect();
            let k = at.len();
            format!(
                "{n} at {} ({k} answer{})",
                speeds_text(at.iter().map(|p| p.speed_mps).collect()),
                if k == 1 { "" } else { "s" }
            )
        })
        .collect();
    Verdict::new(
        format!(
            "{head}; {} of {} (cycle, speed) answers infeasible: {}",
            bad.len(),
            points.len(),
            why.join("; ")
        ),
        false,
    )
}

fn span(v: impl Iterator<Item = f64>, pad_min: f64) -> std::ops::Range<f64> {
    let (lo, hi) = v
        .filter(|x| x.is_finite())
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), x| {
            (a.min(x), b.max(x))
        });
    if !lo.is_finite() {
        return 0.0..1.0;
    }
    let pad = ((hi - lo) * 0.08).max(pad_min);
    (lo - pad)..(hi + pad)
}

type Chart<'a, 'b> =
    ChartContext<'a, BitMapBackend<'b>, Cartesian2d<RangedCoordf64, RangedCoordf64>>;
/// The values of a point one panel shows.
type Get = dyn Fn(&RunPoint) -> Vec<f64>;

/// The line width and marker size of cycle `c` of `n`, px: 4 and 5 for the first, one
/// less for each later cycle down to 1 and 2, so coinciding lines stay visible.
fn cycle_width(c: usize, n: usize) -> (u32, u32) {
    let k = n.saturating_sub(1 + c).min(3) as u32;
    (1 + k, 2 + k)
}

/// Draws cycle `c`'s markers at `pts` (pixel size `size`): circle, square, triangle, ring,
/// in turn.
fn draw_markers(
    chart: &mut Chart<'_, '_>,
    path: &Path,
    (c, pts): (usize, &[(f64, f64)]),
    size: u32,
    colour: RGBColor,
) -> Result<(), PlotError> {
    let s = size as i32;
    let r = match c % 4 {
        0 => chart
            .draw_series(pts.iter().map(|&p| Circle::new(p, size, colour.filled())))
            .map(|_| ()),
        1 => chart
            .draw_series(pts.iter().map(|&p| {
                EmptyElement::at(p) + Rectangle::new([(-s, -s), (s, s)], colour.filled())
            }))
            .map(|_| ()),
        2 => chart
            .draw_series(
                pts.iter()
                    .map(|&p| TriangleMarker::new(p, s + 1, colour.filled())),
            )
            .map(|_| ()),
        _ => chart
            .draw_series(
                pts.iter()
                    .map(|&p| Circle::new(p, size + 1, colour.stroke_width(2))),
            )
            .map(|_| ()),
    };
    r.map_err(|e| err(path, e))
}

/// Cycle `c`'s lines on one panel: one per value slot (stance 1, stance 2; ext_min,
/// ext_max) with its markers, and its limits dashed.
fn draw_cycle(
    chart: &mut Chart<'_, '_>,
    path: &Path,
    points: &[RunPoint],
    (c, n): (usize, usize),
    get: &Get,
    lim: &Get,
) -> Result<(), PlotError> {
    let colour = PALETTE[c % PALETTE.len()];
    let (width, size) = cycle_width(c, n);
    let mine: Vec<&RunPoint> = points.iter().filter(|p| p.cycle == c).collect();
    let slots = mine.iter().map(|p| get(p).len()).max().unwrap_or(0);
    for k in 0..slots {
        let line: Vec<(f64, f64)> = mine
            .iter()
            .filter_map(|p| get(p).get(k).map(|&y| (p.speed_mps, y)))
            .filter(|(_, y)| y.is_finite())
            .collect();
        chart
            .draw_series(LineSeries::new(line.clone(), colour.stroke_width(width)))
            .map_err(|e| err(path, e))?;
        draw_markers(chart, path, (c, &line), size, colour)?;
    }
    for k in 0..mine.iter().map(|p| lim(p).len()).max().unwrap_or(0) {
        let line: Vec<(f64, f64)> = mine
            .iter()
            .filter_map(|p| lim(p).get(k).map(|&y| (p.speed_mps, y)))
            .collect();
        chart
            .draw_series(DashedLineSeries::new(line, 8, 5, colour.stroke_width(1)))
            .map_err(|e| err(path, e))?;
    }
    Ok(())
}

/// The infeasible points whose violated limit panel `panel` shows: a red cross at the
/// panel's value (or at `bottom`) and the limit's name, written on the side of the cross
/// that stays inside the panel.
fn mark_infeasible(
    chart: &mut Chart<'_, '_>,
    path: &Path,
    points: &[RunPoint],
    (panel, get): (usize, &Get),
    bottom: f64,
) -> Result<(), PlotError> {
    let x = chart.x_range();
    let mid = 0.5 * (x.start + x.end);
    let mine = points
        .iter()
        .filter(|p| !p.feasible && panel_of(p.violated.as_deref().unwrap_or("")) == panel);
    for p in mine {
        let y = get(p)
            .into_iter()
            .filter(|y| y.is_finite())
            .reduce(f64::max)
            .unwrap_or(bottom);
        chart
            .draw_series(std::iter::once(Cross::new(
                (p.speed_mps, y),
                6,
                RED.stroke_width(2),
            )))
            .map_err(|e| err(path, e))?;
        let (h, dx) = if p.speed_mps > mid {
            (HPos::Right, -8)
        } else {
            (HPos::Left, 8)
        };
        let style = ("sans-serif", 12)
            .into_font()
            .color(&RED)
            .pos(Pos::new(h, VPos::Bottom));
        chart
            .draw_series(std::iter::once(
                EmptyElement::at((p.speed_mps, y))
                    + Text::new(violation_name(p).to_string(), (dx, -6), style),
            ))
            .map_err(|e| err(path, e))?;
    }
    Ok(())
}

/// The legend row: each cycle's colour and name, then the dashed limit and the red cross.
fn legend_row(
    area: &DrawingArea<BitMapBackend<'_>, Shift>,
    path: &Path,
    points: &[RunPoint],
) -> Result<(), PlotError> {
    let mut names: Vec<(usize, &str)> = points
        .iter()
        .map(|p| (p.cycle, p.cycle_name.as_str()))
        .collect();
    names.sort_unstable();
    names.dedup();
    let font = ("sans-serif", 13).into_font();
    let width = area.dim_in_pixel().0 as i32;
    let (mut x, mut y) = (70, 12);
    let mut item = |label: &str, draw: &dyn Fn((i32, i32)) -> Result<(), PlotError>| {
        let w = area
            .estimate_text_size(label, &font.clone().into())
            .map_or(120, |(w, _)| w as i32)
            + 50;
        if x + w > width - 10 {
            (x, y) = (70, y + 22);
        }
        draw((x, y))?;
        area.draw(&Text::new(label.to_string(), (x + 26, y - 7), font.clone()))
            .map_err(|e| err(path, e))?;
        x += w;
        Ok::<(), PlotError>(())
    };
    let n = names.iter().map(|(c, _)| c + 1).max().unwrap_or(0);
    for (c, name) in names {
        let colour = PALETTE[c % PALETTE.len()];
        let (width, size) = cycle_width(c, n);
        item(&format!("cycle {name}"), &|(x, y)| {
            area.draw(&PathElement::new(
                vec![(x, y), (x + 20, y)],
                colour.stroke_width(width),
            ))
            .map_err(|e| err(path, e))?;
            let s = size as i32;
            let (cx, cy) = (x + 10, y);
            match c % 4 {
                0 => area.draw(&Circle::new((cx, cy), size, colour.filled())),
                1 => area.draw(&Rectangle::new(
                    [(cx - s, cy - s), (cx + s, cy + s)],
                    colour.filled(),
                )),
                2 => area.draw(&TriangleMarker::new((cx, cy), s + 1, colour.filled())),
                _ => area.draw(&Circle::new((cx, cy), size + 1, colour.stroke_width(2))),
            }
            .map_err(|e| err(path, e))
        })?;
    }
    item("limit (dashed, cycle's colour)", &|(x, y)| {
        area.draw(&PathElement::new(vec![(x, y), (x + 8, y)], BLACK))
            .and_then(|()| area.draw(&PathElement::new(vec![(x + 13, y), (x + 20, y)], BLACK)))
            .map_err(|e| err(path, e))
    })?;
    item("infeasible, on the panel of the violated limit", &|(
        x,
        y,
    )| {
        area.draw(&Cross::new((x + 10, y), 6, RED.stroke_width(2)))
            .map_err(|e| err(path, e))
    })?;
    Ok(())
}

/// Writes the figure of `points` to `path` (PNG, [`RUNS_PLOT_PX`]) under `title`, with
/// the verdict of [`runs_verdict`].
///
/// # Errors
/// The file cannot be written or the font cannot be used.
pub fn runs_png(path: &Path, title: &str, points: &[RunPoint]) -> Result<(), PlotError> {
    register_font();
    let root = BitMapBackend::new(path, RUNS_PLOT_PX).into_drawing_area();
    root.fill(&WHITE).map_err(|e| err(path, e))?;
    let root = titled(&root, path, title, &runs_verdict(points))?;
    let (legend, root) = root.split_vertically(LEGEND_ROW_PX);
    legend_row(&legend, path, points)?;
    let panels = root.split_evenly((N_PANELS, 1));
    let speeds = span(points.iter().map(|p| p.speed_mps), 0.25);
    let n_cycles = points.iter().map(|p| p.cycle + 1).max().unwrap_or(0);
    // (a) times, (b) peak force, (c) mu_min, (d) extension: (caption, y label, values per
    // point, limits).
    let times: &Get = &|p| p.contact_s.iter().chain(&p.step_s).copied().collect();
    let peak: &Get = &|p| p.peak_n.into_iter().collect();
    let lim_f: &Get = &|p| vec![p.f_max_n];
    let mu: &Get = &|p| p.mu_min.into_iter().collect();
    let ext: &Get = &|p| p.ext_min_m.into_iter().chain(p.ext_max_m).collect();
    let lim_mu: &Get = &|p| vec![p.limits.0];
    let lim_ext: &Get = &|p| vec![p.limits.1, p.limits.2];
    let none: &Get = &|_| Vec::new();
    let specs: [(&str, &str, &Get, &Get); 4] = [
        (
            "(a) contact time (lower lines) and step period (upper lines) per stance",
            "time (s)",
            times,
            none,
        ),
        (
            "(b) peak force of the cycle, limit F_max dashed",
            "force (N)",
            peak,
            lim_f,
        ),
        (
            "(c) friction the cycle needs mu_min, limit μ dashed",
            "friction coefficient (–)",
            mu,
            lim_mu,
        ),
        (
            "(d) leg extension ext_min, ext_max (m), limits χ_min, χ_max dashed",
            "COM–contact distance (m)",
            ext,
            lim_ext,
        ),
    ];
    for (panel, (area, (caption, ylabel, get, lim))) in panels.iter().zip(specs).enumerate() {
        let ys = span(
            points.iter().flat_map(|p| get(p).into_iter().chain(lim(p))),
            0.05,
        );
        let mut chart = ChartBuilder::on(area)
            .caption(caption, ("sans-serif", 16))
            .margin(10)
            .x_label_area_size(40)
            .y_label_area_size(65)
            .build_cartesian_2d(speeds.clone(), ys.clone())
            .map_err(|e| err(path, e))?;
        value_mesh(&mut chart, path, "target speed (m/s)", ylabel)?;
        for c in 0..n_cycles {
            draw_cycle(&mut chart, path, points, (c, n_cycles), get, lim)?;
        }
        mark_infeasible(
            &mut chart,
            path,
            points,
            (panel, get),
            ys.start + (ys.end - ys.start) * 0.06,
        )?;
    }
    root.present().map_err(|e| err(path, e))?;
    Ok(())
}
