//! Issue 39 item 3 — forces per foot on the force-plate walks: the walking contact
//! timing against the plate events (with its ratios chosen leaving one walk out), and
//! `forces --per-contact` (each foot's share of m(a + g) and its centre of pressure)
//! against that foot's plate, including double support; its CSV and `.mot` outputs and
//! the options it refuses.
//!
//! # Frames and units
//! `grf.csv` is in BVH world axes (+Y up, +X forward, +Z right); the library's Z-up world
//! is `(x, y, z) → (x, −z, y)` (SOURCES.md): vertical = `_fy_n`, fore-aft = `_fx_n`
//! (+X is the walking direction of all three walks), lateral = −`_fz_n`. Errors in body
//! weights (BW = `meta.body_weight_n`).
//!
//! # References
//! Issue 39 item 3 and its targets; `src/contacts/walking.rs`,
//! `src/force_model/per_contact.rs`; `data/forceplate/SOURCES.md`.

use std::path::Path;

use serde_json::Value;
use stancelib::contacts::detect::PointTrack;
use stancelib::contacts::raw_speed;
use stancelib::contacts::walking::{self, DEFAULT_WALK_LO_RATIO, DEFAULT_WALK_TD_RATIO};
use stancelib::ingest::IngestOptions;
use stancelib::library::codec::table::Table;
use stancelib::math::savgol::{window_for_rate, SavGol};

use crate::forceplate::pearson;
use crate::util::{self, outln};

/// The walks: (folder, synthetic: its forces are the model's own, an exact oracle).
const WALKS: [(&str, bool); 3] = [
    ("opencap_s4_walking1", false),
    ("gait2354_s01_walk1", false),
    ("arnold_synth_s18_walk2", true),
];
/// Matching radius of a detected to a plate event, s (as `tests/forceplate.rs`).
const MATCH_TOL_S: f64 = 0.15;
/// The plates' event threshold, N (SOURCES.md): a foot below it carries nothing.
const PLATE_ON_N: f64 = 20.0;
/// Targets the split does not meet, each with its reason: (walk, foot, figure, why).
/// Printed as "KNOWN MISS"; one that starts meeting its target fails the test. Empty since
/// the ingest mirrors the knees of `gait2354_s01_walk1` back where its two-bone IK jumped
/// branch (`ingest::knee_branch`): its fore-aft was 0.088 / 0.064 BW per foot, the total
/// force m(a + g) 0.11 BW off the plates' total.
const KNOWN_MISSES: [(&str, &str, &str, &str); 0] = [];

/// A plate event of one foot: (kind, foot index 0 left 1 right, time s).
type PlateEvent = (&'static str, usize, f64);

fn plate_events(meta: &Value) -> Vec<PlateEvent> {
    let mut out = Vec::new();
    for (foot, side) in ["left", "right"].into_iter().enumerate() {
        for e in meta["plate_events"][side].as_array().expect("plate_events") {
            for (kind, key) in [("touchdown", "touchdown_s"), ("liftoff", "liftoff_s")] {
                if let Some(t) = e[key].as_f64() {
                    out.push((kind, foot, t));
                }
            }
        }
    }
    out
}

/// Per walk, per plate event: the walking rule's event for each ratio of `grid` (ms error,
/// `None` when no crossing is within reach), plus the ingest's own event time.
struct WalkEvents {
    clip: &'static str,
    dt: f64,
    events: Vec<PlateEvent>,
    /// [event][ratio index] error, s.
    by_ratio: Vec<Vec<Option<f64>>>,
    /// The ingest's sub-frame event (the default ratios) per event, error s.
    ingest: Vec<Option<f64>>,
}

fn walk_events(data: &Path, clip: &'static str, grid: &[f64]) -> WalkEvents {
    let fp = util::forceplate_clip(data, clip);
    let opts = IngestOptions {
        mass_kg: fp.mass,
        ..Default::default()
    };
    let (summary, frames, contacts) = util::ingest_body(&fp.bvh, &opts, clip);
    let dt = summary.frame_time_s;
    let t = &frames.time_s;
    let n = t.len();
    let com_h: Vec<f64> = frames.com_v.iter().map(|v| v[0].hypot(v[1])).collect();
    // Not scored: plate events within 2 frames of a clip end (as tests/forceplate.rs), and
    // those inside a detected run that is open at the clip's edge (a run starting at the
    // first kept frame has no touchdown, §7.3: the synthetic walk's right foot lands at
    // 0.015 s, its third frame).
    let (first, last) = (frames.frame[0], frames.frame[n - 1]);
    let open_at_edge = |&(kind, foot, tp): &PlateEvent| {
        contacts.iter().any(|c| {
            let (a, b) = (
                (c.first_frame - first) as f64 * dt,
                (c.last_frame - first) as f64 * dt,
            );
            c.effector == ["left_foot", "right_foot"][foot]
                && a - MATCH_TOL_S <= tp
                && tp <= b + MATCH_TOL_S
                && if kind == "touchdown" {
                    c.first_frame == first
                } else {
                    c.last_frame == last
                }
        })
    };
    let events: Vec<PlateEvent> = plate_events(&fp.meta)
        .into_iter()
        .filter(|e| e.2 - t[0] > 2.0 * dt && t[n - 1] - e.2 > 2.0 * dt && !open_at_edge(e))
        .collect();
    let mut by_ratio = Vec::new();
    let mut ingest = Vec::new();
    for &(kind, foot, tp) in &events {
        let effector = ["left_foot", "right_foot"][foot];
        let ankle = frames.effector_pos[foot].as_ref().expect("ankle");
        let pts: Vec<PointTrack> = [ankle, &frames.toe[foot]]
            .map(|p| PointTrack {
                h: vec![0.0; n],
                v: raw_speed(p, dt),
            })
            .to_vec();
        let r = walking::speed_ratio(&pts, &com_h);
        // The detected run of that foot whose event is nearest the plate's.
        let run = contacts
            .iter()
            .filter(|c| c.effector == effector)
            .filter_map(|c| {
                let ev = if kind == "touchdown" {
                    c.td_time_s
                } else {
                    c.lo_time_s
                };
                ev.map(|x| ((x - tp).abs(), c, x))
            })
            .filter(|(d, _, _)| *d <= MATCH_TOL_S)
            .min_by(|a, b| a.0.total_cmp(&b.0));
        let Some((_, run, x)) = run else {
            by_ratio.push(vec![None; grid.len()]);
            ingest.push(None);
            continue;
        };
        ingest.push(Some(x - tp));
        let (a, b) = (
            (run.first_frame - frames.frame[0]) as usize,
            (run.last_frame - frames.frame[0]) as usize,
        );
        by_ratio.push(
            grid.iter()
                .map(|&k| {
                    let e = if kind == "touchdown" {
                        walking::touchdown(&r, t, a, b, 0, k)
                    } else {
                        walking::liftoff(&r, t, a, b, n - 1, k)
                    };
                    e.map(|e| e - tp)
                })
                .collect(),
        );
    }
    WalkEvents {
        clip,
        dt,
        events,
        by_ratio,
        ingest,
    }
}

fn ms(v: &[Option<f64>]) -> String {
    let s: Vec<String> = v
        .iter()
        .map(|e| e.map_or("none".into(), |e| format!("{:+.1}", e * 1e3)))
        .collect();
    s.join(", ")
}

// See: issue 39 item 3 — "walking touchdowns of the kinematic rule are 70-106 ms early";
// the walking rule's ratios are chosen leaving one walk out and must hold on the third.
#[test]
fn walking_events_match_the_plates_leaving_one_walk_out() {
    let Some(data) = util::shared_or_skip("walking_events_match_the_plates_leaving_one_walk_out")
    else {
        return;
    };
    let grid: Vec<f64> = (8..=24).map(|k| k as f64 * 0.05).collect(); // 0.40 … 1.20
    let walks: Vec<WalkEvents> = WALKS
        .iter()
        .map(|w| walk_events(&data, w.0, &grid))
        .collect();
    let mut out = String::new();
    let mut failures = Vec::new();
    // Target: the worst-case event target of the plate tests, max(2 frames + 10 ms, 30 ms)
    // (a kinematic edge is quantised to the frame; the 20 N threshold is not the contact).
    let worst = |dt: f64| (2.0 * dt + 0.010).max(0.030);
    for kind in ["touchdown", "liftoff"] {
        let default = if kind == "touchdown" {
            DEFAULT_WALK_TD_RATIO
        } else {
            DEFAULT_WALK_LO_RATIO
        };
        let errs = |w: &WalkEvents, i: usize| -> Vec<Option<f64>> {
            (0..w.events.len())
                .filter(|&e| w.events[e].0 == kind)
                .map(|e| w.by_ratio[e][i])
                .collect()
        };
        let score = |ws: &[&WalkEvents], i: usize| -> f64 {
            let v: Vec<f64> = ws
                .iter()
                .flat_map(|w| errs(w, i))
                .map(|e| e.map_or(1.0, f64::abs)) // a miss costs 1 s
                .collect();
            v.iter().sum::<f64>() / v.len().max(1) as f64
        };
        let all: Vec<&WalkEvents> = walks.iter().collect();
        let best = (0..grid.len())
            .min_by(|&a, &b| score(&all, a).total_cmp(&score(&all, b)))
            .unwrap();
        outln!(
            out,
            "{kind}: ratio chosen on all three walks {:.2} (default {default:.2})",
            grid[best]
        );
        if (grid[best] - default).abs() > 1e-9 {
            failures.push(format!(
                "{kind}: the default ratio {default} is not the one the walks choose ({})",
                grid[best]
            ));
        }
        for held in &walks {
            let rest: Vec<&WalkEvents> = walks.iter().filter(|w| w.clip != held.clip).collect();
            let i = (0..grid.len())
                .min_by(|&a, &b| score(&rest, a).total_cmp(&score(&rest, b)))
                .unwrap();
            let e = errs(held, i);
            outln!(
                out,
                "  {:<24} left out: ratio {:.2} from the other two; its errors (ms) {}",
                held.clip,
                grid[i],
                ms(&e)
            );
            for x in &e {
                if x.is_none_or(|x| x.abs() > worst(held.dt)) {
                    failures.push(format!(
                        "{} {kind} left out: error {x:?} beyond {:.0} ms",
                        held.clip,
                        worst(held.dt) * 1e3
                    ));
                }
            }
        }
    }
    outln!(out, "ingest's events (default ratios) against the plates:");
    for w in &walks {
        for (e, x) in w.events.iter().zip(&w.ingest) {
            outln!(
                out,
                "  {:<24} {:<5} {:<9} plate {:.4} s: error {}",
                w.clip,
                ["left", "right"][e.1],
                e.0,
                e.2,
                ms(&[*x])
            );
            if x.is_none_or(|x| x.abs() > worst(w.dt)) {
                failures.push(format!("{} {} {}: error {x:?}", w.clip, e.0, e.1));
            }
        }
    }
    print!("{out}");
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

fn rmse(a: &[f64], b: &[f64]) -> f64 {
    (a.iter().zip(b).map(|(x, y)| (x - y).powi(2)).sum::<f64>() / a.len() as f64).sqrt()
}

/// One foot's figures on one walk.
struct FootFigures {
    vertical_bw: f64,
    r: f64,
    fore_aft_bw: f64,
    lateral_bw: f64,
    cop_m: f64,
    frames: usize,
}

/// Per foot, the ingest's touchdown errors against the scored plate touchdowns, s.
fn touchdown_errors(data: &Path, clip: &'static str) -> [Vec<Option<f64>>; 2] {
    let w = walk_events(data, clip, &[]);
    let mut out: [Vec<Option<f64>>; 2] = Default::default();
    for (e, x) in w.events.iter().zip(&w.ingest) {
        if e.0 == "touchdown" {
            out[e.1].push(*x);
        }
    }
    out
}

/// A library of one force-plate walk (built by the binary), in `dir`.
fn walk_library(data: &Path, clip: &str, mass: f64, dir: &Path) -> std::path::PathBuf {
    let input = dir.join("in");
    std::fs::create_dir_all(&input).unwrap();
    let bvh = input.join(format!("{clip}.bvh"));
    std::fs::copy(data.join("forceplate").join(clip).join("clip.bvh"), &bvh).unwrap();
    let lib = dir.join("lib");
    let m = mass.to_string();
    util::ok(&[
        "build",
        &util::s(&bvh),
        "--mass",
        &m,
        "--out",
        &util::s(&lib),
        "--quiet",
    ]);
    lib
}

// See: issue 39 item 3 — "walking has one force per stance": each foot's force and COP
// against that foot's plate, double support included.
#[test]
fn per_contact_forces_match_each_foots_plate_on_the_walks() {
    let Some(data) = util::shared_or_skip("per_contact_forces_match_each_foots_plate_on_the_walks")
    else {
        return;
    };
    let mut out = String::new();
    let mut failures = Vec::new();
    let mut misses = Vec::new();
    outln!(
        out,
        "per foot against its plate (SG low-passed as the COM), BW = body weight:\n  {:<24} {:<5} {:>7} {:>6} {:>8} {:>8} {:>7} {:>6}  touchdown error",
        "walk",
        "foot",
        "vert BW",
        "r",
        "f-a BW",
        "lat BW",
        "COP m",
        "frames"
    );
    for (clip, synthetic) in WALKS {
        let td_errors = touchdown_errors(&data, clip);
        let fp = util::forceplate_clip(&data, clip);
        let dir = tempfile::tempdir().unwrap();
        let lib = walk_library(&data, clip, fp.mass, dir.path());
        let table = dir.path().join("per_contact.parquet");
        util::ok(&[
            "forces",
            "--lib",
            &util::s(&lib),
            "--per-contact",
            "--clip",
            clip,
            "--out",
            &util::s(&table),
        ]);
        let figures = score_walk(&fp, &table);
        for (foot, f) in figures.iter().enumerate() {
            let side = ["left", "right"][foot];
            outln!(
                out,
                "  {clip:<24} {side:<5} {:>7.3} {:>6.3} {:>8.3} {:>8.3} {:>7.3} {:>6}  {} ms",
                f.vertical_bw,
                f.r,
                f.fore_aft_bw,
                f.lateral_bw,
                f.cop_m,
                f.frames,
                if td_errors[foot].is_empty() {
                    "not scored (at the clip's edge)".to_string()
                } else {
                    ms(&td_errors[foot])
                }
            );
            // Issue 39 targets: vertical ≤ 0.10 BW and r ≥ 0.95; the synthetic walk ≤ 0.05.
            let vert_max = if synthetic { 0.05 } else { 0.10 };
            // Fore-aft: the issue's 0.05 BW on every walk; the known misses below are
            // printed, and fail the test once they pass (so the list stays true).
            let fa_max = 0.05;
            // COP: 6 cm (measured 3–6 cm; a foot is about 25 cm long).
            for (what, v, ok) in [
                ("vertical RMSE", f.vertical_bw, f.vertical_bw <= vert_max),
                ("vertical r", f.r, f.r >= 0.95),
                ("fore-aft RMSE", f.fore_aft_bw, f.fore_aft_bw <= fa_max),
                ("COP RMSE", f.cop_m, f.cop_m <= 0.06),
            ] {
                let known = KNOWN_MISSES
                    .iter()
                    .find(|m| m.0 == clip && m.1 == side && m.2 == what);
                match (ok, known) {
                    (false, None) => failures.push(format!("{clip} {side}: {what} {v:.3}")),
                    (false, Some(m)) => misses.push(format!(
                        "KNOWN MISS {clip} {side}: {what} {v:.3} (target {fa_max}): {}",
                        m.3
                    )),
                    (true, Some(_)) => failures.push(format!(
                        "{clip} {side}: {what} {v:.3} now meets its target: remove it from \
                         KNOWN_MISSES"
                    )),
                    (true, None) => {}
                }
            }
            if f.frames < 50 {
                failures.push(format!("{clip} {side}: only {} frames scored", f.frames));
            }
        }
        let total = total_fore_aft(&fp, &table);
        outln!(
            out,
            "  {clip:<24} total force m(a + g) fore-aft against the plates' total: {total:.3} BW"
        );
    }
    for m in &misses {
        outln!(out, "{m}");
    }
    print!("{out}");
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

/// The plate columns of one foot, SG low-passed, and its raw vertical force.
struct PlateFoot {
    /// World (x, y, z) force, SG, N.
    f: [Vec<f64>; 3],
    /// Raw vertical, N.
    fz_raw: Vec<f64>,
    /// World COP (x, y), m (NaN where empty).
    cop: [Vec<f64>; 2],
}

fn plate_foot(h: &[String], cols: &[Vec<f64>], side: &str, rate: f64) -> PlateFoot {
    let sg = SavGol::new(window_for_rate(rate), 3).expect("SG window");
    let c = |n: &str| util::csv_col(h, cols, &format!("{side}_{n}")).to_vec();
    let lp = |v: Vec<f64>| sg.apply(&v, 0, 1.0 / rate);
    let neg = |v: Vec<f64>| v.into_iter().map(|x| -x).collect::<Vec<f64>>();
    PlateFoot {
        f: [lp(c("fx_n")), lp(neg(c("fz_n"))), lp(c("fy_n"))],
        fz_raw: c("fy_n"),
        cop: [c("copx_m"), neg(c("copz_m"))],
    }
}

/// The per-contact table's rows: frame times, and per foot force and COP (NaN for null).
fn read_rows(table: &Path) -> (Vec<f64>, [[Vec<f64>; 6]; 2]) {
    let t = Table::open(table).expect("per-contact table");
    let time = t.f64s("time_clip_s").unwrap();
    let col = |name: String| -> Vec<f64> {
        t.opt_f64(&name)
            .unwrap()
            .into_iter()
            .map(|v| v.unwrap_or(f64::NAN))
            .collect()
    };
    let foot = |e: &str| {
        [
            col(format!("{e}_fx_n")),
            col(format!("{e}_fy_n")),
            col(format!("{e}_fz_n")),
            col(format!("{e}_cop_x_m")),
            col(format!("{e}_cop_y_m")),
            col(format!("{e}_cop_z_m")),
        ]
    };
    (time, [foot("left_foot"), foot("right_foot")])
}

/// The frames scored: inside the window, half an SG window from either clip end, and
/// after any foot that stands off the plates at the clip's start (in contact from the
/// first frame while its plate reads below 20 N) has lifted off.
fn scored(
    fp: &util::ForcePlateClip,
    time: &[f64],
    feet: &[[Vec<f64>; 6]; 2],
    plates: &[PlateFoot; 2],
    rate: f64,
) -> Vec<(usize, usize)> {
    let n = time.len();
    let dt = time[1] - time[0];
    let half = window_for_rate(1.0 / dt) / 2;
    let at = |t: f64| (t * rate).round() as usize;
    let mut start = 0;
    for foot in 0..2 {
        let on = |k: usize| feet[foot][2][k].is_finite();
        if !on(0) {
            continue;
        }
        let end = (0..n).find(|&k| !on(k)).unwrap_or(n);
        if (0..end).all(|k| plates[foot].fz_raw[at(time[k])] < PLATE_ON_N) {
            start = start.max(end);
        }
    }
    (half.max(start)..n - half)
        .filter(|&k| time[k] >= fp.window[0] - 1e-9 && time[k] <= fp.window[1] + 1e-9)
        .filter(|&k| at(time[k]) < plates[0].fz_raw.len())
        .map(|k| (k, at(time[k])))
        .collect()
}

fn plates_of(fp: &util::ForcePlateClip) -> ([PlateFoot; 2], Vec<String>, Vec<Vec<f64>>, f64) {
    let rate = fp.meta["grf_rate_hz"].as_f64().expect("grf_rate_hz");
    let (h, cols) = util::read_csv(&fp.dir.join("grf.csv"));
    let feet = [
        plate_foot(&h, &cols, "left", rate),
        plate_foot(&h, &cols, "right", rate),
    ];
    (feet, h, cols, rate)
}

fn score_walk(fp: &util::ForcePlateClip, table: &Path) -> Vec<FootFigures> {
    let (plates, _, _, rate) = plates_of(fp);
    let (time, feet) = read_rows(table);
    let rows = scored(fp, &time, &feet, &plates, rate);
    (0..2)
        .map(|foot| {
            let (f, p) = (&feet[foot], &plates[foot]);
            let est = |a: usize| -> Vec<f64> {
                rows.iter()
                    .map(|&(k, _)| if f[a][k].is_finite() { f[a][k] } else { 0.0 })
                    .collect()
            };
            let meas = |a: usize| -> Vec<f64> { rows.iter().map(|&(_, i)| p.f[a][i]).collect() };
            let (ev, mv) = (est(2), meas(2));
            let mut cop = Vec::new();
            for &(k, i) in &rows {
                let loaded = p.fz_raw[i] > 0.2 * fp.bw && p.cop[0][i].is_finite();
                if loaded && f[3][k].is_finite() {
                    cop.push((f[3][k] - p.cop[0][i]).hypot(f[4][k] - p.cop[1][i]));
                }
            }
            FootFigures {
                vertical_bw: rmse(&ev, &mv) / fp.bw,
                r: pearson(&ev, &mv),
                fore_aft_bw: rmse(&est(0), &meas(0)) / fp.bw,
                lateral_bw: rmse(&est(1), &meas(1)) / fp.bw,
                cop_m: (cop.iter().map(|d| d * d).sum::<f64>() / cop.len().max(1) as f64).sqrt(),
                frames: rows.len(),
            }
        })
        .collect()
}

/// The total force's fore-aft RMSE against the plates' total over the scored frames, BW.
fn total_fore_aft(fp: &util::ForcePlateClip, table: &Path) -> f64 {
    let (plates, h, cols, rate) = plates_of(fp);
    let sg = SavGol::new(window_for_rate(rate), 3).expect("SG window");
    let total = sg.apply(util::csv_col(&h, &cols, "fx_n"), 0, 1.0 / rate);
    let (time, feet) = read_rows(table);
    let rows = scored(fp, &time, &feet, &plates, rate);
    let sum = |k: usize| {
        (0..2)
            .map(|f| {
                if feet[f][0][k].is_finite() {
                    feet[f][0][k]
                } else {
                    0.0
                }
            })
            .sum::<f64>()
    };
    let est: Vec<f64> = rows.iter().map(|&(k, _)| sum(k)).collect();
    let meas: Vec<f64> = rows.iter().map(|&(_, i)| total[i]).collect();
    rmse(&est, &meas) / fp.bw
}

// See: issue 39 item 3 review — "feet that stand together are split as if handing over":
// the drop jump's two-foot landing went to the smooth transition (at 0.42 s L 21 N / R 900 N
// where the plates read 470 / 564 N; per-foot vertical RMSE over the landing 0.46 BW). It is
// no handover (0.75 s together): the lever rule shares it.
#[test]
fn per_contact_forces_share_the_drop_jumps_two_foot_landing() {
    let Some(data) =
        util::shared_or_skip("per_contact_forces_share_the_drop_jumps_two_foot_landing")
    else {
        return;
    };
    let clip = "opencap_s4_DJ1_dropjump";
    let fp = util::forceplate_clip(&data, clip);
    let dir = tempfile::tempdir().unwrap();
    let lib = walk_library(&data, clip, fp.mass, dir.path());
    let table = dir.path().join("per_contact.parquet");
    util::ok(&[
        "forces",
        "--lib",
        &util::s(&lib),
        "--per-contact",
        "--clip",
        clip,
        "--out",
        &util::s(&table),
    ]);
    let (plates, _, _, rate) = plates_of(&fp);
    let (time, feet) = read_rows(&table);
    let split = Table::open(&table).unwrap().strings("split").unwrap();
    // The two-foot landing: scored frames with both feet in contact, in the landing
    // (before 1.3 s: the clip ends 0.12 s after the second landing).
    let rows: Vec<(usize, usize)> = scored(&fp, &time, &feet, &plates, rate)
        .into_iter()
        .filter(|&(k, _)| feet[0][2][k].is_finite() && feet[1][2][k].is_finite())
        .filter(|&(k, _)| time[k] < 1.3)
        .collect();
    let mut out = String::new();
    let mut failures = Vec::new();
    outln!(
        out,
        "drop jump, two-foot landing, {} frames, per foot against its plate:",
        rows.len()
    );
    for (foot, side) in ["left", "right"].into_iter().enumerate() {
        let est: Vec<f64> = rows.iter().map(|&(k, _)| feet[foot][2][k]).collect();
        let meas: Vec<f64> = rows.iter().map(|&(_, i)| plates[foot].f[2][i]).collect();
        let fa: Vec<f64> = rows.iter().map(|&(k, _)| feet[foot][0][k]).collect();
        let fa_m: Vec<f64> = rows.iter().map(|&(_, i)| plates[foot].f[0][i]).collect();
        let (v, r, f) = (
            rmse(&est, &meas) / fp.bw,
            pearson(&est, &meas),
            rmse(&fa, &fa_m) / fp.bw,
        );
        outln!(
            out,
            "  {side:<5} vertical {v:.3} BW (r {r:.3}), fore-aft {f:.3} BW"
        );
        // Measured 0.087 / 0.087 BW (the transition: 0.46); 0.10 leaves room for a frame of
        // event timing.
        if v > 0.10 {
            failures.push(format!("{side}: vertical RMSE {v:.3} BW > 0.10"));
        }
    }
    let k = time
        .iter()
        .position(|t| (t - 0.42).abs() < 1e-6)
        .expect("0.42 s");
    let i = (0.42 * rate).round() as usize;
    outln!(
        out,
        "  at 0.42 s ({}): L {:.0} N / R {:.0} N, plates {:.0} / {:.0} N",
        split[k],
        feet[0][2][k],
        feet[1][2][k],
        plates[0].f[2][i],
        plates[1].f[2][i]
    );
    if split[k] != "lever" {
        failures.push(format!(
            "0.42 s split by '{}', not the lever rule",
            split[k]
        ));
    }
    if rows.len() < 50 {
        failures.push(format!("only {} frames of the landing scored", rows.len()));
    }
    print!("{out}");
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

// See: issue 39 item 3 — "`stancelib forces --per-contact` writes per-foot force and COP
// time series, also in OpenSim's `.mot` GRF layout": the three formats hold the same
// rows, the feet sum to m(a + g), `--stance` keeps the stance's frames, and every option
// that cannot act is refused before anything is written.
#[test]
fn per_contact_export_writes_parquet_csv_and_mot_and_refuses_what_cannot_act() {
    let lib = util::fixture_library();
    let dir = tempfile::tempdir().unwrap();
    let (l, clip) = (util::s(lib), "run_120hz_m_yup");
    let path = |n: &str| dir.path().join(n);
    let run = |out: &str, extra: &[&str]| {
        let out = util::s(&path(out));
        let mut args = vec!["forces", "--lib", &l, "--per-contact", "--out", &out];
        args.extend_from_slice(extra);
        util::ok(&args);
    };
    run("a.parquet", &["--clip", clip]);
    run("a.csv", &["--clip", clip]);
    run("a.mot", &["--clip", clip]);
    run("b.txt", &["--clip", clip, "--format", "csv"]);
    let t = Table::open(&path("a.parquet")).unwrap();
    let n = t.height();
    assert!(n > 100, "{n} rows");
    assert_eq!(
        std::fs::read_to_string(path("a.csv")).unwrap(),
        std::fs::read_to_string(path("b.txt")).unwrap()
    );
    let (h, cols) = {
        // The CSV's text columns (clip, split) are not numbers: drop them first.
        let text = std::fs::read_to_string(path("a.csv")).unwrap();
        let stripped: String = text
            .lines()
            .map(|l| {
                let c: Vec<&str> = l.split(',').collect();
                format!("{},{}\n", c[1..3].join(","), c[4..].join(","))
            })
            .collect();
        std::fs::write(path("num.csv"), stripped).unwrap();
        util::read_csv(&path("num.csv"))
    };
    assert_eq!(
        h.len() + 2,
        stancelib::library::readers::per_contact::per_contact_columns().len()
    );
    let parquet_fz = t.opt_f64("left_foot_fz_n").unwrap();
    let csv_fz = util::csv_col(&h, &cols, "left_foot_fz_n");
    for (a, b) in parquet_fz.iter().zip(csv_fz) {
        match a {
            Some(a) => assert!((a - b).abs() < 1e-5, "{a} {b}"), // six decimals
            None => assert!(b.is_nan()),
        }
    }
    // The feet (and hands) carry the whole force m(a + g) wherever something is in contact.
    let frames = Table::open(&lib.join("frames.parquet")).unwrap();
    let (fc, az) = (
        frames.strings("clip").unwrap(),
        frames.f64s("com_az_mps2").unwrap(),
    );
    let az: Vec<f64> = (0..fc.len())
        .filter(|&i| fc[i] == clip)
        .map(|i| az[i])
        .collect();
    let mass = stancelib::ingest::DEFAULT_MASS_KG; // the fixtures' clips have no mass given
    let split = t.strings("split").unwrap();
    let mut shared = 0;
    for k in 0..n {
        let fz: f64 = stancelib::contacts::EFFECTORS
            .iter()
            .filter_map(|e| t.opt_f64(&format!("{e}_fz_n")).unwrap()[k])
            .sum();
        if split[k] == "none" {
            assert_eq!(fz, 0.0);
        } else {
            assert!((fz - mass * (az[k] + 9.81)).abs() < 1e-6, "frame {k}: {fz}");
            shared += 1;
        }
    }
    assert!(shared > n / 4, "{shared} of {n} frames in contact");
    // .mot: OpenSim's header, then time and per foot force, point and torque, Y up.
    let mot = std::fs::read_to_string(path("a.mot")).unwrap();
    let lines: Vec<&str> = mot.lines().collect();
    assert_eq!(lines[0], "a");
    assert_eq!(lines[1], "version=1");
    assert_eq!(lines[2], format!("nRows={n}"));
    assert_eq!(lines[4..6], ["inDegrees=yes", "endheader"]);
    let head: Vec<&str> = lines[6].split('\t').collect();
    assert_eq!(lines[3], format!("nColumns={}", head.len()));
    assert_eq!(head[0], "time");
    assert!(head.contains(&"r_ground_force_vy") && head.contains(&"l_ground_force_pz"));
    let vy = head.iter().position(|c| *c == "l_ground_force_vy").unwrap();
    let parquet_lz = t.opt_f64("left_foot_fz_n").unwrap();
    for (k, line) in lines[7..].iter().enumerate() {
        let v: Vec<f64> = line.split('\t').map(|x| x.parse().unwrap()).collect();
        assert_eq!(v.len(), head.len());
        assert!((v[vy] - parquet_lz[k].unwrap_or(0.0)).abs() < 1e-5);
    }
    // --stance: that stance's frames only.
    let ids = Table::open(&lib.join("stances.parquet"))
        .unwrap()
        .strings("stance_id")
        .unwrap();
    let id = ids
        .iter()
        .find(|i| i.starts_with(clip))
        .expect("a stance of the clip");
    run("s.parquet", &["--stance", id]);
    let st = Table::open(&path("s.parquet")).unwrap();
    let first: i64 = id.rsplit(':').next().unwrap().parse().unwrap();
    assert_eq!(st.i64s("frame").unwrap()[0], first);
    assert!(st.height() < n);

    // Refusals: exit 2, the option named, nothing written.
    let o = util::s(&path("refused.mot"));
    let o_csv = util::s(&path("refused.csv"));
    for (args, needle) in [
        (
            vec!["forces", "--lib", &l, "--clip", clip, "--out", &o],
            "--per-contact",
        ),
        (
            vec!["forces", "--lib", &l, "--format", "csv", "--out", &o_csv],
            "--format csv needs --per-contact",
        ),
        // See: issue 39 item 3 review — no --format was given: name the extension.
        (
            vec!["forces", "--lib", &l, "--out", &o_csv],
            "a .csv output needs --per-contact",
        ),
        (
            vec!["forces", "--lib", &l, "--per-contact", "--out", &o],
            "--clip",
        ),
        (
            vec![
                "forces",
                "--lib",
                &l,
                "--per-contact",
                "--clip",
                clip,
                "--format",
                "csv",
                "--out",
                &o,
            ],
            "--format csv",
        ),
        (
            vec![
                "forces",
                "--lib",
                &l,
                "--per-contact",
                "--clip",
                "no_such_clip",
                "--out",
                &o,
            ],
            "no_such_clip",
        ),
        (
            vec![
                "forces",
                "--lib",
                &l,
                "--per-contact",
                "--stance",
                "a:L:1",
                "--stance",
                "b:R:2",
                "--out",
                &o,
            ],
            "2 --stance",
        ),
    ] {
        util::refused(&args, &[needle]);
    }
    assert!(!path("refused.mot").exists() && !path("refused.csv").exists());
}
