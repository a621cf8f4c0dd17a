//! Static (elevated) contacts on the multi-contact clips (spec com-from-bvh §7.4).

use stancelib::contacts::{runs, EFFECTORS};
use stancelib::ingest::IngestOptions;

use crate::util;

fn load(
    rel: &str,
    static_mode: bool,
) -> Option<(
    stancelib::ingest::ClipFrames,
    Vec<stancelib::ingest::ContactRun>,
)> {
    let data = util::shared_or_skip("multicontact")?;
    let bvh = stancelib::bvh::parse_file(&data.join("bvh").join(rel)).unwrap();
    let mut o = IngestOptions::default();
    o.contacts.static_mode = static_mode;
    let (_, frames, contacts) = util::ingest_body(&bvh, &o, rel);
    Some((frames, contacts))
}

#[test]
fn climbing_clip_holds_bars_and_steps_in_static_mode() {
    let Some((frames, contacts)) = load("multicontact/cmu_01_03_climb_hang_mb.bvh", true) else {
        return;
    };
    let stat = frames
        .static_contact
        .as_ref()
        .expect("static flags in static mode");
    for (e, name) in EFFECTORS.iter().enumerate() {
        let n = stat[e].iter().filter(|s| **s).count();
        println!("{name}: {n} static frames, {} runs", runs(&stat[e]).len());
        // The subject climbs a ladder and hangs from a bar with both hands: every effector
        // is held still above the floor for at least a quarter second somewhere.
        assert!(n as f64 / 120.0 >= 0.25, "{name}: {n} static frames");
        // Static frames are contact frames (the static flag is OR-ed in).
        assert!(stat[e]
            .iter()
            .zip(&frames.contact[e])
            .all(|(s, c)| !s || *c));
    }
    for c in contacts.iter().filter(|c| c.is_static) {
        // Static surfaces are above the floor by construction (> 0.10 m above the point's floor).
        assert!(c.surface_z > 0.1, "{c:?}");
    }
    let bars: Vec<f64> = contacts
        .iter()
        .filter(|c| c.is_static && c.effector.ends_with("hand"))
        .map(|c| c.surface_z)
        .collect();
    // The hands hold a bar well above a standing subject's hip height.
    assert!(bars.iter().all(|z| *z > 1.2), "{bars:?}");
}

#[test]
fn static_mode_is_off_by_default() {
    let Some((frames, contacts)) = load("multicontact/cmu_01_03_climb_hang_mb.bvh", false) else {
        return;
    };
    assert!(frames.static_contact.is_none() && frames.surface_z.is_none());
    assert!(contacts.iter().all(|c| !c.is_static));
}
