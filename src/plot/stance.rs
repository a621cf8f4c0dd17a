//! The per-stance force plot (`stancelib plot stance`): does the stance's force model
//! match the measured force, and how much friction does the stance need? The model's
//! force against the kinematic force m(a + g) and, when given, the plate force, over clip
//! time. The verdict line gives the model's fit to the kinematic force (and the plates)
//! and the friction the queries judge, `mu_req_robust` (on the 20 % active set).
//!
//! # Model
//! ```text
//! panel (a): f_v (N)          panel (b): f_h (N)
//! panel (c): |f_t|/f_v = hypot(f_h, f_p)/f_v   where f_v ≥ 5 % of the series' peak f_v
//!            (below it, in flight, a ratio of two small numbers), drawn in [0, 2] (larger
//!            values at 2, with a note); shaded: the model's active set
//!            A = {τ : f_v(τ) ≥ λ · max_grid f_v}   (λ = --active-set, default the queries'
//!            0.2); dashed: the stored mu_req_robust, what the queries judge
//! fit:  RMS over the measured samples in [touchdown, liftoff] of f_v,model − f_v,measured,
//!       the model linearly interpolated on its grid; good when ≤ FIT_OK_REL · max f_v
//! stance axes of a world force F: (F·e_h, F·e_p, F_z)   (Heading::to_stance)
//! ```
//!
//! # Frames and units
//! Stance axes `h, p, v`, newtons, seconds of clip time.

use std::path::Path;

use plotters::coord::Shift;
use plotters::element::DashedPathElement;
use plotters::prelude::*;

use super::{err, register_font, titled, PlotError, Verdict};
use crate::force_model::export::ForceSample;
use crate::stances::params::Heading;

/// Pixel size of the stance plot (width, height).
pub const STANCE_PLOT_PX: (u32, u32) = (1200, 1050);
/// Width of the legend column on the right, px.
const LEGEND_PX: u32 = 290;
/// Panel (c) draws a series' `|f_t|/f_v` where its `f_v` is at least this fraction of its
/// peak (the 5 % set of the stored `mu_req`): in flight the kinematic force is noise over
/// noise, and its ratio drew a flat line that read as friction before touchdown.
pub const RATIO_MIN_FV_FRACTION: f64 = 0.05;
/// Upper end of the `|f_t|/f_v` axis; larger ratios are drawn there, with a note.
pub const RATIO_AXIS_MAX: f64 = 2.0;
/// The time axis extends this fraction of `Δt` before touchdown and after liftoff.
pub const TIME_PAD_FRACTION: f64 = 0.15;

/// The fit is good news when its RMS error of `f_v` is at most this fraction of the
/// model's peak `f_v`.
pub const FIT_OK_REL: f64 = 0.1;

/// RMS of `f_v,model − f_v,measured` over the measured samples in `[td, lo]` (N), the
/// model linearly interpolated on its grid; `None` without such samples.
pub fn fit_rms_n(d: &StancePlot, measured: &WorldForces) -> Option<f64> {
    let (td, lo) = d.td_lo_s;
    let model_at = |t: f64| {
        let k = d.model.partition_point(|s| s.time_s < t);
        let (a, b) = (d.model.get(k.checked_sub(1)?)?, d.model.get(k)?);
        let w = if b.time_s > a.time_s {
            (t - a.time_s) / (b.time_s - a.time_s)
        } else {
            0.0
        };
        Some(a.f_stance[2] + w * (b.f_stance[2] - a.f_stance[2]))
    };
    let sq: Vec<f64> = measured
        .samples
        .iter()
        .filter(|(t, _)| (td..=lo).contains(t))
        .filter_map(|(t, f)| Some((model_at(*t)? - d.heading.to_stance(*f)[2]).powi(2)))
        .collect();
    (!sq.is_empty()).then(|| (sq.iter().sum::<f64>() / sq.len() as f64).sqrt())
}

/// The verdict of the stance plot: the model's fit to the kinematic force (and the
/// plates), and the friction the queries judge.
pub fn stance_verdict(d: &StancePlot) -> Verdict {
    let peak = d
        .model
        .iter()
        .map(|s| s.f_stance[2])
        .fold(0.0f64, f64::max)
        .max(1.0);
    let mut ok = true;
    let mut fits = Vec::new();
    for m in std::iter::once(&d.kinematic).chain(&d.plate) {
        if let Some(rms) = fit_rms_n(d, m) {
            ok &= rms <= FIT_OK_REL * peak;
            let name = m.label.split(' ').next().unwrap_or("measured");
            fits.push(format!(
                "{rms:.0} N RMS from the {name} f_v ({:.0} % of peak)",
                100.0 * rms / peak
            ));
        }
    }
    let fit = if fits.is_empty() {
        "no measured sample to compare".to_string()
    } else {
        format!("model {}", fits.join(", "))
    };
    Verdict::new(
        format!(
            "{fit}; friction needed μ_req_robust = {:.3} (20 % active set, what the queries judge)",
            d.mu_req_robust
        ),
        ok && !fits.is_empty(),
    )
}

/// A measured force series (kinematic or plate): clip time (s) and world force (N, Z up).
#[derive(Debug, Clone, PartialEq, Default)]
pub struct WorldForces {
    /// Legend text.
    pub label: String,
    /// `(t, F_world)` samples, time increasing.
    pub samples: Vec<(f64, [f64; 3])>,
}

/// Everything the stance plot shows.
#[derive(Debug, Clone, PartialEq)]
pub struct StancePlot {
    /// `<clip>:<label>:<first frame>`.
    pub stance_id: String,
    /// The model's stored required friction on the paper's 5 % active set, `mu_req`.
    pub mu_req: f64,
    /// The model's stored required friction on the 20 % active set, `mu_req_robust`: what
    /// the queries judge.
    pub mu_req_robust: f64,
    /// Touchdown and liftoff, clip time (s).
    pub td_lo_s: (f64, f64),
    /// The stance frame.
    pub heading: Heading,
    /// The model on its grid ([`crate::force_model::export::sample_forces`]).
    pub model: Vec<ForceSample>,
    /// The kinematic force m(a + g) at the clip's frames.
    pub kinematic: WorldForces,
    /// The plate force, when a plate file was given.
    pub plate: Option<WorldForces>,
    /// `λ` of the shaded active set.
    pub active_fraction: f64,
}

/// `hypot(f_h, f_p)/f_v` where `f_v > 0`, else `None`.
pub fn traction_ratio(f_stance: [f64; 3]) -> Option<f64> {
    (f_stance[2] > 0.0).then(|| f_stance[0].hypot(f_stance[1]) / f_stance[2])
}

/// The model's active set as clip-time intervals: maximal runs of grid samples with
/// `f_v ≥ fraction · max f_v` (each from its first to its last sample).
pub fn active_intervals(model: &[ForceSample], fraction: f64) -> Vec<(f64, f64)> {
    let max = model
        .iter()
        .map(|s| s.f_stance[2])
        .fold(f64::NEG_INFINITY, f64::max);
    let mut out: Vec<(f64, f64)> = Vec::new();
    let mut open: Option<(f64, f64)> = None;
    for s in model {
        if s.f_stance[2] >= fraction * max {
            open = Some(open.map_or((s.time_s, s.time_s), |(a, _)| (a, s.time_s)));
        } else if let Some(iv) = open.take() {
            out.push(iv);
        }
    }
    out.extend(open);
    out
}

/// One curve in stance axes: `(t, f_h, f_p, f_v)`.
type Curve = Vec<(f64, [f64; 3])>;

struct Series<'a> {
    label: &'a str,
    colour: RGBColor,
    points: Curve,
    markers: bool,
}

const BLUE_MODEL: RGBColor = RGBColor(30, 90, 200);
const ORANGE_KIN: RGBColor = RGBColor(230, 120, 0);
const GREEN_PLATE: RGBColor = RGBColor(20, 140, 70);
const GREY: RGBColor = RGBColor(120, 120, 120);
const SHADE: RGBColor = RGBColor(255, 215, 0);

impl StancePlot {
    fn series(&self) -> Vec<Series<'_>> {
        let to_stance = |w: &WorldForces| -> Curve {
            w.samples
                .iter()
                .map(|(t, f)| (*t, self.heading.to_stance(*f)))
                .collect()
        };
        let mut out = vec![Series {
            label: "model",
            colour: BLUE_MODEL,
            points: self.model.iter().map(|s| (s.time_s, s.f_stance)).collect(),
            markers: false,
        }];
        out.push(Series {
            label: &self.kinematic.label,
            colour: ORANGE_KIN,
            points: to_stance(&self.kinematic),
            markers: true,
        });
        if let Some(p) = &self.plate {
            out.push(Series {
                label: &p.label,
                colour: GREEN_PLATE,
                points: to_stance(p),
                markers: true,
            });
        }
        out
    }
}

/// The plot's time axis for a stance from `td` to `lo` (s): [`TIME_PAD_FRACTION`] of `Δt`
/// (at least 1 ms) before and after.
pub fn time_window(td: f64, lo: f64) -> (f64, f64) {
    let pad = TIME_PAD_FRACTION * (lo - td).max(1e-3);
    (td - pad, lo + pad)
}

type Chart<'a, 'b> = ChartContext<
    'a,
    BitMapBackend<'b>,
    Cartesian2d<plotters::coord::types::RangedCoordf64, plotters::coord::types::RangedCoordf64>,
>;

/// One panel over clip time; `y_decimals` digits on the y labels.
fn panel<'a, 'b>(
    area: &'a DrawingArea<BitMapBackend<'b>, Shift>,
    path: &Path,
    (caption, y_desc, y_decimals): (&str, &str, usize),
    (x, y): ((f64, f64), (f64, f64)),
) -> Result<Chart<'a, 'b>, PlotError> {
    let mut chart = ChartBuilder::on(area)
        .caption(caption, ("sans-serif", 17))
        .margin(10)
        .x_label_area_size(42)
        .y_label_area_size(70)
        .build_cartesian_2d(x.0..x.1, y.0..y.1)
        .map_err(|e| err(path, e))?;
    chart
        .configure_mesh()
        .x_desc("clip time t (s)")
        .y_desc(y_desc)
        .y_label_formatter(&|v| format!("{v:.y_decimals$}"))
        .bold_line_style(RGBColor(200, 200, 200))
        .light_line_style(RGBColor(242, 242, 242))
        .label_style(("sans-serif", 14))
        .draw()
        .map_err(|e| err(path, e))?;
    Ok(chart)
}

/// `[lo, hi]` of `values` with 0 included and 8 % headroom both ways.
fn force_range(values: impl Iterator<Item = f64>) -> (f64, f64) {
    let (lo, hi) = values
        .filter(|v| v.is_finite())
        .fold((0.0f64, 0.0f64), |(a, b), v| (a.min(v), b.max(v)));
    let span = (hi - lo).max(1.0);
    (lo - 0.08 * span, hi + 0.08 * span)
}

/// Draws `points` as lines, broken where `get` is `None`, and markers when asked.
fn draw_broken(
    chart: &mut Chart,
    path: &Path,
    s: &Series,
    get: &dyn Fn(&[f64; 3]) -> Option<f64>,
) -> Result<(), PlotError> {
    let mut runs: Vec<Vec<(f64, f64)>> = vec![Vec::new()];
    for (t, f) in &s.points {
        match (get(f), runs.last_mut()) {
            (Some(v), Some(run)) if v.is_finite() => run.push((*t, v)),
            _ => runs.push(Vec::new()),
        }
    }
    let width = if s.markers { 2 } else { 3 };
    for run in runs.into_iter().filter(|r| !r.is_empty()) {
        if s.markers {
            chart
                .draw_series(run.iter().map(|p| Circle::new(*p, 3, s.colour.filled())))
                .map_err(|e| err(path, e))?;
        }
        chart
            .draw_series(LineSeries::new(run, s.colour.stroke_width(width)))
            .map_err(|e| err(path, e))?;
    }
    Ok(())
}

/// Dashed vertical lines at touchdown and liftoff.
fn draw_events(chart: &mut Chart, path: &Path, (td, lo): (f64, f64)) -> Result<(), PlotError> {
    let (y0, y1) = {
        let r = chart.y_range();
        (r.start, r.end)
    };
    for t in [td, lo] {
        chart
            .draw_series(std::iter::once(DashedPathElement::new(
                vec![(t, y0), (t, y1)],
                6,
                4,
                GREY.stroke_width(1),
            )))
            .map_err(|e| err(path, e))?;
    }
    Ok(())
}

/// The legend column: one line per series, the shading, the event lines and notes.
fn legend(
    area: &DrawingArea<BitMapBackend<'_>, Shift>,
    path: &Path,
    series: &[Series],
    notes: &[String],
) -> Result<(), PlotError> {
    let font = ("sans-serif", 15).into_font();
    let mut y = 60;
    let x = 14;
    let text = |s: &str, y: i32| Text::new(s.to_string(), (x + 40, y - 8), font.clone());
    for s in series {
        area.draw(&PathElement::new(
            vec![(x, y), (x + 30, y)],
            s.colour.stroke_width(3),
        ))
        .map_err(|e| err(path, e))?;
        if s.markers {
            area.draw(&Circle::new((x + 15, y), 3, s.colour.filled()))
                .map_err(|e| err(path, e))?;
        }
        area.draw(&text(s.label, y)).map_err(|e| err(path, e))?;
        y += 28;
    }
    area.draw(&Rectangle::new(
        [(x, y - 8), (x + 30, y + 8)],
        SHADE.mix(0.35).filled(),
    ))
    .map_err(|e| err(path, e))?;
    area.draw(&text("active set (panel c)", y))
        .map_err(|e| err(path, e))?;
    y += 28;
    area.draw(&DashedPathElement::new(
        vec![(x, y), (x + 30, y)],
        6,
        4,
        GREY.stroke_width(1),
    ))
    .map_err(|e| err(path, e))?;
    area.draw(&text("touchdown, liftoff", y))
        .map_err(|e| err(path, e))?;
    y += 28;
    area.draw(&DashedPathElement::new(
        vec![(x, y), (x + 30, y)],
        8,
        5,
        RED.stroke_width(2),
    ))
    .map_err(|e| err(path, e))?;
    area.draw(&text("μ_req_robust (panel c)", y))
        .map_err(|e| err(path, e))?;
    y += 44;
    let small = ("sans-serif", 14).into_font();
    for n in notes {
        area.draw(&Text::new(n.clone(), (x, y), small.clone()))
            .map_err(|e| err(path, e))?;
        y += 22;
    }
    Ok(())
}

/// Draws the stance plot ([`STANCE_PLOT_PX`]) to `path`.
///
/// # Errors
/// The file cannot be written or the font cannot be used.
pub fn stance_png(path: &Path, d: &StancePlot) -> Result<(), PlotError> {
    register_font();
    let root = BitMapBackend::new(path, STANCE_PLOT_PX).into_drawing_area();
    root.fill(&WHITE).map_err(|e| err(path, e))?;
    let title = format!(
        "Stance {}: does the force model match the measured force?",
        d.stance_id
    );
    let root = titled(&root, path, &title, &stance_verdict(d))?;
    let (charts, side) = root.split_horizontally(STANCE_PLOT_PX.0 - LEGEND_PX);
    let panels = charts.split_evenly((3, 1));
    let series = d.series();
    let x = time_window(d.td_lo_s.0, d.td_lo_s.1);
    let in_x = |t: f64| (x.0..=x.1).contains(&t);
    let all = |axis: usize| -> Vec<f64> {
        let visible = series.iter().flat_map(|s| &s.points).filter(|p| in_x(p.0));
        visible.map(|p| p.1[axis]).collect()
    };
    let mut a = panel(
        &panels[0],
        path,
        ("(a) vertical force f_v", "f_v (N)", 0),
        (x, force_range(all(2).into_iter())),
    )?;
    let mut b = panel(
        &panels[1],
        path,
        ("(b) heading force f_h (+ forward)", "f_h (N)", 0),
        (x, force_range(all(0).into_iter())),
    )?;
    let ratio = |f: &[f64; 3]| traction_ratio(*f);
    let clipped = series
        .iter()
        .flat_map(|s| &s.points)
        .filter(|p| in_x(p.0))
        .any(|p| ratio(&p.1).is_some_and(|r| r > RATIO_AXIS_MAX));
    let caption = if clipped {
        format!("(c) |f_t|/f_v = hypot(f_h, f_p)/f_v   (values above {RATIO_AXIS_MAX} drawn at {RATIO_AXIS_MAX})")
    } else {
        "(c) |f_t|/f_v = hypot(f_h, f_p)/f_v".to_string()
    };
    let mut c = panel(
        &panels[2],
        path,
        (&caption, "|f_t| / f_v (–)", 1),
        (x, (0.0, RATIO_AXIS_MAX * 1.02)),
    )?;
    let active = active_intervals(&d.model, d.active_fraction);
    c.draw_series(active.iter().map(|&(t0, t1)| {
        Rectangle::new(
            [(t0, 0.0), (t1, RATIO_AXIS_MAX * 1.02)],
            SHADE.mix(0.35).filled(),
        )
    }))
    .map_err(|e| err(path, e))?;
    for chart in [&mut a, &mut b, &mut c] {
        draw_events(chart, path, d.td_lo_s)?;
    }
    c.draw_series(std::iter::once(DashedPathElement::new(
        vec![(x.0, d.mu_req_robust), (x.1, d.mu_req_robust)],
        8,
        5,
        RED.stroke_width(2),
    )))
    .map_err(|e| err(path, e))?;
    // Measured series first, the model on top.
    for s in series.iter().rev() {
        let s = Series {
            label: s.label,
            colour: s.colour,
            points: s.points.iter().filter(|p| in_x(p.0)).copied().collect(),
            markers: s.markers,
        };
        draw_broken(&mut a, path, &s, &|f| Some(f[2]))?;
        draw_broken(&mut b, path, &s, &|f| Some(f[0]))?;
        let peak_fv = s.points.iter().map(|p| p.1[2]).fold(0.0, f64::max);
        draw_broken(&mut c, path, &s, &|f| {
            (f[2] >= RATIO_MIN_FV_FRACTION * peak_fv)
                .then(|| traction_ratio(*f))
                .flatten()
                .map(|r| r.min(RATIO_AXIS_MAX))
        })?;
    }
    let max_active = d
        .model
        .iter()
        .filter(|s| active.iter().any(|&(t0, t1)| (t0..=t1).contains(&s.time_s)))
        .filter_map(|s| traction_ratio(s.f_stance))
        .fold(0.0, f64::max);
    let (td, lo) = d.td_lo_s;
    let notes = vec![
        format!("touchdown {td:.3} s, liftoff {lo:.3} s"),
        format!("Δt = {:.3} s", lo - td),
        format!("shaded: f_v ≥ {} · max f_v", d.active_fraction),
        "  of the model (--active-set)".to_string(),
        format!("model max |f_t|/f_v there: {max_active:.3}"),
        format!("stored μ_req_robust: {:.3}", d.mu_req_robust),
        "  (20 % set; the queries' check)".to_string(),
        format!("stored μ_req: {:.3} (5 % set)", d.mu_req),
        "forces: applied on the body,".to_string(),
        "  stance axes h (heading),".to_string(),
        "  p (left), v (up)".to_string(),
    ];
    legend(&side, path, &series, &notes)?;
    root.present().map_err(|e| err(path, e))?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sample(t: f64, f_v: f64) -> ForceSample {
        ForceSample {
            tau: t,
            time_s: t,
            f_stance: [0.0, 0.0, f_v],
            f_world: [0.0, 0.0, f_v],
        }
    }

    #[test]
    fn active_set_is_the_runs_above_the_fraction_of_the_peak() {
        // Peak 1000 N: threshold 200 N at λ = 0.2; two runs, the second open at the end.
        let m: Vec<ForceSample> = [0.0, 300.0, 1000.0, 150.0, 100.0, 250.0, 400.0]
            .iter()
            .enumerate()
            .map(|(i, &f)| sample(i as f64 * 0.1, f))
            .collect();
        let iv = active_intervals(&m, 0.2);
        assert_eq!(iv.len(), 2);
        assert!((iv[0].0 - 0.1).abs() < 1e-12 && (iv[0].1 - 0.2).abs() < 1e-12);
        assert!((iv[1].0 - 0.5).abs() < 1e-12 && (iv[1].1 - 0.6).abs() < 1e-12);
        assert_eq!(active_intervals(&m, 0.0).len(), 1, "λ = 0: every f_v ≥ 0");
        assert!(active_intervals(&[], 0.2).is_empty());
    }

    #[test]
    fn ratio_is_tangential_over_normal_where_the_foot_pushes() {
        assert_eq!(traction_ratio([3.0, 4.0, 10.0]), Some(0.5));
        assert_eq!(traction_ratio([3.0, 4.0, 0.0]), None);
        assert_eq!(traction_ratio([3.0, 4.0, -1.0]), None);
    }
}
