//! `trajectory.png` of `twopac` (spec two-pac §8): a side view and a top view of the
//! contacts, phase states, transition points, the 2PAC curve, the quasi-static polyline,
//! the recorded COM (`--clip`) and the curve's dynamically invalid samples, with equal
//! scales on both axes of a view (metres).
//!
//! The views are along the path's own direction, not world x (a walk along y would
//! collapse): `s` is the horizontal direction from the curve's start to its end (or, for
//! a path that returns to its start, the principal horizontal direction of all points),
//! `l` the horizontal direction to its left, and `z` up.

use std::path::Path;

use plotters::coord::types::RangedCoordf64;
use plotters::coord::Shift;
use plotters::prelude::*;

use super::{err, register_font, PlotError};

/// What `trajectory.png` shows (world frame, m).
#[derive(Debug, Clone, PartialEq, Default)]
pub struct TrajectoryPlot {
    /// Title.
    pub title: String,
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
    /// Samples of the 2PAC curve that fail the dynamic validation.
    pub invalid: Vec<[f64; 3]>,
}

/// The unit horizontal direction `e_s` of the path: start to end of the curve, else the
/// principal horizontal axis of every point, else world x.
pub fn path_direction(d: &TrajectoryPlot) -> [f64; 2] {
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
        invalid: all(&d.invalid),
    }
}

/// Pixel size of one view.
const VIEW_PX: (u32, u32) = (760, 640);
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
    (caption, k, y_desc, legend): (&str, usize, &str, SeriesLabelPosition),
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
        .label_style(("sans-serif", 14))
        .draw()
        .map_err(|e| err(path, e))?;
    draw_contacts(&mut chart, path, d, k)?;
    for (pts, colour, width, label) in [
        (
            &d.quasi_static,
            RGBColor(255, 140, 0),
            2,
            "quasi-static polyline",
        ),
        (&d.curve, RGBColor(30, 90, 200), 3, "2PAC COM curve"),
    ] {
        chart
            .draw_series(LineSeries::new(
                pts.iter().map(pr),
                colour.stroke_width(width),
            ))
            .map_err(|e| err(path, e))?
            .label(label)
            .legend(move |(x, y)| {
                PathElement::new(vec![(x, y), (x + 16, y)], colour.stroke_width(width))
            });
    }
    draw_markers(&mut chart, path, d, k)?;
    chart
        .configure_series_labels()
        .background_style(WHITE.mix(0.85))
        .border_style(BLACK)
        .label_font(("sans-serif", 14))
        .position(legend)
        .draw()
        .map_err(|e| err(path, e))?;
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
    if !d.invalid.is_empty() {
        chart
            .draw_series(
                d.invalid
                    .iter()
                    .map(|p| Cross::new(pr(p), 4, RED.stroke_width(2))),
            )
            .map_err(|e| err(path, e))?
            .label(format!("dynamically invalid samples ({})", d.invalid.len()))
            .legend(|(x, y)| Cross::new((x + 8, y), 4, RED.stroke_width(2)));
    }
    Ok(())
}

/// Draws `trajectory.png`: side view (s–z) left, top view (s–l) right, in the path's
/// coordinates ([`along_path`]).
///
/// # Errors
/// The file cannot be written or the font cannot be used.
pub fn trajectory_png(path: &Path, d: &TrajectoryPlot) -> Result<(), PlotError> {
    register_font();
    let d = &along_path(d);
    let root = BitMapBackend::new(path, (2 * VIEW_PX.0, VIEW_PX.1 + 40)).into_drawing_area();
    root.fill(&WHITE).map_err(|e| err(path, e))?;
    let root = root
        .titled(&d.title, ("sans-serif", 22))
        .map_err(|e| err(path, e))?;
    let (left, right) = root.split_horizontally(VIEW_PX.0);
    view(
        &left,
        path,
        d,
        (
            "Side view along the path (s–z)",
            2,
            "z (m)",
            SeriesLabelPosition::MiddleRight,
        ),
    )?;
    view(
        &right,
        path,
        d,
        (
            "Top view (s–l)",
            1,
            "l, left of the path (m)",
            SeriesLabelPosition::UpperRight,
        ),
    )?;
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
