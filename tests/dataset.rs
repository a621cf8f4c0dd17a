//! Issue 16 item 3: `--layout dataset` — every table a hive-partitioned Parquet dataset.
//! The queries give the same outputs on both layouts; DuckDB, pyarrow, polars and Spark
//! read a character's partition and get exactly the file layout's rows for it.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::process::Command;

use polars::prelude::*;
use stancelib::library::codec::schema::{
    CLIPS_FILE, DATASET_PART_FILE, FRAMES_FILE, INPUTS_KEY, KINEMATICS_FILE, LIBRARY_MANIFEST_KEY,
    LIBRARY_PATH_KEY, LIMITS_KEY, OPTIONS_KEY, STANCES_FILE, TABLE_FILES,
};
use stancelib::library::storage::layout::{read_table, table_name};

use crate::util::{files_below, fixture_clips, fixture_library, ok, s};

/// A library of the fixture clips in `layout` at `out`.
fn build(out: &Path, layout: &str) {
    let clips = fixture_clips();
    let mut args = vec!["build"];
    args.extend(clips.iter().map(String::as_str));
    let o = s(out);
    args.extend(["--out", &o, "--layout", layout]);
    ok(&args);
}

/// `query run`, `query jump`, `map jumps` and `twopac --clip --lib` on `lib`, into `out`.
fn queries(lib: &Path, out: &Path) {
    let (l, o) = (s(lib), |n: &str| s(&out.join(n)));
    ok(&[
        "query",
        "run",
        "--lib",
        &l,
        "--speeds",
        "0:6:0.5",
        "--out",
        &o("runs.parquet"),
    ]);
    ok(&[
        "query",
        "jump",
        "--lib",
        &l,
        "--height",
        "0.3",
        "--distance=1.0",
        "--out",
        &o("jump.parquet"),
    ]);
    ok(&["map", "jumps", "--lib", &l, "--out", &o("map")]);
    let clip = s(&crate::util::root().join("fixtures/bvh/run_120hz_m_yup.bvh"));
    ok(&[
        "twopac",
        "--clip",
        &clip,
        "--lib",
        &l,
        "--out",
        &o("twopac"),
    ]);
}

/// The key-value metadata of a Parquet file (its footer), `ARROW:schema` left out (it
/// encodes the same pairs).
fn kv(path: &Path) -> BTreeMap<String, String> {
    let mut kv = crate::util::parquet_kv(path);
    kv.remove("ARROW:schema");
    kv
}

fn frame(path: &Path) -> DataFrame {
    ParquetReader::new(std::fs::File::open(path).unwrap())
        .finish()
        .unwrap()
}

/// The text of `path` with every string naming its library (`lib`, its manifest hash)
/// replaced by a placeholder.
fn neutral(text: &str, lib: &Path) -> String {
    let sha = stancelib::library::codec::provenance::manifest_sha256(lib).unwrap();
    text.replace(&s(lib), "<lib>").replace(&sha, "<manifest>")
}

/// `a` and `b` (outputs of the same command on libraries `la` and `lb`) are the same:
/// tables by columns, types, values and metadata (the library path and manifest hash
/// aside), JSON and text as text with those two replaced, anything else byte for byte.
fn assert_same_output(a: &Path, la: &Path, b: &Path, lb: &Path) {
    let ext = a.extension().and_then(|e| e.to_str()).unwrap_or("");
    match ext {
        "parquet" => {
            let (fa, fb) = (frame(a), frame(b));
            assert!(fa.equals_missing(&fb), "{}: rows differ", a.display());
            let strip = |m: BTreeMap<String, String>, lib: &Path| -> BTreeMap<String, String> {
                m.into_iter()
                    .filter(|(k, _)| k != LIBRARY_MANIFEST_KEY && k != LIBRARY_PATH_KEY)
                    .map(|(k, v)| (k, neutral(&v, lib)))
                    .collect()
            };
            assert_eq!(strip(kv(a), la), strip(kv(b), lb), "{}", a.display());
        }
        "json" | "txt" | "csv" => {
            let (ta, tb) = (
                std::fs::read_to_string(a).unwrap(),
                std::fs::read_to_string(b).unwrap(),
            );
            assert_eq!(neutral(&ta, la), neutral(&tb, lb), "{}", a.display());
        }
        _ => assert!(
            std::fs::read(a).unwrap() == std::fs::read(b).unwrap(),
            "{}: bytes differ",
            a.display()
        ),
    }
}

#[test]
fn both_layouts_give_the_same_tables_and_query_outputs() {
    let d = tempfile::tempdir().unwrap();
    let file_lib = fixture_library();
    let ds = d.path().join("ds");
    build(&ds, "dataset");
    let m: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(ds.join("manifest.json")).unwrap()).unwrap();
    assert_eq!(m["layout"], "dataset");
    // `info` reads either layout and says which (same counts as the file library).
    let info = |lib: &Path| -> serde_json::Value {
        serde_json::from_str(ok(&["info", lib.to_str().unwrap(), "--json"]).trim()).unwrap()
    };
    let (fi, di) = (info(file_lib), info(&ds));
    assert_eq!(
        (fi["layout"].as_str(), di["layout"].as_str()),
        (Some("file"), Some("dataset"))
    );
    assert_eq!(fi["stances_by_label"], di["stances_by_label"]);
    assert_eq!(fi["clips_by_character"], di["clips_by_character"]);
    // The layout on disk: partitioned tables by character, the others one file each.
    let chars = read_table(file_lib, STANCES_FILE).unwrap();
    let id = chars.column("character_id").unwrap().str().unwrap().get(0);
    let id = id.unwrap().to_string();
    let part = |f: &str| ds.join(table_name(f)).join(format!("character_id={id}"));
    for f in [STANCES_FILE, CLIPS_FILE, KINEMATICS_FILE] {
        assert!(part(f).join(DATASET_PART_FILE).is_file(), "{f}");
    }
    assert!(ds.join("frames").join(DATASET_PART_FILE).is_file());
    for f in TABLE_FILES {
        assert!(!ds.join(f).exists(), "{f} left in the dataset library");
        if file_lib.join(f).is_file() {
            let (a, b) = (
                read_table(file_lib, f).unwrap(),
                read_table(&ds, f).unwrap(),
            );
            assert!(a.equals_missing(&b), "{f}: rows differ between layouts");
        }
    }
    // The partition files carry the table's metadata but the library-wide entries (input
    // hashes, limits: in the manifest), which would be repeated in every partition.
    let mut want = kv(&file_lib.join(STANCES_FILE));
    want.retain(|k, _| k != INPUTS_KEY && k != LIMITS_KEY);
    assert!(want.contains_key(OPTIONS_KEY), "{want:?}");
    assert_eq!(want, kv(&part(STANCES_FILE).join(DATASET_PART_FILE)));
    let (qa, qb) = (d.path().join("qa"), d.path().join("qb"));
    queries(file_lib, &qa);
    queries(&ds, &qb);
    let (fa, fb) = (files_below(&qa), files_below(&qb));
    assert_eq!(fa, fb, "different output files");
    assert!(fa.len() >= 6, "{fa:?}");
    for rel in &fa {
        if rel.to_string_lossy().contains("timing") {
            continue; // wall times only
        }
        assert_same_output(&qa.join(rel), file_lib, &qb.join(rel), &ds);
    }
}

#[test]
fn a_merge_and_an_incremental_build_read_dataset_libraries() {
    let d = tempfile::tempdir().unwrap();
    let clips = fixture_clips();
    let shard = |i: usize, layout: &str| -> PathBuf {
        let out = d.path().join(format!("s{i}"));
        let mut args = vec!["build"];
        args.extend(clips.iter().map(String::as_str));
        let (o, sh) = (s(&out), format!("{i}/2"));
        args.extend(["--out", &o, "--shard", &sh, "--layout", layout]);
        ok(&args);
        out
    };
    // Shards of both layouts merge into a file library equal to the single build.
    let (s1, s2) = (shard(1, "dataset"), shard(2, "file"));
    let merged = d.path().join("merged");
    ok(&["merge", &s(&s1), &s(&s2), "--out", &s(&merged)]);
    let single = fixture_library();
    for f in TABLE_FILES {
        let a = single.join(f);
        if a.is_file() {
            assert!(
                std::fs::read(&a).unwrap() == std::fs::read(merged.join(f)).unwrap(),
                "{f}: merge of dataset shards differs from the single build"
            );
        }
    }
    // An incremental rebuild of a dataset library reuses every clip, same rows.
    let ds = d.path().join("ds");
    build(&ds, "dataset");
    let mut args = vec!["build"];
    args.extend(clips.iter().map(String::as_str));
    let o = s(&ds);
    args.extend(["--out", &o, "--layout", "dataset", "--incremental"]);
    let printed = ok(&args);
    let m: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(ds.join("manifest.json")).unwrap()).unwrap();
    assert_eq!(m["layout"], "dataset", "{printed}");
    for f in [FRAMES_FILE, STANCES_FILE, CLIPS_FILE] {
        let (a, b) = (read_table(single, f).unwrap(), read_table(&ds, f).unwrap());
        assert!(a.equals_missing(&b), "{f}: incremental dataset rows differ");
    }
}

fn python_has(modules: &str) -> bool {
    Command::new("python3")
        .args(["-c", &format!("import {modules}")])
        .output()
        .is_ok_and(|o| o.status.success())
}

/// The script run by [`foreign_readers_read_one_character`]: every reader's rows of one
/// character equal the file layout's (pyarrow on `stances.parquet` filtered), partition
/// pruning shown by DuckDB's plan (one file scanned) and pyarrow's fragments.
const READERS_PY: &str = r#"
import sys, pyarrow.parquet as pq, pyarrow.dataset as ds, pyarrow.compute as pc
file_lib, ds_lib, cid, spark = sys.argv[1], sys.argv[2], sys.argv[3], sys.argv[4] == "1"
want = pq.read_table(file_lib + "/stances.parquet")
want = want.filter(pc.equal(want["character_id"], cid)).to_pylist()
assert len(want) > 0
glob = ds_lib + "/stances/*/*.parquet"
import duckdb
con = duckdb.connect()
q = f"select * from read_parquet('{glob}', hive_partitioning=true) where character_id = '{cid}'"
rel = con.sql(q)
got = [dict(zip(rel.columns, r)) for r in rel.fetchall()]
assert got == want, ("duckdb", len(got), len(want))
plan = "\n".join(r[1] for r in con.sql("explain analyze " + q).fetchall())
n_parts = len(ds.dataset(ds_lib + "/stances", format="parquet", partitioning="hive").files)
assert "Total Files Read: 1" in plan or n_parts == 1, plan
d = ds.dataset(ds_lib + "/stances", format="parquet", partitioning="hive")
f = ds.field("character_id") == cid
assert len(list(d.get_fragments(filter=f))) == 1
got = d.to_table(filter=f).to_pylist()
assert got == want, ("pyarrow", len(got), len(want))
import polars as pl
got = pl.scan_parquet(glob, hive_partitioning=True).filter(pl.col("character_id") == cid)
got = got.collect().to_arrow().to_pylist()
assert got == want, ("polars", len(got), len(want))
readers = "duckdb pyarrow polars"
if spark:
    from pyspark.sql import SparkSession
    sp = SparkSession.builder.master("local[1]").config("spark.ui.enabled", "false").getOrCreate()
    sp.sparkContext.setLogLevel("ERROR")
    rows = sp.read.parquet(ds_lib + "/stances").where(f"character_id = '{cid}'")
    assert rows.count() == len(want), ("spark", rows.count(), len(want))
    assert rows.columns == list(want[0].keys()), rows.columns
    sids = [r["stance_id"] for r in rows.orderBy("stance_id").collect()]
    assert sids == sorted(w["stance_id"] for w in want), "spark"
    sp.stop()
    readers += " spark"
print("ok", readers, len(want), n_parts)
"#;

/// Partitions of several characters when the shared bulk set is there, else the fixtures'
/// one character.
#[test]
fn foreign_readers_read_one_character() {
    if !python_has("pyarrow, duckdb, polars") {
        crate::util::skip_or_fail(
            "foreign_readers_read_one_character",
            "python3 with pyarrow, duckdb and polars not found (.ci/run installs them)",
        );
        return;
    }
    let d = tempfile::tempdir().unwrap();
    let (file_lib, ds) = (d.path().join("file"), d.path().join("ds"));
    let bulk = crate::util::shared_data().map(|p| p.join("bvh-bulk/cmu"));
    let inputs: Vec<String> = match bulk.filter(|p| p.is_dir()) {
        Some(p) => vec![s(&p)],
        None => fixture_clips(),
    };
    for (out, layout) in [(&file_lib, "file"), (&ds, "dataset")] {
        let mut args: Vec<&str> = vec!["build"];
        args.extend(inputs.iter().map(String::as_str));
        let o = s(out);
        args.extend(["--out", &o, "--layout", layout]);
        ok(&args);
    }
    let st = read_table(&file_lib, STANCES_FILE).unwrap();
    let ids = st.column("character_id").unwrap().str().unwrap().clone();
    // The character with the most stances (ties by id).
    let mut counts: BTreeMap<String, usize> = BTreeMap::new();
    for v in ids.iter().flatten() {
        *counts.entry(v.to_string()).or_default() += 1;
    }
    let (cid, _) = counts
        .iter()
        .max_by_key(|(k, n)| (**n, std::cmp::Reverse(*k)))
        .unwrap();
    let spark = python_has("pyspark")
        && Command::new("java")
            .arg("-version")
            .output()
            .is_ok_and(|o| o.status.success());
    if !spark {
        crate::util::skip_or_fail(
            "foreign_readers_read_one_character (Spark part)",
            "pyspark or java not found (.ci/run installs pyspark)",
        );
    }
    let o = Command::new("python3")
        .args(["-c", READERS_PY, &s(&file_lib), &s(&ds), cid])
        .arg(if spark { "1" } else { "0" })
        .output()
        .unwrap();
    let (out, err) = (
        String::from_utf8_lossy(&o.stdout),
        String::from_utf8_lossy(&o.stderr),
    );
    assert!(o.status.success(), "{out}\n{err}");
    eprintln!("{} characters; {out}", counts.len());
}
