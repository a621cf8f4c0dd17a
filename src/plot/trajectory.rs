//! `trajectory.png` of `twopac` (spec two-pac §8): is the planned COM trajectory
//! dynamically valid, and where and why not? A side view and a top view of the contacts,
//! phase states, transition points, the 2PAC curve, the quasi-static polyline and the
//! recorded COM (`--clip`), with equal scales on both axes of a view (metres); the
//! stretches of the curve that fail the dynamic validation are highlighted under it in the
//! colour of their cause ([`crate::twopac::diagnose::Cause`]); below, the validation slack
//! `s*` over time with the phases and their contacts. The verdict line gives the 2PAC
//! curve's and the baseline's verdicts.
//!
//! The views are along the path's own direction, not world x (a walk along y would
//! collapse): `s` is the horizontal direction from the curve's start to its end (or, for
//! a path that returns to its start, the principal horizontal direction of all points),
//! `l` the horizontal direction to its left, and `z` up; a direction within 10° of a world
//! axis is snapped to it ([`SNAP_TO_AXIS_RAD`]).

use std::path::Path;

use plotters::coord::types::RangedCoordf64;
use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};

use super::{err, register_font, tick_label, titled, PlotError, Verdict};
use crate::twopac::diagnose::Cause;

/// One validated sample of the 2PAC curve.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CurveSample {
    /// Time, s.
    pub t_s: f64,
    /// COM, world m.
    pub pos: [f64; 3],
    /// Validation slack `s*`, N (`+∞`: no force distribution).
    pub slack_n: f64,
    /// Why the sample fails; `None` when valid.
    pub cause: Option<Cause>,
}

/// One phase on the time axis: `[start, end)` (s) and its contacts' effectors.
#[derive(Debug, Clone, PartialEq)]
pub struct PhaseSpan {
    /// Start, s.
    pub start_s: f64,
    /// End, s.
    pub end_s: f64,
    /// `left_foot+right_foot`.
    pub effectors: String,
}

/// What `trajectory.png` shows (world frame, m).
#[derive(Debug, Clone, PartialEq, Default)]
pub struct TrajectoryPlot {
    /// Title.
    pub title: String,
    /// The verdict line.
    pub verdict: Option<Verdict>,
    /// Each contact's points (a rectangle's 4 corners, or one point).
    pub contacts: Vec<Vec<[f64; 3]>>,
    /// The 2PAC COM curve, sampled.
    pub curve: Vec<[f64; 3]>,
    /// The quasi-static polyline's knots.
    pub quasi_static: Vec<[f64; 3]>,
    /// Transition points.
    pub transitions: Vec<[f64; 3]>,
    /// Phase states `c^(j)`.
    pub phase_states: Vec<[f64; 3]>,
    /// The recorded COM over the planned span (`--clip`), empty otherwise.
    pub recorded: Vec<[f64; 3]>,
    /// The validated samples of the 2PAC curve (the §7 times).
    pub samples: Vec<CurveSample>,
    /// The phases on the time axis.
    pub phases: Vec<PhaseSpan>,
}

/// The colour of a cause of failure.
pub fn cause_colour(c: Cause) -> RGBColor {
    match c {
        Cause::OffSupport => RGBColor(220, 30, 30),
        Cause::TooFast => RGBColor(230, 140, 0),
        Cause::NoForce => RGBColor(130, 0, 160),
    }
}

/// Legend text of a cause of failure.
fn cause_label(c: Cause) -> &'static str {
    match c {
        Cause::OffSupport => "invalid: COM outside the static support of the contacts",
        Cause::TooFast => "invalid: held at rest, not at this acceleration",
        Cause::NoForce => "invalid: no contact force can hold it",
    }
}

/// A path direction within this angle of a world axis (±x, ±y) is drawn along that axis,
/// rad (10°): a walk that ends on one foot, beside its start line, would otherwise show
/// its square-set feet turned by a few degrees.
pub const SNAP_TO_AXIS_RAD: f64 = 10.0 * std::f64::consts::PI / 180.0;

/// `e` turned onto the nearest world axis when it is within [`SNAP_TO_AXIS_RAD`] of it.
fn snapped(e: [f64; 2]) -> [f64; 2] {
    let axes = [[1.0, 0.0], [-1.0, 0.0], [0.0, 1.0], [0.0, -1.0]];
    axes.into_iter()
        .find(|a| (e[0] * a[0] + e[1] * a[1]).clamp(-1.0, 1.0).acos() <= SNAP_TO_AXIS_RAD)
        .unwrap_or(e)
}

/// The unit horizontal direction `e_s` of the path: start to end of the curve, else the
/// principal horizontal axis of every point, else world x; snapped to a world axis within
/// [`SNAP_TO_AXIS_RAD`].
pub fn path_direction(d: &TrajectoryPlot) -> [f64; 2] {
    snapped(raw_path_direction(d))
}

/// [`path_direction`] before snapping.
fn raw_path_direction(d: &TrajectoryPlot) -> [f64; 2] {
    let unit = |v: [f64; 2]| {
        let n = v[0].hypot(v[1]);
        (n > 1e-6).then(|| [v[0] / n, v[1] / n])
    };
    if let (Some(a), Some(b)) = (d.curve.first(), d.curve.last()) {
        if let Some(e) = unit([b[0] - a[0], b[1] - a[1]]) {
            return e;
        }
    }
    let pts: Vec<&[f64; 3]> = d.contacts.iter().flatten().chain(&d.curve).collect();
    if pts.is_empty() {
        return [1.0, 0.0];
    }
    let n = pts.len() as f64;
    let (mx, my) = (
        pts.iter().map(|p| p[0]).sum::<f64>() / n,
        pts.iter().map(|p| p[1]).sum::<f64>() / n,
    );
    let (mut sxx, mut sxy, mut syy) = (0.0, 0.0, 0.0);
    for p in &pts {
        let (x, y) = (p[0] - mx, p[1] - my);
        sxx += x * x;
        sxy += x * y;
        syy += y * y;
    }
    // Major axis of the 2 × 2 covariance: angle ½·atan2(2 sxy, sxx − syy).
    let a = 0.5 * (2.0 * sxy).atan2(sxx - syy);
    unit([a.cos(), a.sin()]).unwrap_or([1.0, 0.0])
}

/// `d` with every point in path coordinates `(s, l, z)` (see the module docs).
pub fn along_path(d: &TrajectoryPlot) -> TrajectoryPlot {
    let e = path_direction(d);
    let f = |p: &[f64; 3]| [p[0] * e[0] + p[1] * e[1], -p[0] * e[1] + p[1] * e[0], p[2]];
    let all = |v: &[[f64; 3]]| v.iter().map(f).collect::<Vec<_>>();
    TrajectoryPlot {
        title: d.title.clone(),
        contacts: d.contacts.iter().map(|c| all(c)).collect(),
        curve: all(&d.curve),
        quasi_static: all(&d.quasi_static),
        transitions: all(&d.transitions),
        phase_states: all(&d.phase_states),
        recorded: all(&d.recorded),
        samples: d
            .samples
            .iter()
            .map(|c| CurveSample {
                pos: f(&c.pos),
                ..*c
            })
            .collect(),
        phases: d.phases.clone(),
        verdict: d.verdict.clone(),
    }
}

/// Pixel size of one view.
const VIEW_PX: (u32, u32) = (760, 600);
/// Height of the slack strip under the views, px.
const STRIP_PX: u32 = 300;
/// Height of the title and verdict lines, px.
const TITLE_PX: u32 = 70;
/// Width of the highlight under an invalid stretch of the curve, px.
const HIGHLIGHT_PX: u32 = 9;
/// Label areas of a view, px (x axis, y axis).
const LABEL_PX: (u32, u32) = (45, 60);

/// Ranges around every point on axes `(i, k)`, padded, with equal metres per pixel.
fn ranges(d: &TrajectoryPlot, i: usize, k: usize) -> (std::ops::Range<f64>, std::ops::Range<f64>) {
    let all = d
        .contacts
        .iter()
        .flatten()
        .chain(&d.curve)
        .chain(&d.quasi_static)
        .chain(&d.transitions)
        .chain(&d.phase_states)
        .chain(&d.recorded);
    let mut lo = [f64::INFINITY; 2];
    let mut hi = [f64::NEG_INFINITY; 2];
    for p in all.filter(|p| p.iter().all(|v| v.is_finite())) {
        for (a, axis) in [i, k].into_iter().enumerate() {
            lo[a] = lo[a].min(p[axis]);
            hi[a] = hi[a].max(p[axis]);
        }
    }
    if !lo[0].is_finite() {
        return (-1.0..1.0, -1.0..1.0);
    }
    let w = f64::from(VIEW_PX.0 - LABEL_PX.1 - 30);
    let h = f64::from(VIEW_PX.1 - LABEL_PX.0 - 60);
    let span = [
        (hi[0] - lo[0]).max(0.2) * 1.15,
        (hi[1] - lo[1]).max(0.2) * 1.15,
    ];
    let per_px = (span[0] / w).max(span[1] / h);
    let half = [0.5 * per_px * w, 0.5 * per_px * h];
    let mid = [0.5 * (lo[0] + hi[0]), 0.5 * (lo[1] + hi[1])];
    (
        (mid[0] - half[0])..(mid[0] + half[0]),
        (mid[1] - half[1])..(mid[1] + half[1]),
    )
}

fn view(
    area: &DrawingArea<BitMapBackend<'_>, Shift>,
    path: &Path,
    d: &TrajectoryPlot,
    (caption, k, y_desc, legend): (&str, usize, &str, Option<SeriesLabelPosition>),
) -> Result<(), PlotError> {
    let pr = |p: &[f64; 3]| (p[0], p[k]);
    let (xr, yr) = ranges(d, 0, k);
    let mut chart = ChartBuilder::on(area)
        .caption(caption, ("sans-serif", 18))
        .margin(12)
        .x_label_area_size(LABEL_PX.0)
        .y_label_area_size(LABEL_PX.1)
        .build_cartesian_2d(xr, yr)
        .map_err(|e| err(path, e))?;
    chart
        .configure_mesh()
        .x_desc("s, along the path (m)")
        .y_desc(y_desc)
        .x_label_formatter(&tick_label)
        .y_label_formatter(&tick_label)
        .light_line_style(WHITE.mix(0.0))
        .label_style(("sans-serif", 14))
        .draw()
        .map_err(|e| err(path, e))?;
    draw_contacts(&mut chart, path, d, k)?;
    draw_invalid(&mut chart, path, d, k)?;
    let olive = RGBColor(120, 120, 40);
    chart
        .draw_series(DashedLineSeries::new(
            d.quasi_static.iter().map(pr),
            7,
            4,
            olive.stroke_width(2),
        ))
        .map_err(|e| err(path, e))?
        .label("quasi-static polyline (baseline)")
        .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 16, y)], olive.stroke_width(2)));
    let blue = RGBColor(30, 90, 200);
    chart
        .draw_series(LineSeries::new(
            d.curve.iter().map(pr),
            blue.stroke_width(2),
        ))
        .map_err(|e| err(path, e))?
        .label("2PAC COM curve")
        .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 16, y)], blue.stroke_width(2)));
    draw_markers(&mut chart, path, d, k)?;
    if let Some(position) = legend {
        chart
            .configure_series_labels()
            .background_style(WHITE.mix(0.85))
            .border_style(BLACK)
            .label_font(("sans-serif", 14))
            .position(position)
            .draw()
            .map_err(|e| err(path, e))?;
    }
    Ok(())
}

type Chart<'a, 'b> =
    ChartContext<'a, BitMapBackend<'b>, Cartesian2d<RangedCoordf64, RangedCoordf64>>;

/// The contact polygons (crosses at the points, closed outline), projected on axes 0, `k`.
fn draw_contacts(
    chart: &mut Chart<'_, '_>,
    path: &Path,
    d: &TrajectoryPlot,
    k: usize,
) -> Result<(), PlotError> {
    let pr = |p: &[f64; 3]| (p[0], p[k]);
    let grey = RGBColor(110, 110, 110);
    let mut first = true;
    for c in &d.contacts {
        let mut pts: Vec<(f64, f64)> = c.iter().map(pr).collect();
        if pts.len() > 1 {
            pts.push(pts[0]);
        }
        chart
            .draw_series(pts.iter().map(|p| Cross::new(*p, 4, grey)))
            .map_err(|e| err(path, e))?;
        let s = chart
            .draw_series(std::iter::once(PathElement::new(pts, grey.stroke_width(2))))
            .map_err(|e| err(path, e))?;
        if first {
            s.label("contacts").legend(move |(x, y)| {
                PathElement::new(vec![(x, y), (x + 16, y)], grey.stroke_width(2))
            });
            first = false;
        }
    }
    Ok(())
}

/// The phase states, transition points, recorded COM and invalid samples, projected on
/// axes 0, `k`.
fn draw_markers(
    chart: &mut Chart<'_, '_>,
    path: &Path,
    d: &TrajectoryPlot,
    k: usize,
) -> Result<(), PlotError> {
    let pr = |p: &[f64; 3]| (p[0], p[k]);
    let green = RGBColor(46, 139, 87);
    chart
        .draw_series(
            d.phase_states
                .iter()
                .map(|p| Circle::new(pr(p), 5, green.filled())),
        )
        .map_err(|e| err(path, e))?
        .label("phase states c(j)")
        .legend(move |(x, y)| Circle::new((x + 8, y), 5, green.filled()));
    chart
        .draw_series(
            d.transitions
                .iter()
                .map(|p| TriangleMarker::new(pr(p), 7, RED.filled())),
        )
        .map_err(|e| err(path, e))?
        .label("transition points c(j, j+1)")
        .legend(|(x, y)| TriangleMarker::new((x + 8, y), 7, RED.filled()));
    if !d.recorded.is_empty() {
        let black = RGBColor(20, 20, 20);
        chart
            .draw_series(DashedLineSeries::new(
                d.recorded.iter().map(pr),
                6,
                4,
                black.stroke_width(2),
            ))
            .map_err(|e| err(path, e))?
            .label("recorded COM")
            .legend(move |(x, y)| {
                PathElement::new(vec![(x, y), (x + 16, y)], black.stroke_width(2))
            });
    }
    Ok(())
}

/// The invalid stretches of the curve: a wide band under it, coloured by cause, one
/// legend entry per cause present.
fn draw_invalid(
    chart: &mut Chart<'_, '_>,
    path: &Path,
    d: &TrajectoryPlot,
    k: usize,
) -> Result<(), PlotError> {
    let pr = |p: &[f64; 3]| (p[0], p[k]);
    for cause in Cause::ALL {
        let colour = cause_colour(cause);
        let style = colour.mix(0.55).stroke_width(HIGHLIGHT_PX);
        let mut runs: Vec<Vec<(f64, f64)>> = Vec::new();
        let mut open = false;
        for (i, s) in d.samples.iter().enumerate() {
            if s.cause == Some(cause) {
                if !open {
                    // Start the band at the previous sample, so one sample shows too.
                    let from = i.checked_sub(1).map_or(s.pos, |j| d.samples[j].pos);
                    runs.push(vec![pr(&from)]);
                }
                if let Some(r) = runs.last_mut() {
                    r.push(pr(&s.pos));
                }
                open = true;
            } else {
                open = false;
            }
        }
        if runs.is_empty() {
            continue;
        }
        chart
            .draw_series(runs.into_iter().map(|r| PathElement::new(r, style)))
            .map_err(|e| err(path, e))?
            .label(cause_label(cause))
            .legend(move |(x, y)| {
                PathElement::new(
                    vec![(x, y), (x + 16, y)],
                    colour.mix(0.55).stroke_width(HIGHLIGHT_PX),
                )
            });
    }
    Ok(())
}

/// The validation slack `s*` of the curve's samples over time, coloured by cause, over
/// the phases (alternately shaded, numbered and named).
fn slack_strip(
    area: &DrawingArea<BitMapBackend<'_>, Shift>,
    path: &Path,
    d: &TrajectoryPlot,
) -> Result<(), PlotError> {
    let t0 = d.samples.first().map_or(0.0, |s| s.t_s);
    let t1 = d.samples.last().map_or(1.0, |s| s.t_s).max(t0 + 1e-3);
    let finite_max = d
        .samples
        .iter()
        .map(|s| s.slack_n)
        .filter(|v| v.is_finite())
        .fold(0.0f64, f64::max);
    let top = (finite_max * 1.25).max(1.0);
    let mut chart = ChartBuilder::on(area)
        .caption(
            "validation slack s* of the 2PAC curve (0 = the contacts hold the COM; ∞ drawn at the top); shaded: phases and their contacts",
            ("sans-serif", 16),
        )
        .margin(12)
        .x_label_area_size(40)
        .y_label_area_size(LABEL_PX.1)
        .build_cartesian_2d(t0..t1, 0.0..top)
        .map_err(|e| err(path, e))?;
    chart
        .configure_mesh()
        .x_desc("time (s)")
        .y_desc("s* (N)")
        .y_label_formatter(&tick_label)
        .light_line_style(WHITE.mix(0.0))
        .label_style(("sans-serif", 13))
        .draw()
        .map_err(|e| err(path, e))?;
    let grey = RGBColor(225, 225, 225);
    for (j, p) in d.phases.iter().enumerate() {
        let (a, b) = (p.start_s.max(t0), p.end_s.min(t1));
        if b <= a {
            continue;
        }
        if j % 2 == 0 {
            chart
                .draw_series(std::iter::once(Rectangle::new(
                    [(a, 0.0), (b, top)],
                    grey.mix(0.6).filled(),
                )))
                .map_err(|e| err(path, e))?;
        }
        let style = ("sans-serif", 11)
            .into_font()
            .color(&BLACK)
            .pos(Pos::new(HPos::Center, VPos::Top));
        let name = p.effectors.replace("_foot", "").replace("_hand", " hand");
        chart
            .draw_series(std::iter::once(Text::new(
                format!("{j}: {name}"),
                (0.5 * (a + b), top * 0.97),
                style,
            )))
            .map_err(|e| err(path, e))?;
    }
    let line: Vec<(f64, f64)> = d
        .samples
        .iter()
        .map(|s| (s.t_s, s.slack_n.min(top)))
        .collect();
    let blue = RGBColor(30, 90, 200);
    chart
        .draw_series(LineSeries::new(line, blue.stroke_width(1)))
        .map_err(|e| err(path, e))?;
    chart
        .draw_series(d.samples.iter().filter_map(|s| {
            let c = s.cause?;
            Some(Circle::new(
                (s.t_s, s.slack_n.min(top)),
                3,
                cause_colour(c).filled(),
            ))
        }))
        .map_err(|e| err(path, e))?;
    Ok(())
}

/// The verdict of a validated 2PAC curve: valid, or how many samples fail and mostly why.
pub fn curve_verdict(samples: &[CurveSample]) -> Verdict {
    let n = samples.len();
    let bad: Vec<Cause> = samples.iter().filter_map(|s| s.cause).collect();
    if bad.is_empty() {
        return Verdict::new(
            format!("2PAC curve dynamically valid (all {n} samples)"),
            true,
        );
    }
    let main = Cause::ALL
        .into_iter()
        .max_by_key(|c| bad.iter().filter(|b| *b == c).count())
        .unwrap_or(Cause::OffSupport);
    Verdict::new(
        format!(
            "2PAC curve NOT dynamically valid: {} of {n} samples fail, mostly because {}",
            bad.len(),
            main.describe()
        ),
        false,
    )
}

/// Draws `trajectory.png`: side view (s–z, with the legend of both views) left, top view
/// (s–l) right, in the path's coordinates ([`along_path`]), the slack strip below; the verdict is `d.verdict`, else
/// [`curve_verdict`].
///
/// # Errors
/// The file cannot be written or the font cannot be used.
pub fn trajectory_png(path: &Path, d: &TrajectoryPlot) -> Result<(), PlotError> {
    register_font();
    let d = &along_path(d);
    let size = (2 * VIEW_PX.0, VIEW_PX.1 + STRIP_PX + TITLE_PX);
    let root = BitMapBackend::new(path, size).into_drawing_area();
    root.fill(&WHITE).map_err(|e| err(path, e))?;
    let verdict = d
        .verdict
        .clone()
        .unwrap_or_else(|| curve_verdict(&d.samples));
    let root = titled(&root, path, &d.title, &verdict)?;
    let (views, strip) = root.split_vertically(VIEW_PX.1);
    let (left, right) = views.split_horizontally(VIEW_PX.0);
    view(
        &left,
        path,
        d,
        (
            "Side view along the path (s–z)",
            2,
            "z (m)",
            Some(SeriesLabelPosition::MiddleRight),
        ),
    )?;
    view(
        &right,
        path,
        d,
        ("Top view (s–l)", 1, "l, left of the path (m)", None),
    )?;
    slack_strip(&strip, path, d)?;
    root.present().map_err(|e| err(path, e))?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_walk_along_y_is_drawn_along_its_own_direction() {
        // A path along world +y: s is y, l is −x, z unchanged.
        let d = TrajectoryPlot {
            curve: vec![[0.0, 0.0, 0.9], [0.05, 1.0, 0.92], [0.0, 2.0, 0.9]],
            contacts: vec![vec![[0.1, 0.5, 0.0]]],
            ..TrajectoryPlot::default()
        };
        let e = path_direction(&d);
        assert!((e[0]).abs() < 1e-12 && (e[1] - 1.0).abs() < 1e-12, "{e:?}");
        let p = along_path(&d);
        assert_eq!(p.curve[1], [1.0, -0.05, 0.92]);
        assert_eq!(p.contacts[0][0], [0.5, -0.1, 0.0]);
        // A closed loop: the principal axis of the points (here along x).
        let loop_ = TrajectoryPlot {
            curve: vec![[0.0, 0.0, 1.0], [2.0, 0.1, 1.0], [0.0, 0.0, 1.0]],
            ..TrajectoryPlot::default()
        };
        let e = path_direction(&loop_);
        assert!(e[0].abs() > 0.99, "{e:?}");
    }
}
