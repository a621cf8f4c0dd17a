//! Real clips of `../shared/data/bvh`: every file loads or is skipped with a reason, the
//! flight physics of the runs and jumps, walking and running contact patterns. The
//! translation / yaw invariance of COM and contacts is in `invariance`.
//!
//! # References
//! spec com-from-bvh §1.1, §2.1, §7.3, §7.7; CORRECTIONS issue 2 items 2, 5, 11.

use std::panic::{catch_unwind, AssertUnwindSafe};
use std::path::{Path, PathBuf};

use stancelib::bvh::{parse_file, Bvh};
use stancelib::contacts::flight::{Flight, G};
use stancelib::ingest::{ingest, ClipFrames, ClipOutcome, ClipSummary, ContactRun, IngestOptions};
use stancelib::math::stats::median;

use crate::util::{self, outln};

/// Every `.bvh` under `dir`, recursively, sorted, as (clip name `sub/stem`, path).
fn bvh_files(dir: &Path) -> Vec<(String, PathBuf)> {
    fn walk(d: &Path, out: &mut Vec<PathBuf>) {
        let mut entries: Vec<PathBuf> = std::fs::read_dir(d)
            .expect("readable data dir")
            .map(|e| e.unwrap().path())
            .collect();
        entries.sort();
        for p in entries {
            if p.is_dir() {
                walk(&p, out);
            } else if p.extension().is_some_and(|e| e.eq_ignore_ascii_case("bvh")) {
                out.push(p);
            }
        }
    }
    let mut paths = Vec::new();
    walk(dir, &mut paths);
    paths
        .into_iter()
        .map(|p| {
            let rel = p.strip_prefix(dir).unwrap().with_extension("");
            (rel.to_string_lossy().replace('\\', "/"), p)
        })
        .collect()
}

/// A clip ingested with default options that must be a body.
pub(super) struct Clip {
    pub(super) bvh: Bvh,
    pub(super) summary: ClipSummary,
    pub(super) frames: ClipFrames,
    pub(super) contacts: Vec<ContactRun>,
}

pub(super) fn load(data: &Path, clip: &str) -> Clip {
    let path = data.join("bvh").join(format!("{clip}.bvh"));
    let bvh = parse_file(&path).unwrap_or_else(|e| panic!("{clip}: parse error: {e}"));
    let (summary, frames, contacts) = util::ingest_body(&bvh, &IngestOptions::default(), clip);
    Clip {
        bvh,
        summary,
        frames,
        contacts,
    }
}

fn fmt_opt(v: Option<f64>, prec: usize) -> String {
    v.map_or("-".to_string(), |v| format!("{v:.prec$}"))
}

fn n_int(f: &Flight) -> i64 {
    f.last_frame - f.first_frame - 3
}

#[test]
fn every_shared_clip_loads_or_is_rejected_with_a_reason() {
    let Some(data) = util::shared_or_skip("every_shared_clip_loads_or_is_rejected_with_a_reason")
    else {
        return;
    };
    let mut out = String::new();
    let files = bvh_files(&data.join("bvh"));
    // The shared set has 22 files (data/bvh/SOURCES.md); fewer means the walk is broken.
    assert!(
        files.len() >= 20,
        "only {} .bvh files found under data/bvh",
        files.len()
    );
    let may_skip = ["odd/bvh_anim_test_simple_2frames"];
    let mut failures = Vec::new();
    outln!(
        out,
        "{:<50} {:>7} {:>6} {:>6} {:>10} {:>3} {:>6} {:>7}  note",
        "clip",
        "outcome",
        "rows",
        "kept",
        "unit",
        "up",
        "leadin",
        "flights"
    );
    for (name, path) in &files {
        let res = catch_unwind(AssertUnwindSafe(|| {
            parse_file(path).and_then(|b| ingest(&b, &IngestOptions::default()))
        }));
        match res {
            Err(p) => {
                let msg = p
                    .downcast_ref::<String>()
                    .cloned()
                    .or_else(|| p.downcast_ref::<&str>().map(|s| s.to_string()))
                    .unwrap_or_default();
                outln!(out, "{name:<50} PANIC {msg}");
                failures.push(format!("{name}: panicked: {msg}"));
            }
            Ok(Err(e)) => {
                outln!(out, "{name:<50} ERROR {e}");
                failures.push(format!("{name}: error: {e}"));
            }
            Ok(Ok(ClipOutcome::Skipped { summary, reason })) => {
                outln!(
                    out,
                    "{name:<50} {:>7} {:>6} {:>6}  reason: {reason}",
                    "skipped",
                    summary.frames_data,
                    summary.frames_kept
                );
                if !may_skip.contains(&name.as_str()) {
                    failures.push(format!(
                        "{name}: skipped ({reason}) but only {may_skip:?} may be"
                    ));
                }
                if reason.trim().is_empty() {
                    failures.push(format!("{name}: skipped without a reason"));
                }
            }
            Ok(Ok(ClipOutcome::Body {
                summary,
                frames,
                contacts,
            })) => {
                outln!(
                    out,
                    "{name:<50} {:>7} {:>6} {:>6} {:>10} {:>3} {:>6} {:>7}  s_eff {} runs {} warnings {:?}",
                    "body",
                    summary.frames_data,
                    summary.frames_kept,
                    summary.unit.as_deref().unwrap_or("?"),
                    summary.up_axis.as_deref().unwrap_or("?"),
                    summary.leadin_dropped.len(),
                    summary.flights.len(),
                    fmt_opt(summary.s_eff, 2),
                    contacts.len(),
                    summary.warnings
                );
                let n = summary.frames_kept as usize;
                if n == 0
                    || frames.frame.len() != n
                    || frames.com.len() != n
                    || frames.contact.iter().any(|c| c.len() != n)
                {
                    failures.push(format!(
                        "{name}: per-frame columns do not have frames_kept = {n} rows"
                    ));
                }
                if frames
                    .com
                    .iter()
                    .flatten()
                    .chain(frames.com_a.iter().flatten())
                    .any(|v| !v.is_finite())
                {
                    failures.push(format!("{name}: non-finite COM or COM acceleration"));
                }
            }
        }
    }
    print!("{out}");
    assert!(
        failures.is_empty(),
        "{} clip(s) failed:\n{}",
        failures.len(),
        failures.join("\n")
    );
}

#[test]
fn flight_physics_on_runs_and_jumps() {
    let Some(data) = util::shared_or_skip("flight_physics_on_runs_and_jumps") else {
        return;
    };
    let mut out = String::new();
    // CORRECTIONS issue 2 item 5: reported, not checked.
    let report_only = [
        "jump/mass_backflip",
        "run/mass_run_fast",
        "run/cmu_16_36_runjog_daz",
    ];
    let clips: Vec<String> = bvh_files(&data.join("bvh"))
        .into_iter()
        .map(|c| c.0)
        .filter(|c| c.starts_with("run/") || c.starts_with("jump/"))
        .collect();
    assert!(
        clips.len() >= 8,
        "expected the 3 runs and 5 jumps, found {clips:?}"
    );
    let mut failures = Vec::new();
    let mut s_eff_of = std::collections::BTreeMap::new();
    outln!(
        out,
        "{:<36} {:>4} {:<14} {:<30} {:>8} {:>8} {:>6} {:>6}  status",
        "clip",
        "air",
        "n_int",
        "a_z per interval",
        "a_z med",
        "|a_h|med",
        "limit",
        "s_eff"
    );
    for clip in &clips {
        let c = load(&data, clip);
        let air: Vec<&Flight> = c.summary.flights.iter().filter(|f| f.airborne).collect();
        let az: Vec<f64> = air.iter().filter_map(|f| f.a_z).collect();
        let ah: Vec<f64> = air
            .iter()
            .filter_map(|f| Some(f.a_x?.abs().max(f.a_y?.abs())))
            .collect();
        let nint: Vec<i64> = air.iter().map(|f| n_int(f)).collect();
        let az_med = median(&az);
        let ah_med = median(&ah);
        // Limit 1.5 m/s² when every airborne interval has ≥ 24 interior frames (jumps,
        // measured ≤ 0.32), else 3 m/s² (short running flights: 1 mm of COM error moves an
        // 8-frame curvature by ~2 m/s²) — CORRECTIONS issue 2 item 5.
        let limit = if !nint.is_empty() && nint.iter().all(|&k| k >= 24) {
            1.5
        } else {
            3.0
        };
        let checked = !report_only.contains(&clip.as_str());
        let mut status = Vec::new();
        if checked {
            if air.is_empty() || az.len() != air.len() || ah.len() != air.len() {
                status.push("no airborne interval with a fit".to_string());
            }
            // Vertical: within 1.5 m/s² of −g (CORRECTIONS issue 2 item 5): single flights
            // scatter by ~1 m/s² (−8.7 … −10.7 on the checked jumps, spec §7.7 table).
            if !az_med.is_some_and(|a| (a + G).abs() <= 1.5) {
                status.push(format!(
                    "a_z median {} not within 1.5 of -9.81",
                    fmt_opt(az_med, 2)
                ));
            }
            if !ah_med.is_some_and(|a| a <= limit) {
                status.push(format!(
                    "horizontal median {} > {limit}",
                    fmt_opt(ah_med, 2)
                ));
            }
        }
        outln!(
            out,
            "{:<36} {:>4} {:<14} {:<30} {:>8} {:>8} {:>6} {:>6}  {}",
            clip,
            air.len(),
            format!("{nint:?}"),
            az.iter()
                .map(|a| format!("{a:.2}"))
                .collect::<Vec<_>>()
                .join(","),
            fmt_opt(az_med, 2),
            fmt_opt(ah_med, 2),
            limit,
            fmt_opt(c.summary.s_eff, 3),
            if !checked {
                "reported only".to_string()
            } else if status.is_empty() {
                "ok".to_string()
            } else {
                format!("FAIL: {}", status.join("; "))
            }
        );
        for f in &c.summary.flights {
            outln!(out,
                "    no-contact {:>5}-{:<5} n_int {:>3} airborne {:<5} ballistic {:<5} tested {:<5} a_z {:>7} a_x {:>6} a_y {:>6} rms {:>7} s_eff {:>5} a_z_mean {:>7}",
                f.first_frame,
                f.last_frame,
                n_int(f),
                f.airborne,
                f.ballistic,
                f.tested,
                fmt_opt(f.a_z, 2),
                fmt_opt(f.a_x, 2),
                fmt_opt(f.a_y, 2),
                fmt_opt(f.rms_m.map(|r| r * 1e3), 2),
                fmt_opt(f.s_eff, 2),
                fmt_opt(f.a_z_mean, 2)
            );
        }
        if !status.is_empty() {
            failures.push(format!("{clip}: {}", status.join("; ")));
        }
        s_eff_of.insert(clip.clone(), c.summary.s_eff);
    }
    // Clip s_eff (spec §7.7 table, CORRECTIONS item 5): mass_run_fast's one airborne
    // interval gives 1.25 (its frame time is short); ±0.05 (≈ ±1.2 m/s² in a_z) allows the
    // de Leva COM error on an 8-interior-frame fit.
    let run_fast = s_eff_of.get("run/mass_run_fast").copied().flatten();
    if !run_fast.is_some_and(|s| (s - 1.25).abs() <= 0.05) {
        failures.push(format!(
            "run/mass_run_fast: clip s_eff {} not 1.25 ± 0.05",
            fmt_opt(run_fast, 3)
        ));
    }
    // cmu_02_04's 66-frame vertical jump fits −9.80 m/s²: ±0.03 in s_eff is ±0.6 m/s² in a_z.
    let vj = s_eff_of
        .get("jump/cmu_02_04_vertical_jump_mb")
        .copied()
        .flatten();
    if !vj.is_some_and(|s| (s - 1.00).abs() <= 0.03) {
        failures.push(format!(
            "jump/cmu_02_04_vertical_jump_mb: clip s_eff {} not 1.00 ± 0.03",
            fmt_opt(vj, 3)
        ));
    }
    outln!(
        out,
        "mass_backflip clip s_eff (reported; spec: 2.21): {}",
        fmt_opt(s_eff_of.get("jump/mass_backflip").copied().flatten(), 3)
    );
    print!("{out}");
    assert!(
        failures.is_empty(),
        "flight physics failures:\n{}",
        failures.join("\n")
    );
}

/// Maximal runs of single support: (foot 0 = left / 1 = right, first kept index, last).
fn single_support_runs(contact: &[Vec<bool>; 4]) -> Vec<(usize, usize, usize)> {
    let mut out: Vec<(usize, usize, usize)> = Vec::new();
    for (k, (&l, &r)) in contact[0].iter().zip(&contact[1]).enumerate() {
        let foot = match (l, r) {
            (true, false) => 0,
            (false, true) => 1,
            _ => continue,
        };
        match out.last_mut() {
            Some(r) if r.0 == foot && r.2 + 1 == k => r.2 = k,
            _ => out.push((foot, k, k)),
        }
    }
    out
}

#[test]
fn walks_alternate_support_without_flight() {
    let Some(data) = util::shared_or_skip("walks_alternate_support_without_flight") else {
        return;
    };
    let mut out = String::new();
    let walks = [
        "walk/cmu_07_01_walk_mb",
        "walk/cmu_07_04_slow_walk_mb",
        "walk/cmu_131_01_walk_3dsmax",
        "walk/cmu_16_15_walk_daz",
    ];
    let odd = [
        "odd/cmu_old_drunk1_mixed_rot_orders",
        "odd/bvhtoolbox_test_freebvh_mixamorig",
    ];
    let mut failures = Vec::new();
    for clip in walks.iter().chain(&odd) {
        let c = load(&data, clip);
        let n = c.frames.frame.len();
        let ballistic: Vec<String> = c
            .summary
            .flights
            .iter()
            .filter(|f| f.ballistic)
            .map(|f| format!("{}-{}", f.first_frame, f.last_frame))
            .collect();
        let no_contact: Vec<String> = c
            .summary
            .flights
            .iter()
            .map(|f| {
                format!(
                    "{}-{} (ā_z {}, a_z {}, ballistic {})",
                    f.first_frame,
                    f.last_frame,
                    fmt_opt(f.a_z_mean, 3),
                    fmt_opt(f.a_z, 2),
                    f.ballistic
                )
            })
            .collect();
        let feet = |k: usize| c.frames.contact[0][k] as usize + c.frames.contact[1][k] as usize;
        let single = (0..n).filter(|&k| feet(k) == 1).count();
        let double = (0..n).filter(|&k| feet(k) == 2).count();
        let none = n - single - double;
        let ss = single_support_runs(&c.frames.contact);
        let pairs = ss.len().saturating_sub(1);
        let alternating = ss.windows(2).filter(|w| w[0].0 != w[1].0).count();
        let frac = if pairs > 0 {
            alternating as f64 / pairs as f64
        } else {
            0.0
        };
        let seq: String = ss
            .iter()
            .map(|r| if r.0 == 0 { 'L' } else { 'R' })
            .collect();
        outln!(out,
            "{clip:<42} frames {n:>4} single {single:>4} double {double:>4} none {none:>3}  single-support runs {:>2} {seq:<16} alternating {alternating}/{pairs}  no-contact {no_contact:?}",
            ss.len()
        );
        // stance-model §1 flights are ballistic no-contact runs; a walk has none.
        if !ballistic.is_empty() {
            failures.push(format!("{clip}: ballistic flights {ballistic:?}"));
        }
        // Walking alternates single and double support (spec §7.7).
        if single == 0 || double == 0 {
            failures.push(format!(
                "{clip}: single support {single} frames, double support {double} frames"
            ));
        }
        if !walks.contains(clip) {
            // The two odd files (a drunk walk, a 69-frame test clip) are checked for flights
            // and support phases only; their step sequence is reported above.
            continue;
        }
        if pairs < 2 {
            failures.push(format!("{clip}: only {} single-support runs", ss.len()));
        }
        // cmu_131_01 is a stylised start–walk–stop: around its starts and stops the stepping
        // is irregular (two short no-contact runs, 217–219 and 341–346), where one foot may
        // legitimately carry two single-support runs in a row; ≥ 80 % of its consecutive
        // pairs must alternate (measured 8/8). The steady walks alternate throughout.
        let need = if *clip == "walk/cmu_131_01_walk_3dsmax" {
            0.8
        } else {
            1.0
        };
        if frac < need {
            failures.push(format!("{clip}: single-support runs alternate in {alternating}/{pairs} pairs ({seq}), need {need}"));
        }
    }
    print!("{out}");
    assert!(
        failures.is_empty(),
        "walk failures:\n{}",
        failures.join("\n")
    );
}

#[test]
fn runs_show_flights_between_alternating_single_foot_stances() {
    let Some(data) =
        util::shared_or_skip("runs_show_flights_between_alternating_single_foot_stances")
    else {
        return;
    };
    let clip = "run/cmu_09_01_run_mb";
    let c = load(&data, clip);
    let mut feet: Vec<&ContactRun> = c
        .contacts
        .iter()
        .filter(|r| r.effector.ends_with("_foot"))
        .collect();
    feet.sort_by_key(|r| r.first_frame);
    for r in &feet {
        println!(
            "{clip}: {:<10} {:>4}-{:<4} t_td {} t_lo {}",
            r.effector,
            r.first_frame,
            r.last_frame,
            fmt_opt(r.t_td_s, 4),
            fmt_opt(r.t_lo_s, 4)
        );
    }
    for f in &c.summary.flights {
        println!(
            "{clip}: no-contact {:>4}-{:<4} ballistic {} airborne {} a_z {} ā_z {}",
            f.first_frame,
            f.last_frame,
            f.ballistic,
            f.airborne,
            fmt_opt(f.a_z, 2),
            fmt_opt(f.a_z_mean, 2)
        );
    }
    let hands: Vec<&ContactRun> = c
        .contacts
        .iter()
        .filter(|r| r.effector.ends_with("_hand"))
        .collect();
    assert!(
        hands.is_empty(),
        "{clip}: hand contacts in a run: {:?}",
        hands
            .iter()
            .map(|r| (r.effector, r.first_frame, r.last_frame))
            .collect::<Vec<_>>()
    );
    // Spec §7.7 table: no-contact runs 26–39, 72–83, 116–128; ±1 frame allows one frame of
    // threshold jitter at either edge.
    let expected = [(26i64, 39i64), (72, 83), (116, 128)];
    let got: Vec<(i64, i64)> = c
        .summary
        .flights
        .iter()
        .map(|f| (f.first_frame, f.last_frame))
        .collect();
    assert_eq!(
        got.len(),
        expected.len(),
        "{clip}: no-contact runs {got:?}, expected {expected:?}"
    );
    for (g, e) in got.iter().zip(&expected) {
        assert!(
            (g.0 - e.0).abs() <= 1 && (g.1 - e.1).abs() <= 1,
            "{clip}: no-contact run {g:?}, expected {e:?} ± 1 frame"
        );
    }
    assert!(
        c.summary.flights.iter().all(|f| f.ballistic),
        "{clip}: every running no-contact run is a ballistic flight"
    );
    assert_eq!(
        feet.len(),
        expected.len() + 1,
        "{clip}: one foot stance before, between and after the three flights"
    );
    for w in feet.windows(2) {
        assert_ne!(
            w[0].effector, w[1].effector,
            "{clip}: consecutive stances {}-{} and {}-{} on the same foot",
            w[0].first_frame, w[0].last_frame, w[1].first_frame, w[1].last_frame
        );
        let flight =
            c.summary.flights.iter().find(|f| {
                f.first_frame == w[0].last_frame + 1 && f.last_frame + 1 == w[1].first_frame
            });
        assert!(
            flight.is_some_and(|f| f.ballistic),
            "{clip}: no ballistic flight exactly between stance {}-{} and {}-{}",
            w[0].first_frame,
            w[0].last_frame,
            w[1].first_frame,
            w[1].last_frame
        );
    }
}
