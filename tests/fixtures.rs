//! The project's own generated clips (`fixtures/bvh`): they equal the generator's output,
//! and ingest recovers their known COM, contacts, unit and up axis.

use stancelib::contacts::runs;
use stancelib::ingest::{ingest, ClipOutcome, IngestOptions};
use stancelib::synth::generate;

use crate::util;

#[test]
fn committed_fixtures_match_the_generator() {
    for c in &util::FIXTURES {
        let on_disk = std::fs::read_to_string(util::fixture_path(c)).unwrap();
        assert!(
            on_disk == generate(&util::fixture_opts(c)).bvh,
            "{} differs from the generator: run `make fixtures`",
            c.file
        );
    }
}

#[test]
fn ingest_recovers_com_contacts_unit_and_axis_of_the_fixtures() {
    for c in &util::FIXTURES {
        let truth = generate(&util::fixture_opts(c));
        let (summary, frames, _) = util::ingest_fixture(c);
        assert_eq!(summary.unit.as_deref(), Some(c.unit), "{}", c.file);
        assert_eq!(summary.up_axis.as_deref(), Some(c.up_axis), "{}", c.file);
        // The generator's skeleton has a 0.84 m leg by construction.
        assert!(
            (summary.leg_length_m.unwrap() - 0.84).abs() < 1e-6,
            "{}",
            c.file
        );
        assert_eq!(
            frames.frame.len(),
            truth.com.len(),
            "{}: no lead-in frame may be dropped",
            c.file
        );
        // COM: the file prints 9 decimals in file units (≤ 3e-11 m at the CMU unit); FK and
        // the generator's own de Leva sum agree to round-off, so 1e-7 m is generous.
        let worst = frames
            .com
            .iter()
            .zip(&truth.com)
            .map(|(a, b)| (0..3).map(|i| (a[i] - b[i]).powi(2)).sum::<f64>().sqrt())
            .fold(0.0, f64::max);
        assert!(worst < 1e-7, "{}: COM error {worst:e} m", c.file);
        for (k, t) in [&truth.contact_left, &truth.contact_right]
            .into_iter()
            .enumerate()
        {
            let (det, tru) = (runs(&frames.contact[k]), runs(t));
            assert_eq!(
                det.len(),
                tru.len(),
                "{} foot {k}: {det:?} vs {tru:?}",
                c.file
            );
            for (d, t) in det.iter().zip(&tru) {
                // Spec com-from-bvh §7.3: within one frame on noise-free fixtures.
                assert!(
                    d.0.abs_diff(t.0) <= 1 && d.1.abs_diff(t.1) <= 1,
                    "{} foot {k}: {d:?} vs {t:?}",
                    c.file
                );
            }
        }
        println!(
            "{}: unit {} up {} COM err {worst:.1e} m, contacts {:?}",
            c.file,
            c.unit,
            c.up_axis,
            runs(&frames.contact[0])
        );
    }
}

#[test]
fn fixture_flights_are_ballistic() {
    // 120 Hz run: 14-frame flights, exactly ballistic in the generator.
    let c = &util::FIXTURES[0];
    let bvh = stancelib::bvh::parse_file(&util::fixture_path(c)).unwrap();
    let ClipOutcome::Body { summary, .. } = ingest(&bvh, &IngestOptions::default()).unwrap() else {
        panic!()
    };
    let tested: Vec<_> = summary.flights.iter().filter(|f| f.tested).collect();
    assert!(!tested.is_empty());
    for f in tested {
        // Noise-free data: only the 1e-9 m print rounding perturbs the parabola.
        assert!((f.a_z.unwrap() + 9.81).abs() < 1e-3, "{f:?}");
        assert!(f.ballistic && f.rms_m.unwrap() < 1e-6);
    }
    assert!((summary.s_eff.unwrap() - 1.0).abs() < 1e-4);
}
