//! `FILE.png` of `edit`: what motion was written, and does it hold? A side view along the
//! direction of travel (`s–z`) and a top view (`s–l`) of the planned COM path, the
//! footprints (planned contact points) and a few sampled poses (stick figures shaded from
//! light to dark with time and labelled with their time), equal scales on both axes of a
//! view. The verdict line says whether every stance is feasible and every frame converged.
//!
//! # Frames and units
//! `s` is the horizontal direction from the planned COM's first point to its last (the
//! direction of travel); when the COM travels less than [`MIN_TRAVEL_M`] (a jump in place)
//! it is the body's facing direction (from the hips), else world x. `l` is the horizontal
//! direction to the left of `s`, `z` up. Metres, seconds of output time.
//!
//! A motion in place would draw every pose on the same spot: there the views are spread
//! in time like a chronophotograph, the horizontal axis being `s + v·t` with `v` chosen so
//! that consecutive poses stand [`SPREAD_SPACING_M`] apart (the axis label gives `v`); the
//! COM is drawn at its own times, the footprints (whose times the plot does not carry)
//! are left out.

use std::path::Path;

use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};

use super::{draw_legend, err, register_font, titled, travel_direction, PlotError, Verdict};

/// One sampled pose: its output time and the bones of its stick figure (world, m).
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Pose {
    /// Output time, s.
    pub time_s: f64,
    /// Bones (parent, child), world frame, m.
    pub bones: Vec<[[f64; 3]; 2]>,
}

/// What the edit plot shows (world frame, m).
#[derive(Debug, Clone, PartialEq, Default)]
pub struct EditPlot {
    /// Title.
    pub title: String,
    /// Planned COM per output frame.
    pub com: Vec<[f64; 3]>,
    /// Planned contact point of each stance.
    pub footprints: Vec<[f64; 3]>,
    /// A few sampled poses, in time order.
    pub poses: Vec<Pose>,
    /// The body's mean horizontal facing direction (unit, world x, y), when known.
    pub facing: Option<[f64; 2]>,
    /// `<stance_id>: <constraint>` of every stance that breaks a limit.
    pub violated: Vec<String>,
    /// Output frames.
    pub n_frames: usize,
    /// Time between output frames (of `com`), s.
    pub frame_time_s: f64,
    /// Output frames whose pose did not converge (COM off the plan or a support foot out of
    /// reach).
    pub unconverged: usize,
}

/// Below this horizontal travel of the planned COM (m) the views follow the body's facing
/// direction instead of the direction of travel.
pub const MIN_TRAVEL_M: f64 = 0.3;
/// Distance between consecutive poses of a motion in place, spread in time, m.
pub const SPREAD_SPACING_M: f64 = 0.9;
/// Pixel size of one view.
const VIEW_PX: (u32, u32) = (900, 420);
/// Height of the title and verdict lines, px.
const TITLE_PX: u32 = 70;

/// The verdict of an edit: feasible and converged, or what is not.
pub fn edit_verdict(d: &EditPlot) -> Verdict {
    let frames = match d.unconverged {
        0 => format!("all {} frames converged", d.n_frames),
        k => format!("{k} of {} frames NOT converged", d.n_frames),
    };
    if d.violated.is_empty() {
        Verdict::new(
            format!("feasible: every stance within its limits; {frames}"),
            d.unconverged == 0,
        )
    } else {
        Verdict::new(
            format!("INFEASIBLE: {}; {frames}", d.violated.join("; ")),
            false,
        )
    }
}

/// The horizontal axes `(e_s, why)` of the views: the direction of travel, else the
/// facing, else world x; `why` says which, for the captions.
pub fn view_axis(d: &EditPlot) -> ([f64; 2], String) {
    if let Some(e) = travel_direction(&d.com, MIN_TRAVEL_M) {
        return (e, "along the direction of travel".into());
    }
    let travel = match (d.com.first(), d.com.last()) {
        (Some(a), Some(b)) => (b[0] - a[0]).hypot(b[1] - a[1]),
        _ => 0.0,
    };
    match d.facing {
        Some(e) => (
            e,
            format!("along the body's facing (the COM travels {travel:.2} m)"),
        ),
        None => (
            [1.0, 0.0],
            format!("world x (the COM travels {travel:.2} m)"),
        ),
    }
}

/// `p` in view coordinates `(s, l, z)` for the unit horizontal axis `e`.
fn to_view(e: [f64; 2], p: &[f64; 3]) -> [f64; 3] {
    [p[0] * e[0] + p[1] * e[1], -p[0] * e[1] + p[1] * e[0], p[2]]
}

/// The shade of pose `i` of `n`: light grey-blue early, dark late.
fn pose_colour(i: usize, n: usize) -> RGBColor {
    let f = if n > 1 {
        i as f64 / (n - 1) as f64
    } else {
        1.0
    };
    let c = |light: f64, dark: f64| (light + (dark - light) * f).round() as u8;
    RGBColor(c(170.0, 20.0), c(185.0, 40.0), c(215.0, 90.0))
}

/// One view of `d` (already in view coordinates) on axes `s` and `k` (1: `l`, 2: `z`).
fn view(
    area: &DrawingArea<BitMapBackend<'_>, Shift>,
    path: &Path,
    d: &EditPlot,
    (caption, x_desc): (&str, &str),
    k: usize,
) -> Result<(), PlotError> {
    let pr = |p: &[f64; 3]| (p[0], p[k]);
    let pts = d
        .com
        .iter()
        .chain(&d.footprints)
        .chain(d.poses.iter().flat_map(|p| p.bones.iter().flatten()));
    let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
    for p in pts.filter(|p| p.iter().all(|v| v.is_finite())) {
        let q = pr(p);
        lo = [lo[0].min(q.0), lo[1].min(q.1)];
        hi = [hi[0].max(q.0), hi[1].max(q.1)];
    }
    if !lo[0].is_finite() {
        (lo, hi) = ([-1.0; 2], [1.0; 2]);
    }
    // Equal metres per pixel on both axes; room above for the time labels.
    let (w, h) = (f64::from(VIEW_PX.0 - 90), f64::from(VIEW_PX.1 - 90));
    let per_px = ((hi[0] - lo[0]).max(0.2) * 1.1 / w).max((hi[1] - lo[1]).max(0.2) * 1.25 / h);
    let mid = [0.5 * (lo[0] + hi[0]), 0.5 * (lo[1] + hi[1])];
    let (hw, hh) = (0.5 * per_px * w, 0.5 * per_px * h);
    // The side view stands on its lowest point; the top view is centred.
    let y0 = if k == 2 {
        lo[1] - 0.1 * (hi[1] - lo[1])
    } else {
        mid[1] - hh
    };
    let mut chart = ChartBuilder::on(area)
        .caption(caption, ("sans-serif", 17))
        .margin(10)
        .x_label_area_size(40)
        .y_label_area_size(50)
        .build_cartesian_2d((mid[0] - hw)..(mid[0] + hw), y0..(y0 + 2.0 * hh))
        .map_err(|e| err(path, e))?;
    let y_desc = if k == 2 { "z, up (m)" } else { "l, left (m)" };
    chart
        .configure_mesh()
        .x_desc(x_desc)
        .y_desc(y_desc)
        .light_line_style(WHITE.mix(0.0))
        .label_style(("sans-serif", 13))
        .draw()
        .map_err(|e| err(path, e))?;
    let n = d.poses.len();
    for (i, pose) in d.poses.iter().enumerate() {
        let colour = pose_colour(i, n);
        chart
            .draw_series(
                pose.bones
                    .iter()
                    .map(|b| PathElement::new(vec![pr(&b[0]), pr(&b[1])], colour.stroke_width(2))),
            )
            .map_err(|e| err(path, e))?;
        if k == 2 {
            let top = pose
                .bones
                .iter()
                .flatten()
                .max_by(|a, b| a[2].total_cmp(&b[2]));
            if let Some(top) = top {
                let style = ("sans-serif", 12)
                    .into_font()
                    .color(&colour)
                    .pos(Pos::new(HPos::Center, VPos::Bottom));
                chart
                    .draw_series(std::iter::once(Text::new(
                        format!("{:.2} s", pose.time_s),
                        (top[0], top[2] + 4.0 * per_px),
                        style,
                    )))
                    .map_err(|e| err(path, e))?;
            }
        }
    }
    let dark = pose_colour(1, 1);
    chart
        .draw_series(std::iter::empty::<PathElement<(f64, f64)>>())
        .map_err(|e| err(path, e))?
        .label(format!("{n} sampled poses (light: early, dark: late)"))
        .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 16, y)], dark.stroke_width(2)));
    let blue = RGBColor(30, 90, 200);
    chart
        .draw_series(LineSeries::new(d.com.iter().map(pr), blue.stroke_width(2)))
        .map_err(|e| err(path, e))?
        .label("planned COM")
        .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 16, y)], blue.stroke_width(2)));
    if !d.footprints.is_empty() {
        let orange = RGBColor(230, 120, 0);
        chart
            .draw_series(
                d.footprints
                    .iter()
                    .map(|p| TriangleMarker::new(pr(p), 6, orange.filled())),
            )
            .map_err(|e| err(path, e))?
            .label("footprints (planned contact points)")
            .legend(move |(x, y)| TriangleMarker::new((x + 8, y), 6, orange.filled()));
    }
    draw_legend(&mut chart, path)?;
    Ok(())
}

/// The spreading speed `v` (m/s) of a motion in place: consecutive poses
/// [`SPREAD_SPACING_M`] apart; `None` when the motion travels (or has fewer than 2 poses).
pub fn spread_speed(d: &EditPlot) -> Option<f64> {
    if travel_direction(&d.com, MIN_TRAVEL_M).is_some() {
        return None;
    }
    let dt = d.poses.get(1)?.time_s - d.poses.first()?.time_s;
    (dt > 0.0).then(|| SPREAD_SPACING_M / dt)
}

/// `d` in view coordinates `(s, l, z)` along `e`, spread in time at `v` m/s when given.
fn in_view(d: &EditPlot, e: [f64; 2], v: Option<f64>) -> EditPlot {
    let at = |p: &[f64; 3], t: f64| {
        let mut q = to_view(e, p);
        q[0] += v.unwrap_or(0.0) * t;
        q
    };
    EditPlot {
        com: d
            .com
            .iter()
            .enumerate()
            .map(|(i, p)| at(p, i as f64 * d.frame_time_s))
            .collect(),
        footprints: match v {
            Some(_) => Vec::new(),
            None => d.footprints.iter().map(|p| to_view(e, p)).collect(),
        },
        poses: d
            .poses
            .iter()
            .map(|p| Pose {
                time_s: p.time_s,
                bones: p
                    .bones
                    .iter()
                    .map(|b| [at(&b[0], p.time_s), at(&b[1], p.time_s)])
                    .collect(),
            })
            .collect(),
        ..d.clone()
    }
}

/// Draws the edit plot: side view (`s–z`) above, top view (`s–l`) below, the title and
/// the verdict of [`edit_verdict`].
///
/// # Errors
/// The file cannot be written or the font cannot be used.
pub fn edit_png(path: &Path, d: &EditPlot) -> Result<(), PlotError> {
    register_font();
    let root = BitMapBackend::new(path, (VIEW_PX.0, 2 * VIEW_PX.1 + TITLE_PX)).into_drawing_area();
    root.fill(&WHITE).map_err(|e| err(path, e))?;
    let root = titled(&root, path, &d.title, &edit_verdict(d))?;
    let (e, why) = view_axis(d);
    let spread = spread_speed(d);
    let v = in_view(d, e, spread);
    let (side, x_desc) = match spread {
        Some(v) => (
            format!("Side view, s {why}; poses spread in time"),
            format!("s + {v:.2} m/s · t (m): in place, spread in time"),
        ),
        None => (format!("Side view, s {why}"), "s (m)".to_string()),
    };
    let (top, bottom) = root.split_vertically(VIEW_PX.1);
    view(&top, path, &v, (&side, &x_desc), 2)?;
    view(
        &bottom,
        path,
        &v,
        ("Top view (l: to the left of s)", &x_desc),
        1,
    )?;
    root.present().map_err(|e| err(path, e))?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn views_follow_the_travel_else_the_facing() {
        // A run along world +y: s is y, whatever the facing says.
        let mut d = EditPlot {
            com: vec![[0.0, 0.0, 1.0], [0.02, 2.0, 1.0]],
            facing: Some([1.0, 0.0]),
            ..EditPlot::default()
        };
        let (e, why) = view_axis(&d);
        assert!(e[1] > 0.99 && why.contains("travel"), "{e:?} {why}");
        assert_eq!(to_view(e, &[0.0, 1.0, 0.5])[0], e[1]);
        // In place: the facing.
        d.com = vec![[0.0, 0.0, 1.0], [0.01, 0.0, 1.3]];
        d.facing = Some([0.0, -1.0]);
        let (e, why) = view_axis(&d);
        assert_eq!(e, [0.0, -1.0]);
        assert!(why.contains("facing") && why.contains("0.01 m"), "{why}");
    }

    #[test]
    fn the_verdict_names_what_fails() {
        let mut d = EditPlot {
            n_frames: 300,
            ..EditPlot::default()
        };
        assert!(edit_verdict(&d).ok);
        d.unconverged = 12;
        let v = edit_verdict(&d);
        assert!(
            !v.ok && v.text.contains("12 of 300 frames NOT converged"),
            "{v:?}"
        );
        d.violated = vec!["run:R:51: friction".into()];
        let v = edit_verdict(&d);
        assert!(
            v.text.starts_with("INFEASIBLE: run:R:51: friction"),
            "{v:?}"
        );
    }
}
