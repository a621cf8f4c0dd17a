//! The two layouts of a library folder and the one path every reader takes to a table.
//!
//! # Layouts
//! ```text
//! file     LIB/<table>.parquet                                     one file per table
//! dataset  LIB/<table>/character_id=<value>/part-0.parquet         tables with character_id
//!          LIB/<table>/part-0.parquet                              the others, and an empty
//!                                                                  partitioned table
//! ```
//! The layout is the manifest's `layout` key ([`LAYOUT_MANIFEST_KEY`]; absent = `file`).
//! A `dataset` library is a hive-partitioned Parquet dataset per table, which DuckDB
//! (`hive_partitioning=true`), polars (`scan_parquet`), pyarrow (`partitioning="hive"`) and
//! Spark read with partition pruning.
//!
//! # Choices (docs/decisions.md)
//! - The partition column stays inside the files too. All four readers accept it there
//!   (tested): polars, DuckDB, pyarrow and Spark keep the file's column position and dtype
//!   and take the value from the path; without it in the files they append it as the last
//!   column. Kept, a partition file alone is a complete slice of the table. Its Arrow type
//!   hint is `string` (the other strings' is `large_string`): pyarrow types the path's
//!   value as `string` and refuses to merge it with a `large_string` file column.
//! - Values are percent-encoded as Hive's `escapePathName` does (`%XX`, upper-case hex,
//!   for the control characters, `"#%'*/:=?\^{[]` and DEL); a null or empty value is
//!   the partition [`HIVE_NULL_PARTITION`], which the readers give as null (stancelib
//!   reads the value stored in the file).
//! - A partition file has its table's key-value metadata but the library-wide input
//!   hashes and limits (in `manifest.json`), which would be repeated in every partition.
//! - A partition holds the rows of one character in the order of the file layout; the
//!   rows of a table are those of its partitions in value order (byte order, null first),
//!   re-sorted by the table's keys where they are sorted by clip (`clips`, `stances`), so
//!   [`read_table`] gives the rows of the file layout in its order.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use polars::prelude::*;

use super::stream::TableWriter;
use crate::error::{Error, Result};
use crate::library::codec::schema::{
    sort_keys, CLIPS_FILE, DATASET_PART_FILE, HIVE_NULL_PARTITION, INPUTS_KEY, LAYOUT_MANIFEST_KEY,
    LIMITS_KEY, MANIFEST_FILE, PARTITIONED_FILES, PARTITION_COLUMN, STANCES_FILE, TABLE_FILES,
};

/// How a library's tables are laid out on disk (module docs).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub enum Layout {
    /// One Parquet file per table (`LIB/<table>.parquet`).
    #[default]
    File,
    /// A hive-partitioned Parquet dataset per table (`LIB/<table>/character_id=…/`).
    Dataset,
}

impl Layout {
    /// The name in the manifest, the CLI and the pipeline file.
    pub fn as_str(self) -> &'static str {
        match self {
            Layout::File => "file",
            Layout::Dataset => "dataset",
        }
    }

    /// The layout of a name ([`Layout::as_str`]), `None` for any other.
    pub fn parse(name: &str) -> Option<Layout> {
        [Layout::File, Layout::Dataset]
            .into_iter()
            .find(|l| l.as_str() == name)
    }
}

/// The partitioned tables sorted by clip: their partitions are re-sorted by the table's
/// keys when read (the others are sorted by `character_id` first).
const CLIP_ORDERED: [&str; 2] = [CLIPS_FILE, STANCES_FILE];

/// Refuses an output path that is one of the library `lib`'s own files: the folder itself,
/// `manifest.json`, a table file ([`TABLE_FILES`]) or a dataset table's folder. Those are
/// written only by `build` and `merge`; a query, edit, plot or force export written there
/// replaced a table (`forces --out LIB/frames.parquet` broke the next read). Other paths
/// inside the folder stay allowed (the pipelines write their answers beside the tables).
/// Paths are compared after resolving `..` and the symbolic links of the parts that exist.
///
/// # Errors
/// `out` is the library folder or one of its tables.
pub fn check_output_outside(lib: &Path, out: &Path) -> Result<()> {
    let resolve = |p: &Path| -> PathBuf {
        let abs = std::path::absolute(p).unwrap_or_else(|_| p.to_path_buf());
        // The deepest existing ancestor, canonicalised, with the rest appended.
        let mut head = abs.clone();
        let mut tail = Vec::new();
        while !head.exists() {
            match (head.file_name().map(|n| n.to_os_string()), head.parent()) {
                (Some(n), Some(parent)) => {
                    tail.push(n);
                    head = parent.to_path_buf();
                }
                _ => return abs,
            }
        }
        let mut r = head.canonicalize().unwrap_or(head);
        r.extend(tail.iter().rev());
        r
    };
    let (lib_r, out_r) = (resolve(lib), resolve(out));
    let Ok(rel) = out_r.strip_prefix(&lib_r) else {
        return Ok(());
    };
    let first = rel
        .components()
        .next()
        .map(|c| c.as_os_str().to_string_lossy().into_owned());
    let owned = match first.as_deref() {
        None => true,
        Some(f) => f == MANIFEST_FILE || TABLE_FILES.iter().any(|t| f == *t || f == table_name(t)),
    };
    if owned {
        return Err(Error::invalid(
            "--out",
            format!(
                "{} is the library {}'s own file or folder, written only by `build` and \
                 `merge`; write the output elsewhere",
                out.display(),
                lib.display()
            ),
        ));
    }
    Ok(())
}

/// The layout of the library at `lib` (manifest [`LAYOUT_MANIFEST_KEY`]; a folder without
/// a readable manifest, or a manifest without the key, is a `file` library).
///
/// # Errors
/// The manifest names a layout this tool does not know (the key is named).
pub fn layout_of(lib: &Path) -> Result<Layout> {
    let path = lib.join(MANIFEST_FILE);
    let Ok(m) = crate::library::codec::manifest::read_manifest(lib) else {
        return Ok(Layout::File);
    };
    match m.get(LAYOUT_MANIFEST_KEY) {
        None => Ok(Layout::File),
        Some(v) => v.as_str().and_then(Layout::parse).ok_or_else(|| {
            Error::config(
                Some(path.clone()),
                None,
                format!("{LAYOUT_MANIFEST_KEY}: unknown value {v} (file or dataset)"),
            )
        }),
    }
}

/// The dataset folder name of a table file: `stances.parquet` → `stances`.
pub fn table_name(file: &str) -> &str {
    file.strip_suffix(".parquet").unwrap_or(file)
}

/// Whether Hive escapes `c` in a partition value (`escapePathName`).
fn hive_escaped(c: char) -> bool {
    matches!(c, '\u{1}'..='\u{1f}' | '\u{7f}') || "\"#%'*/:=?\\{[]^".contains(c)
}

/// A partition value as a path segment: the characters Hive escapes as `%XX` (upper-case
/// hex of each UTF-8 byte), every other character as it is.
pub fn hive_escape(value: &str) -> String {
    let mut out = String::with_capacity(value.len());
    for c in value.chars() {
        if hive_escaped(c) {
            let mut buf = [0u8; 4];
            for b in c.encode_utf8(&mut buf).bytes() {
                out.push_str(&format!("%{b:02X}"));
            }
        } else {
            out.push(c);
        }
    }
    out
}

/// The value of a path segment written by [`hive_escape`] (`%XX` decoded; a `%` not
/// followed by two hex digits is kept).
pub fn hive_unescape(segment: &str) -> String {
    let b = segment.as_bytes();
    let mut out: Vec<u8> = Vec::with_capacity(b.len());
    let mut i = 0;
    while i < b.len() {
        let hex = b.get(i + 1..i + 3).and_then(|h| {
            std::str::from_utf8(h)
                .ok()
                .and_then(|h| u8::from_str_radix(h, 16).ok())
        });
        match (b[i], hex) {
            (b'%', Some(v)) => {
                out.push(v);
                i += 3;
            }
            (c, _) => {
                out.push(c);
                i += 1;
            }
        }
    }
    String::from_utf8_lossy(&out).into_owned()
}

/// The partition folder of a value: `character_id=<escaped value>`, or
/// `character_id=__HIVE_DEFAULT_PARTITION__` for a null or empty one.
pub fn partition_dir(value: Option<&str>) -> String {
    match value.filter(|v| !v.is_empty()) {
        Some(v) => format!("{PARTITION_COLUMN}={}", hive_escape(v)),
        None => format!("{PARTITION_COLUMN}={HIVE_NULL_PARTITION}"),
    }
}

/// The value a partition folder name stands for (`None`: the null partition, or not a
/// partition folder of [`PARTITION_COLUMN`]).
fn partition_value(dir_name: &str) -> Option<Option<String>> {
    let v = dir_name.strip_prefix(PARTITION_COLUMN)?.strip_prefix('=')?;
    Some((v != HIVE_NULL_PARTITION).then(|| hive_unescape(v)))
}

/// Where the rows of one library table are.
#[derive(Debug, Clone, PartialEq)]
pub enum TableSource {
    /// One Parquet file (the `file` layout, or an unpartitioned `dataset` table).
    File(PathBuf),
    /// The files of a partitioned table, in read order, under its folder.
    Parts {
        /// The table's folder (`LIB/<table>`).
        dir: PathBuf,
        /// The table's file name in the `file` layout (its sort order).
        file: &'static str,
        /// The data files, in partition order.
        parts: Vec<PathBuf>,
    },
}

impl TableSource {
    /// The path errors name: the file, or the table's folder.
    pub fn path(&self) -> &Path {
        match self {
            TableSource::File(p) => p,
            TableSource::Parts { dir, .. } => dir,
        }
    }

    /// The data files, in read order.
    pub fn files(&self) -> Vec<PathBuf> {
        match self {
            TableSource::File(p) => vec![p.clone()],
            TableSource::Parts { parts, .. } => parts.clone(),
        }
    }
}

/// Where table `file` (a name of [`TABLE_FILES`]) of the library at `lib` is, in the
/// library's layout.
///
/// # Errors
/// An unknown layout in the manifest, or a dataset folder that cannot be listed.
pub fn locate(lib: &Path, file: &'static str) -> Result<TableSource> {
    if layout_of(lib)? == Layout::File {
        return Ok(TableSource::File(lib.join(file)));
    }
    let dir = lib.join(table_name(file));
    let single = dir.join(DATASET_PART_FILE);
    if !PARTITIONED_FILES.contains(&file) {
        return Ok(TableSource::File(single));
    }
    let mut parts: Vec<(Option<String>, PathBuf)> = Vec::new();
    if single.is_file() {
        parts.push((None, single));
    }
    let entries = std::fs::read_dir(&dir).map_err(|e| Error::io(&dir, "cannot open table", e))?;
    for entry in entries {
        let entry = entry.map_err(|e| Error::io(&dir, "cannot list table", e))?;
        let name = entry.file_name().to_string_lossy().into_owned();
        if let Some(value) = partition_value(&name) {
            parts.push((value, entry.path().join(DATASET_PART_FILE)));
        }
    }
    parts.sort();
    Ok(TableSource::Parts {
        dir,
        file,
        parts: parts.into_iter().map(|(_, p)| p).collect(),
    })
}

/// Where the table a `file`-layout path names is: the path itself when it is a file (or
/// its name is not a library table's), else (`LIB/stances.parquet` of a `dataset`
/// library) the table in the library's layout.
///
/// # Errors
/// As [`locate`].
pub fn locate_path(path: &Path) -> Result<TableSource> {
    let name = path.file_name().and_then(|n| n.to_str()).unwrap_or("");
    let table = TABLE_FILES.iter().find(|f| **f == name);
    let (Some(file), Some(lib), false) = (table, path.parent(), path.is_file()) else {
        return Ok(TableSource::File(path.to_path_buf()));
    };
    locate(lib, file)
}

/// Whether table `file` of the library at `lib` exists (its file, or its dataset folder).
pub fn table_exists(lib: &Path, file: &'static str) -> bool {
    match locate(lib, file) {
        Ok(TableSource::File(p)) => p.is_file(),
        Ok(TableSource::Parts { dir, .. }) => dir.is_dir(),
        Err(_) => false,
    }
}

/// One Parquet file, all columns or only `columns`.
///
/// # Errors
/// The file cannot be opened or is not valid Parquet (or lacks one of `columns`).
pub fn read_file(path: &Path, columns: Option<&[&str]>) -> Result<DataFrame> {
    let f = std::fs::File::open(path).map_err(|e| Error::io(path, "cannot open", e))?;
    ParquetReader::new(f)
        .with_columns(columns.map(|c| c.iter().map(|n| n.to_string()).collect()))
        .finish()
        .map_err(|e| Error::io(path, "cannot read parquet", e))
}

/// `df` sorted by the keys of table `file` ([`sort_keys`]; stable), in one chunk.
///
/// # Errors
/// A key column is missing.
pub fn sorted(df: DataFrame, file: &str) -> Result<DataFrame> {
    if df.height() < 2 {
        return Ok(df);
    }
    let keys: Vec<PlSmallStr> = sort_keys(file).iter().map(|k| (*k).into()).collect();
    let mut all = df
        .sort(
            keys,
            SortMultipleOptions::default().with_maintain_order(true),
        )
        .map_err(|e| Error::io(file, "cannot build table", e))?;
    all.rechunk_mut();
    Ok(all)
}

/// The rows of `src` (all columns or only `columns`), in the order of the `file` layout.
///
/// # Errors
/// A file that cannot be read, or partitions of different schemas.
pub fn read_source(src: &TableSource, columns: Option<&[&str]>) -> Result<DataFrame> {
    let (dir, file, parts) = match src {
        TableSource::File(p) => return read_file(p, columns),
        TableSource::Parts { dir, file, parts } => (dir, *file, parts),
    };
    let resort = CLIP_ORDERED.contains(&file);
    // The sort keys are read too when the rows are re-sorted, and dropped after.
    let cols: Option<Vec<&str>> = columns.map(|c| {
        let keys = sort_keys(file).iter().filter(|k| resort && !c.contains(k));
        c.iter().copied().chain(keys.copied()).collect()
    });
    let mut all: Option<DataFrame> = None;
    for p in parts {
        let df = read_file(p, cols.as_deref())?;
        match all.as_mut() {
            None => all = Some(df),
            Some(a) => {
                a.vstack_mut(&df)
                    .map_err(|e| Error::io(p, "partition of another schema", e))?;
            }
        }
    }
    let Some(mut all) = all else {
        return Err(Error::io(
            dir,
            "cannot read table",
            std::io::Error::new(std::io::ErrorKind::NotFound, "no partition files"),
        ));
    };
    all.rechunk_mut();
    if resort {
        all = sorted(all, file)?;
    }
    match columns {
        Some(c) => all
            .select(c.iter().copied())
            .map_err(|e| Error::io(dir, "cannot read table", e)),
        None => Ok(all),
    }
}

/// Table `file` of the library at `lib`, either layout: the rows and columns of the `file`
/// layout in its order (module docs).
///
/// # Errors
/// As [`locate`] and [`read_source`].
pub fn read_table(lib: &Path, file: &'static str) -> Result<DataFrame> {
    read_source(&locate(lib, file)?, None)
}

/// The key-value metadata of a Parquet file's footer, without `ARROW:schema` (which a
/// [`TableWriter`] writes itself).
///
/// # Errors
/// The file cannot be opened or its footer read.
pub fn file_kv(path: &Path) -> Result<Vec<(String, String)>> {
    let mut f = std::fs::File::open(path).map_err(|e| Error::io(path, "cannot open", e))?;
    let meta = polars_parquet::read::read_metadata(&mut f)
        .map_err(|e| Error::io(path, "cannot read parquet footer", e))?;
    Ok(meta
        .key_value_metadata()
        .iter()
        .flatten()
        .filter(|kv| kv.key != "ARROW:schema")
        .map(|kv| (kv.key.clone(), kv.value.clone().unwrap_or_default()))
        .collect())
}

/// Key-value entries about the whole library, left out of partition files: they grow
/// with the clips and the characters and would be repeated in every partition (they stay
/// in `manifest.json` and in the unpartitioned tables' files).
const LIBRARY_WIDE_KEYS: [&str; 2] = [INPUTS_KEY, LIMITS_KEY];

/// The row numbers of each partition of `df`, by partition folder, in row order.
fn partition_rows(df: &DataFrame, path: &Path) -> Result<BTreeMap<String, Vec<IdxSize>>> {
    let ids = df
        .column(PARTITION_COLUMN)
        .and_then(|c| c.str().cloned())
        .map_err(|e| Error::io(path, "partition column", e))?;
    let mut rows: BTreeMap<String, Vec<IdxSize>> = BTreeMap::new();
    for (i, v) in ids.iter().enumerate() {
        rows.entry(partition_dir(v)).or_default().push(i as IdxSize);
    }
    Ok(rows)
}

/// Split the table file `src` into partition files under `table_dir` (same columns, rows
/// and key-value metadata but [`LIBRARY_WIDE_KEYS`]; each partition's rows in file
/// order), then remove `src`.
fn partition_file(src: &Path, table_dir: &Path) -> Result<()> {
    let df = read_file(src, None)?;
    let single = table_dir.join(DATASET_PART_FILE);
    if df.height() == 0 {
        // No partition to name: the empty table is one file (readers keep its schema).
        return std::fs::rename(src, &single).map_err(|e| Error::io(&single, "cannot move", e));
    }
    let mut kv = file_kv(src)?;
    kv.retain(|(k, _)| !LIBRARY_WIDE_KEYS.contains(&k.as_str()));
    for (dir_name, idx) in partition_rows(&df, src)? {
        let dir = table_dir.join(dir_name);
        std::fs::create_dir_all(&dir).map_err(|e| Error::io(&dir, "cannot create folder", e))?;
        let part = df
            .take(&IdxCa::from_vec("idx".into(), idx))
            .map_err(|e| Error::io(&dir, "cannot build partition", e))?;
        let mut w =
            TableWriter::create(&dir, DATASET_PART_FILE, &part)?.with_string_hint(PARTITION_COLUMN);
        w.push(&part)?;
        w.finish(&kv)?;
    }
    std::fs::remove_file(src).map_err(|e| Error::io(src, "cannot remove", e))
}

/// Turn the `file`-layout tables in `dir` (a library being written in its temporary
/// folder) into the `dataset` layout: the partitioned tables split by `character_id`
/// (each read whole, one at a time), the others moved to `<table>/part-0.parquet`.
/// Only the tables of [`TABLE_FILES`] found in `dir` are touched.
///
/// # Errors
/// A table that cannot be read, written or moved (the error names it).
pub fn convert_to_dataset(dir: &Path) -> Result<()> {
    for file in TABLE_FILES {
        let src = dir.join(file);
        if !src.is_file() {
            continue;
        }
        let table_dir = dir.join(table_name(file));
        std::fs::create_dir_all(&table_dir)
            .map_err(|e| Error::io(&table_dir, "cannot create folder", e))?;
        if PARTITIONED_FILES.contains(&file) {
            partition_file(&src, &table_dir)?;
        } else {
            let to = table_dir.join(DATASET_PART_FILE);
            std::fs::rename(&src, &to).map_err(|e| Error::io(&to, "cannot move", e))?;
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn hive_escape_round_trips_and_leaves_plain_ids_alone() {
        assert_eq!(hive_escape("sk-9f71a3e6fbd4"), "sk-9f71a3e6fbd4");
        assert_eq!(hive_escape("a/b=c%d"), "a%2Fb%3Dc%25d");
        for v in ["sk-1", "a/b=c%d", "x:y?z#\u{1}", "héllo wörld", "%zz"] {
            assert_eq!(hive_unescape(&hive_escape(v)), v, "{v}");
        }
        assert_eq!(partition_dir(None), partition_dir(Some("")));
        assert_eq!(
            partition_value(&partition_dir(Some("a/b"))),
            Some(Some("a/b".into()))
        );
        assert_eq!(partition_value(&partition_dir(None)), Some(None));
        assert_eq!(partition_value("other=1"), None);
    }

    #[test]
    fn layout_names_parse_back() {
        for l in [Layout::File, Layout::Dataset] {
            assert_eq!(Layout::parse(l.as_str()), Some(l));
        }
        assert_eq!(Layout::parse("hive"), None);
    }

    #[test]
    fn a_partitioned_table_reads_back_in_file_order() {
        let d = tempfile::tempdir().unwrap();
        // Clips interleave characters; one clip has none.
        let df = df! {
            "clip" => ["a", "b", "c", "d", "e"],
            PARTITION_COLUMN => [Some("sk-2"), Some("sk-1"), None, Some("sk-2"), Some("x/y")],
            "v" => [1.0, 2.0, 3.0, 4.0, 5.0],
        }
        .unwrap();
        let mut w = TableWriter::create(d.path(), CLIPS_FILE, &df).unwrap();
        w.push(&df).unwrap();
        w.finish(&[("k".into(), "v".into())]).unwrap();
        let file_rows = read_table(d.path(), CLIPS_FILE).unwrap();
        convert_to_dataset(d.path()).unwrap();
        std::fs::write(d.path().join(MANIFEST_FILE), r#"{"layout":"dataset"}"#).unwrap();
        assert!(d
            .path()
            .join("clips/character_id=x%2Fy/part-0.parquet")
            .is_file());
        assert!(!d.path().join(CLIPS_FILE).exists());
        let back = read_table(d.path(), CLIPS_FILE).unwrap();
        assert!(back.equals_missing(&file_rows), "{back}\n{file_rows}");
        let part = d.path().join("clips/character_id=sk-2/part-0.parquet");
        assert_eq!(file_kv(&part).unwrap(), vec![("k".into(), "v".into())]);
        let some = read_source(&locate(d.path(), CLIPS_FILE).unwrap(), Some(&["v"])).unwrap();
        assert_eq!(some.get_column_names(), vec!["v"]);
        assert!(some
            .column("v")
            .unwrap()
            .equals(file_rows.column("v").unwrap()));
    }
}
