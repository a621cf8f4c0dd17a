//! Issue 40 ("Trust nothing read back"), items 2, 3, 8 and 10: side inputs are guarded
//! as BVH inputs (regular files only, a size bound per kind, the OS reason), a clip over
//! the point-sample budget is a per-clip error in bounded memory, a closed stdout ends
//! quietly, and `synth --out` writes atomically.
//!
//! Every run of the binary here that could hang (a FIFO) or grow without bound goes
//! through [`run_bounded`]: killed after [`TIMEOUT`], which fails the test.

use std::os::unix::process::CommandExt;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

use crate::util::{fixture_clips, fixture_library, root, s};
use stancelib::library::codec::table::Table;
use stancelib::pipeline::engine::inputs::{
    SideInput, MAX_BVH_BYTES, MAX_JSON_BYTES, MAX_PLATES_BYTES, MAX_POINTS_BYTES, MAX_TOML_BYTES,
};

/// Longest a run may take before it counts as hung (killed, and the test fails). Every
/// run here ends in well under a second when guarded.
const TIMEOUT: Duration = Duration::from_secs(10);

/// `(exit code, stdout, stderr)` of a run that ended by itself.
type Ran = (i32, String, String);

/// Runs the binary with `args`, stdout and stderr into files of `dir`, `limit` applied to
/// the child before it starts; kills it and fails the test if it is still running after
/// [`TIMEOUT`].
fn run_bounded(dir: &Path, args: &[&str], limit: impl Fn() + Send + Sync + 'static) -> Ran {
    let (out_p, err_p) = (dir.join("run.stdout"), dir.join("run.stderr"));
    let mut cmd = Command::new(env!("CARGO_BIN_EXE_stancelib"));
    cmd.args(args)
        .stdin(Stdio::null())
        .stdout(std::fs::File::create(&out_p).unwrap())
        .stderr(std::fs::File::create(&err_p).unwrap());
    // SAFETY: the closure only calls async-signal-safe functions (setrlimit, signal).
    unsafe {
        cmd.pre_exec(move || {
            limit();
            Ok(())
        });
    }
    let mut child = cmd.spawn().unwrap();
    let t0 = Instant::now();
    let status = loop {
        if let Some(st) = child.try_wait().unwrap() {
            break st;
        }
        if t0.elapsed() > TIMEOUT {
            child.kill().unwrap();
            child.wait().unwrap();
            panic!("stancelib {args:?} still running after {TIMEOUT:?} (killed)");
        }
        std::thread::sleep(Duration::from_millis(20));
    };
    let read = |p: &Path| String::from_utf8_lossy(&std::fs::read(p).unwrap()).into_owned();
    (status.code().unwrap_or(-1), read(&out_p), read(&err_p))
}

/// No limit for [`run_bounded`].
fn no_limit() {}

/// Caps the child's address space at `bytes` (its allocations beyond fail).
fn address_space(bytes: u64) -> impl Fn() + Send + Sync + 'static {
    move || {
        let lim = libc::rlimit {
            rlim_cur: bytes,
            rlim_max: bytes,
        };
        // SAFETY: plain system call on a valid struct.
        unsafe { libc::setrlimit(libc::RLIMIT_AS, &lim) };
    }
}

/// Caps the size of any file the child writes at `bytes` (a disk that fills up there: a
/// write past it fails with EFBIG instead of killing the process with SIGXFSZ).
fn file_size(bytes: u64) -> impl Fn() + Send + Sync + 'static {
    move || {
        let lim = libc::rlimit {
            rlim_cur: bytes,
            rlim_max: bytes,
        };
        // SAFETY: plain system calls; SIG_IGN is a valid disposition for SIGXFSZ.
        unsafe {
            libc::signal(libc::SIGXFSZ, libc::SIG_IGN);
            libc::setrlimit(libc::RLIMIT_FSIZE, &lim);
        }
    }
}

/// A FIFO at `path` (nobody ever writes it: reading it would block forever).
fn mkfifo(path: &Path) {
    let made = Command::new("mkfifo").arg(path).status().unwrap();
    assert!(made.success(), "mkfifo {}", path.display());
}

/// A sparse file of `len` bytes at `path` (no disk space; never meant to be read).
fn sparse(path: &Path, len: u64) {
    std::fs::File::create(path).unwrap().set_len(len).unwrap();
}

/// One fixture clip, the twopac contacts fixture, and a stance of the fixture library.
struct Inputs {
    clip: String,
    contacts: String,
    points: PathBuf,
    lib: String,
    stance: String,
}

fn inputs(dir: &Path) -> Inputs {
    let points = dir.join("p.parquet");
    let mut df = polars::df!("x_m" => [0.0], "y_m" => [0.0], "z_m" => [1.0]).unwrap();
    polars::prelude::ParquetWriter::new(std::fs::File::create(&points).unwrap())
        .finish(&mut df)
        .unwrap();
    let lib = fixture_library();
    let stances = Table::open(&lib.join("stances.parquet")).unwrap();
    Inputs {
        clip: fixture_clips()[0].clone(),
        contacts: s(&root().join("fixtures/twopac/r2_contacts.json")),
        points,
        lib: s(lib),
        stance: stances.strings("stance_id").unwrap()[0].clone(),
    }
}

/// The command line that reads `file` as a side input of `kind`, everything else valid;
/// outputs go into `dir` (`out`, `stance.png`).
fn reading(kind: SideInput, file: &str, i: &Inputs, dir: &Path) -> Vec<String> {
    let (out, png, points) = (
        s(&dir.join("out")),
        s(&dir.join("stance.png")),
        s(&i.points),
    );
    let v: Vec<&str> = match kind {
        SideInput::Pipeline => vec!["run", file],
        SideInput::Body => vec!["frames", &i.clip, "--body", file, "--out", &out],
        SideInput::Phases => vec!["twopac", "--phases", file, "--out", &out],
        SideInput::Contacts => {
            vec![
                "equilibrium",
                "--contacts",
                file,
                "--points",
                &points,
                "--out",
                &out,
            ]
        }
        SideInput::Points => {
            vec![
                "equilibrium",
                "--contacts",
                &i.contacts,
                "--points",
                file,
                "--out",
                &out,
            ]
        }
        SideInput::Plates => {
            vec![
                "plot", "stance", "--lib", &i.lib, "--stance", &i.stance, "--plates", file,
                "--out", &png,
            ]
        }
        SideInput::Clip => vec!["twopac", "--clip", file, "--lib", &i.lib, "--out", &out],
        _ => unreachable!("a side input without a test: add it here"),
    };
    v.into_iter().map(String::from).collect()
}

/// Every kind of side input, with the name of its bound.
const KINDS: [(SideInput, &str); 7] = [
    (SideInput::Pipeline, "MAX_TOML_BYTES"),
    (SideInput::Body, "MAX_TOML_BYTES"),
    (SideInput::Phases, "MAX_JSON_BYTES"),
    (SideInput::Contacts, "MAX_JSON_BYTES"),
    (SideInput::Points, "MAX_POINTS_BYTES"),
    (SideInput::Plates, "MAX_PLATES_BYTES"),
    (SideInput::Clip, "MAX_BVH_BYTES"),
];

/// Runs `reading(kind, file)` bounded; it must exit 2 with `needles` (and the file's path)
/// in stderr, and write no output.
fn refused_side(kind: SideInput, file: &Path, i: &Inputs, needles: &[&str]) {
    let d = tempfile::tempdir().unwrap();
    let args = reading(kind, &s(file), i, d.path());
    let args: Vec<&str> = args.iter().map(String::as_str).collect();
    let (code, out, err) = run_bounded(d.path(), &args, no_limit);
    assert_eq!(code, 2, "{kind:?}: stancelib {args:?}:\n{out}\n{err}");
    let mut wanted = vec![s(file), kind.what().to_string()];
    wanted.extend(needles.iter().map(|n| n.to_string()));
    for n in &wanted {
        assert!(
            err.contains(n.as_str()),
            "{kind:?}: stderr lacks {n:?}:\n{err}"
        );
    }
    assert!(!err.contains("panicked"), "{kind:?}:\n{err}");
    let written: Vec<_> = ["out", "stance.png"]
        .iter()
        .filter(|n| d.path().join(n).exists())
        .collect();
    assert!(written.is_empty(), "{kind:?} wrote {written:?}");
}

// See: issue 40 item 3 — a FIFO as `run`'s pipeline file, `--body`, `--phases`,
// `--contacts`, `--points`, `--plates` or `twopac --clip` hung (7 of 8).
#[test]
fn issue40_a_fifo_as_any_side_input_is_refused_without_hanging() {
    let d = tempfile::tempdir().unwrap();
    let i = inputs(d.path());
    for (kind, _) in KINDS {
        let fifo = d.path().join(format!("{kind:?}.fifo"));
        mkfifo(&fifo);
        refused_side(
            kind,
            &fifo,
            &i,
            &["FIFO (named pipe)", "only regular files"],
        );
    }
}

// See: issue 40 item 3 — `/dev/zero` as a body file grew to 14.4 GB in 60 s.
#[test]
fn issue40_a_device_as_any_side_input_is_refused() {
    let d = tempfile::tempdir().unwrap();
    let i = inputs(d.path());
    for (kind, _) in KINDS {
        refused_side(
            kind,
            Path::new("/dev/zero"),
            &i,
            &["character device", "only regular files"],
        );
    }
}

// See: issue 40 item 3 — a 3 GB sparse TOML aborted with "memory allocation of
// 3221225472 bytes failed". Every kind has its bound, checked before the file is read.
#[test]
fn issue40_a_side_input_over_its_bound_is_refused_before_it_is_read() {
    let d = tempfile::tempdir().unwrap();
    let i = inputs(d.path());
    for (kind, limit) in KINDS {
        let f = d.path().join(format!("{kind:?}.big"));
        sparse(&f, kind.max_bytes() + 1);
        let found = format!("{} bytes", kind.max_bytes() + 1);
        refused_side(kind, &f, &i, &[&found, limit]);
    }
    // The constants are the bounds the kinds report.
    let bounds = KINDS.map(|(k, _)| k.max_bytes());
    let expected = [
        MAX_TOML_BYTES,
        MAX_TOML_BYTES,
        MAX_JSON_BYTES,
        MAX_JSON_BYTES,
        MAX_POINTS_BYTES,
        MAX_PLATES_BYTES,
        MAX_BVH_BYTES,
    ];
    assert_eq!(bounds, expected);
}

// See: issue 40 item 3 — an unreadable side input names the file and the OS reason.
#[test]
fn issue40_a_missing_side_input_names_the_file_and_the_os_reason() {
    let d = tempfile::tempdir().unwrap();
    let i = inputs(d.path());
    let reason = std::io::Error::from_raw_os_error(libc::ENOENT).to_string();
    for (kind, _) in KINDS {
        let f = d.path().join(format!("{kind:?}.missing"));
        refused_side(kind, &f, &i, &["not found", &reason]);
    }
}

/// A body clip of the generator with `extra` joints without channels (children of the
/// root, no End Site) and `frames` frames: points × frames grows with `extra` while the
/// file stays small (about 40 bytes per joint).
fn clip_with_empty_joints(extra: usize, frames: usize) -> String {
    let opts = stancelib::synth::SynthOptions {
        duration_s: 30.0,
        ..Default::default()
    };
    let clip = stancelib::synth::generate(&opts);
    let (head, motion) = clip.bvh.split_once("MOTION").unwrap();
    // After the root's CHANNELS line: the new joints come before its other children.
    let at = head.find("CHANNELS").unwrap();
    let at = at + head[at..].find('\n').unwrap() + 1;
    let mut text = head[..at].to_string();
    for j in 0..extra {
        text.push_str(&format!("JOINT pad{j}\n{{\nOFFSET 0 0 0\nCHANNELS 0\n}}\n"));
    }
    text.push_str(&head[at..]);
    let rows: Vec<&str> = motion.lines().skip(3).filter(|l| !l.is_empty()).collect();
    let frame_time = motion.lines().nth(2).unwrap();
    text.push_str(&format!("MOTION\nFrames: {frames}\n{frame_time}\n"));
    for f in 0..frames {
        text.push_str(rows[f % rows.len()]);
        text.push('\n');
    }
    text
}

// See: issue 40 item 2 — 100,000 `CHANNELS 0` joints × 2,500 frames made forward
// kinematics ask for 6.0 GB at once; the batch aborted (exit 134) and the good clips were
// lost. Here 40,000 × 3,600 (3.5 GB of FK points) in a 5 MB file, under a 2 GiB address
// space: the clip is a per-clip error, the good clip is built.
#[test]
fn issue40_a_clip_over_the_point_sample_budget_is_a_per_clip_error() {
    use stancelib::ingest::MAX_POINT_SAMPLES;
    let (extra, frames) = (40_000, 3_600);
    let d = tempfile::tempdir().unwrap();
    let clips = d.path().join("clips");
    std::fs::create_dir(&clips).unwrap();
    let text = clip_with_empty_joints(extra, frames);
    assert!(text.len() < 8 << 20, "{} bytes", text.len());
    std::fs::write(clips.join("wide.bvh"), &text).unwrap();
    let good = &fixture_clips()[0];
    std::fs::copy(good, clips.join("good.bvh")).unwrap();
    let bvh = stancelib::bvh::parse_reader(text.as_bytes()).unwrap();
    let n_points = stancelib::skeleton::Skeleton::from_bvh(&bvh).n_points();
    assert!(
        n_points * frames > 2 * MAX_POINT_SAMPLES,
        "{n_points} points"
    );

    let out = d.path().join("out");
    let args = ["build", &s(&clips), "--out", &s(&out)];
    let (code, stdout, err) = run_bounded(d.path(), &args, address_space(2 << 30));
    assert_eq!(code, 1, "{stdout}\n{err}");
    let t = Table::open(&out.join("clips.parquet")).unwrap();
    let rows: Vec<(String, String)> = t
        .strings("clip")
        .unwrap()
        .into_iter()
        .zip(t.strings("status").unwrap())
        .collect();
    assert_eq!(
        rows,
        vec![
            ("good".into(), "ok".into()),
            ("wide".into(), "error".into())
        ]
    );
    let e = Table::open(&out.join("errors.parquet")).unwrap();
    let (stage, msg) = (e.strings("stage").unwrap(), e.strings("message").unwrap());
    assert_eq!(stage, vec!["frames"], "{msg:?}");
    let samples = n_points * frames;
    for n in [
        "wide.bvh",
        &format!("{n_points} points (joints and End Sites) × {frames} frames"),
        &format!("{samples} point samples"),
        &MAX_POINT_SAMPLES.to_string(),
        "MAX_POINT_SAMPLES",
    ] {
        assert!(msg[0].contains(n), "lacks {n:?}: {}", msg[0]);
    }
}

/// Runs the binary with stdout a pipe whose reader is already closed: every write there
/// fails with a broken pipe.
fn with_closed_stdout(args: &[&str]) -> (i32, String) {
    let (reader, writer) = std::io::pipe().unwrap();
    drop(reader);
    let o = Command::new(env!("CARGO_BIN_EXE_stancelib"))
        .args(args)
        .stdin(Stdio::null())
        .stdout(writer)
        .stderr(Stdio::piped())
        .output()
        .unwrap();
    (
        o.status.code().unwrap_or(-1),
        String::from_utf8_lossy(&o.stderr).into_owned(),
    )
}

// See: issue 40 item 8 — `info LIB | true`, `query run … | true` and `twopac` panicked
// (exit 101, a backtrace) on a closed stdout.
#[test]
fn issue40_a_closed_stdout_ends_quietly() {
    let d = tempfile::tempdir().unwrap();
    let lib = s(fixture_library());
    let (bvh, tw) = (d.path().join("c.bvh"), d.path().join("tw"));
    let runs = s(&d.path().join("runs.parquet"));
    let phases = s(&root().join("fixtures/twopac/walk_flat.json"));
    let cases: [Vec<&str>; 5] = [
        vec!["info", &lib],
        vec!["--json", "info", &lib],
        vec![
            "query", "run", "--lib", &lib, "--speed", "2", "--out", &runs,
        ],
        vec!["synth", "--out", bvh.to_str().unwrap()],
        vec!["twopac", "--phases", &phases, "--out", tw.to_str().unwrap()],
    ];
    for args in &cases {
        let (code, err) = with_closed_stdout(args);
        assert_eq!(code, 0, "stancelib {args:?}:\n{err}");
        assert!(
            err.is_empty(),
            "stancelib {args:?}: stderr not empty:\n{err}"
        );
    }
    // The work still happened: only the report on stdout was dropped.
    assert!(bvh.is_file() && bvh.with_extension("truth.csv").is_file());
    assert!(tw.is_dir() && d.path().join("runs.parquet").is_file());
}

// See: issue 40 item 10 — `synth --out existing.bvh` on a full disk left a 4 KB
// half-written file. The full disk is a file-size limit of 4 KB on the process.
#[test]
fn issue40_synth_on_a_full_disk_keeps_the_earlier_files() {
    let d = tempfile::tempdir().unwrap();
    let out = d.path().join("clip.bvh");
    let truth = d.path().join("clip.truth.csv");
    std::fs::write(&out, "earlier clip\n").unwrap();
    std::fs::write(&truth, "earlier truth\n").unwrap();
    let runs = d.path().join("runs");
    std::fs::create_dir(&runs).unwrap();
    let (code, stdout, err) = run_bounded(&runs, &["synth", "--out", &s(&out)], file_size(4096));
    assert_eq!(code, 2, "{stdout}\n{err}");
    assert!(err.contains("clip.bvh"), "{err}");
    assert_eq!(std::fs::read_to_string(&out).unwrap(), "earlier clip\n");
    assert_eq!(std::fs::read_to_string(&truth).unwrap(), "earlier truth\n");
    let mut names: Vec<String> = std::fs::read_dir(d.path())
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    names.sort();
    assert_eq!(
        names,
        ["clip.bvh", "clip.truth.csv", "runs"],
        "temporary left"
    );
    // Without the limit the same command replaces both.
    let (code, stdout, err) = run_bounded(&runs, &["synth", "--out", &s(&out)], no_limit);
    assert_eq!(code, 0, "{stdout}\n{err}");
    assert!(std::fs::read_to_string(&out)
        .unwrap()
        .starts_with("HIERARCHY"));
}
