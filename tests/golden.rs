//! Golden outputs of the demo job (issue 13 item 5): `stancelib run pipelines/demo.toml`
//! on the bundled fixtures, compared with the committed copy in `fixtures/golden/demo/`.
//!
//! - Library Parquet files (`out/demo/*.parquet`): byte for byte.
//! - `manifest.json`: as JSON, without its volatile fields (build date, command line, wall
//!   times: `util::MANIFEST_VOLATILE_KEYS`), which the committed copy does not carry.
//! - Query outputs (`out/demo/queries/`): by content (polars frames: column names, types
//!   and values), since their key-value metadata names the manifest hash, which changes
//!   with the build date.
//!
//! A mismatch names the file and, where the tables can be read, the first differing column
//! and row. `UPDATE_GOLDEN=1 cargo test --test integration golden` (`make golden`) rewrites
//! the committed copy from the current build; review its diff before committing it.

use std::collections::BTreeSet;
use std::path::{Path, PathBuf};

use polars::prelude::*;

use crate::util::{files_below, root, stable_manifest, without_volatile, Demo};

/// The committed golden copy of `out/demo`.
fn golden_dir() -> PathBuf {
    root().join("fixtures/golden/demo")
}

/// `UPDATE_GOLDEN` set to anything but empty or `0`.
fn updating() -> bool {
    std::env::var_os("UPDATE_GOLDEN").is_some_and(|v| !v.is_empty() && v != "0")
}

/// How one output file is compared.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Kind {
    /// Every byte.
    Bytes,
    /// JSON without `util::MANIFEST_VOLATILE_KEYS`.
    Manifest,
    /// Table content, metadata excluded.
    Content,
}

fn kind(rel: &Path) -> Kind {
    if rel == Path::new("manifest.json") {
        Kind::Manifest
    } else if rel.extension().is_some_and(|e| e == "parquet") && rel.components().count() > 1 {
        Kind::Content
    } else {
        Kind::Bytes
    }
}

/// The compared files below `dir` (timing files excluded: they hold wall times only).
fn outputs_below(dir: &Path) -> BTreeSet<PathBuf> {
    files_below(dir)
        .into_iter()
        .filter(|p| !p.file_name().unwrap().to_string_lossy().contains("timing"))
        .collect()
}

fn read_frame(p: &Path) -> Result<DataFrame, String> {
    let f = std::fs::File::open(p).map_err(|e| format!("{}: {e}", p.display()))?;
    ParquetReader::new(f)
        .finish()
        .map_err(|e| format!("{}: {e}", p.display()))
}

/// The first difference between two frames (`None` if equal): names and types, height,
/// then the first column and row whose values differ (NaN equals NaN, null equals null).
fn first_difference(got: &DataFrame, want: &DataFrame) -> Option<String> {
    let (gn, wn) = (got.get_column_names(), want.get_column_names());
    if gn != wn {
        return Some(format!("columns {gn:?}, golden {wn:?}"));
    }
    if got.height() != want.height() {
        return Some(format!("{} rows, golden {}", got.height(), want.height()));
    }
    for (g, w) in got.columns().iter().zip(want.columns()) {
        if g.dtype() != w.dtype() {
            return Some(format!(
                "column {}: type {}, golden {}",
                g.name(),
                g.dtype(),
                w.dtype()
            ));
        }
        let same = |a: &Column, b: &Column| {
            a.as_materialized_series()
                .equals_missing(b.as_materialized_series())
        };
        if same(g, w) {
            continue;
        }
        let row = (0..got.height())
            .find(|&i| !same(&g.slice(i as i64, 1), &w.slice(i as i64, 1)))
            .unwrap_or(0);
        let (a, b) = (g.get(row).unwrap(), w.get(row).unwrap());
        return Some(format!("column {}, row {row}: {a}, golden {b}", g.name()));
    }
    None
}

/// `None` if `got` equals the golden file `want` under `kind`, else what differs.
fn compare(kind: Kind, got: &Path, want: &Path) -> Option<String> {
    match kind {
        Kind::Manifest => {
            let (g, w) = (stable_manifest(got), stable_manifest(want));
            (g != w).then(|| {
                let (g, w) = (
                    serde_json::to_string_pretty(&g).unwrap(),
                    serde_json::to_string_pretty(&w).unwrap(),
                );
                let line = g
                    .lines()
                    .zip(w.lines())
                    .position(|(a, b)| a != b)
                    .unwrap_or(g.lines().count().min(w.lines().count()));
                format!(
                    "differs at line {} of the stripped JSON: {:?}, golden {:?}",
                    line + 1,
                    g.lines().nth(line).unwrap_or("<end>"),
                    w.lines().nth(line).unwrap_or("<end>")
                )
            })
        }
        Kind::Bytes | Kind::Content => {
            if kind == Kind::Bytes && std::fs::read(got).unwrap() == std::fs::read(want).unwrap() {
                return None;
            }
            let is_table = got.extension().is_some_and(|e| e == "parquet");
            if !is_table {
                return Some("bytes differ".into());
            }
            match (read_frame(got), read_frame(want)) {
                (Ok(g), Ok(w)) => match (first_difference(&g, &w), kind) {
                    (Some(d), _) => Some(d),
                    (None, Kind::Bytes) => {
                        Some("bytes differ with equal content (encoding or metadata)".into())
                    }
                    (None, _) => None,
                },
                (g, w) => Some(format!(
                    "unreadable: {}",
                    [g.err(), w.err()]
                        .into_iter()
                        .flatten()
                        .collect::<Vec<_>>()
                        .join("; ")
                )),
            }
        }
    }
}

/// Replace the golden copy by `lib` (manifest stripped and pretty-printed).
fn write_golden(lib: &Path, files: &BTreeSet<PathBuf>) {
    let dir = golden_dir();
    if dir.exists() {
        std::fs::remove_dir_all(&dir).unwrap();
    }
    for rel in files {
        let to = dir.join(rel);
        std::fs::create_dir_all(to.parent().unwrap()).unwrap();
        if kind(rel) == Kind::Manifest {
            let text = serde_json::to_string_pretty(&stable_manifest(&lib.join(rel))).unwrap();
            std::fs::write(&to, text + "\n").unwrap();
        } else {
            std::fs::copy(lib.join(rel), &to).unwrap();
        }
    }
    eprintln!(
        "UPDATE_GOLDEN: wrote {} files to {}",
        files.len(),
        dir.display()
    );
}

#[test]
fn demo_outputs_equal_the_golden_copy() {
    let demo = Demo::build();
    let lib = demo.lib();
    let got = outputs_below(&lib);
    assert!(
        got.iter().any(|f| kind(f) == Kind::Content),
        "the demo wrote no query output: {got:?}"
    );
    if updating() {
        write_golden(&lib, &got);
    }
    let want = outputs_below(&golden_dir());
    let mut bad: Vec<String> = Vec::new();
    for rel in got.symmetric_difference(&want) {
        let side = if got.contains(rel) {
            "the golden copy"
        } else {
            "the demo's output"
        };
        bad.push(format!("{}: missing from {side}", rel.display()));
    }
    for rel in got.intersection(&want) {
        if let Some(d) = compare(kind(rel), &lib.join(rel), &golden_dir().join(rel)) {
            bad.push(format!("{} ({:?}): {d}", rel.display(), kind(rel)));
        }
    }
    assert!(
        bad.is_empty(),
        "the demo's outputs differ from fixtures/golden/demo/ (if on purpose: `make golden`, \
         then review the diff):\n  {}",
        bad.join("\n  ")
    );
}

#[test]
fn golden_comparison_names_the_first_differing_column_and_row() {
    // The comparator itself: equal frames (NaN and null included) pass, a changed value is
    // named by column and row, a changed type or height is named.
    let frame = |x: Vec<Option<f64>>, s: Vec<&str>| {
        DataFrame::new_infer_height(vec![Column::new("x".into(), x), Column::new("s".into(), s)])
            .unwrap()
    };
    let a = frame(vec![Some(1.0), Some(f64::NAN), None], vec!["a", "b", "c"]);
    assert_eq!(first_difference(&a, &a.clone()), None);
    let b = frame(vec![Some(1.0), Some(f64::NAN), None], vec!["a", "b", "d"]);
    let d = first_difference(&b, &a).expect("a changed string is a difference");
    assert!(d.contains("column s, row 2"), "{d}");
    let c = frame(vec![Some(1.0), Some(2.0), None], vec!["a", "b", "c"]);
    let d = first_difference(&c, &a).expect("NaN → 2.0 is a difference");
    assert!(d.contains("column x, row 1"), "{d}");
    let d = first_difference(&a.head(Some(2)), &a).expect("a row fewer is a difference");
    assert!(d.contains("2 rows, golden 3"), "{d}");
    let m = without_volatile(serde_json::json!({
        "created_utc": "2026", "clips": [{"wall_time_s": 1.0, "n": 2}], "command_line": []
    }));
    assert_eq!(m, serde_json::json!({"clips": [{"n": 2}]}));
}
