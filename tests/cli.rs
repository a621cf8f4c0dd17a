//! The binary end to end: tables and their layout, exit codes, per-file failures that do
//! not stop a batch, deterministic and atomic outputs, clip-name collisions, pipelines.

use std::path::{Path, PathBuf};

use stancelib::library::codec::schema::{CLIPS_COLUMNS, CONTACTS_COLUMNS};
use stancelib::library::codec::table::read_parquet;

pub(super) use crate::util::{root, stancelib};

pub(super) fn fixture(name: &str) -> String {
    root().join("fixtures/bvh").join(name).display().to_string()
}

/// The five generated clips (not the `bad/` folder below them).
pub(super) fn good_fixtures() -> Vec<String> {
    let mut v: Vec<String> = std::fs::read_dir(root().join("fixtures/bvh"))
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "bvh"))
        .map(|p| p.display().to_string())
        .collect();
    v.sort();
    v
}

/// `frames <good fixtures> <extra…>`.
fn frames_on_fixtures(extra: &[&str]) -> (i32, String, String) {
    let files = good_fixtures();
    let mut args: Vec<&str> = vec!["frames"];
    args.extend(files.iter().map(String::as_str));
    args.extend(extra);
    stancelib(&args)
}

pub(super) fn tmp() -> tempfile::TempDir {
    tempfile::tempdir().unwrap()
}

/// A string column as owned strings.
pub(super) fn strings(df: &polars::prelude::DataFrame, col: &str) -> Vec<String> {
    df.column(col)
        .unwrap()
        .str()
        .unwrap()
        .iter()
        .map(|s| s.unwrap().to_string())
        .collect()
}

fn names(df: &polars::prelude::DataFrame) -> Vec<String> {
    df.get_column_names()
        .iter()
        .map(|s| s.to_string())
        .collect()
}

#[test]
fn frames_writes_the_documented_tables() {
    let out = tmp();
    let o = out.path().display().to_string();
    let (code, stdout, stderr) = frames_on_fixtures(&["--out", &o, "--joints"]);
    assert_eq!(code, 0, "{stdout}{stderr}");
    let frames = read_parquet(&out.path().join("frames.parquet")).unwrap();
    let clips = read_parquet(&out.path().join("clips.parquet")).unwrap();
    let contacts = read_parquet(&out.path().join("contacts.parquet")).unwrap();
    let joints = read_parquet(&out.path().join("joints.parquet")).unwrap();
    assert_eq!(names(&clips), CLIPS_COLUMNS.to_vec());
    assert_eq!(names(&contacts), CONTACTS_COLUMNS.to_vec());
    assert_eq!(
        names(&joints),
        vec!["clip", "frame", "joint", "x_m", "y_m", "z_m"]
    );
    let fcols = names(&frames);
    for c in [
        "clip",
        "frame",
        "time_clip_s",
        "com_x_m",
        "com_vz_mps",
        "com_az_mps2",
        "ground_z_m",
        "contact_left_foot",
        "contact_right_hand",
        "static_left_foot",
        "surface_z_left_foot_m",
        "left_foot_x_m",
        "right_hand_z_m",
        "left_toe_x_m",
        "right_toe_z_m",
    ] {
        assert!(fcols.iter().any(|f| f == c), "frames.parquet lacks {c}");
    }
    // One row per kept frame of the 5 fixtures, sorted by clip then frame.
    let kept: i64 = clips
        .column("frames_kept")
        .unwrap()
        .i64()
        .unwrap()
        .iter()
        .flatten()
        .sum();
    assert_eq!(frames.height() as i64, kept);
    let clip = strings(&frames, "clip");
    let frame: Vec<i64> = frames
        .column("frame")
        .unwrap()
        .i64()
        .unwrap()
        .iter()
        .map(|v| v.unwrap())
        .collect();
    let keys: Vec<(String, i64)> = clip.into_iter().zip(frame).collect();
    assert!(
        keys.windows(2).all(|w| w[0] < w[1]),
        "frames not sorted by (clip, frame)"
    );
    // The generator's skeleton: 21 joints (6 + 20·3 = 66 channels) and 5 End Sites.
    assert_eq!(joints.height() as i64, kept * 26);
    assert!(stdout.contains("5 clips: 5 ok"));
}

#[test]
fn a_batch_with_bad_files_processes_the_rest_and_exits_1() {
    let out = tmp();
    let o = out.path().display().to_string();
    let bad = root().join("fixtures/bvh/bad").display().to_string();
    let (code, _, stderr) =
        stancelib(&["frames", &fixture("run_30hz_in_yup.bvh"), &bad, "--out", &o]);
    assert_eq!(code, 1, "{stderr}");
    assert!(
        stderr.contains("truncated_last_row.bvh: line 21: truncated"),
        "{stderr}"
    );
    let clips = read_parquet(&out.path().join("clips.parquet")).unwrap();
    let status = strings(&clips, "status");
    assert_eq!(status.iter().filter(|s| *s == "ok").count(), 1);
    assert_eq!(status.iter().filter(|s| *s == "error").count(), 15);
    let frames = read_parquet(&out.path().join("frames.parquet")).unwrap();
    assert!(frames.height() > 0);
    // Nothing half-written is left behind.
    let leftovers: Vec<_> = std::fs::read_dir(out.path())
        .unwrap()
        .filter_map(|e| e.ok())
        .filter(|e| e.file_name().to_string_lossy().contains(".tmp"))
        .collect();
    assert!(leftovers.is_empty());
}

#[test]
fn fatal_errors_exit_2_and_keep_earlier_outputs() {
    let out = tmp();
    let o = out.path().display().to_string();
    assert_eq!(
        stancelib(&["frames", &fixture("run_30hz_in_yup.bvh"), "--out", &o]).0,
        0
    );
    let before = std::fs::read(out.path().join("frames.parquet")).unwrap();
    let (code, _, err) = stancelib(&["frames", "/no/such/file.bvh", "--out", &o]);
    assert_eq!(code, 2);
    assert!(err.contains("/no/such/file.bvh"), "{err}");
    assert_eq!(frames_on_fixtures(&["--out", &o, "--unit", "furlong"]).0, 2);
    assert_eq!(frames_on_fixtures(&["--out", &o, "--up-axis", "up"]).0, 2);
    assert_eq!(
        std::fs::read(out.path().join("frames.parquet")).unwrap(),
        before,
        "a failed run changed an earlier output"
    );
}

#[test]
fn outputs_do_not_depend_on_thread_count() {
    let (a, b) = (tmp(), tmp());
    for (d, t) in [(&a, "1"), (&b, "2")] {
        let o = d.path().display().to_string();
        assert_eq!(frames_on_fixtures(&["--out", &o, "--threads", t]).0, 0);
    }
    for f in ["frames.parquet", "clips.parquet", "contacts.parquet"] {
        assert_eq!(
            std::fs::read(a.path().join(f)).unwrap(),
            std::fs::read(b.path().join(f)).unwrap(),
            "{f} differs"
        );
    }
}

#[test]
fn colliding_stems_get_parent_prefixes() {
    let inp = tmp();
    for d in ["a", "b"] {
        std::fs::create_dir_all(inp.path().join(d)).unwrap();
        std::fs::copy(
            fixture("run_30hz_in_yup.bvh"),
            inp.path().join(d).join("clip.bvh"),
        )
        .unwrap();
    }
    let out = tmp();
    let (code, ..) = stancelib(&[
        "frames",
        &inp.path().display().to_string(),
        "--out",
        &out.path().display().to_string(),
    ]);
    assert_eq!(code, 0);
    let clips = read_parquet(&out.path().join("clips.parquet")).unwrap();
    let c = strings(&clips, "clip");
    assert_eq!(c, vec!["a/clip", "b/clip"]);
}

#[test]
fn every_pipeline_file_parses() {
    let dir = root().join("pipelines");
    let files: Vec<PathBuf> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "toml"))
        .collect();
    assert!(files.len() >= 2);
    for f in files {
        let p = stancelib::pipeline::spec::read_pipeline(&f).unwrap_or_else(|e| panic!("{e}"));
        if let Some(b) = &p.body {
            stancelib::pipeline::spec::read_body(&stancelib::pipeline::spec::relative_to(&f, b))
                .unwrap();
        }
    }
}

#[test]
fn the_demo_pipeline_runs() {
    // Copy the demo job next to a temporary output folder: same inputs, other `out`.
    let dir = tmp();
    let text = std::fs::read_to_string(root().join("pipelines/demo.toml")).unwrap();
    let text = text
        .replace(
            "\"../fixtures/",
            &format!("\"{}/fixtures/", root().display()),
        )
        .replace("\"../out/demo\"", "\"out\"");
    let p = dir.path().join("demo.toml");
    std::fs::write(&p, text).unwrap();
    let (code, stdout, stderr) = stancelib(&["run", &p.display().to_string()]);
    assert_eq!(code, 0, "{stdout}{stderr}");
    assert!(dir.path().join("out/frames.parquet").is_file());
}

#[test]
fn a_batch_where_every_clip_fails_exits_2_with_its_tables() {
    let out = tmp();
    let bad = root().join("fixtures/bvh/bad").display().to_string();
    let lib = out.path().join("lib");
    let (code, _, stderr) = stancelib(&["build", &bad, "--out", &lib.display().to_string()]);
    assert_eq!(code, 2, "{stderr}");
    let errors = read_parquet(&lib.join("errors.parquet")).unwrap();
    assert_eq!(errors.height(), 15);
    assert!(strings(&errors, "stage").iter().all(|s| s == "parse"));
}

#[test]
fn an_incremental_build_equals_a_full_rebuild() {
    let (inc, full) = (tmp(), tmp());
    let (lib_inc, lib_full) = (inc.path().join("lib"), full.path().join("lib"));
    let f = good_fixtures();
    let lib = |p: &Path| p.display().to_string();
    // First a library of two clips, then an incremental build of all five: two reused.
    assert_eq!(
        stancelib(&["build", &f[0], &f[1], "--out", &lib(&lib_inc)]).0,
        0
    );
    let mut args: Vec<&str> = vec!["build"];
    args.extend(f.iter().map(String::as_str));
    let li = lib(&lib_inc);
    args.extend(["--out", &li, "--incremental"]);
    let (code, stdout, stderr) = stancelib(&args);
    assert_eq!(code, 0, "{stderr}");
    assert!(stdout.contains("2 clips reused"), "{stdout}");
    let lf = lib(&lib_full);
    let mut full_args: Vec<&str> = vec!["build"];
    full_args.extend(f.iter().map(String::as_str));
    full_args.extend(["--out", &lf]);
    assert_eq!(stancelib(&full_args).0, 0);
    for t in ["frames", "contacts", "clips", "stances", "errors"] {
        let name = format!("{t}.parquet");
        assert!(
            std::fs::read(lib_inc.join(&name)).unwrap()
                == std::fs::read(lib_full.join(&name)).unwrap(),
            "{name} differs"
        );
    }
    // Nothing of the swap is left beside the library.
    let leftovers: Vec<_> = std::fs::read_dir(inc.path())
        .unwrap()
        .filter_map(|e| e.ok())
        .map(|e| e.file_name())
        .collect();
    assert_eq!(leftovers.len(), 1, "{leftovers:?}");
}

#[test]
fn a_library_does_not_depend_on_threads_or_input_order() {
    let (a, b) = (tmp(), tmp());
    let mut f = good_fixtures();
    let la = a.path().join("lib").display().to_string();
    let lb = b.path().join("lib").display().to_string();
    let mut args: Vec<&str> = vec!["build"];
    args.extend(f.iter().map(String::as_str));
    args.extend(["--out", &la, "--threads", "1"]);
    assert_eq!(stancelib(&args).0, 0);
    f.reverse();
    let mut args: Vec<&str> = vec!["build"];
    args.extend(f.iter().map(String::as_str));
    args.extend(["--out", &lb, "--threads", "2"]);
    assert_eq!(stancelib(&args).0, 0);
    for t in ["frames", "contacts", "clips", "stances", "errors"] {
        let name = format!("{t}.parquet");
        assert!(
            std::fs::read(a.path().join("lib").join(&name)).unwrap()
                == std::fs::read(b.path().join("lib").join(&name)).unwrap(),
            "{name} differs"
        );
    }
}

#[test]
fn force_model_is_selectable_and_recorded_per_stance_and_in_the_manifest() {
    // See: issue 12 item 1 — the ratio model is the default, the paper's Fourier model stays
    // selectable, and both the stance rows and the manifest say which one was fitted.
    let dir = tmp();
    let (a, b) = (dir.path().join("a"), dir.path().join("b"));
    let f = fixture("run_120hz_m_yup.bvh");
    assert_eq!(
        stancelib(&["build", &f, "--out", &a.display().to_string()]).0,
        0
    );
    let fourier = [
        "build",
        &f,
        "--out",
        &b.display().to_string(),
        "--force-model",
        "fourier",
    ];
    assert_eq!(stancelib(&fourier).0, 0);
    let (sa, sb) = (
        read_parquet(&a.join("stances.parquet")).unwrap(),
        read_parquet(&b.join("stances.parquet")).unwrap(),
    );
    assert!(sa.height() > 0 && sa.height() == sb.height());
    assert!(strings(&sa, "force_model").iter().all(|s| s == "ratio"));
    assert!(strings(&sb, "force_model").iter().all(|s| s == "fourier"));
    let list_lens = |df: &polars::prelude::DataFrame, c: &str| -> Vec<usize> {
        let l = df.column(c).unwrap().list().unwrap().clone();
        l.amortized_iter()
            .map(|s| s.map_or(0, |s| s.as_ref().len()))
            .collect()
    };
    assert!(list_lens(&sa, "poly_v_n").iter().all(|&n| n >= 3));
    assert!(list_lens(&sa, "harmonic_v").iter().all(|&n| n == 0));
    assert!(list_lens(&sb, "poly_v_n").iter().all(|&n| n == 0));
    assert!(list_lens(&sb, "harmonic_v").iter().any(|&n| n > 0));
    for (lib, name) in [(&a, "ratio"), (&b, "fourier")] {
        let m: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(lib.join("manifest.json")).unwrap())
                .unwrap();
        let text = m.to_string();
        assert!(text.contains(&format!("\"model\":\"{name}\"")), "{text}");
    }
    let bad = [
        "build",
        &f,
        "--out",
        &b.display().to_string(),
        "--force-model",
        "dft",
    ];
    assert_eq!(stancelib(&bad).0, 2);
    let removed = ["build", &f, "--out", &b.display().to_string(), "--stage-b"];
    assert_eq!(stancelib(&removed).0, 2, "Stage B was removed");
}
