//! Writing a table in pieces: rows are appended batch by batch and leave memory as soon as
//! a row group of [`ROW_GROUP_ROWS`] rows is full, so a table of any length is written with
//! at most one row group held.
//!
//! # Layout
//! ```text
//! row groups: ROW_GROUP_ROWS rows each, the last one shorter (never empty unless the table is)
//! footer:     ARROW:schema (oldest compatibility level), then the caller's key-value pairs
//! ```
//! The layout depends only on the rows and their order, never on how they were cut into
//! batches, so a streaming build, a one-batch build and a merge of shards write the same
//! bytes for the same rows. The key-value metadata is given at [`TableWriter::finish`], once
//! everything it describes (the per-character limits) is known.
//!
//! # Parallel encoding
//! The column chunks of a row group are encoded and compressed in parallel on the caller's
//! rayon pool (the workers of `--threads`), then written in column order: the pages are
//! those polars' serial `BatchedWriter::write_batch` makes (same encodings, options and
//! compressor), so the bytes do not depend on the thread count (the test below compares).
//! Each column is copied into one buffer on its own while it is encoded (never the whole
//! group a second time), and a group whose rows wait in scratch files is read back one
//! column at a time ([`TableWriter::with_pending_spill`]); a row group's compressed pages
//! are held until it is written (the build's peak memory on a 25× replica of the bulk set:
//! `tests/bench/scale.rs`).

use std::fs::File;
use std::path::{Path, PathBuf};

use polars::io::parquet::write::get_encodings;
use polars::prelude::*;
use polars_parquet::read::ParquetError;
use polars_parquet::write::{
    array_to_columns, CompressedPage, Compressor, Encoding, KeyValue, ParquetType, Version,
    WriteOptions,
};
use rayon::prelude::*;

use super::scratch::{scratch_name, Scratch};
use super::write::ROW_GROUP_ROWS;
use crate::error::{Error, Result};

/// A Parquet table being written under a temporary name in its folder; renamed into place
/// by [`TableWriter::finish`], removed when dropped unfinished.
pub struct TableWriter {
    path: PathBuf,
    tmp: PathBuf,
    schema: Schema,
    writer: Option<polars::io::parquet::write::BatchedWriter<File>>,
    /// Per column: its Parquet type and encodings, as the writer derived them.
    columns: Vec<(ParquetType, Vec<Encoding>)>,
    pending: DataFrame,
    /// Older pending rows moved to scratch Parquet files in the table's folder, in order
    /// (`PENDING_SPILL_BYTES`, `PENDING_SPILL_CHUNKS`), with their row count.
    spilled: Vec<PathBuf>,
    spilled_rows: usize,
    /// Pending rows go to scratch files ([`TableWriter::with_pending_spill`]).
    spill: bool,
    rows: usize,
    /// A string column whose Arrow type hint is `string`, not `large_string`
    /// ([`TableWriter::with_string_hint`]).
    string_hint: Option<PlSmallStr>,
}

/// Pending rows (fewer than a row group) beyond this size in memory, bytes, go to a scratch
/// file until their row group is full ([`TableWriter::with_pending_spill`]): a table of
/// few, wide rows (stances: ~1.3 kB a row) would otherwise hold up to a row group's worth,
/// tens of MB, for the whole build.
const PENDING_SPILL_BYTES: usize = 1 << 20;

/// Pending pushes (chunks) beyond this many go to a scratch file as well, whatever their
/// estimated size ([`TableWriter::with_pending_spill`]): every push is a chunk whose string
/// columns each hold a buffer of at least polars' 8 kB block however few their bytes, which
/// `estimated_size` does not count. The clips table of the 25× replica (one row a clip,
/// eight clips a batch) held 7.1 MB at the build's peak for 1 MB estimated.
const PENDING_SPILL_CHUNKS: usize = 16;

/// Page compression of every table: zstd at its default level.
const COMPRESSION: ParquetCompression = ParquetCompression::Zstd(None);

/// The page options polars' `ParquetWriter` derives from [`COMPRESSION`] and full
/// statistics (its `materialize_options`): the writer and the parallel encoder share them.
fn write_options() -> WriteOptions {
    WriteOptions {
        statistics: StatisticsOptions::full(),
        compression: COMPRESSION.into(),
        version: Version::V1,
        data_page_size: None,
    }
}

/// The compressed pages of one column chunk (one Arrow array of a row group), in leaf
/// order: what polars' serial writer makes of it, page for page.
fn encode_column(
    array: &ArrayRef,
    type_: &ParquetType,
    encoding: &[Encoding],
) -> PolarsResult<Vec<Vec<CompressedPage>>> {
    let options = write_options();
    array_to_columns(array, type_.clone(), options, encoding)?
        .into_iter()
        .map(|pages| {
            let pages = pages.map(|p| {
                p.map_err(|e| ParquetError::FeatureNotSupported(format!("reraised in polars: {e}")))
            });
            Compressor::new_from_vec(pages, options.compression, vec![])
                .collect::<std::result::Result<Vec<_>, _>>()
                .map_err(PolarsError::from)
        })
        .collect()
}

/// The compressed pages of every column of one row group, in column order: each column is
/// made one Arrow array ([`column_array`]) and encoded ([`encode_column`]) on its own, in
/// parallel, so only the columns being encoded are copied into one buffer, never the group.
fn encode_group(
    group: &[Column],
    columns: &[(ParquetType, Vec<Encoding>)],
) -> PolarsResult<Vec<Vec<CompressedPage>>> {
    let per_column: Vec<Vec<Vec<CompressedPage>>> = group
        .par_iter()
        .zip(columns.par_iter())
        .map(|(column, (type_, encoding))| {
            column_array(column.clone()).and_then(|array| encode_column(&array, type_, encoding))
        })
        .collect::<PolarsResult<_>>()?;
    Ok(per_column.into_iter().flatten().collect())
}

/// The Arrow array `df.iter_chunks(CompatLevel::newest(), false)` makes of `column` (one
/// chunk), so that a column encoded alone gives the pages of the same column encoded with
/// its table ([`write_groups`]).
fn column_array(column: Column) -> PolarsResult<ArrayRef> {
    let mut df = DataFrame::new_infer_height(vec![column])?;
    df.rechunk_mut();
    let batch = df
        .iter_chunks(CompatLevel::newest(), false)
        .next()
        // `iter_chunks` yields at least one batch, empty for no rows.
        .ok_or_else(|| polars_err!(ComputeError: "no record batch"))?;
    Ok(batch.columns()[0].clone())
}

/// Write `df` as one row group, as polars' `BatchedWriter::write_batch` writes a
/// one-chunk frame, its columns encoded by [`encode_group`] (nothing for no rows).
fn write_groups<W: std::io::Write>(
    w: &mut polars::io::parquet::write::BatchedWriter<W>,
    df: &DataFrame,
    columns: &[(ParquetType, Vec<Encoding>)],
) -> PolarsResult<()> {
    if df.height() == 0 {
        return Ok(());
    }
    let pages = encode_group(df.columns(), columns)?;
    w.write_row_group(df.height() as u64, &pages)
}

/// Per column of a writer: its Parquet type and encodings, as the writer derived them.
fn column_types<W: std::io::Write>(
    w: &mut polars::io::parquet::write::BatchedWriter<W>,
    schema: &Schema,
) -> Vec<(ParquetType, Vec<Encoding>)> {
    let encodings = get_encodings(&schema.to_arrow(CompatLevel::newest()));
    let types = w.parquet_schema().fields().to_vec();
    types.into_iter().zip(encodings.iter().cloned()).collect()
}

impl std::fmt::Debug for TableWriter {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("TableWriter")
            .field("path", &self.path)
            .field("rows", &self.rows)
            .finish()
    }
}

fn io(path: &Path, what: &str, e: impl std::error::Error + Send + Sync + 'static) -> Error {
    Error::io(path, what, e)
}

impl TableWriter {
    /// Start `dir/name` with the schema of `empty` (a table of the same kind, any rows).
    ///
    /// # Errors
    /// The temporary file cannot be created.
    pub fn create(dir: &Path, name: &str, empty: &DataFrame) -> Result<TableWriter> {
        let path = dir.join(name);
        let tmp = dir.join(scratch_name(name, Scratch::Tmp));
        let file = File::create(&tmp).map_err(|e| io(&tmp, "cannot create", e))?;
        let schema = empty.schema().as_ref().clone();
        let mut writer = ParquetWriter::new(file)
            .with_compression(COMPRESSION)
            .with_statistics(write_options().statistics)
            .set_parallel(false)
            .batched(&schema)
            .map_err(|e| io(&tmp, "cannot write parquet", e))?;
        let columns = column_types(&mut writer, &schema);
        Ok(TableWriter {
            path,
            tmp,
            pending: empty.clear(),
            spilled: Vec::new(),
            spilled_rows: 0,
            spill: false,
            schema,
            writer: Some(writer),
            columns,
            rows: 0,
            string_hint: None,
        })
    }

    /// Give `column` (a string column) the Arrow type hint `string` instead of
    /// `large_string` (the data pages are the same). A hive reader types a partition
    /// value from its path as `string`; pyarrow refuses to merge it with a file column of
    /// `large_string`, so the partition column of a dataset's files carries this hint.
    pub fn with_string_hint(mut self, column: &str) -> TableWriter {
        self.string_hint = Some(column.into());
        self
    }

    /// Keep at most `PENDING_SPILL_BYTES` or `PENDING_SPILL_CHUNKS` pushes of pending rows
    /// in memory, the older ones in scratch files beside the table: for a table of few, wide rows, which takes many
    /// batches to fill a row group. A long table (frames) fills one in a few batches and
    /// is better held than written twice.
    pub fn with_pending_spill(mut self) -> TableWriter {
        self.spill = true;
        self
    }

    /// Rows appended so far.
    pub fn rows(&self) -> usize {
        self.rows
    }

    /// Append `df` (same columns; cast to the table's types, as rows read back from
    /// Parquet may carry other string or list encodings); full row groups are written.
    ///
    /// # Errors
    /// Columns missing or not castable, or a write that fails.
    pub fn push(&mut self, df: &DataFrame) -> Result<()> {
        if df.height() == 0 {
            return Ok(());
        }
        let df = self
            .conform(df)
            .map_err(|e| io(&self.path, "rows of another schema", e))?;
        self.rows += df.height();
        self.pending
            .vstack_mut(&df)
            .map_err(|e| io(&self.path, "rows of another schema", e))?;
        if self.spilled_rows + self.pending.height() < ROW_GROUP_ROWS {
            // The rows wait as one chunk per push: copying them into one buffer at every
            // push would copy a small table's rows once per batch and leave the heap with
            // a trail of freed buffers of growing sizes.
            if self.pending_too_large() {
                self.spill_pending()?;
            }
            return Ok(());
        }
        if !self.spilled.is_empty() {
            self.write_pending_by_column(ROW_GROUP_ROWS)?;
        }
        while self.pending.height() >= ROW_GROUP_ROWS {
            let head = self.pending.slice(0, ROW_GROUP_ROWS);
            self.write_group(head)?;
            let rest = self.pending.slice(ROW_GROUP_ROWS as i64, usize::MAX);
            self.pending = rest;
        }
        // Free the buffers of the rows just written (the remainder is copied once).
        self.pending.rechunk_mut();
        if self.pending_too_large() {
            self.spill_pending()?;
        }
        Ok(())
    }

    /// Pending rows that go to a scratch file: more than [`PENDING_SPILL_BYTES`] or
    /// [`PENDING_SPILL_CHUNKS`] pushes (only with [`TableWriter::with_pending_spill`]).
    fn pending_too_large(&self) -> bool {
        self.spill
            && (self.pending.estimated_size() > PENDING_SPILL_BYTES
                || self.pending.first_col_n_chunks() > PENDING_SPILL_CHUNKS)
    }

    /// `df`'s columns of the table, cast to its types.
    fn conform(&self, df: &DataFrame) -> PolarsResult<DataFrame> {
        let cols = self
            .schema
            .iter()
            .map(|(name, dtype)| df.column(name).and_then(|c| c.cast(dtype)))
            .collect::<PolarsResult<Vec<Column>>>()?;
        DataFrame::new_infer_height(cols)
    }

    /// Move the pending rows to a new scratch file (uncompressed Parquet: the values come
    /// back bit for bit, and are cast to the table's types on the way back).
    fn spill_pending(&mut self) -> Result<()> {
        let dir = self.path.parent().unwrap_or(Path::new("."));
        let stem = self
            .path
            .file_name()
            .map(|n| n.to_string_lossy())
            .unwrap_or_default();
        let part = dir.join(scratch_name(
            &format!("{stem}.pending-{}", self.spilled.len()),
            Scratch::Tmp,
        ));
        let file = File::create(&part).map_err(|e| io(&part, "cannot create scratch file", e))?;
        self.spilled.push(part.clone());
        ParquetWriter::new(file)
            .with_compression(ParquetCompression::Uncompressed)
            .with_statistics(StatisticsOptions::empty())
            .finish(&mut self.pending)
            .map_err(|e| io(&part, "cannot write scratch file", e))?;
        self.spilled_rows += self.pending.height();
        self.pending = self.pending.clear();
        Ok(())
    }

    /// Column `name` of every pending row, the spilled ones first, cast to `dtype` (only
    /// that column is read from the scratch files).
    fn pending_column(&self, name: &PlSmallStr, dtype: &DataType) -> Result<Column> {
        let here = self
            .pending
            .column(name)
            .map_err(|e| io(&self.path, "rows of another schema", e))?;
        let mut all = here.clear();
        for part in &self.spilled {
            let rows = File::open(part)
                .map_err(|e| io(part, "cannot open scratch file", e))
                .and_then(|f| {
                    ParquetReader::new(f)
                        .with_columns(Some(vec![name.to_string()]))
                        .finish()
                        .map_err(|e| io(part, "cannot read scratch file", e))
                })?;
            let column = rows
                .column(name)
                .and_then(|c| c.cast(dtype))
                .map_err(|e| io(part, "scratch rows of another schema", e))?;
            all.append(&column)
                .map_err(|e| io(part, "scratch rows of another schema", e))?;
        }
        all.append(here)
            .map_err(|e| io(&self.path, "rows of another schema", e))?;
        Ok(all)
    }

    /// Write the first `group_rows` pending rows (all of them if fewer) as one row group,
    /// one column at a time from the scratch files and the rows in memory, and keep the
    /// rest pending. Each worker holds one column of the pending rows at a time; the
    /// compressed pages and the rows left over are kept until the group is written. A
    /// group of wide rows loaded whole (the stances of a large build) would be tens of MB.
    /// The pages are those of [`write_groups`] on the same rows.
    fn write_pending_by_column(&mut self, group_rows: usize) -> Result<()> {
        let n = group_rows.min(self.spilled_rows + self.pending.height());
        let fields: Vec<(PlSmallStr, DataType)> = self
            .schema
            .iter()
            .map(|(name, dtype)| (name.clone(), dtype.clone()))
            .collect();
        let encoded: Vec<(Vec<Vec<CompressedPage>>, Column)> = fields
            .par_iter()
            .zip(self.columns.par_iter())
            .map(|((name, dtype), (type_, encoding))| {
                let all = self.pending_column(name, dtype)?;
                let rest = all.slice(n as i64, usize::MAX).rechunk();
                let pages = column_array(all.slice(0, n))
                    .and_then(|array| encode_column(&array, type_, encoding))
                    .map_err(|e| io(&self.tmp, "cannot write parquet", e))?;
                Ok((pages, rest))
            })
            .collect::<Result<_>>()?;
        let (pages, rest): (Vec<_>, Vec<Column>) = encoded.into_iter().unzip();
        let pages: Vec<Vec<CompressedPage>> = pages.into_iter().flatten().collect();
        // The rows left over are put together before anything is written, so that a
        // failure leaves the writer as it was (parts listed, rows pending).
        let rest = DataFrame::new_infer_height(rest)
            .map_err(|e| io(&self.path, "rows of another schema", e))?;
        if n > 0 {
            if let Some(w) = self.writer.as_mut() {
                w.write_row_group(n as u64, &pages)
                    .map_err(|e| io(&self.tmp, "cannot write parquet", e))?;
            }
        }
        self.pending = rest;
        self.spilled_rows = 0;
        // A part that cannot be removed now stays listed, for `Drop` to try again.
        self.spilled
            .retain(|part| std::fs::remove_file(part).is_err());
        Ok(())
    }

    fn write_group(&mut self, group: DataFrame) -> Result<()> {
        let Some(w) = self.writer.as_mut() else {
            return Ok(());
        };
        write_groups(w, &group, &self.columns).map_err(|e| io(&self.tmp, "cannot write parquet", e))
    }

    /// Write the last row group and the footer with `kv` (after an `ARROW:schema` entry of
    /// the oldest Arrow compatibility level), then rename the file into place.
    ///
    /// The oldest level (`large_string`, not `string_view`): with polars' newest Arrow types
    /// in the footer, pyarrow reads list columns as `list<string_view>`, which `to_pandas`
    /// cannot convert. The data pages are the same either way; only the type hint differs.
    ///
    /// # Errors
    /// A write or the rename fails (the temporary file is removed).
    pub fn finish(mut self, kv: &[(String, String)]) -> Result<()> {
        if !self.spilled.is_empty() {
            self.write_pending_by_column(usize::MAX)?;
        } else if self.pending.height() > 0 {
            let rest = std::mem::replace(&mut self.pending, DataFrame::empty());
            self.write_group(rest)?;
        }
        let mut arrow = Schema::from_iter(self.schema.iter().map(|(n, d)| (n.clone(), d.clone())))
            .to_arrow(CompatLevel::oldest());
        if let Some(f) = self.string_hint.as_ref().and_then(|c| arrow.get_mut(c)) {
            if f.dtype == ArrowDataType::LargeUtf8 {
                f.dtype = ArrowDataType::Utf8;
            }
        }
        let (key, value) = super::write::arrow_schema_entry(&arrow, kv);
        let mut meta: Vec<KeyValue> = Vec::with_capacity(kv.len() + 1);
        meta.push(KeyValue {
            key,
            value: Some(value),
        });
        meta.extend(kv.iter().map(|(k, v)| KeyValue {
            key: k.clone(),
            value: Some(v.clone()),
        }));
        let Some(w) = self.writer.take() else {
            return Ok(());
        };
        let ended = w
            .get_writer()
            .lock()
            .map_err(|_| {
                io(
                    &self.tmp,
                    "cannot write parquet",
                    std::io::Error::other("writer poisoned"),
                )
            })?
            .end(Some(meta))
            .map(|_| ())
            .map_err(|e| io(&self.tmp, "cannot write parquet", e));
        drop(w);
        if let Err(e) = ended {
            let _ = std::fs::remove_file(&self.tmp);
            return Err(e);
        }
        std::fs::rename(&self.tmp, &self.path)
            .map_err(|e| io(&self.path, "cannot rename into place", e))
    }
}

impl Drop for TableWriter {
    fn drop(&mut self) {
        for part in &self.spilled {
            let _ = std::fs::remove_file(part);
        }
        if self.writer.is_some() {
            self.writer = None;
            let _ = std::fs::remove_file(&self.tmp);
        }
    }
}

/// Read rows `offset .. offset + len` of a Parquet file (only the row groups they touch).
///
/// # Errors
/// The file cannot be opened or read.
pub fn read_rows(path: &Path, offset: usize, len: usize) -> Result<DataFrame> {
    let f = File::open(path).map_err(|e| io(path, "cannot open", e))?;
    ParquetReader::new(f)
        .with_slice(Some((offset, len)))
        .finish()
        .map_err(|e| io(path, "cannot read parquet", e))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A table of `n` rows with strings, integers, floats, booleans and nulls.
    fn table(n: usize) -> DataFrame {
        df! {
            "clip" => (0..n).map(|i| format!("clip_{:03}", i / 1000)).collect::<Vec<_>>(),
            "frame" => (0..n as i64).collect::<Vec<_>>(),
            "x" => (0..n).map(|i| (i as f64 * 0.37).sin()).collect::<Vec<_>>(),
            "flag" => (0..n).map(|i| i % 7 < 3).collect::<Vec<_>>(),
            "z" => (0..n).map(|i| (i % 5 != 0).then_some(i as f64)).collect::<Vec<_>>(),
        }
        .unwrap()
    }

    // See: issue 15 item 4 — Parquet written in parallel: the serial writer's bytes.
    #[test]
    fn parallel_encoding_gives_the_serial_writers_bytes() {
        let df = table(ROW_GROUP_ROWS + 1234);
        let groups = [
            df.slice(0, ROW_GROUP_ROWS),
            df.slice(ROW_GROUP_ROWS as i64, 1234),
        ];
        fn writer<'a>(out: &'a mut Vec<u8>, df: &DataFrame) -> BatchedWriter<&'a mut Vec<u8>> {
            ParquetWriter::new(out)
                .with_compression(COMPRESSION)
                .with_statistics(write_options().statistics)
                .set_parallel(false)
                .batched(df.schema())
                .unwrap()
        }
        let mut serial = Vec::new();
        let mut w = writer(&mut serial, &df);
        for g in &groups {
            w.write_batch(&g.clone()).unwrap();
        }
        w.finish().unwrap();
        drop(w);
        for threads in [1, 2] {
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap();
            let mut par = Vec::new();
            let mut w = writer(&mut par, &df);
            let columns = column_types(&mut w, df.schema());
            for g in &groups {
                pool.install(|| write_groups(&mut w, &g.clone(), &columns))
                    .unwrap();
            }
            w.finish().unwrap();
            drop(w);
            assert!(par == serial, "{threads} threads: the bytes differ");
        }
    }

    /// `pieces` pushed one by one through a spilling writer of `template`'s columns into a
    /// fresh folder: the file's bytes, the most scratch files and the most pending chunks
    /// seen; asserts that no scratch file is left.
    fn write_pieces(template: &DataFrame, pieces: &[DataFrame]) -> (Vec<u8>, usize, usize) {
        let d = tempfile::tempdir().unwrap();
        let mut w = TableWriter::create(d.path(), "t.parquet", &template.clear())
            .unwrap()
            .with_pending_spill();
        let (mut most_spilled, mut most_chunks) = (0, 0);
        for p in pieces {
            w.push(p).unwrap();
            most_spilled = most_spilled.max(w.spilled.len());
            most_chunks = most_chunks.max(w.pending.first_col_n_chunks());
        }
        w.finish(&[]).unwrap();
        let bytes = std::fs::read(d.path().join("t.parquet")).unwrap();
        let left: Vec<_> = std::fs::read_dir(d.path()).unwrap().collect();
        assert_eq!(left.len(), 1, "scratch files left: {left:?}");
        (bytes, most_spilled, most_chunks)
    }

    /// Many pushes of a few rows (far below the pending bytes) wait in scratch files once
    /// they are more than `PENDING_SPILL_CHUNKS` chunks, and give the bytes of one push.
    #[test]
    fn many_small_pushes_spill_by_count_and_give_the_same_bytes() {
        let df = table(3 * (PENDING_SPILL_CHUNKS + 1) * 4);
        assert!(df.estimated_size() < PENDING_SPILL_BYTES);
        let (whole, none, _) = write_pieces(&df, std::slice::from_ref(&df));
        assert_eq!(none, 0);
        let pieces: Vec<DataFrame> = (0..df.height())
            .step_by(3)
            .map(|at| df.slice(at as i64, 3))
            .collect();
        let (pieced, spilled, chunks) = write_pieces(&df, &pieces);
        assert!(spilled >= 3, "{spilled} scratch files");
        assert!(chunks <= PENDING_SPILL_CHUNKS, "{chunks} chunks waited");
        assert!(pieced == whole, "the bytes differ");
    }

    /// Rows pushed in small pieces, past the pending limit so that they wait in scratch
    /// files, give the bytes of one push; no scratch file is left.
    #[test]
    fn spilled_pending_rows_give_the_same_bytes() {
        let df = table(2 * ROW_GROUP_ROWS + 777);
        assert!(
            df.estimated_size() > 2 * PENDING_SPILL_BYTES,
            "the test must spill"
        );
        let (whole, _, _) = write_pieces(&df, std::slice::from_ref(&df));
        let pieces: Vec<DataFrame> = (0..df.height())
            .step_by(5000)
            .map(|at| df.slice(at as i64, 5000))
            .collect();
        let (pieced, spilled, _) = write_pieces(&df, &pieces);
        assert!(spilled > 0, "no piece waited in a scratch file");
        assert!(pieced == whole, "the bytes differ");
        // Small pieces that wait in scratch files, then one push of two groups' rows that
        // meets them, the total ending exactly on a group boundary.
        let exact = table(3 * ROW_GROUP_ROWS);
        let (whole, _, _) = write_pieces(&exact, std::slice::from_ref(&exact));
        let small = 40 * 1000;
        let mut pieces: Vec<DataFrame> = (0..small)
            .step_by(1000)
            .map(|at| exact.slice(at as i64, 1000))
            .collect();
        pieces.push(exact.slice(small as i64, 2 * ROW_GROUP_ROWS));
        pieces.push(exact.slice((small + 2 * ROW_GROUP_ROWS) as i64, usize::MAX));
        let (pieced, spilled, _) = write_pieces(&exact, &pieces);
        assert!(spilled > 0, "no piece waited in a scratch file");
        assert!(
            pieced == whole,
            "the bytes differ (a large push after spilled rows)"
        );
    }
}
