//! Issue 16 items 1–2, memory: the kinematic samples of a build wait in a scratch file
//! inside the library's temporary folder instead of in memory, and a merge reads the
//! shards' samples a row group at a time. The outputs stay byte for byte those of a
//! single in-memory build.

use std::path::Path;

use super::scale::{assert_same_library, build_cli, real_subset, shard_and_merge};
use super::util::{root, s};

/// Rows of a Parquet file (from its footer).
fn rows(path: &Path) -> usize {
    use polars::prelude::*;
    let mut r = ParquetReader::new(std::fs::File::open(path).unwrap());
    r.get_metadata().unwrap().num_rows
}

/// Every entry of `dir` and below whose name starts with a dot (scratch names).
fn hidden(dir: &Path) -> Vec<String> {
    let mut out = Vec::new();
    for e in std::fs::read_dir(dir).unwrap() {
        let e = e.unwrap();
        let name = e.file_name().to_string_lossy().into_owned();
        if name.starts_with('.') {
            out.push(s(&e.path()));
        }
        if e.path().is_dir() {
            out.extend(hidden(&e.path()));
        }
    }
    out
}

// See: issue 16 item 1 — the polytope stage held every contact frame's COM in memory
// until the end of the build; the samples now wait in a scratch file that must not
// survive into the library (nor beside it) once the build is done.
#[test]
fn the_sample_scratch_file_never_survives_the_build() {
    let d = tempfile::tempdir().unwrap();
    let inputs = vec![root().join("fixtures/bvh")];
    let lib = d.path().join("lib");
    build_cli(&inputs, &lib, &[]);
    let shard = d.path().join("shard");
    build_cli(&inputs, &shard, &["--shard", "1/1"]);
    assert!(rows(&lib.join("kinematics_points.parquet")) > 0);
    assert!(rows(&shard.join("kinematics_samples.parquet")) > 0);
    assert_eq!(hidden(d.path()), Vec::<String>::new());
}

// See: issue 16 item 1 — a merge read every shard's samples table whole; it now spills
// it a row group at a time, so one clip's samples may arrive in two slices.
#[test]
fn shard_samples_over_several_row_groups_merge_to_the_single_build() {
    let test = "shard_samples_over_several_row_groups_merge_to_the_single_build";
    let Some(inputs) = real_subset(test, 32) else {
        return;
    };
    let d = tempfile::tempdir().unwrap();
    let single = d.path().join("single");
    build_cli(&inputs, &single, &[]);
    let merged = shard_and_merge(&inputs, &d.path().join("n1"), 1, &[]);
    let samples = rows(&d.path().join("n1/shard-1/kinematics_samples.parquet"));
    assert!(
        samples > stancelib::library::storage::stream::ROW_GROUP_ROWS,
        "the shard's samples fill more than one row group ({samples} rows)"
    );
    assert_same_library(&single, &merged);
    let merged2 = shard_and_merge(&inputs, &d.path().join("n2"), 2, &[]);
    assert_same_library(&single, &merged2);
}
