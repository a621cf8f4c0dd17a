//! `stancelib plot clip`: one clip over clip time. (a) COM height, with each flight's
//! parabola of curvature −g fitted to its frames (dashed; red when the flight fails the
//! ballistic test) and its free curvature `a_z` written beside it; (b) horizontal COM
//! speed; (c) a contact bar per effector; the clip's warnings listed below.
//!
//! # Model
//! ```text
//! flight a..b:  z(t) ≈ −½ g t² + v t + z₀,   (v, z₀) = least squares of z + ½ g t² on t
//! ```
//!
//! # Frames and units
//! World Z up, metres, m/s, seconds of clip time.

use std::path::Path;

use plotters::coord::types::RangedCoordf64;
use plotters::coord::Shift;
use plotters::prelude::*;

use super::{err, register_font, value_mesh, PlotError};
use crate::force_model::GRAVITY as G;
use crate::library::clip_view::{ClipView, EFFECTORS};

/// Pixel size of the clip plot.
pub const CLIP_PLOT_PX: (u32, u32) = (1300, 1000);

/// The −g parabola through the COM heights of frames `idx` (least squares in `v`, `z₀`),
/// sampled at those frames' times; `None` with fewer than 2 frames.
pub fn ballistic_fit(t: &[f64], z: &[f64]) -> Option<Vec<(f64, f64)>> {
    let n = t.len();
    if n < 2 {
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
    let z0 = my - v * mt;
    Some(
        t.iter()
            .map(|ti| {
                let s = ti - t0;
                (*ti, z0 + v * s - 0.5 * G * s * s)
            })
            .collect(),
    )
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
        "clip {}: {} frames, {} flight(s), {} warning(s)",
        view.clip,
        view.time_s.len(),
        view.flights.len(),
        view.warnings.len()
    );
    let root = root
        .titled(&title, ("sans-serif", 22))
        .map_err(|e| err(path, e))?;
    let notes_px = 30 + 16 * view.warnings.len().min(6) as u32;
    let (plots, notes) = root.split_vertically(CLIP_PLOT_PX.1 - 40 - notes_px);
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
        .y_label_area_size(65)
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
    let mut a = time_chart(
        area,
        path,
        "(a) COM height; flights: −g parabola fitted (dashed, red = not ballistic)",
        t,
        (z_lo - pad)..(z_hi + pad),
    )?;
    value_mesh(&mut a, path, "clip time (s)", "COM z (m)")?;
    let com: Vec<(f64, f64)> = view
        .time_s
        .iter()
        .copied()
        .zip(view.com_z.iter().copied())
        .collect();
    a.draw_series(LineSeries::new(com, BLACK.stroke_width(2)))
        .map_err(|e| err(path, e))?;
    for f in &view.flights {
        let idx: Vec<usize> = (0..view.frame.len())
            .filter(|&i| (f.frames.0..=f.frames.1).contains(&view.frame[i]))
            .collect();
        let t: Vec<f64> = idx.iter().map(|&i| view.time_s[i]).collect();
        let z: Vec<f64> = idx.iter().map(|&i| view.com_z[i]).collect();
        let colour = if f.ballistic { BLUE } else { RED };
        if let Some(fit) = ballistic_fit(&t, &z) {
            let top = fit.iter().map(|p| p.1).fold(f64::NEG_INFINITY, f64::max);
            let tm = fit[fit.len() / 2].0;
            a.draw_series(DashedLineSeries::new(fit, 5, 3, colour.stroke_width(2)))
                .map_err(|e| err(path, e))?;
            let label = f.a_z.map_or("a_z –".to_string(), |v| format!("a_z {v:.1}"));
            a.draw_series(std::iter::once(Text::new(
                label,
                (tm, top + pad * 0.3),
                ("sans-serif", 12).into_font().color(&colour),
            )))
            .map_err(|e| err(path, e))?;
        }
    }
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

/// (c) contact bars.
fn contact_panel(
    area: &Area<'_>,
    path: &Path,
    view: &ClipView,
    t: std::ops::Range<f64>,
) -> Result<(), PlotError> {
    let mut c = time_chart(
        area,
        path,
        "(c) contacts (bars: frames in contact)",
        t,
        0.0..4.0,
    )?;
    c.configure_mesh()
        .x_desc("clip time (s)")
        .y_labels(4)
        .y_label_formatter(&|y: &f64| {
            let k = y.floor() as usize;
            EFFECTORS.get(k).map_or(String::new(), |e| e.to_string())
        })
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
