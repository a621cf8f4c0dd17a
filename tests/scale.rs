//! Issue 16: the streaming build, `--shard I/N` and `merge`, and the Spark driver.
//!
//! Every comparison is byte for byte on the Parquet files of two libraries; the manifests
//! must be equal apart from `wall_time_s`.

use std::path::{Path, PathBuf};

use stancelib::pipeline::engine::output::OutputRules;
use stancelib::pipeline::engine::shard::{shard_of, Shard};
use stancelib::pipeline::engine::streaming::{
    build, build_into, write_library, BuildOptions, BuildPlan,
};

use super::util::{root, s, shared_or_skip, stable_manifest, stancelib};

fn tmp() -> tempfile::TempDir {
    tempfile::tempdir().unwrap()
}

/// Every fixture clip, the malformed ones of `fixtures/bvh/bad` too (their error rows
/// must merge as well).
fn fixture_inputs() -> Vec<PathBuf> {
    stancelib::pipeline::engine::inputs::discover(&[root().join("fixtures/bvh")]).unwrap()
}

/// `n` real clips of the bulk CMU set (every `step`-th, so several subjects), or `None`
/// (skipped outside CI) when the shared data is absent.
pub(super) fn real_subset(test: &str, n: usize) -> Option<Vec<PathBuf>> {
    let data = shared_or_skip(test)?;
    let all = stancelib::pipeline::engine::inputs::discover(&[data.join("bvh-bulk/cmu")]).unwrap();
    let step = (all.len() / n).max(1);
    Some(all.into_iter().step_by(step).take(n).collect())
}

fn files_of(lib: &Path) -> Vec<String> {
    let mut v: Vec<String> = std::fs::read_dir(lib)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    v.sort();
    v
}

/// Two libraries hold the same files with the same bytes (manifests: but the wall time).
pub(super) fn assert_same_library(a: &Path, b: &Path) {
    assert_eq!(
        files_of(a),
        files_of(b),
        "{} vs {}",
        a.display(),
        b.display()
    );
    for f in files_of(a) {
        if f == "manifest.json" {
            assert_eq!(
                stable_manifest(&a.join("manifest.json")),
                stable_manifest(&b.join("manifest.json")),
                "manifest of {}",
                b.display()
            );
            continue;
        }
        let (x, y) = (
            std::fs::read(a.join(&f)).unwrap(),
            std::fs::read(b.join(&f)).unwrap(),
        );
        assert!(x == y, "{f} differs: {} vs {}", a.display(), b.display());
    }
}

/// `stancelib build` of `inputs` into `out` with `extra` options; the exit code.
pub(super) fn build_cli(inputs: &[PathBuf], out: &Path, extra: &[&str]) -> i32 {
    let mut args: Vec<String> = vec!["build".into()];
    args.extend(inputs.iter().map(|p| s(p)));
    args.extend(["--out".into(), s(out)]);
    args.extend(extra.iter().map(|e| e.to_string()));
    let argv: Vec<&str> = args.iter().map(String::as_str).collect();
    let (code, _, err) = stancelib(&argv);
    assert!(
        code == 0 || code == 1,
        "build {extra:?}: exit {code}\n{err}"
    );
    code
}

/// Build every shard of `n` into `dir/shard-I`, merge into `dir/merged`; the merged path.
pub(super) fn shard_and_merge(inputs: &[PathBuf], dir: &Path, n: usize, extra: &[&str]) -> PathBuf {
    let mut shards = Vec::new();
    for i in 1..=n {
        let out = dir.join(format!("shard-{i}"));
        let spec = format!("{i}/{n}");
        let mut e: Vec<&str> = vec!["--shard", &spec];
        e.extend(extra);
        build_cli(inputs, &out, &e);
        shards.push(s(&out));
    }
    let merged = dir.join("merged");
    let mut args: Vec<&str> = vec!["merge"];
    // Any order: the last shard first.
    args.extend(shards.iter().rev().map(String::as_str));
    let m = s(&merged);
    args.extend(["--out", &m]);
    let (code, out, err) = stancelib(&args);
    assert!(
        code == 0 || code == 1,
        "merge of {n}: exit {code}\n{out}\n{err}"
    );
    merged
}

#[test]
fn shards_merged_equal_the_single_build_for_1_3_and_7_shards() {
    let inputs = fixture_inputs();
    let d = tmp();
    let single = d.path().join("single");
    assert_eq!(build_cli(&inputs, &single, &[]), 1, "the bad fixtures fail");
    for n in [1, 3, 7] {
        let dir = d.path().join(format!("n{n}"));
        let merged = shard_and_merge(&inputs, &dir, n, &[]);
        assert_same_library(&single, &merged);
        // The shards hold every clip once between them.
        let clips: usize = (1..=n)
            .map(|i| {
                stable_manifest(&dir.join(format!("shard-{i}")).join("manifest.json"))["counts"]
                    ["clips"]
                    .as_u64()
                    .unwrap()
            })
            .sum::<u64>() as usize;
        assert_eq!(clips, inputs.len());
    }
}

#[test]
fn shards_merged_keep_joints_and_the_force_model() {
    let inputs = fixture_inputs();
    let d = tmp();
    let single = d.path().join("single");
    let opts = ["--joints", "--force-model", "fourier"];
    build_cli(&inputs, &single, &opts);
    let merged = shard_and_merge(&inputs, &d.path().join("n3"), 3, &opts);
    assert!(merged.join("joints.parquet").is_file());
    assert_same_library(&single, &merged);
}

#[test]
fn shards_of_real_clips_merge_to_the_single_build() {
    let Some(inputs) = real_subset("shards_of_real_clips_merge_to_the_single_build", 9) else {
        return;
    };
    let d = tmp();
    let single = d.path().join("single");
    build_cli(&inputs, &single, &[]);
    let merged = shard_and_merge(&inputs, &d.path().join("n3"), 3, &[]);
    assert_same_library(&single, &merged);
    let m = stable_manifest(&merged.join("manifest.json"));
    assert!(m["counts"]["stances"].as_u64().unwrap() > 0, "{m}");
}

/// A build written through the streaming sink with `batch` clips per batch on `threads`.
fn streamed(files: &[PathBuf], out: &Path, batch: usize, threads: usize) {
    let plan = BuildPlan {
        batch_clips: batch,
        ..BuildPlan::default()
    };
    rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .unwrap()
        .install(|| {
            build_into(
                files,
                out,
                &BuildOptions::default(),
                &plan,
                &OutputRules::default(),
            )
        })
        .unwrap();
}

#[test]
fn a_streaming_build_does_not_depend_on_batch_size_or_threads() {
    let mut files = fixture_inputs();
    if let Some(real) = real_subset("a_streaming_build_does_not_depend_on_batch_size", 4) {
        files.extend(real);
    }
    let d = tmp();
    // The whole build in memory, written in one batch: the reference.
    let whole = d.path().join("whole");
    let opts = BuildOptions::default();
    write_library(&whole, &build(&files, &opts), &opts).unwrap();
    for (batch, threads) in [(1, 1), (2, 2), (3, 1), (1000, 2)] {
        let out = d.path().join(format!("b{batch}-t{threads}"));
        streamed(&files, &out, batch, threads);
        assert_same_library(&whole, &out);
    }
}

/// `frames` streams its tables batch by batch (at most 4 clips and 4 MiB of files per
/// thread), writing one batch while the next is ingested: the files equal one in-memory
/// batch of every clip, byte for byte, at 1 and 2 threads, `--joints` included.
#[test]
fn a_streamed_frames_run_equals_one_batch_of_every_clip() {
    use stancelib::ingest::IngestOptions;
    use stancelib::pipeline::commands::frames::frames_into;
    use stancelib::pipeline::engine::batch::ingest_all;
    let mut files = fixture_inputs();
    if let Some(real) = real_subset("a_streamed_frames_run_equals_one_batch", 6) {
        files.extend(real);
    }
    let d = tmp();
    let opts = IngestOptions {
        joints: true,
        ..IngestOptions::default()
    };
    let whole = d.path().join("whole");
    let all = ingest_all(&files, &opts);
    stancelib::library::codec::write::write_all(&whole, &all, true).unwrap();
    let outcomes: Vec<_> = all.into_iter().map(|r| r.written()).collect();
    let tables = files_of(&whole);
    assert!(tables.len() >= 4, "{tables:?}");
    for threads in [1, 2] {
        let out = d.path().join(format!("t{threads}"));
        let records = frames_into(&files, &out, &opts, threads).unwrap();
        // The outcome of every clip, as the in-memory batch has it (some inputs are bad).
        assert_eq!(records, outcomes, "{threads} threads");
        assert_eq!(files_of(&out), tables, "{threads} threads");
        for t in &tables {
            let (a, b) = (
                std::fs::read(whole.join(t)).unwrap(),
                std::fs::read(out.join(t)).unwrap(),
            );
            assert!(a == b, "{t} differs at {threads} threads");
        }
    }
}

#[test]
fn row_groups_hold_64_ki_rows_whatever_the_batches() {
    // 150,000 rows pushed in uneven pieces: groups of 65,536, 65,536 and 18,928 rows.
    use polars::prelude::*;
    let d = tmp();
    let df = |a: i64, b: i64| {
        DataFrame::new_infer_height(vec![Column::new("v".into(), (a..b).collect::<Vec<i64>>())])
            .unwrap()
    };
    let mut w =
        stancelib::library::storage::stream::TableWriter::create(d.path(), "t.parquet", &df(0, 0))
            .unwrap();
    for (a, b) in [
        (0, 1000),
        (1000, 70_000),
        (70_000, 70_001),
        (70_001, 150_000),
    ] {
        w.push(&df(a, b)).unwrap();
    }
    w.finish(&[]).unwrap();
    let mut whole = df(0, 150_000);
    stancelib::library::codec::write::write_atomic(d.path(), "u.parquet", &mut whole, &[]).unwrap();
    let (x, y) = (
        std::fs::read(d.path().join("t.parquet")).unwrap(),
        std::fs::read(d.path().join("u.parquet")).unwrap(),
    );
    assert!(x == y, "streamed and whole writes differ");
    let mut r = ParquetReader::new(std::fs::File::open(d.path().join("t.parquet")).unwrap());
    let groups: Vec<usize> = r
        .get_metadata()
        .unwrap()
        .row_groups
        .iter()
        .map(|g| g.num_rows())
        .collect();
    assert_eq!(groups, vec![65_536, 65_536, 18_928]);
}

/// Per row group of `path`: the one value of each column of `names` (an error, so a
/// failure, where a group holds more than one).
fn group_values(path: &Path, names: &[&str]) -> Vec<Vec<String>> {
    let mut r = stancelib::library::storage::group_reader::GroupFileReader::open(path).unwrap();
    let mut out = Vec::new();
    loop {
        let values: Vec<Option<Vec<u8>>> = names.iter().map(|n| r.peek_value(n).unwrap()).collect();
        if values.iter().any(Option::is_none) {
            break;
        }
        out.push(
            values
                .into_iter()
                .map(|v| String::from_utf8(v.unwrap()).unwrap())
                .collect(),
        );
        r.next_group().unwrap().unwrap();
    }
    assert!(r.next_group().unwrap().is_none());
    out
}

/// (row, clip) of the rows of a clips table whose clip kept frames.
fn clips_with_frames(clips: &polars::prelude::DataFrame) -> Vec<(usize, String)> {
    let names = clips.column("clip").unwrap().str().unwrap();
    let kept = clips.column("frames_kept").unwrap().i64().unwrap();
    names
        .iter()
        .zip(kept.iter())
        .enumerate()
        .filter(|(_, (_, n))| n.unwrap_or(0) > 0)
        .map(|(i, (c, _))| (i, c.unwrap().to_string()))
        .collect()
}

/// The per-frame tables hold one row group per clip and the polytopes' points one per
/// (character, effector), so that a merge copies them without decoding them.
#[test]
fn per_clip_tables_hold_a_row_group_per_clip() {
    let d = tmp();
    let out = d.path().join("lib");
    streamed(&fixture_inputs(), &out, 2, 2);
    let clips = stancelib::library::codec::table::read_parquet(&out.join("clips.parquet")).unwrap();
    let with_frames: Vec<String> = clips_with_frames(&clips)
        .into_iter()
        .map(|(_, c)| c)
        .collect();
    let per_group: Vec<String> = group_values(&out.join("frames.parquet"), &["clip"])
        .into_iter()
        .map(|mut v| v.remove(0))
        .collect();
    assert_eq!(per_group, with_frames);
    let points = group_values(
        &out.join("kinematics_points.parquet"),
        &["character_id", "effector"],
    );
    assert!(!points.is_empty());
    let mut keys = points.clone();
    keys.dedup();
    assert_eq!(keys, points, "a (character, effector) in two row groups");
}

#[test]
fn a_file_s_shard_follows_its_content_not_its_name_or_neighbours() {
    let d = tmp();
    let src = root().join("fixtures/bvh/run_60hz_cm_zup.bvh");
    let copy = d.path().join("another_name.bvh");
    std::fs::copy(&src, &copy).unwrap();
    for n in [2, 3, 7, 1000] {
        assert_eq!(shard_of(&src, n), shard_of(&copy, n));
    }
    // Shard 1/2 of two fixtures holds the same clips with or without the others.
    let fx = fixture_inputs();
    let clips_of = |inputs: &[PathBuf], out: &Path| -> Vec<String> {
        build_cli(inputs, out, &["--shard", "1/2"]);
        let m = stable_manifest(&out.join("manifest.json"));
        m["inputs"].as_object().unwrap().keys().cloned().collect()
    };
    let all = clips_of(&fx, &d.path().join("all"));
    let good: Vec<PathBuf> = fx
        .iter()
        .filter(|p| !p.starts_with(root().join("fixtures/bvh/bad")))
        .cloned()
        .collect();
    let some = clips_of(&good, &d.path().join("some"));
    let stems: Vec<String> = good
        .iter()
        .map(|p| p.file_stem().unwrap().to_string_lossy().into_owned())
        .collect();
    let expected: Vec<String> = all.iter().filter(|c| stems.contains(c)).cloned().collect();
    assert_eq!(some, expected);
    assert!(all.len() > some.len(), "{all:?}");
}

/// `merge` of `shards` into `out`: (exit code, stderr).
fn merge_cli(shards: &[&Path], out: &Path) -> (i32, String) {
    let mut args: Vec<String> = vec!["merge".into()];
    args.extend(shards.iter().map(|p| s(p)));
    args.extend(["--out".into(), s(out)]);
    let argv: Vec<&str> = args.iter().map(String::as_str).collect();
    let (code, _, err) = stancelib(&argv);
    (code, err)
}

/// The fixtures built as shards 1/2 and 2/2 (folders `a` and `b` of the returned
/// temporary folder).
fn two_fixture_shards() -> (tempfile::TempDir, PathBuf, PathBuf) {
    let inputs = fixture_inputs();
    let d = tmp();
    let (a, b) = (d.path().join("a"), d.path().join("b"));
    build_cli(&inputs, &a, &["--shard", "1/2"]);
    build_cli(&inputs, &b, &["--shard", "2/2"]);
    (d, a, b)
}

/// A shard whose frames hold a clip its clips table does not (here its last clip with
/// frames, and those after it, are cut from `clips.parquet`) is refused, naming the shard,
/// the table and the clip: the merge copies frames by row group and would otherwise drop
/// the groups left after the shard's last listed clip.
#[test]
fn merge_refuses_frames_of_a_clip_the_shard_does_not_list() {
    let (d, a, b) = two_fixture_shards();
    let clips_path = b.join("clips.parquet");
    let mut clips = stancelib::library::codec::table::read_parquet(&clips_path).unwrap();
    let (last, name) = clips_with_frames(&clips)
        .pop()
        .expect("a clip with frames in shard 2");
    // The clips from it on are cut, so that no listed clip of this shard comes after it.
    clips = clips.slice(0, last);
    stancelib::library::codec::write::write_atomic(&b, "clips.parquet", &mut clips, &[]).unwrap();
    // Its hashes recorded again: the check behind them is the one tested here.
    crate::util::reseal(&b);
    let out = d.path().join("merged");
    let (code, err) = merge_cli(&[&a, &b], &out);
    assert_eq!(code, 2, "{err}");
    assert!(
        err.contains(&s(&b)) && err.contains("frames.parquet") && err.contains(&name),
        "{err}"
    );
    assert!(!out.exists());
}

/// A table the merge reads while its row group copy runs beside it (here a shard's
/// samples, cut in half) fails the merge with that table's own error, not the copy's
/// "stopped" one, and the library already at `--out` is kept as it was.
#[test]
fn a_failure_beside_the_row_group_copy_names_its_table_and_keeps_the_old_library() {
    let (d, a, b) = two_fixture_shards();
    let out = d.path().join("merged");
    let (code, err) = merge_cli(&[&a, &b], &out);
    assert!(code <= 1, "{err}");
    let before = std::fs::read(out.join("frames.parquet")).unwrap();
    let samples = b.join("kinematics_samples.parquet");
    let bytes = std::fs::read(&samples).unwrap();
    std::fs::write(&samples, &bytes[..bytes.len() / 2]).unwrap();
    // Its hashes recorded again, so that the merge starts and meets the table itself.
    crate::util::reseal(&b);
    let mut args: Vec<String> = vec!["merge".into(), s(&a), s(&b), "--out".into(), s(&out)];
    args.push("--force".into());
    let argv: Vec<&str> = args.iter().map(String::as_str).collect();
    let (code, _, err) = stancelib(&argv);
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("kinematics_samples.parquet"), "{err}");
    assert!(!err.contains("copy was stopped"), "{err}");
    assert_eq!(std::fs::read(out.join("frames.parquet")).unwrap(), before);
}

#[test]
fn merge_refuses_shards_built_with_other_options_naming_the_shard() {
    let inputs = fixture_inputs();
    let d = tmp();
    let (a, b) = (d.path().join("a"), d.path().join("b"));
    build_cli(&inputs, &a, &["--shard", "1/2"]);
    build_cli(&inputs, &b, &["--shard", "2/2", "--mass", "80"]);
    let out = d.path().join("merged");
    let (code, err) = merge_cli(&[&a, &b], &out);
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("options") && err.contains(&s(&b)), "{err}");
    assert!(!out.exists());
    // Another tool version, or another source at the same version (shards computed by
    // different code): the manifest says so (edited here to stand for an old build).
    let path = b.join("manifest.json");
    for (key, mark) in [("tool_version", "0.0.0-"), ("source_digest", "f00d")] {
        build_cli(&inputs, &b, &["--shard", "2/2"]);
        let text = std::fs::read_to_string(&path).unwrap();
        let from = format!("\"{key}\": \"");
        std::fs::write(&path, text.replace(&from, &format!("{from}{mark}"))).unwrap();
        let (code, err) = merge_cli(&[&a, &b], &out);
        assert_eq!(code, 2, "{err}");
        assert!(err.contains(key), "{err}");
    }
    // Shards that agree with each other but were written by other code (both digests
    // edited alike, or both missing as in a library written before the digest): the merged
    // manifest would record this build's digest on their rows, so they are refused too.
    for foreign in [Some("0".repeat(64)), None] {
        for shard in [(&a, "1/2"), (&b, "2/2")] {
            build_cli(&inputs, shard.0, &["--shard", shard.1]);
            let p = shard.0.join("manifest.json");
            let mut m: serde_json::Value =
                serde_json::from_str(&std::fs::read_to_string(&p).unwrap()).unwrap();
            let o = m.as_object_mut().unwrap();
            match &foreign {
                Some(d) => o.insert("source_digest".into(), d.clone().into()),
                None => o.remove("source_digest"),
            };
            std::fs::write(&p, serde_json::to_string_pretty(&m).unwrap()).unwrap();
        }
        let (code, err) = merge_cli(&[&a, &b], &out);
        assert_eq!(code, 2, "{err}");
        assert!(
            err.contains("written by another build of stancelib"),
            "{err}"
        );
        assert!(!out.exists());
    }
    build_cli(&inputs, &a, &["--shard", "1/2"]);
    // Shards of different input lists never merge either.
    build_cli(&inputs[1..], &b, &["--shard", "2/2"]);
    let (code, err) = merge_cli(&[&a, &b], &out);
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("inputs_sha256"), "{err}");
}

#[test]
fn merge_names_a_missing_or_failed_shard() {
    let inputs = fixture_inputs();
    let d = tmp();
    let (a, b, c) = (d.path().join("a"), d.path().join("b"), d.path().join("c"));
    build_cli(&inputs, &a, &["--shard", "1/3"]);
    build_cli(&inputs, &b, &["--shard", "2/3"]);
    let out = d.path().join("merged");
    // Shard 3 never ran.
    let (code, err) = merge_cli(&[&a, &b], &out);
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("shard 3/3 missing"), "{err}");
    // Shard 3's folder exists but its build died before writing the library.
    std::fs::create_dir_all(&c).unwrap();
    let (code, err) = merge_cli(&[&a, &b, &c], &out);
    assert_eq!(code, 2, "{err}");
    assert!(
        err.contains(&s(&c)) && err.contains("did not finish"),
        "{err}"
    );
    // A library built without --shard is not a shard.
    build_cli(&inputs, &c, &[]);
    let (code, err) = merge_cli(&[&a, &b, &c], &out);
    assert_eq!(code, 2, "{err}");
    assert!(
        err.contains(&s(&c)) && err.contains("not a shard library"),
        "{err}"
    );
    // A shard given twice.
    let (code, err) = merge_cli(&[&a, &b, &b], &out);
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("given twice"), "{err}");
    // A shard whose summary is gone.
    build_cli(&inputs, &c, &["--shard", "3/3"]);
    std::fs::remove_file(c.join("kinematics_samples.parquet")).unwrap();
    let (code, err) = merge_cli(&[&a, &b, &c], &out);
    assert_eq!(code, 2, "{err}");
    assert!(
        err.contains("kinematics_samples.parquet is missing") && err.contains(&s(&c)),
        "{err}"
    );
    assert!(!out.exists());
}

#[test]
fn merge_output_follows_the_build_output_rules() {
    let inputs = fixture_inputs();
    let d = tmp();
    let a = d.path().join("a");
    build_cli(&inputs, &a, &["--shard", "1/1"]);
    // --out naming a shard, or a folder inside one, is refused and the shard survives.
    let before = std::fs::read(a.join("stances.parquet")).unwrap();
    for out in [a.clone(), a.join("inner")] {
        let (code, err) = merge_cli(&[&a], &out);
        assert_eq!(code, 2, "{err}");
        assert!(err.contains("input"), "{err}");
    }
    assert_eq!(std::fs::read(a.join("stances.parquet")).unwrap(), before);
    // A folder that is not a library is refused.
    let other = d.path().join("notes");
    std::fs::create_dir_all(&other).unwrap();
    std::fs::write(other.join("keep.txt"), "mine").unwrap();
    let (code, err) = merge_cli(&[&a], &other);
    assert_eq!(code, 2, "{err}");
    assert!(other.join("keep.txt").is_file());
    // The shard's --shard parse errors name the option.
    let (code, _, err) = stancelib(&[
        "build",
        &s(&inputs[0]),
        "--out",
        &s(&d.path().join("x")),
        "--shard",
        "4/3",
    ]);
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("--shard"), "{err}");
    let _ = Shard { index: 1, count: 1 };
}

/// Why the Spark driver cannot run here (no `java`, or no `pyspark` for `python3`).
fn spark_missing() -> Option<String> {
    let runs = |cmd: &str, args: &[&str]| {
        std::process::Command::new(cmd)
            .args(args)
            .output()
            .is_ok_and(|o| o.status.success())
    };
    if !runs("java", &["-version"]) {
        return Some("java is not installed".into());
    }
    if !runs("python3", &["-c", "import pyspark"]) {
        return Some("pyspark is not installed (python3 -m pip install pyspark)".into());
    }
    None
}

#[test]
fn the_spark_driver_builds_the_single_run_library() {
    if let Some(why) = spark_missing() {
        // .ci/run installs both: there, a missing engine is a failure.
        crate::util::skip_or_fail("the_spark_driver_builds_the_single_run_library", &why);
        return;
    }
    let inputs = fixture_inputs();
    let d = tmp();
    let single = d.path().join("single");
    build_cli(&inputs, &single, &["--joints"]);
    let lib = d.path().join("spark-lib");
    let o = std::process::Command::new("python3")
        .arg(root().join("pipelines/spark/stancelib_spark.py"))
        .args(["--master", "local[2]", "--shards", "3", "--stancelib"])
        .arg(env!("CARGO_BIN_EXE_stancelib"))
        .arg("--out")
        .arg(&lib)
        .arg(root().join("fixtures/bvh"))
        .args(["--", "--joints"])
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&o.stderr);
    // Exit 1: the malformed fixtures fail, as in the single build.
    assert_eq!(o.status.code(), Some(1), "{err}");
    assert_same_library(&single, &lib);
    // The shard libraries are removed after the merge; nothing else is left beside it.
    let mut left = files_of(d.path());
    left.sort();
    assert_eq!(left, vec!["single", "spark-lib"]);
}

#[test]
fn the_spark_driver_names_a_failed_shard_and_writes_nothing() {
    if let Some(why) = spark_missing() {
        // .ci/run installs both: there, a missing engine is a failure.
        crate::util::skip_or_fail(
            "the_spark_driver_names_a_failed_shard_and_writes_nothing",
            &why,
        );
        return;
    }
    let d = tmp();
    let lib = d.path().join("lib");
    // A bad build option: every shard's build exits 2 before any work.
    let o = std::process::Command::new("python3")
        .arg(root().join("pipelines/spark/stancelib_spark.py"))
        .args(["--master", "local[1]", "--shards", "2", "--stancelib"])
        .arg(env!("CARGO_BIN_EXE_stancelib"))
        .arg("--out")
        .arg(&lib)
        .arg(root().join("fixtures/bvh"))
        .args(["--", "--mass=-1"])
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert!(
        err.contains("shard 1/2 failed") && err.contains("--mass"),
        "{err}"
    );
    assert!(!lib.exists());
}

#[test]
fn an_incremental_shard_rebuilds_only_its_missing_clips() {
    let inputs = fixture_inputs();
    let d = tmp();
    let (part, full) = (d.path().join("part"), d.path().join("full"));
    // The first run saw only some of the inputs (a crash, or files that came later): all
    // but the last good clip of shard 1/2, chosen by shard rather than by position so that
    // the first run holds a good clip of the shard whatever the fixtures' content hashes.
    let bad = root().join("fixtures/bvh/bad");
    let good_in_shard: Vec<&PathBuf> = inputs
        .iter()
        .filter(|p| !p.starts_with(&bad) && stancelib::pipeline::engine::shard::shard_of(p, 2) == 1)
        .collect();
    assert!(good_in_shard.len() >= 2, "{good_in_shard:?}");
    let late = good_in_shard[good_in_shard.len() - 1].clone();
    let few: Vec<PathBuf> = inputs.iter().filter(|p| **p != late).cloned().collect();
    let first = |p: &Path| -> Vec<String> {
        stable_manifest(&p.join("manifest.json"))["inputs"]
            .as_object()
            .unwrap()
            .keys()
            .cloned()
            .collect()
    };
    build_cli(&few, &part, &["--shard", "1/2"]);
    let had = first(&part).len();
    let mut args: Vec<String> = vec!["build".into()];
    args.extend(inputs.iter().map(|p| s(p)));
    args.extend(["--out", &s(&part), "--shard", "1/2", "--incremental"].map(String::from));
    let argv: Vec<&str> = args.iter().map(String::as_str).collect();
    let (code, out, err) = stancelib(&argv);
    assert!(code <= 1, "{err}");
    // Reused: the clips of the first run that did not fail (failed ones are retried).
    let reused: usize = out
        .split(" clips reused")
        .next()
        .and_then(|t| t.rsplit(' ').next())
        .and_then(|n| n.parse().ok())
        .unwrap_or_else(|| panic!("{out}"));
    assert!(reused > 0 && reused <= had, "{out}");
    build_cli(&inputs, &full, &["--shard", "1/2"]);
    assert_same_library(&full, &part);
}

// See: issue 16 item 1 — "the per-character reductions (limits …) run on compact
// per-character summaries": a build folds each clip's stance facts into one entry per mass
// and support (`stances::limits::group_facts`); the limits it writes in the manifest are
// those recomputed from every stance of the library (`query::limits::absolute_limits`,
// one fact a stance), bit for bit.
#[test]
fn the_manifest_limits_are_those_of_every_stance() {
    let lib = super::util::fixture_library();
    let library = stancelib::library::readers::read::open_library(lib).unwrap();
    let every = stancelib::query::limits::absolute_limits(&library);
    let manifest: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(lib.join("manifest.json")).unwrap()).unwrap();
    let written = manifest["limits"].as_object().expect("manifest limits");
    assert!(!written.is_empty());
    assert_eq!(written.len(), every.len());
    for (id, w) in written {
        let e = &every[id];
        for (key, value) in [
            ("f_max_n", e.f_max),
            ("chi_min_m", e.chi_min),
            ("chi_max_m", e.chi_max),
            ("mu", e.mu),
        ] {
            let got = w[key].as_f64().unwrap();
            assert_eq!(
                got.to_bits(),
                value.to_bits(),
                "{id} {key}: {got} vs {value}"
            );
        }
    }
}
