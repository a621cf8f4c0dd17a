//! Differential test of `stancelib::bvh` against the independent `bvh_anim` 0.4 reader.
//!
//! `bvh_anim` is an oracle with known defects, so a file is compared only when it reads
//! the file at all (no panic, no error), and only on what it keeps faithfully:
//! - it stores everything as `f32`: values are compared within
//!   `|a − b| ≤ 1e-5 · max(1, |a|)`, a loose bound over f32 rounding (2⁻²⁴ ≈ 6e-8
//!   relative); the largest scaled error is printed per file (at most 6.0e-8 on the
//!   shared clips in 2026-11, i.e. both sides round correctly);
//! - it splits names on `:` and whitespace, so a name is compared only when its name is not
//!   a cut-off prefix of ours;
//! - it drops (when last in the file) or misplaces a leaf joint without End Site, panics
//!   on a UTF-8 BOM and on several malformations, needs `Frames:` to match the data rows
//!   exactly, and writes a root End Site over the root OFFSET: such files are reported as
//!   skipped, with the reason.
//!
//! The frame time goes through `Duration::from_nanos(truncated)` there, so it is compared
//! to 1 ns.

use std::panic::{catch_unwind, AssertUnwindSafe};
use std::path::{Path, PathBuf};

use bvh_anim::ChannelType;
use stancelib::bvh::{self, Bvh, Channel};

/// Equal to f32 storage precision, with margin (see the module docs).
fn close(a: f64, b: f64) -> bool {
    (a - b).abs() <= 1e-5 * a.abs().max(1.0)
}

fn channel_of(t: ChannelType) -> Channel {
    match t {
        ChannelType::PositionX => Channel::Xposition,
        ChannelType::PositionY => Channel::Yposition,
        ChannelType::PositionZ => Channel::Zposition,
        ChannelType::RotationX => Channel::Xrotation,
        ChannelType::RotationY => Channel::Yrotation,
        ChannelType::RotationZ => Channel::Zrotation,
    }
}

/// Every `.bvh` below `dir`, sorted.
fn bvh_files(dir: &Path) -> Vec<PathBuf> {
    let mut out = Vec::new();
    let mut stack = vec![dir.to_path_buf()];
    while let Some(d) = stack.pop() {
        for e in std::fs::read_dir(&d).unwrap() {
            let p = e.unwrap().path();
            if p.is_dir() {
                stack.push(p);
            } else if p.extension().is_some_and(|x| x.eq_ignore_ascii_case("bvh")) {
                out.push(p);
            }
        }
    }
    out.sort();
    out
}

/// What `bvh_anim` made of a file.
enum Oracle {
    Read(bvh_anim::Bvh),
    Error(String),
    Panicked(String),
}

fn oracle(bytes: &[u8]) -> Oracle {
    match catch_unwind(AssertUnwindSafe(|| bvh_anim::from_bytes(bytes))) {
        Ok(Ok(b)) => Oracle::Read(b),
        Ok(Err(e)) => Oracle::Error(format!("{e}")),
        Err(p) => {
            let msg = p
                .downcast_ref::<String>()
                .cloned()
                .or_else(|| p.downcast_ref::<&str>().map(|s| s.to_string()))
                .unwrap_or_else(|| "non-string payload".into());
            Oracle::Panicked(msg)
        }
    }
}

/// Why `bvh_anim` cannot be trusted on this file although it read it (a documented
/// defect), judged from our hierarchy.
fn known_defect(ours: &Bvh) -> Option<String> {
    let j = &ours.hierarchy.joints;
    let leaves_without_end = j
        .iter()
        .enumerate()
        .filter(|(i, jd)| jd.end_site.is_none() && !j.iter().any(|c| c.parent == Some(*i)))
        .count();
    if leaves_without_end > 0 {
        let why = "bvh_anim drops or misplaces them";
        return Some(format!(
            "{leaves_without_end} leaf joint(s) without End Site ({why})"
        ));
    }
    if j[0].end_site.is_some() {
        return Some("root End Site (bvh_anim writes it over the root OFFSET)".into());
    }
    None
}

/// The outcome of comparing one file.
struct Comparison {
    /// Every disagreement (empty = agree).
    diffs: Vec<String>,
    /// Joint names compared exactly (the others were cut at `:` by `bvh_anim`).
    names_compared: usize,
    /// Motion values compared.
    n_values: usize,
    /// Largest `|a − b| / max(1, |a|)` over the motion values.
    max_err: f64,
}

/// Compare our parse with `bvh_anim`'s.
fn compare(ours: &Bvh, theirs: &bvh_anim::Bvh) -> Comparison {
    let mut diffs = Vec::new();
    let mut names_compared = 0;
    let oj = &ours.hierarchy.joints;
    let tj: Vec<_> = theirs.joints().collect();
    if oj.len() != tj.len() {
        diffs.push(format!(
            "joint count: ours {} vs bvh_anim {}",
            oj.len(),
            tj.len()
        ));
        return Comparison {
            diffs,
            names_compared,
            n_values: 0,
            max_err: f64::NAN,
        };
    }
    let mut n_values = 0;
    let mut max_err: f64 = 0.0;
    for (i, (o, t)) in oj.iter().zip(&tj).enumerate() {
        let d = t.data();
        let tname = String::from_utf8_lossy(d.name().as_bytes()).to_string();
        if tname == o.name {
            names_compared += 1;
        } else if !(o.name.starts_with(&tname)
            && o.name[tname.len()..].starts_with([':', ' ', '\t']))
        {
            diffs.push(format!("joint {i}: name '{}' vs '{tname}'", o.name));
        }
        let tparent = if d.is_root() { None } else { d.parent_index() };
        if o.parent != tparent {
            diffs.push(format!(
                "joint {i} '{}': parent {:?} vs {tparent:?}",
                o.name, o.parent
            ));
        }
        let toff = d.offset();
        let toff = [toff.x, toff.y, toff.z].map(f64::from);
        if !(0..3).all(|k| close(o.offset[k], toff[k])) {
            diffs.push(format!(
                "joint {i} '{}': offset {:?} vs {toff:?}",
                o.name, o.offset
            ));
        }
        let tend = d.end_site().map(|e| [e.x, e.y, e.z].map(f64::from));
        match (o.end_site, tend) {
            (None, None) => {}
            (Some(a), Some(b)) if (0..3).all(|k| close(a[k], b[k])) => {}
            (a, b) => diffs.push(format!("joint {i} '{}': End Site {a:?} vs {b:?}", o.name)),
        }
        let tch: Vec<Channel> = d
            .channels()
            .iter()
            .map(|c| channel_of(c.channel_type()))
            .collect();
        if o.channels != tch {
            diffs.push(format!(
                "joint {i} '{}': channels {:?} vs {tch:?}",
                o.name, o.channels
            ));
        }
        let tidx: Vec<usize> = d.channels().iter().map(|c| c.motion_index()).collect();
        let oidx: Vec<usize> = (o.first_channel..o.first_channel + o.channels.len()).collect();
        if oidx != tidx {
            diffs.push(format!(
                "joint {i} '{}': motion indices {oidx:?} vs {tidx:?}",
                o.name
            ));
        }
    }
    let m = &ours.motion;
    if m.n_frames() != theirs.num_frames() {
        diffs.push(format!(
            "frame count: ours {} vs bvh_anim {}",
            m.n_frames(),
            theirs.num_frames()
        ));
    }
    let dt_ns = theirs.frame_time().as_nanos() as f64;
    if (m.frame_time_s * 1e9 - dt_ns).abs() > 1.0 {
        diffs.push(format!(
            "frame time: ours {} s vs bvh_anim {dt_ns} ns",
            m.frame_time_s
        ));
    }
    let mut bad_values = 0;
    for (f, frame) in theirs.frames().enumerate().take(m.n_frames()) {
        let row = m.row(f);
        let tv = frame.as_slice();
        if tv.len() != row.len() {
            diffs.push(format!("frame {f}: {} values vs {}", row.len(), tv.len()));
            break;
        }
        for (c, (&a, &b)) in row.iter().zip(tv).enumerate() {
            n_values += 1;
            max_err = max_err.max((a - b as f64).abs() / a.abs().max(1.0));
            if !close(a, b as f64) {
                bad_values += 1;
                if bad_values <= 5 {
                    diffs.push(format!("frame {f} channel {c}: {a} vs {b}"));
                }
            }
        }
    }
    if bad_values > 5 {
        diffs.push(format!("… {bad_values} motion values differ in all"));
    }
    Comparison {
        diffs,
        names_compared,
        n_values,
        max_err,
    }
}

#[test]
fn shared_clips_agree_with_bvh_anim() {
    let Some(data) = crate::util::shared_or_skip("shared_clips_agree_with_bvh_anim") else {
        return;
    };
    let files = bvh_files(&data.join("bvh"));
    let mut compared = 0;
    let mut failures = Vec::new();
    for path in &files {
        let rel = path
            .strip_prefix(data.join("bvh"))
            .unwrap()
            .display()
            .to_string();
        let bytes = std::fs::read(path).unwrap();
        let ours =
            bvh::parse_file(path).unwrap_or_else(|e| panic!("{rel}: our reader failed: {e}"));
        let theirs = match oracle(&bytes) {
            Oracle::Read(b) => b,
            Oracle::Error(e) => {
                println!("{rel}: skipped by bvh_anim: error: {e}");
                continue;
            }
            Oracle::Panicked(m) => {
                println!("{rel}: skipped by bvh_anim: panicked: {m}");
                continue;
            }
        };
        if let Some(why) = known_defect(&ours) {
            println!("{rel}: skipped by bvh_anim: read, but {why}");
            continue;
        }
        let c = compare(&ours, &theirs);
        compared += 1;
        let nj = ours.hierarchy.joints.len();
        if c.diffs.is_empty() {
            println!(
                "{rel}: read by both, agree ({nj} joints, {} names exact, {} frames, {} values, max scaled error {:.1e})",
                c.names_compared,
                ours.motion.n_frames(),
                c.n_values,
                c.max_err
            );
        } else {
            println!("{rel}: read by both, DISAGREE:\n  {}", c.diffs.join("\n  "));
            failures.push(rel);
        }
    }
    println!("{compared} of {} files compared with bvh_anim", files.len());
    assert!(
        failures.is_empty(),
        "files that disagree with bvh_anim: {failures:?}"
    );
    assert!(
        compared >= 15,
        "only {compared} of {} files could be compared (need 15)",
        files.len()
    );
}

/// Write a parsed file back as BVH text (tabs, LF, shortest round-trip `f64` text).
fn write_bvh(b: &Bvh) -> String {
    use std::fmt::Write;
    fn joint(b: &Bvh, j: usize, depth: usize, s: &mut String) {
        let jd = &b.hierarchy.joints[j];
        let ind = "\t".repeat(depth);
        let kw = if jd.parent.is_none() { "ROOT" } else { "JOINT" };
        let [x, y, z] = jd.offset;
        let _ = writeln!(
            s,
            "{ind}{kw} {}\n{ind}{{\n{ind}\tOFFSET {x} {y} {z}",
            jd.name
        );
        if !jd.channels.is_empty() {
            let names: Vec<String> = jd.channels.iter().map(|c| format!("{c:?}")).collect();
            let _ = writeln!(s, "{ind}\tCHANNELS {} {}", names.len(), names.join(" "));
        }
        for c in
            (j + 1..b.hierarchy.joints.len()).filter(|&c| b.hierarchy.joints[c].parent == Some(j))
        {
            joint(b, c, depth + 1, s);
        }
        if let Some([x, y, z]) = jd.end_site {
            let _ = writeln!(
                s,
                "{ind}\tEnd Site\n{ind}\t{{\n{ind}\t\tOFFSET {x} {y} {z}\n{ind}\t}}"
            );
        }
        let _ = writeln!(s, "{ind}}}");
    }
    let mut s = String::from("HIERARCHY\n");
    joint(b, 0, 0, &mut s);
    let m = &b.motion;
    let _ = writeln!(
        s,
        "MOTION\nFrames: {}\nFrame Time: {}",
        m.n_frames(),
        m.frame_time_s
    );
    for f in 0..m.n_frames() {
        let row: Vec<String> = m.row(f).iter().map(|v| v.to_string()).collect();
        let _ = writeln!(s, "{}", row.join(" "));
    }
    s
}

/// A file `bvh_anim` reads faithfully (checked here again) survives our reader → text →
/// our reader exactly, the rewritten text still agrees with `bvh_anim`, and `bvh_anim`'s
/// own writer's output reads back equal to the original within f32 precision.
#[test]
fn reader_round_trips_on_a_clip_bvh_anim_reads() {
    let Some(data) = crate::util::shared_or_skip("reader_round_trips_on_a_clip_bvh_anim_reads")
    else {
        return;
    };
    let path = data.join("bvh/walk/cmu_07_01_walk_mb.bvh");
    let bytes = std::fs::read(&path).unwrap();
    let ours = bvh::parse_file(&path).unwrap();
    let Oracle::Read(theirs) = oracle(&bytes) else {
        panic!("bvh_anim no longer reads {}", path.display())
    };
    assert!(known_defect(&ours).is_none());
    let c = compare(&ours, &theirs);
    assert!(c.diffs.is_empty(), "original: {:?}", c.diffs);

    // Ours → text → ours: exact (Display of f64 is the shortest text that parses back).
    let text = write_bvh(&ours);
    let again = bvh::parse_reader(text.as_bytes()).unwrap();
    let strip = |b: &Bvh| {
        let mut b = b.clone();
        b.hierarchy.joints.iter_mut().for_each(|j| j.line = 0);
        b
    };
    assert_eq!(strip(&again), strip(&ours));
    let Oracle::Read(theirs_again) = oracle(text.as_bytes()) else {
        panic!("bvh_anim cannot read our rewrite")
    };
    let c = compare(&again, &theirs_again);
    assert!(c.diffs.is_empty(), "rewrite vs bvh_anim: {:?}", c.diffs);

    // bvh_anim's writer → ours: equal to the original within f32 precision. Its default
    // writes motion values with 2 decimals (the option says "significant figures" but
    // counts decimals); 6 decimals keep every f32 digit of values below 1000.
    let mut written = Vec::new();
    bvh_anim::write::WriteOptions::default()
        .with_motion_values_significant_figures(6)
        .write(&theirs, &mut written)
        .unwrap();
    let from_theirs = bvh::parse_reader(&written[..]).unwrap_or_else(|e| {
        panic!(
            "our reader rejects bvh_anim's output: {e}\n{}",
            String::from_utf8_lossy(&written[..2000.min(written.len())])
        )
    });
    let (a, b) = (&ours.hierarchy.joints, &from_theirs.hierarchy.joints);
    assert_eq!(a.len(), b.len());
    for (x, y) in a.iter().zip(b) {
        assert_eq!(
            (&x.name, x.parent, &x.channels, x.first_channel),
            (&y.name, y.parent, &y.channels, y.first_channel)
        );
        assert!(
            (0..3).all(|k| close(x.offset[k], y.offset[k])),
            "{}: {:?} vs {:?}",
            x.name,
            x.offset,
            y.offset
        );
        assert_eq!(x.end_site.is_some(), y.end_site.is_some(), "{}", x.name);
    }
    assert_eq!(ours.motion.n_frames(), from_theirs.motion.n_frames());
    assert!((ours.motion.frame_time_s - from_theirs.motion.frame_time_s).abs() < 1e-9);
    let bad = ours
        .motion
        .values
        .iter()
        .zip(&from_theirs.motion.values)
        .filter(|(a, b)| !close(**a, **b))
        .count();
    assert_eq!(bad, 0, "motion values that differ after bvh_anim's writer");
}

/// The comparison is not vacuous: a changed value, parent, channel, offset or name of our
/// parse is reported against `bvh_anim`.
#[test]
fn comparison_reports_planted_differences() {
    let text = "HIERARCHY\nROOT Base\n{\n OFFSET 0 0 0\n CHANNELS 6 Xposition Yposition Zposition Zrotation Xrotation Yrotation\n JOINT Mid\n {\n  OFFSET 0 0 15\n  CHANNELS 3 Zrotation Xrotation Yrotation\n  JOINT Tip\n  {\n   OFFSET 0 0 15\n   CHANNELS 3 Zrotation Xrotation Yrotation\n   End Site\n   {\n    OFFSET 0 0 30\n   }\n  }\n }\n}\nMOTION\nFrames: 2\nFrame Time: 0.0333333\n0 0 0 0 0 0 0 0 0 0 0 0\n1 2 3 4 5 6 7 8 9 10 11 12.5\n";
    let ours = bvh::parse_reader(text.as_bytes()).unwrap();
    let Oracle::Read(theirs) = oracle(text.as_bytes()) else {
        panic!("bvh_anim reads the nested example")
    };
    assert!(
        compare(&ours, &theirs).diffs.is_empty(),
        "{:?}",
        compare(&ours, &theirs).diffs
    );
    let planted: [Mutation; 6] = [
        ("value", |b| b.motion.values[23] += 1e-3 * 12.5),
        ("parent", |b| b.hierarchy.joints[2].parent = Some(0)),
        ("channel", |b| b.hierarchy.joints[1].channels.swap(0, 1)),
        ("offset", |b| b.hierarchy.joints[2].offset[2] = 15.01),
        ("End Site", |b| b.hierarchy.joints[2].end_site = None),
        ("name", |b| b.hierarchy.joints[1].name = "Mod".into()),
    ];
    for (what, plant) in planted {
        let mut b = ours.clone();
        plant(&mut b);
        assert_eq!(
            compare(&b, &theirs).diffs.len(),
            1,
            "planted {what} difference"
        );
    }
    let mut b = ours.clone();
    b.hierarchy.joints[1].name = "ns:Mid".into();
    // A name that bvh_anim cut at ':' is not a difference, any other name change is:
    // ours "ns:Mid" vs theirs "Mid" differs, ours "Mid:x" vs theirs "Mid" does not.
    assert_eq!(compare(&b, &theirs).diffs.len(), 1);
    b.hierarchy.joints[1].name = "Mid:x".into();
    let c = compare(&b, &theirs);
    assert!(c.diffs.is_empty() && c.names_compared == 2, "{:?}", c.diffs);
}

/// A named defect planted in a parsed file (the comparison must see it).
type Mutation = (&'static str, fn(&mut Bvh));
