//! Contact timing and the physics cross-check of contacts (issue 12 items 4 and 6):
//! sub-frame touchdown and liftoff times against the force plates, no non-ballistic
//! no-contact interval on the real clips, a stance on a platform recovered by the
//! speed-led rule, and a skeleton without a head joint.
//!
//! # References
//! spec com-from-bvh §7.3, §7.7; `src/contacts/timing.rs`, `src/contacts/support.rs`;
//! `data/forceplate/SOURCES.md`, `data/bvh/SOURCES.md`.

use std::path::PathBuf;

use serde_json::Value;
use stancelib::ingest::{ingest, ClipOutcome, ContactRun, IngestOptions};
use stancelib::synth::{generate, SynthOptions};

use crate::util::{self, outln};

/// Signed errors (detected − plate) of one foot and event type: each plate event is
/// matched to the nearest detected event within 0.15 s (CORRECTIONS issue 2 item 4);
/// plate events within 2 frames of a clip end are not scored. `None`: unmatched.
fn event_errors(
    plate: &[f64],
    detected: &[f64],
    t_first: f64,
    t_last: f64,
    dt: f64,
) -> Vec<Option<f64>> {
    plate
        .iter()
        .filter(|&&tp| tp - t_first > 2.0 * dt && t_last - tp > 2.0 * dt)
        .map(|&tp| {
            detected
                .iter()
                .map(|&t| t - tp)
                .filter(|e| e.abs() <= 0.15)
                .min_by(|a, b| a.abs().total_cmp(&b.abs()))
        })
        .collect()
}

// See: issue 12 item 4 — contacts about one frame late against the plates.
#[test]
fn subframe_contact_events_are_within_half_a_frame_of_the_force_plates() {
    let Some(data) =
        util::shared_or_skip("subframe_contact_events_are_within_half_a_frame_of_the_force_plates")
    else {
        return;
    };
    let mut out = String::new();
    let mut failures = Vec::new();
    for clip in ["hamner_s02_run_4ms", "opencap_s4_DJ1_dropjump"] {
        let fp = util::forceplate_clip(&data, clip);
        let opts = IngestOptions {
            mass_kg: fp.mass,
            ..Default::default()
        };
        let (summary, frames, contacts) = util::ingest_body(&fp.bvh, &opts, clip);
        let dt = summary.frame_time_s;
        let n = frames.time_s.len();
        let (t_first, t_last) = (frames.time_s[0], frames.time_s[n - 1]);
        // Target (issue 12): mean |error| ≤ half a frame + 5 ms per foot and event type.
        let target = 0.5 * dt + 0.005;
        outln!(
            out,
            "== {clip} at {:.0} Hz: target mean |error| ≤ {:.1} ms",
            1.0 / dt,
            target * 1e3
        );
        for (side, effector) in [("left", "left_foot"), ("right", "right_foot")] {
            let runs: Vec<&ContactRun> =
                contacts.iter().filter(|r| r.effector == effector).collect();
            let events = fp.meta["plate_events"][side]
                .as_array()
                .expect("plate_events");
            for kind in ["touchdown", "liftoff"] {
                let plate: Vec<f64> = events
                    .iter()
                    .filter_map(|e: &Value| e[format!("{kind}_s")].as_f64())
                    .collect();
                let pick = |sub: bool| -> Vec<f64> {
                    runs.iter()
                        .filter_map(|r| match (kind, sub) {
                            ("touchdown", false) => r.t_td_s,
                            ("touchdown", true) => r.td_time_s,
                            (_, false) => r.t_lo_s,
                            (_, true) => r.lo_time_s,
                        })
                        .collect()
                };
                let mut line = format!("  {side:<5} {kind:<9}");
                for (label, sub) in [
                    ("frame edge t_td_s/t_lo_s", false),
                    ("sub-frame td_time_s/lo_time_s", true),
                ] {
                    let errs = event_errors(&plate, &pick(sub), t_first, t_last, dt);
                    let unmatched = errs.iter().filter(|e| e.is_none()).count();
                    let e: Vec<f64> = errs.into_iter().flatten().collect();
                    let mean_abs = e.iter().map(|x| x.abs()).sum::<f64>() / e.len().max(1) as f64;
                    let signed = e.iter().sum::<f64>() / e.len().max(1) as f64;
                    let worst = e.iter().fold(0.0f64, |m, x| m.max(x.abs()));
                    line.push_str(&format!(
                        " | {label}: n {:>2}, |err| mean {:5.1} ms, worst {:5.1} ms, signed {:+5.1} ms",
                        e.len(),
                        mean_abs * 1e3,
                        worst * 1e3,
                        signed * 1e3
                    ));
                    if sub {
                        if unmatched > 0 || e.is_empty() {
                            failures.push(format!("{clip} {side} {kind}: {unmatched} plate events unmatched, {} scored", e.len()));
                        }
                        // + 1e-12 s: round-off of the frame-time arithmetic only.
                        if mean_abs > target + 1e-12 {
                            failures.push(format!(
                                "{clip} {side} {kind}: sub-frame mean |error| {:.1} ms > {:.1} ms",
                                mean_abs * 1e3,
                                target * 1e3
                            ));
                        }
                    }
                }
                outln!(out, "{line}");
            }
        }
    }
    print!("{out}");
    assert!(
        failures.is_empty(),
        "sub-frame event failures:\n{}",
        failures.join("\n")
    );
}

// See: issue 12 item 6 — a non-ballistic "flight" is a missed support.
#[test]
fn no_contact_interval_of_a_real_clip_is_non_ballistic() {
    let Some(data) = util::shared_or_skip("no_contact_interval_of_a_real_clip_is_non_ballistic")
    else {
        return;
    };
    // The one interval the speed-led rule cannot resolve (measured; see the report of
    // issue 12): CMU 01_13, a playground clip, drops from a bar at frames 1348-1367 while
    // the hands still move at 1.6-3.4 m/s and the feet at 2.4-3.1 m/s: the COM curves at
    // -6 m/s² over 0.16 s, so something still holds it, but nothing is slow. It must be
    // reported in the clip's warnings.
    let unresolved = [("bvh-bulk/cmu/01_13.bvh", 1348, 1367)];
    let mut files = util::bvh_files(&data.join("bvh"));
    files.extend(util::bvh_files(&data.join("bvh-bulk/cmu")));
    assert!(files.len() > 100, "only {} clips found", files.len());
    let mut out = String::new();
    let mut failures = Vec::new();
    let (mut clips, mut recovered) = (0, 0);
    for path in &files {
        let name = path
            .strip_prefix(&data)
            .unwrap_or(path)
            .display()
            .to_string();
        let Ok(bvh) = stancelib::bvh::parse_file(path) else {
            continue; // readers are tested elsewhere; the 2-joint file and the like
        };
        let Ok(ClipOutcome::Body { summary, .. }) = ingest(&bvh, &IngestOptions::default()) else {
            continue;
        };
        clips += 1;
        let known = |f: &&stancelib::contacts::flight::Flight| {
            unresolved
                .iter()
                .any(|(c, a, b)| name.ends_with(c) && f.first_frame == *a && f.last_frame == *b)
        };
        for f in summary.flights.iter().filter(known) {
            let reported = summary.warnings.iter().any(|w| {
                w.starts_with("missed support")
                    && w.contains(&format!("{}-{}", f.first_frame, f.last_frame))
                    && w.contains("no support found")
            });
            outln!(
                out,
                "{name}: known unresolved interval {}-{} (a_z {:+.2}), reported: {reported}",
                f.first_frame,
                f.last_frame,
                f.a_z_all.unwrap_or(f64::NAN)
            );
            if !reported {
                failures.push(format!(
                    "{name}: unresolved interval {}-{} not in warnings",
                    f.first_frame, f.last_frame
                ));
            }
        }
        let bad: Vec<String> = summary
            .flights
            .iter()
            .filter(|f| stancelib::contacts::support::is_missed_support(f) && !known(f))
            .map(|f| {
                format!(
                    "{}-{} ({:.2} s, a_z {:+.2})",
                    f.first_frame,
                    f.last_frame,
                    f.duration_s,
                    f.a_z.unwrap_or(f64::NAN)
                )
            })
            .collect();
        let warned = summary
            .warnings
            .iter()
            .filter(|w| w.starts_with("missed support"))
            .count();
        recovered += warned;
        let scaled = util::TIME_SCALED_CLIPS.iter().any(|s| name.ends_with(s));
        outln!(out, "{name:<60} non-ballistic no-contact intervals ≥ 0.1 s: {:>2}{}; missed supports re-detected: {warned} {bad:?}", bad.len(), if scaled { " (time-scaled: not checked)" } else { "" });
        if !bad.is_empty() && !scaled {
            failures.push(format!("{name}: {bad:?}"));
        }
    }
    outln!(
        out,
        "{clips} clips, {recovered} missed supports re-detected, {} clips fail",
        failures.len()
    );
    print!("{out}");
    assert!(
        failures.is_empty(),
        "non-ballistic no-contact intervals:\n{}",
        failures.join("\n")
    );
}

/// Truth runs `(first, last)` of a per-frame flag.
fn truth_runs(flags: &[bool]) -> Vec<(i64, i64)> {
    stancelib::contacts::runs(flags)
        .into_iter()
        .map(|(a, b)| (a as i64, b as i64))
        .collect()
}

// See: issue 12 item 6 — a foot planted 5 cm above its lowest point loses a whole stance.
#[test]
fn stance_on_a_platform_is_recovered_by_the_speed_led_rule() {
    let synth = SynthOptions {
        platform_m: 0.05,
        ..Default::default()
    };
    let clip = generate(&synth);
    let bvh = stancelib::bvh::parse_reader(clip.bvh.as_bytes()).expect("generated BVH parses");
    let truth = truth_runs(&clip.contact_right);
    let (a, b) = truth[0]; // the right foot's first stance is the one on the platform
    let overlaps = |runs: &[ContactRun]| {
        runs.iter()
            .filter(|r| r.effector == "right_foot" && r.first_frame <= b && r.last_frame >= a)
            .map(|r| (r.first_frame, r.last_frame))
            .collect::<Vec<_>>()
    };
    // Without the check (the height rule alone), the whole stance is lost and the COM
    // "flight" over it curves upwards.
    let mut off = IngestOptions::default();
    off.contacts.support_check = false;
    let (s_off, _, c_off) = util::ingest_body(&bvh, &off, "platform run, check off");
    println!(
        "truth right {truth:?}; check off: flights {:?}; runs {:?}",
        s_off
            .flights
            .iter()
            .map(|f| (f.first_frame, f.last_frame, f.a_z_all))
            .collect::<Vec<_>>(),
        c_off
            .iter()
            .map(|r| (r.effector, r.first_frame, r.last_frame))
            .collect::<Vec<_>>()
    );
    let lost = s_off
        .flights
        .iter()
        .find(|f| f.first_frame <= a && f.last_frame >= b)
        .expect("a no-contact interval over the platform stance");
    println!(
        "platform stance {a}-{b} ({:.3} s): check off: right-foot runs over it {:?}, no-contact {}-{} with a_z {:+.2} m/s²",
        (b - a + 1) as f64 / 120.0,
        overlaps(&c_off),
        lost.first_frame,
        lost.last_frame,
        lost.a_z.unwrap_or(f64::NAN)
    );
    assert!(overlaps(&c_off).is_empty());
    assert!(stancelib::contacts::support::is_missed_support(lost));

    let (s_on, _, c_on) = util::ingest_body(&bvh, &IngestOptions::default(), "platform run");
    let found = overlaps(&c_on);
    println!(
        "check on: right-foot runs {found:?}; warnings {:?}",
        s_on.warnings
    );
    assert_eq!(found.len(), 1, "one recovered stance: {found:?}");
    let (fa, fb) = found[0];
    // Within one frame of the truth at each edge (the speeds are central differences: the
    // first and last planted frames carry half the swing speed).
    assert!(
        (fa - a).abs() <= 1 && (fb - b).abs() <= 1,
        "recovered {fa}-{fb}, truth {a}-{b}"
    );
    let r = c_on
        .iter()
        .find(|r| r.first_frame == fa && r.effector == "right_foot")
        .unwrap();
    assert!(r.speed_led, "the run is marked speed-led");
    // The contact height is the platform's, not the floor's.
    assert!(
        (r.surface_z - 0.05).abs() < 0.01,
        "surface_z {}",
        r.surface_z
    );
    assert!(s_on
        .warnings
        .iter()
        .any(|w| w.starts_with("missed support") && w.contains("right_foot")));
    assert!(!s_on
        .flights
        .iter()
        .any(stancelib::contacts::support::is_missed_support));
    // Every other stance is unchanged by the check.
    let others = |c: &[ContactRun]| {
        c.iter()
            .filter(|r| !(r.effector == "right_foot" && r.first_frame <= b && r.last_frame >= a))
            .map(|r| (r.effector, r.first_frame, r.last_frame))
            .collect::<Vec<_>>()
    };
    assert_eq!(others(&c_on), others(&c_off));
}

/// CMU mb joint names → the CMU ASF names of the same bones (Hahne's conversion keeps the
/// ASF tree: `Spine` is `upperback`, `LeftHand` is `lwrist`, `LeftFingerBase` is `lhand`).
const MB_TO_ASF: [(&str, &str); 30] = [
    ("Hips", "root"),
    ("LHipJoint", "lhipjoint"),
    ("LeftUpLeg", "lfemur"),
    ("LeftLeg", "ltibia"),
    ("LeftFoot", "lfoot"),
    ("LeftToeBase", "ltoes"),
    ("RHipJoint", "rhipjoint"),
    ("RightUpLeg", "rfemur"),
    ("RightLeg", "rtibia"),
    ("RightFoot", "rfoot"),
    ("RightToeBase", "rtoes"),
    ("LowerBack", "lowerback"),
    ("Spine", "upperback"),
    ("Spine1", "thorax"),
    ("Neck", "lowerneck"),
    ("Neck1", "upperneck"),
    ("LeftShoulder", "lclavicle"),
    ("LeftArm", "lhumerus"),
    ("LeftForeArm", "lradius"),
    ("LeftHand", "lwrist"),
    ("LeftFingerBase", "lhand"),
    ("LeftHandIndex1", "lfingers"),
    ("LThumb", "lthumb"),
    ("RightShoulder", "rclavicle"),
    ("RightArm", "rhumerus"),
    ("RightForeArm", "rradius"),
    ("RightHand", "rwrist"),
    ("RightFingerBase", "rhand"),
    ("RightHandIndex1", "rfingers"),
    ("RThumb", "rthumb"),
];

/// The CMU mb text with ASF joint names, without the `Head` joint (and its 3 channels in
/// every motion row) and without any End Site.
fn strip_head_and_end_sites(text: &str) -> String {
    let (head, motion) = text.split_once("MOTION").expect("MOTION");
    let mut out = String::new();
    let (mut col, mut head_cols, mut skip_depth) = (0usize, None, None::<usize>);
    let mut depth = 0usize;
    for line in head.lines() {
        let t = line.trim();
        let opens = t == "{";
        let closes = t == "}";
        if let Some(d) = skip_depth {
            if opens {
                depth += 1;
            }
            if closes {
                depth -= 1;
                if depth == d {
                    skip_depth = None;
                }
            }
            if let Some(n) = t.strip_prefix("CHANNELS ") {
                let k: usize = n.split_whitespace().next().unwrap().parse().unwrap();
                if head_cols.is_none() {
                    head_cols = Some((col, k));
                }
                col += k;
            }
            continue;
        }
        if t == "JOINT Head" || t.starts_with("End Site") {
            skip_depth = Some(depth);
            continue;
        }
        if opens {
            depth += 1;
        }
        if closes {
            depth -= 1;
        }
        if let Some(n) = t.strip_prefix("CHANNELS ") {
            col += n
                .split_whitespace()
                .next()
                .unwrap()
                .parse::<usize>()
                .unwrap();
        }
        let mut l = line.to_string();
        for (mb, asf) in MB_TO_ASF {
            for kw in ["ROOT", "JOINT"] {
                if t == format!("{kw} {mb}") {
                    l = line.replace(&format!("{kw} {mb}"), &format!("{kw} {asf}"));
                }
            }
        }
        out.push_str(&l);
        out.push('\n');
    }
    let (c0, k) = head_cols.expect("the Head joint has channels");
    out.push_str("MOTION");
    for (i, line) in motion.lines().enumerate() {
        if i == 0 || line.trim().is_empty() || line.starts_with("Frame") {
            out.push_str(line);
        } else {
            let v: Vec<&str> = line.split_whitespace().collect();
            let kept: Vec<&str> = v[..c0].iter().chain(&v[c0 + k..]).copied().collect();
            out.push_str(&kept.join(" "));
        }
        out.push('\n');
    }
    out
}

// See: issue 12 item 6 — a skeleton without a head joint is rejected outright.
#[test]
fn skeleton_without_a_head_takes_its_head_from_the_neck_chain() {
    let Some(data) =
        util::shared_or_skip("skeleton_without_a_head_takes_its_head_from_the_neck_chain")
    else {
        return;
    };
    let path = data.join("bvh/run/cmu_09_01_run_mb.bvh");
    let text = std::fs::read_to_string(&path).expect("cmu_09_01");
    let edited = strip_head_and_end_sites(&text);
    assert!(
        !edited.contains("Head")
            && !edited.contains("End Site")
            && edited.contains("JOINT lowerneck")
    );
    let orig = stancelib::bvh::parse_reader(text.as_bytes()).expect("original parses");
    let bvh = stancelib::bvh::parse_reader(edited.as_bytes()).expect("edited BVH parses");
    assert_eq!(bvh.motion.n_frames(), orig.motion.n_frames());
    let (s0, f0, _) = util::ingest_body(&orig, &IngestOptions::default(), "cmu_09_01");
    let (s1, f1, c1) =
        util::ingest_body(&bvh, &IngestOptions::default(), "cmu_09_01 without a head");
    println!("skeleton: {:?}\nwarnings: {:?}", s1.skeleton, s1.warnings);
    assert!(
        s1.warnings.iter().any(|w| w.starts_with("no head joint")),
        "{:?}",
        s1.warnings
    );
    assert_eq!(s1.unit, s0.unit);
    assert_eq!(s1.up_axis, s0.up_axis);
    assert_eq!(f1.com.len(), f0.com.len());
    let d: Vec<f64> = f0
        .com
        .iter()
        .zip(&f1.com)
        .map(|(a, b)| (0..3).map(|i| (a[i] - b[i]).powi(2)).sum::<f64>().sqrt())
        .collect();
    let max = d.iter().cloned().fold(0.0, f64::max);
    let mean = d.iter().sum::<f64>() / d.len() as f64;
    println!(
        "COM difference without the head joint: mean {:.2} mm, max {:.2} mm",
        mean * 1e3,
        max * 1e3
    );
    // Tolerance 5 mm: the head segment carries 6.94 % of the mass with its COM half-way
    // between C7 and the vertex, so a vertex misplaced by d moves the COM by 0.035·d: 5 mm
    // allows d ≈ 14 cm, far more than a correct estimate needs (the rebuilt vertex sits
    // within a few cm of the file's own) and far less than a missing head segment (its
    // mass on C7 alone moves the COM by 0.035 × the 0.24 m head length ≈ 8 mm).
    // Also different, by well under 1 mm: the toe tips (the toe joints, with no End
    // Sites) and MET3 (extrapolated along the forearm).
    assert!(max < 0.005, "COM moved by {:.2} mm", max * 1e3);
    // Contacts still work: the three flights of the run are there.
    assert_eq!(
        s1.flights.iter().filter(|f| f.ballistic).count(),
        s0.flights.iter().filter(|f| f.ballistic).count()
    );
    assert!(!c1.is_empty());
}

// See: issue 12 item 4 — sub-frame times on the noise-free fixtures; issue 39 item 5 — the
// generator's feet now meet the event test at the force's first and last frame, so the
// 15 ms the rigid feet's early touchdowns needed is gone.
#[test]
fn subframe_events_of_the_fixtures_are_within_a_frame_of_the_truth() {
    let mut out = String::new();
    for case in &util::FIXTURES {
        let clip = generate(&util::fixture_opts(case));
        let bvh = stancelib::bvh::parse_file(&util::fixture_path(case)).expect("fixture parses");
        let (summary, frames, contacts) =
            util::ingest_body(&bvh, &IngestOptions::default(), case.file);
        let dt = summary.frame_time_s;
        let mut worst: f64 = 0.0;
        for (flags, effector) in [
            (&clip.contact_left, "left_foot"),
            (&clip.contact_right, "right_foot"),
        ] {
            for (a, b) in truth_runs(flags) {
                // The foot arrives at frame a and leaves after frame b (synth module docs).
                let (t_td, t_lo) = (a as f64 * dt, b as f64 * dt);
                let r = contacts
                    .iter()
                    .find(|r| r.effector == effector && r.first_frame <= b && r.last_frame >= a)
                    .unwrap_or_else(|| {
                        panic!("{}: no detected run over {effector} {a}-{b}", case.file)
                    });
                // One frame: the feet meet the event test (3 cm, spec §7.3) exactly at
                // the force's first and last frame (synth module docs, the sole's give);
                // 1e-9 s: round-off.
                let tol = dt + 1e-9;
                for (det, truth, kind) in [
                    (r.td_time_s, t_td, "touchdown"),
                    (r.lo_time_s, t_lo, "liftoff"),
                ] {
                    let (Some(det), true) = (det, a > 0 && (b as usize) + 1 < frames.time_s.len())
                    else {
                        continue;
                    };
                    worst = worst.max((det - truth).abs() / dt);
                    assert!(
                        (det - truth).abs() <= tol,
                        "{} {effector} {kind}: {det:.4} s, truth {truth:.4} s",
                        case.file
                    );
                }
            }
        }
        outln!(
            out,
            "{}: worst sub-frame event error {worst:.2} frames",
            case.file
        );
    }
    print!("{out}");
}

/// Stances of one clip ingested with `mass` (default options otherwise).
fn clip_stances(
    bvh: &stancelib::bvh::Bvh,
    name: &str,
    mass: f64,
) -> Vec<stancelib::stances::Stance> {
    use stancelib::stances::{assemble_clip, StanceOptions};
    let opts = IngestOptions {
        mass_kg: mass,
        ..Default::default()
    };
    let (summary, frames, contacts) = util::ingest_body(bvh, &opts, name);
    assemble_clip(
        name,
        &frames,
        &summary,
        &contacts,
        mass,
        &StanceOptions::default(),
    )
    .0
}

// See: issue 37 item 3 — a 2 m/s jog's 40–60 ms flights, closed up by the contact gates,
// are opened by the whole-body force (`contacts::hidden_flight`); no walk gains a flight.
#[test]
fn hidden_flights_open_jogs_and_leave_walks() {
    use stancelib::stances::segment::Boundary;
    let Some(data) = util::shared_or_skip("hidden_flights_open_jogs_and_leave_walks") else {
        return;
    };
    let fp = util::forceplate_clip(&data, "hamner_multi_run_2ms");
    let st = clip_stances(&fp.bvh, "hamner_multi_run_2ms", fp.mass);
    let both = st
        .iter()
        .filter(|s| s.boundary_start == Boundary::Flight && s.boundary_end == Boundary::Flight)
        .count();
    let flights = st
        .iter()
        .filter(|s| s.boundary_end == Boundary::Flight)
        .count();
    // Sub-frame events of the opened flights against the plates' (matched within 0.15 s).
    let plate = |side: &str, kind: &str| -> Vec<f64> {
        fp.meta["plate_events"][side]
            .as_array()
            .expect("plate_events")
            .iter()
            .filter_map(|e: &Value| e[format!("{kind}_s")].as_f64())
            .collect()
    };
    let mut errs = Vec::new();
    for s in &st {
        let side = match s.label.as_str() {
            "L" => "left",
            "R" => "right",
            _ => continue,
        };
        if s.boundary_start == Boundary::Flight {
            errs.extend(nearest(&plate(side, "touchdown"), s.td_clip_s));
        }
        if s.boundary_end == Boundary::Flight {
            errs.extend(nearest(&plate(side, "liftoff"), s.lo_clip_s));
        }
    }
    let mean_abs = errs.iter().map(|e: &f64| e.abs()).sum::<f64>() / errs.len().max(1) as f64;
    println!(
        "hamner_multi_run_2ms: {} stances, {both} with flights on both sides, {flights} flights; \
         events at opened flights vs plates: n {}, mean |error| {:.1} ms, signed {:+.1} ms",
        st.len(),
        errs.len(),
        mean_abs * 1e3,
        errs.iter().sum::<f64>() / errs.len().max(1) as f64 * 1e3
    );
    assert!(flights >= 5 && both >= 4, "the jog's flights stay closed");
    // The plates lag the kinematics by 7 ms here (SOURCES.md); the opened events are frame
    // edges of the force's flight: within 3 frames on average.
    assert!(mean_abs <= 0.03, "mean |error| {:.1} ms", mean_abs * 1e3);
    // Walks: every force-plate walk, every shared walk and the bulk set's walking subjects.
    let mut walks: Vec<(PathBuf, f64)> = [
        "opencap_s4_walking1",
        "gait2354_s01_walk1",
        "arnold_synth_s18_walk2",
    ]
    .iter()
    .map(|c| {
        let w = util::forceplate_clip(&data, c);
        (w.dir.join("clip.bvh"), w.mass)
    })
    .collect();
    walks.extend(
        util::bvh_files(&data.join("bvh").join("walk"))
            .into_iter()
            .map(|p| (p, 70.0)),
    );
    walks.extend(
        util::bvh_files(&data.join("bvh-bulk").join("cmu"))
            .into_iter()
            .filter(|p| {
                let n = p.file_name().unwrap().to_string_lossy();
                n.starts_with("07_") || n.starts_with("08_")
            })
            .map(|p| (p, 70.0)),
    );
    let mut with_flight = Vec::new();
    for (path, mass) in &walks {
        let bvh = stancelib::bvh::parse_file(path).unwrap();
        let name = path.display().to_string();
        let st = clip_stances(&bvh, &name, *mass);
        if st
            .iter()
            .any(|s| s.boundary_start == Boundary::Flight || s.boundary_end == Boundary::Flight)
        {
            with_flight.push(name);
        }
    }
    println!("{} walks, {} with a flight", walks.len(), with_flight.len());
    assert!(walks.len() >= 25, "only {} walks found", walks.len());
    assert!(
        with_flight.is_empty(),
        "walks with a flight: {with_flight:?}"
    );
}

/// The signed error of `t` against the nearest of `plate` within 0.15 s.
fn nearest(plate: &[f64], t: f64) -> Option<f64> {
    plate
        .iter()
        .map(|p| t - p)
        .filter(|e| e.abs() <= 0.15)
        .min_by(|a, b| a.abs().total_cmp(&b.abs()))
}
