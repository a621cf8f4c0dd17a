//! `stancelib plot clip`: is this clip's motion physically consistent? One clip over clip
//! time: (a) COM height, each flight shaded with the parabola of curvature −g fitted to its
//! frames (dashed, extended a little beyond the flight so it can be told from the COM
//! curve; red when the flight fails the ballistic test) and its free curvature `a_z` in
//! m/s²; (b) horizontal COM speed; (c) one labelled contact row per effector; the clip's
//! warnings listed below. The verdict line says whether every flight is ballistic.
//!
//! # Model
//! ```text
//! flight a..b:  z(t) ≈ −½ g t² + v t + z₀,   (v, z₀) = least squares of z + ½ g t² on t
//! ```
//!
//! # Frames and units
//! World Z up, metres, m/s, m/s², seconds of clip time.

use std::path::Path;

use plotters::coord::types::RangedCoordf64;
use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};

use super::{err, register_font, titled, value_mesh, PlotError, Verdict};
use crate::force_model::GRAVITY as G;
use crate::library::readers::clip_view::{ClipView, EFFECTORS};

/// Pixel size of the clip plot.
pub const CLIP_PLOT_PX: (u32, u32) = (1300, 1000);

/// The −g parabola through the COM heights `z` at times `t` (least squares in `v`, `z₀`):
/// `(t₀, v, z₀)` with `z(t) = z₀ + v (t − t₀) − ½ g (t − t₀)²`; `None` with fewer than 2
/// distinct times.
pub fn ballistic_params(t: &[f64], z: &[f64]) -> Option<(f64, f64, f64)> {
    let n = t.len();
    if n < 2 || z.len() != n {
        return None;
    }
    let t0 = t[0];
    let y: Vec<f64> = t
        .iter()
        .zip(z)
        .map(|(ti, zi)| zi + 0.5 * G * (ti - t0).powi(2))
        .collect();
    let mt = t.iter().map(|ti| ti - t0).sum::<f64>() / n as f64;
    let my = y.iter().sum::<f64>() / n as f64;
    let sxx: f64 = t.iter().map(|ti| (ti - t0 - mt).powi(2)).sum();
    if sxx <= 0.0 {
        return None;
    }
    let sxy: f64 = t
        .iter()
        .zip(&y)
        .map(|(ti, yi)| (ti - t0 - mt) * (yi - my))
        .sum();
    let v = sxy / sxx;
    Some((t0, v, my - v * mt))
}

/// The parabola of [`ballistic_params`] at `t`.
fn parabola((t0, v, z0): (f64, f64, f64), t: f64) -> f64 {
    let s = t - t0;
    z0 + v * s - 0.5 * G * s * s
}

/// The −g parabola through the COM heights of a flight's frames, sampled at those
/// frames' times; `None` with fewer than 2 frames.
pub fn ballistic_fit(t: &[f64], z: &[f64]) -> Option<Vec<(f64, f64)>> {
    let p = ballistic_params(t, z)?;
    Some(t.iter().map(|&ti| (ti, parabola(p, ti))).collect())
}

/// The dashed parabola extends this fraction of the flight's duration before and after it.
pub const FIT_EXTENSION: f64 = 0.35;
/// Headroom above the COM curve of panel (a), as a fraction of its range: room for the
/// a_z labels under the legend.
const LEGEND_HEADROOM: f64 = 0.7;
/// Sampling step of the drawn parabola, s.
const FIT_STEP_S: f64 = 0.002;

/// The verdict of the clip plot: are its flights ballistic?
pub fn clip_verdict(view: &ClipView) -> Verdict {
    let n = view.flights.len();
    let bad: Vec<String> = view
        .flights
        .iter()
        .filter(|f| !f.ballistic)
        .map(|f| {
            f.a_z
                .map_or("untested".into(), |a| format!("a_z {a:.1} m/s²"))
        })
        .collect();
    let warnings = match view.warnings.len() {
        0 => String::new(),
        k => format!("; {k} warning(s) listed below"),
    };
    let range = || {
        let a: Vec<f64> = view.flights.iter().filter_map(|f| f.a_z).collect();
        let lo = a.iter().copied().fold(f64::INFINITY, f64::min);
        let hi = a.iter().copied().fold(f64::NEG_INFINITY, f64::max);
        if a.is_empty() {
            String::new()
        } else if format!("{lo:.1}") == format!("{hi:.1}") {
            format!(" (a_z {lo:.1} m/s², g = {G:.2} m/s²)")
        } else {
            format!(" (a_z {lo:.1} to {hi:.1} m/s², g = {G:.2} m/s²)")
        }
    };
    match (n, bad.len()) {
        (0, _) => Verdict::new(format!("no flight to test{warnings}"), true),
        (_, 0) => Verdict::new(
            format!("all {n} flight(s) ballistic{}{warnings}", range()),
            true,
        ),
        (_, k) => Verdict::new(
            format!(
                "{k} of {n} flight(s) NOT ballistic ({}){warnings}",
                bad.join(", ")
            ),
            false,
        ),
    }
}

type Area<'a> = DrawingArea<BitMapBackend<'a>, Shift>;
type TimeChart<'a, 'b> =
    ChartContext<'a, BitMapBackend<'b>, Cartesian2d<RangedCoordf64, RangedCoordf64>>;

/// Writes the clip plot of `view` to `path`.
///
/// # Errors
/// The file cannot be written or the font cannot be used.
pub fn clip_png(path: &Path, view: &ClipView) -> Result<(), PlotError> {
    register_font();
    let root = BitMapBackend::new(path, CLIP_PLOT_PX).into_drawing_area();
    root.fill(&WHITE).map_err(|e| err(path, e))?;
    let title = format!(
        "clip {}: are its flights ballistic? ({} frames, {:.2} s)",
        view.clip,
        view.time_s.len(),
        view.time_s.last().copied().unwrap_or(0.0) - view.time_s.first().copied().unwrap_or(0.0)
    );
    let root = titled(&root, path, &title, &clip_verdict(view))?;
    let notes_px = 30 + 16 * view.warnings.len().min(6) as u32;
    let (plots, notes) = root.split_vertically(CLIP_PLOT_PX.1 - 70 - notes_px);
    let parts = plots.split_by_breakpoints([] as [u32; 0], [330, 620]);
    let t0 = view.time_s.first().copied().unwrap_or(0.0);
    let t1 = view.time_s.last().copied().unwrap_or(1.0).max(t0 + 1e-3);
    height_panel(&parts[0], path, view, t0..t1)?;
    speed_panel(&parts[1], path, view, t0..t1)?;
    contact_panel(&parts[2], path, view, t0..t1)?;
    warning_notes(&notes, path, &view.warnings)?;
    root.present().map_err(|e| err(path, e))?;
    Ok(())
}

/// The smallest and largest finite value of `v` (±∞ when there is none).
fn finite_range(v: &[f64]) -> (f64, f64) {
    v.iter()
        .filter(|x| x.is_finite())
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &x| {
            (a.min(x), b.max(x))
        })
}

/// A panel over clip time `t` (s) with the given caption and value range.
fn time_chart<'a, 'b>(
    area: &'a Area<'b>,
    path: &Path,
    caption: &str,
    t: std::ops::Range<f64>,
    y: std::ops::Range<f64>,
) -> Result<TimeChart<'a, 'b>, PlotError> {
    ChartBuilder::on(area)
        .caption(caption, ("sans-serif", 16))
        .margin(10)
        .x_label_area_size(35)
        .y_label_area_size(CONTACT_LABEL_PX)
        .build_cartesian_2d(t, y)
        .map_err(|e| err(path, e))
}

/// (a) COM height and the flights.
fn height_panel(
    area: &Area<'_>,
    path: &Path,
    view: &ClipView,
    t: std::ops::Range<f64>,
) -> Result<(), PlotError> {
    let (z_lo, z_hi) = finite_range(&view.com_z);
    let pad = ((z_hi - z_lo) * 0.1).max(0.02);
    // Headroom above the curve for the a_z labels and the legend.
    let (y0, y1) = (
        z_lo - pad,
        z_hi + LEGEND_HEADROOM * (z_hi - z_lo + 2.0 * pad),
    );
    let mut a = time_chart(
        area,
        path,
        "(a) COM height; flights shaded, each with its −g parabola (dashed) and fitted a_z",
        t,
        y0..y1,
    )?;
    value_mesh(&mut a, path, "clip time (s)", "COM height z (m)")?;
    let flights: Vec<(
        Vec<f64>,
        Vec<f64>,
        &crate::library::readers::clip_view::FlightView,
    )> = view
        .flights
        .iter()
        .map(|f| {
            let idx = (0..view.frame.len())
                .filter(|&i| (f.frames.0..=f.frames.1).contains(&view.frame[i]));
            let (t, z): (Vec<f64>, Vec<f64>) = idx.map(|i| (view.time_s[i], view.com_z[i])).unzip();
            (t, z, f)
        })
        .collect();
    let shade = RGBColor(200, 220, 255);
    a.draw_series(
        flights
            .iter()
            .filter(|(t, _, _)| !t.is_empty())
            .map(|(t, _, _)| {
                Rectangle::new([(t[0], y0), (t[t.len() - 1], y1)], shade.mix(0.5).filled())
            }),
    )
    .map_err(|e| err(path, e))?
    .label("flight (no contact)")
    .legend(move |(x, y)| Rectangle::new([(x, y - 5), (x + 14, y + 5)], shade.filled()));
    let com: Vec<(f64, f64)> = view
        .time_s
        .iter()
        .copied()
        .zip(view.com_z.iter().copied())
        .collect();
    let grey = RGBColor(60, 60, 60);
    a.draw_series(LineSeries::new(com, grey.stroke_width(2)))
        .map_err(|e| err(path, e))?
        .label("COM height")
        .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 16, y)], grey.stroke_width(2)));
    for (ts, z, f) in &flights {
        let Some(p) = ballistic_params(ts, z) else {
            continue;
        };
        let colour = if f.ballistic { BLUE } else { RED };
        let (ta, tb) = (ts[0], ts[ts.len() - 1]);
        let ext = FIT_EXTENSION * (tb - ta);
        let n = (((tb - ta) + 2.0 * ext) / FIT_STEP_S).ceil() as usize;
        let fit: Vec<(f64, f64)> = (0..=n)
            .map(|k| ta - ext + k as f64 * FIT_STEP_S)
            .map(|t| (t, parabola(p, t)))
            .filter(|(_, z)| (y0..y1).contains(z))
            .collect();
        let top = fit.iter().map(|q| q.1).fold(f64::NEG_INFINITY, f64::max);
        a.draw_series(DashedLineSeries::new(fit, 10, 6, colour.stroke_width(3)))
            .map_err(|e| err(path, e))?;
        let label = f
            .a_z
            .map_or("a_z untested".to_string(), |v| format!("a_z = {v:.1} m/s²"));
        let style = ("sans-serif", 13)
            .into_font()
            .color(&colour)
            .pos(Pos::new(HPos::Center, VPos::Bottom));
        a.draw_series(std::iter::once(Text::new(
            label,
            (0.5 * (ta + tb), top + pad * 0.3),
            style,
        )))
        .map_err(|e| err(path, e))?;
    }
    a.draw_series(std::iter::empty::<PathElement<(f64, f64)>>())
        .map_err(|e| err(path, e))?
        .label("−g parabola fitted to a flight (blue: ballistic, red: not)")
        .legend(|(x, y)| PathElement::new(vec![(x, y), (x + 16, y)], BLUE.stroke_width(3)));
    super::draw_legend(&mut a, path)?;
    Ok(())
}

/// (b) horizontal speed.
fn speed_panel(
    area: &Area<'_>,
    path: &Path,
    view: &ClipView,
    t: std::ops::Range<f64>,
) -> Result<(), PlotError> {
    let (_, v_hi) = finite_range(&view.speed_xy);
    let mut b = time_chart(
        area,
        path,
        "(b) horizontal COM speed",
        t,
        0.0..(v_hi.max(0.1) * 1.1),
    )?;
    value_mesh(&mut b, path, "clip time (s)", "speed (m/s)")?;
    let speed: Vec<(f64, f64)> = view
        .time_s
        .iter()
        .copied()
        .zip(view.speed_xy.iter().copied())
        .collect();
    b.draw_series(LineSeries::new(speed, BLACK.stroke_width(2)))
        .map_err(|e| err(path, e))?;
    Ok(())
}

/// Width of the contact panel's label area (the longest effector name), px.
const CONTACT_LABEL_PX: u32 = 85;

/// The effector name of contact row `k` at `y = k + 0.5` (the row's centre), else nothing:
/// every row is labelled at its bar, none at the row boundaries.
pub fn row_name(y: &f64) -> String {
    let k = y.floor();
    let centred = (y - k - 0.5).abs() < 1e-6;
    match EFFECTORS.get(k as usize) {
        Some(name) if centred && k >= 0.0 => name.to_string(),
        _ => String::new(),
    }
}

/// (c) contact bars.
fn contact_panel(
    area: &Area<'_>,
    path: &Path,
    view: &ClipView,
    t: std::ops::Range<f64>,
) -> Result<(), PlotError> {
    let mut c = ChartBuilder::on(area)
        .caption(
            "(c) contacts: one row per effector, a bar where it touches the ground",
            ("sans-serif", 16),
        )
        .margin(10)
        .x_label_area_size(35)
        .y_label_area_size(CONTACT_LABEL_PX)
        .build_cartesian_2d(t, 0.0..EFFECTORS.len() as f64)
        .map_err(|e| err(path, e))?;
    c.configure_mesh()
        .x_desc("clip time (s)")
        .disable_y_mesh()
        .y_labels(2 * EFFECTORS.len() + 1)
        .y_label_formatter(&row_name)
        .light_line_style(WHITE.mix(0.0))
        .label_style(("sans-serif", 13))
        .draw()
        .map_err(|e| err(path, e))?;
    let half = view
        .time_s
        .windows(2)
        .map(|w| w[1] - w[0])
        .next()
        .unwrap_or(0.01)
        / 2.0;
    let colours = [
        RGBColor(31, 119, 180),
        RGBColor(214, 39, 40),
        RGBColor(44, 160, 44),
        RGBColor(255, 127, 14),
    ];
    for (k, flags) in view.contact.iter().enumerate() {
        let mut bars = Vec::new();
        let mut i = 0;
        while i < flags.len() {
            if !flags[i] {
                i += 1;
                continue;
            }
            let start = i;
            while i < flags.len() && flags[i] {
                i += 1;
            }
            let (ta, tb) = (view.time_s[start] - half, view.time_s[i - 1] + half);
            let y = k as f64;
            bars.push(Rectangle::new(
                [(ta, y + 0.2), (tb, y + 0.8)],
                colours[k].filled(),
            ));
        }
        c.draw_series(bars).map_err(|e| err(path, e))?;
    }
    Ok(())
}

/// The warnings, one line each (at most six).
fn warning_notes(notes: &Area<'_>, path: &Path, warnings: &[String]) -> Result<(), PlotError> {
    let mut y = 8;
    for w in warnings.iter().take(6) {
        let text: String = w.chars().take(150).collect();
        notes
            .draw(&Text::new(
                format!("warning: {text}"),
                (20, y),
                ("sans-serif", 13).into_font().color(&RED),
            ))
            .map_err(|e| err(path, e))?;
        y += 16;
    }
    if warnings.len() > 6 {
        let more = format!(
            "… and {} more (clips.parquet, warnings)",
            warnings.len() - 6
        );
        notes
            .draw(&Text::new(more, (20, y), ("sans-serif", 13)))
            .map_err(|e| err(path, e))?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_ballistic_fit_recovers_a_projectile() {
        // z = 1 + 2 s − g s²/2 sampled at 100 Hz: the fit reproduces it to rounding.
        let t: Vec<f64> = (0..30).map(|i| 0.3 + i as f64 * 0.01).collect();
        let z: Vec<f64> = t
            .iter()
            .map(|ti| {
                let s = ti - 0.3;
                1.0 + 2.0 * s - 0.5 * G * s * s
            })
            .collect();
        let fit = ballistic_fit(&t, &z).unwrap();
        for ((_, f), z) in fit.iter().zip(&z) {
            assert!((f - z).abs() < 1e-12, "{f} vs {z}");
        }
        assert!(ballistic_fit(&t[..1], &z[..1]).is_none());
    }
}
