//! Issue 40 ("Trust nothing read back"), items 1, 4 and 7: what `build --incremental` and
//! `merge` take from a library they did not just write is checked against the manifest's
//! content hashes and rows per clip first, and `frames` never writes into a library.
//!
//! Every attack here is the audit's: a table copied in from another library (or from one
//! built with `--mass 80` under a 70 kg manifest), a flipped bit, a 4 KB zero block, a
//! shard holding another shard's table. The incremental build then rebuilds and says why,
//! equal byte for byte to a full build; the merge refuses, naming shard and table, with
//! the previous library intact.

use std::path::{Path, PathBuf};

use crate::util::{fixture_clips, s, snapshot, stable_manifest, stancelib};

/// The fixtures split: the library's clips and another library's.
fn clip_sets() -> (Vec<String>, Vec<String>) {
    let all = fixture_clips();
    (all[..3].to_vec(), all[3..].to_vec())
}

/// `build clips --out out extra…`: (exit code, stdout, stderr).
fn build(clips: &[String], out: &Path, extra: &[&str]) -> (i32, String, String) {
    let o = s(out);
    let mut args: Vec<&str> = vec!["build"];
    args.extend(clips.iter().map(String::as_str));
    args.extend(["--out", &o]);
    args.extend(extra);
    stancelib(&args)
}

/// A library built at `out` (must succeed).
fn built(clips: &[String], out: &Path, extra: &[&str]) -> PathBuf {
    let (code, _, err) = build(clips, out, extra);
    assert!(code <= 1, "build {extra:?}: exit {code}\n{err}");
    out.to_path_buf()
}

/// Two libraries hold the same files, byte for byte (manifests without the volatile keys).
fn assert_same_library(got: &Path, want: &Path) {
    let (g, w) = (snapshot(got), snapshot(want));
    assert_eq!(
        g.keys().collect::<Vec<_>>(),
        w.keys().collect::<Vec<_>>(),
        "files of {}",
        got.display()
    );
    for (rel, bytes) in &w {
        if rel == Path::new("manifest.json") {
            assert_eq!(
                stable_manifest(&got.join(rel)),
                stable_manifest(&want.join(rel))
            );
        } else {
            assert!(
                g[rel] == *bytes,
                "{} differs from a full build",
                rel.display()
            );
        }
    }
}

/// `dir` copied to `to` (files only, one level: a `file` layout library).
fn copy_library(dir: &Path, to: &Path) {
    std::fs::create_dir_all(to).unwrap();
    for e in std::fs::read_dir(dir).unwrap() {
        let p = e.unwrap().path();
        std::fs::copy(&p, to.join(p.file_name().unwrap())).unwrap();
    }
}

/// Libraries of the same three clips at 70 kg (the default) and at 80 kg, and one of two
/// other clips, built once per test binary.
struct Sources {
    _dir: tempfile::TempDir,
    lib: PathBuf,
    heavy: PathBuf,
    other: PathBuf,
}

fn sources() -> &'static Sources {
    static S: std::sync::OnceLock<Sources> = std::sync::OnceLock::new();
    S.get_or_init(|| {
        let dir = tempfile::tempdir().unwrap();
        let (mine, theirs) = clip_sets();
        Sources {
            lib: built(&mine, &dir.path().join("lib"), &[]),
            heavy: built(&mine, &dir.path().join("heavy"), &["--mass", "80"]),
            other: built(&theirs, &dir.path().join("other"), &[]),
            _dir: dir,
        }
    })
}

/// A copy of the library with `damage` done to it, built again with `--incremental`:
/// nothing reused, a line saying why naming `needle`, and the library equal to a full
/// build.
fn rebuilt_after(damage: impl FnOnce(&Path), needle: &str) {
    let src = sources();
    let d = tempfile::tempdir().unwrap();
    let lib = d.path().join("lib");
    copy_library(&src.lib, &lib);
    damage(&lib);
    let (code, out, err) = build(&clip_sets().0, &lib, &["--incremental", "--json"]);
    assert_eq!(code, 0, "{err}");
    let summary: serde_json::Value = serde_json::from_str(out.trim()).unwrap();
    assert_eq!(summary["clips_reused"], 0, "{out}\n{err}");
    let line = err
        .lines()
        .find(|l| l.starts_with("incremental: "))
        .unwrap_or_else(|| panic!("no line saying why:\n{err}"));
    assert!(
        line.contains(needle) && line.contains("every clip is rebuilt"),
        "{line}"
    );
    assert_eq!(summary["reuse_refused"][0], line["incremental: ".len()..]);
    assert_same_library(&lib, &src.lib);
}

// See: issue 40 item 1 — another library's stances.parquet copied in: exit 0,
// "clips_reused": 3, and a library of 0 stances.
#[test]
fn incremental_rebuilds_another_librarys_stances_copied_in() {
    let other = sources().other.join("stances.parquet");
    rebuilt_after(
        |lib| {
            std::fs::copy(&other, lib.join("stances.parquet")).unwrap();
        },
        "stances.parquet is not the file that was written",
    );
}

// See: issue 40 item 1 — the stances of a --mass 80 library under a manifest that says
// 70 kg; and the same for contacts and frames.
#[test]
fn incremental_rebuilds_mass_80_tables_under_a_70_kg_manifest() {
    for table in ["stances.parquet", "contacts.parquet", "frames.parquet"] {
        let heavy = sources().heavy.join(table);
        rebuilt_after(
            |lib| {
                std::fs::copy(&heavy, lib.join(table)).unwrap();
            },
            &format!("{table} is not the file that was written"),
        );
    }
}

// See: issue 40 item 1 — the same for another library's contacts and frames.
#[test]
fn incremental_rebuilds_another_librarys_contacts_and_frames_copied_in() {
    for table in ["contacts.parquet", "frames.parquet", "clips.parquet"] {
        let other = sources().other.join(table);
        rebuilt_after(
            |lib| {
                std::fs::copy(&other, lib.join(table)).unwrap();
            },
            table,
        );
    }
}

// See: issue 40 item 1 — bit flips inside a reused table persisted.
#[test]
fn incremental_rebuilds_a_table_with_a_flipped_bit() {
    for table in ["frames.parquet", "stances.parquet", "errors.parquet"] {
        rebuilt_after(
            |lib| {
                let p = lib.join(table);
                let mut b = std::fs::read(&p).unwrap();
                let k = b.len() / 2;
                b[k] ^= 0x04;
                std::fs::write(&p, b).unwrap();
            },
            &format!("{table} is not the file that was written"),
        );
    }
}

// A library written before the hashes were recorded is rebuilt whole, once.
#[test]
fn incremental_rebuilds_a_library_without_content_hashes() {
    rebuilt_after(
        |lib| {
            let p = lib.join("manifest.json");
            let mut m: serde_json::Value =
                serde_json::from_str(&std::fs::read_to_string(&p).unwrap()).unwrap();
            m.as_object_mut().unwrap().remove("tables");
            std::fs::write(&p, serde_json::to_string_pretty(&m).unwrap()).unwrap();
        },
        "records no content hashes",
    );
}

/// The library's manifest with its `source_digest` set to `digest` (removed if `None`).
fn set_source_digest(lib: &Path, digest: Option<&str>) {
    let p = lib.join("manifest.json");
    let mut m: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&p).unwrap()).unwrap();
    let o = m.as_object_mut().unwrap();
    assert!(
        o["source_digest"].as_str().is_some_and(|d| d.len() == 64),
        "a build records its 64-hex source digest: {:?}",
        o.get("source_digest")
    );
    match digest {
        Some(d) => o.insert("source_digest".into(), d.into()),
        None => o.remove("source_digest"),
    };
    std::fs::write(&p, serde_json::to_string_pretty(&m).unwrap()).unwrap();
}

// A library written by other code (its rows computed by another COM, say) is not this
// build's: before the source digest, its rows were reused because the options and the
// clips' bytes were the same.
#[test]
fn incremental_rebuilds_a_library_written_by_another_build() {
    rebuilt_after(
        |lib| set_source_digest(lib, Some(&"0".repeat(64))),
        "written by another build of stancelib (source digest 000000000000",
    );
    rebuilt_after(
        |lib| set_source_digest(lib, None),
        "written by another build of stancelib (source digest none",
    );
}

// A clip whose rows are not as many as the manifest records is rebuilt on its own, the
// other clips reused.
#[test]
fn incremental_rebuilds_only_the_clip_whose_rows_do_not_match() {
    let src = sources();
    let d = tempfile::tempdir().unwrap();
    let lib = d.path().join("lib");
    copy_library(&src.lib, &lib);
    let p = lib.join("manifest.json");
    let mut m: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&p).unwrap()).unwrap();
    let rows = m["clip_rows"].as_object_mut().unwrap();
    let (clip, tables) = rows.iter_mut().next().unwrap();
    let clip = clip.clone();
    let frames = tables["frames"].as_u64().unwrap();
    tables["frames"] = (frames + 1).into();
    std::fs::write(&p, serde_json::to_string_pretty(&m).unwrap()).unwrap();
    let (code, out, err) = build(&clip_sets().0, &lib, &["--incremental", "--json"]);
    assert_eq!(code, 0, "{err}");
    let summary: serde_json::Value = serde_json::from_str(out.trim()).unwrap();
    assert_eq!(summary["clips_reused"], 2, "{out}\n{err}");
    let want = format!(
        "frames holds {frames} rows of clip {clip}, manifest.json records {}",
        frames + 1
    );
    assert!(err.contains(&want), "{err}");
    assert_same_library(&lib, &src.lib);
}

/// The fixtures as shards 1/2 and 2/2, and their merge at `merged` (the previous library
/// of the refusal tests).
fn two_shards(d: &Path) -> (PathBuf, PathBuf, PathBuf) {
    let all = fixture_clips();
    let (a, b) = (d.join("a"), d.join("b"));
    built(&all, &a, &["--shard", "1/2"]);
    built(&all, &b, &["--shard", "2/2"]);
    let merged = d.join("merged");
    let (code, _, err) = stancelib(&["merge", &s(&a), &s(&b), "--out", &s(&merged)]);
    assert!(code <= 1, "{err}");
    (a, b, merged)
}

/// `merge a b --out merged` after `damage` to shard `a` (of two shards of the fixtures):
/// exit 2, the error naming shard `a` and `table`, and the previous library untouched.
fn merge_refused_after(damage: impl FnOnce(&Path, &Path), table: &str) {
    let d = tempfile::tempdir().unwrap();
    let (a, b, merged) = two_shards(d.path());
    let before = snapshot(&merged);
    damage(&a, &b);
    let (code, out, err) = stancelib(&["merge", &s(&a), &s(&b), "--out", &s(&merged)]);
    assert_eq!(code, 2, "{out}\n{err}");
    assert!(
        err.contains(&s(&a)) && err.contains(table),
        "the error names neither the shard nor {table}:\n{err}"
    );
    assert!(snapshot(&merged) == before, "the previous library changed");
}

// See: issue 40 item 4 — a 4 KB zero block in one shard's frames.parquet: exit 0, an
// undecodable merged table, the previous library replaced.
#[test]
fn merge_refuses_a_zero_block_in_a_shards_frames() {
    merge_refused_after(
        |a, _| {
            let p = a.join("frames.parquet");
            let mut bytes = std::fs::read(&p).unwrap();
            let at = bytes.len() / 3;
            let end = (at + 4096).min(bytes.len() - 8);
            bytes[at..end].fill(0);
            std::fs::write(&p, bytes).unwrap();
        },
        "frames.parquet",
    );
}

// See: issue 40 item 4 — a shard holding another shard's stances.parquet: 197 duplicate
// stance ids.
#[test]
fn merge_refuses_a_shard_holding_another_shards_stances() {
    merge_refused_after(
        |a, b| {
            std::fs::copy(b.join("stances.parquet"), a.join("stances.parquet")).unwrap();
        },
        "stances.parquet",
    );
}

// See: issue 40 item 4 — another library's stances in a shard: 336 stances silently
// dropped.
#[test]
fn merge_refuses_another_librarys_stances_in_a_shard() {
    let other = sources().other.join("stances.parquet");
    merge_refused_after(
        |a, _| {
            std::fs::copy(&other, a.join("stances.parquet")).unwrap();
        },
        "stances.parquet",
    );
}

// Behind the hashes: a shard whose manifest was rewritten to match a foreign table (its
// hashes recomputed) is still refused by the row checks: its rows belong to clips of the
// other shard.
#[test]
fn merge_refuses_rows_of_another_shards_clips_even_with_matching_hashes() {
    merge_refused_after(
        |a, b| {
            std::fs::copy(b.join("contacts.parquet"), a.join("contacts.parquet")).unwrap();
            crate::util::reseal(a);
        },
        "contacts.parquet holds rows of clip",
    );
}

// See: issue 40 item 7 — `frames --out LIB` on a library replaced its frames, clips and
// contacts (the library then held 3 clips and 1,071 stances of other clips).
#[test]
fn frames_refuses_to_write_into_a_library() {
    let d = tempfile::tempdir().unwrap();
    let lib = d.path().join("lib");
    copy_library(&sources().lib, &lib);
    let before = snapshot(&lib);
    let (_, theirs) = clip_sets();
    let mut args: Vec<&str> = vec!["frames"];
    args.extend(theirs.iter().map(String::as_str));
    let o = s(&lib);
    args.extend(["--out", &o]);
    let (code, out, err) = stancelib(&args);
    assert_eq!(code, 2, "{out}\n{err}");
    assert!(err.contains("holds a stancelib library"), "{err}");
    assert!(snapshot(&lib) == before, "the library changed");
    // A folder of `frames` tables is still written into.
    let tables = d.path().join("tables");
    let o = s(&tables);
    args.pop();
    args.push(&o);
    assert_eq!(stancelib(&args).0, 0);
    assert_eq!(
        stancelib(&args).0,
        0,
        "a second `frames` into its own folder"
    );
}

// See: `library::codec::schema::ADDED_COLUMNS` — a library written before `clips.parquet` had
// `reach_m` (issue 37's jump limits) is read as it is, and an incremental build over it
// keeps its clips (their reach null) and adds the new clips with theirs; the jump query
// answers on it, with the old limit for the clips without a reach.
#[test]
fn a_library_written_before_reach_m_is_read_and_grows() {
    use polars::prelude::*;
    let src = sources();
    let d = tempfile::tempdir().unwrap();
    let lib = d.path().join("lib");
    copy_library(&src.lib, &lib);
    // The clips table as a library before the column wrote it, and its manifest entry.
    let clips = lib.join("clips.parquet");
    let mut df = stancelib::library::codec::table::read_parquet(&clips)
        .unwrap()
        .drop("reach_m")
        .unwrap();
    ParquetWriter::new(std::fs::File::create(&clips).unwrap())
        .finish(&mut df)
        .unwrap();
    let bytes = std::fs::read(&clips).unwrap();
    let p = lib.join("manifest.json");
    let mut m: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&p).unwrap()).unwrap();
    let entry = &mut m["tables"]["clips.parquet"];
    entry["bytes"] = bytes.len().into();
    entry["sha256"] = stancelib::pipeline::engine::inputs::file_sha256(&clips)
        .unwrap()
        .into();
    std::fs::write(&p, serde_json::to_string_pretty(&m).unwrap()).unwrap();

    let q = d.path().join("jumps.parquet");
    let (code, _, err) = stancelib(&[
        "query",
        "jump",
        "--lib",
        &s(&lib),
        "--height-scale",
        "1.1",
        "--out",
        &s(&q),
    ]);
    assert_eq!(code, 0, "query jump on a library without reach_m: {err}");

    let (mine, theirs) = clip_sets();
    let all: Vec<String> = mine.iter().chain(&theirs).cloned().collect();
    let (code, out, err) = build(&all, &lib, &["--incremental", "--json"]);
    assert_eq!(code, 0, "{err}");
    let summary: serde_json::Value = serde_json::from_str(out.trim()).unwrap();
    assert_eq!(summary["clips_reused"], mine.len(), "{out}\n{err}");
    let t = stancelib::library::codec::table::read_parquet(&clips).unwrap();
    let reach = t.column("reach_m").unwrap().f64().unwrap().clone();
    let nulls = reach.null_count();
    assert_eq!(nulls, mine.len(), "the kept clips have no reach: {reach:?}");
    assert!(
        reach.iter().flatten().all(|r| (0.5..2.0).contains(&r)),
        "a new clip's reach is a body's"
    );
}
