//! `stancelib synth`: write a generated clip and its ground truth (fixtures/README.md).

use std::fmt::Write as _;

use anyhow::Context;

use super::super::args::SynthArgs;
use super::super::Outcome;
use crate::library::storage::atomic::write_text_atomic;
use crate::skeleton::units::parse_unit;
use crate::synth::{
    generate, SynthMotion, SynthOptions, SynthUp, MAX_DURATION_S, MAX_FRAME_RATE_HZ, MAX_UNIT_M,
    MIN_FRAME_RATE_HZ, MIN_UNIT_M,
};

/// Write `<out>` (BVH) and `<out stem>.truth.csv` (frame, time_s, com_x/y/z in metres Z up,
/// contact_left_foot, contact_right_foot, force per kg x/y/z), each atomically (a
/// temporary beside it, then renamed: a failed write keeps an earlier file).
///
/// # Errors
/// An unknown unit; a rate, duration or unit out of range; an unwritable output.
pub fn run(a: SynthArgs) -> anyhow::Result<Outcome> {
    let (motion, up): (SynthMotion, SynthUp) = (a.motion.into(), a.up.into());
    let unit_m =
        parse_unit(&a.unit).ok_or_else(|| anyhow::anyhow!("--unit: '{}' is not a unit", a.unit))?;
    // The generator clamps these; the command refuses them instead of writing another clip.
    anyhow::ensure!(
        (MIN_FRAME_RATE_HZ..=MAX_FRAME_RATE_HZ).contains(&a.rate),
        "--rate: must lie in [{MIN_FRAME_RATE_HZ}, {MAX_FRAME_RATE_HZ}] Hz (MAX_FRAME_RATE_HZ), found {}",
        a.rate
    );
    anyhow::ensure!(
        a.duration > 0.0 && a.duration <= MAX_DURATION_S,
        "--duration: must lie in (0, {MAX_DURATION_S}] s (MAX_DURATION_S), found {}",
        a.duration
    );
    anyhow::ensure!(
        (MIN_UNIT_M..=MAX_UNIT_M).contains(&unit_m),
        "--unit: must lie in [{MIN_UNIT_M}, {MAX_UNIT_M}] m per unit, found {unit_m}"
    );
    let opts = SynthOptions {
        motion,
        frame_rate_hz: a.rate,
        duration_s: a.duration,
        unit_m,
        up,
        seed: a.seed,
        ..Default::default()
    };
    let clip = generate(&opts);
    // Atomic, as every output: a failed write (a full disk) keeps an earlier file whole.
    write_text_atomic(&a.out, &clip.bvh).with_context(|| format!("writing {}", a.out.display()))?;
    let mut csv = String::from("frame,time_s,com_x,com_y,com_z,contact_left_foot,contact_right_foot,force_x_per_kg,force_y_per_kg,force_z_per_kg\n");
    let dt = 1.0 / opts.frame_rate_hz;
    for (f, c) in clip.com.iter().enumerate() {
        let g = clip.force_n_per_kg[f];
        let _ = writeln!(
            csv,
            "{f},{:.9},{:.9},{:.9},{:.9},{},{},{:.9},{:.9},{:.9}",
            f as f64 * dt,
            c[0],
            c[1],
            c[2],
            clip.contact_left[f],
            clip.contact_right[f],
            g[0],
            g[1],
            g[2]
        );
    }
    let truth = a.out.with_extension("truth.csv");
    write_text_atomic(&truth, &csv).with_context(|| format!("writing {}", truth.display()))?;
    crate::say!("wrote {} and {}", a.out.display(), truth.display());
    Ok(Outcome::Clean)
}
