//! `query run --png`: how a run changes with speed (Table 1 of the paper, with the gait
//! law's times). Over the target speed, (a) each stance's contact time and step period,
//! (b) the cycle's peak force against `F_max`, (c) the friction the cycle needs, `mu_min`,
//! against the friction limit μ, and (d) the leg extension extremes `ext_min`, `ext_max`
//! against `χ_min`, `χ_max`. Infeasible speeds are marked with a red cross and the name of
//! the constraint they violate.

use std::path::Path;

use plotters::coord::types::RangedCoordf64;
use plotters::prelude::*;

use super::{err, register_font, value_mesh, PlotError};

/// One cycle at one speed, as the figure needs it.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct RunPoint {
    /// Index of the cycle (one colour each).
    pub cycle: usize,
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

const PALETTE: [RGBColor; 6] = [
    RGBColor(31, 119, 180),
    RGBColor(44, 160, 44),
    RGBColor(148, 103, 189),
    RGBColor(140, 86, 75),
    RGBColor(23, 190, 207),
    RGBColor(188, 189, 34),
];

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

/// Cycle `c`'s lines on one panel: one per value slot (stance 1, stance 2; ext_min,
/// ext_max) with its points, and its limits dashed.
fn draw_cycle(
    chart: &mut Chart<'_, '_>,
    path: &Path,
    points: &[RunPoint],
    c: usize,
    get: &Get,
    lim: &Get,
) -> Result<(), PlotError> {
    let colour = PALETTE[c % PALETTE.len()];
    let mine: Vec<&RunPoint> = points.iter().filter(|p| p.cycle == c).collect();
    let slots = mine.iter().map(|p| get(p).len()).max().unwrap_or(0);
    for k in 0..slots {
        let line: Vec<(f64, f64)> = mine
            .iter()
            .filter_map(|p| get(p).get(k).map(|&y| (p.speed_mps, y)))
            .filter(|(_, y)| y.is_finite())
            .collect();
        chart
            .draw_series(LineSeries::new(line.clone(), colour.stroke_width(2)))
            .map_err(|e| err(path, e))?;
        chart
            .draw_series(line.iter().map(|&pt| Circle::new(pt, 3, colour.filled())))
            .map_err(|e| err(path, e))?;
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

/// Infeasible speeds: a red cross at the panel's value (or at `bottom`) and the violated
/// constraint's name.
fn mark_infeasible(
    chart: &mut Chart<'_, '_>,
    path: &Path,
    points: &[RunPoint],
    get: &Get,
    bottom: f64,
) -> Result<(), PlotError> {
    for p in points.iter().filter(|p| !p.feasible) {
        let y = get(p)
            .first()
            .copied()
            .filter(|y| y.is_finite())
            .unwrap_or(bottom);
        chart
            .draw_series(std::iter::once(Cross::new(
                (p.speed_mps, y),
                6,
                RED.stroke_width(2),
            )))
            .map_err(|e| err(path, e))?;
        let why = p.violated.as_deref().unwrap_or("infeasible");
        let name = why.rsplit(": ").next().unwrap_or(why);
        chart
            .draw_series(std::iter::once(Text::new(
                name.to_string(),
                (p.speed_mps, y),
                ("sans-serif", 11).into_font().color(&RED),
            )))
            .map_err(|e| err(path, e))?;
    }
    Ok(())
}

/// Writes the figure of `points` to `path` (PNG, 1100 × 1400 px).
///
/// # Errors
/// The file cannot be written or the font cannot be used.
pub fn runs_png(path: &Path, title: &str, points: &[RunPoint]) -> Result<(), PlotError> {
    register_font();
    let root = BitMapBackend::new(path, (1100, 1400)).into_drawing_area();
    root.fill(&WHITE).map_err(|e| err(path, e))?;
    let root = root
        .titled(title, ("sans-serif", 22))
        .map_err(|e| err(path, e))?;
    let panels = root.split_evenly((4, 1));
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
            "(c) friction needed mu_min, limit μ dashed",
            "mu_min",
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
    for (area, (caption, ylabel, get, lim)) in panels.iter().zip(specs) {
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
            draw_cycle(&mut chart, path, points, c, get, lim)?;
        }
        mark_infeasible(
            &mut chart,
            path,
            points,
            get,
            ys.start + (ys.end - ys.start) * 0.06,
        )?;
    }
    root.present().map_err(|e| err(path, e))?;
    Ok(())
}
