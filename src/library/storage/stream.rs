//! Writing a table in pieces: rows are appended batch by batch and leave memory as soon as
//! a row group of [`ROW_GROUP_ROWS`] rows is full, so a table of any length is written with
//! at most one row group held.
//!
//! # Layout
//! ```text
//! row groups: ROW_GROUP_ROWS rows each, the last one shorter (never empty unless the table is);
//!             a table with group keys (`schema::group_keys`: per clip, per character and
//!             effector): one group per run of equal keys, a run of more than
//!             ROW_GROUP_ROWS rows in groups of ROW_GROUP_ROWS and its shorter rest
//! footer:     ARROW:schema (oldest compatibility level), then the caller's key-value pairs
//! ```
//! The layout depends only on the rows and their order, never on how they were cut into
//! batches, so a streaming build, a one-batch build and a merge of shards write the same
//! bytes for the same rows. A merge appends a clip's groups as its shard holds them
//! ([`TableWriter::push_group`]): the file is assembled by [`super::row_groups`], which
//! keeps at most 3 MiB of footer entries and page indexes in memory (the rest in scratch
//! files until the footer is written). The key-value metadata is given at [`TableWriter::finish`], once
//! everything it describes (the per-character limits) is known.
//!
//! # Parallel encoding
//! The column chunks of a row group are encoded and compressed in parallel on the caller's
//! rayon pool (the workers of `--threads`), then written in column order: the pages are
//! those polars' serial `BatchedWriter::write_batch` makes (same encodings, options and
//! compressor), so the bytes do not depend on the thread count (the test below compares).
//! The groups of a per-frame table are encoded in parallel as well. Each column is copied
//! into one buffer on its own while it is encoded (never the whole group a second time), and a group whose rows wait in scratch files is read back one
//! column at a time ([`TableWriter::with_pending_spill`]); a row group's compressed pages
//! are held until it is written (the build's peak memory on a 25× replica of the bulk set:
//! `tests/bench/scale.rs`).

use std::cell::RefCell;
use std::fs::File;
use std::path::{Path, PathBuf};

use polars::io::parquet::write::get_encodings;
use polars::prelude::*;
use polars_parquet::parquet::compression::Compression;
use polars_parquet::parquet::error::ParquetResult;
use polars_parquet::parquet::page::{CompressedDataPage, CompressedDictPage, DataPageHeader};
use polars_parquet::parquet::CowBuffer;
use polars_parquet::read::ParquetError;
use polars_parquet::write::{
    array_to_columns, to_parquet_schema, CompressedPage, CompressionOptions, Compressor, Encoding,
    KeyValue, Page, ParquetType, Version, WriteOptions, ZstdLevel,
};
use rayon::prelude::*;

use super::row_groups::{encode, EncodedGroup, GroupFileWriter, GroupSchema};
use super::scratch::{scratch_name, Scratch};
use crate::error::{Error, Result};

/// A Parquet table being written under a temporary name in its folder; renamed into place
/// by [`TableWriter::finish`], removed when dropped unfinished.
pub struct TableWriter {
    path: PathBuf,
    tmp: PathBuf,
    schema: Schema,
    writer: Option<GroupFileWriter>,
    /// The Arrow and Parquet schemas and page options every group is encoded with.
    group_schema: GroupSchema,
    /// Per column: its Parquet type and encodings, as polars' writer derives them.
    columns: Vec<LeafType>,
    /// The columns whose every change ends a row group (`schema::group_keys`).
    group_keys: &'static [&'static str],
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
pub(super) fn write_options() -> WriteOptions {
    WriteOptions {
        // Full statistics, string minima and maxima never truncated (polars cuts them to
        // 64 bytes by default, or to `POLARS_PARQUET_BINARY_STATISTICS_TRUNCATE_LEN`): a
        // per-clip row group is found by its clip name (min = max), and the bytes must
        // not depend on the environment.
        statistics: StatisticsOptions {
            binary_statistics_truncate_length: Some(0),
            ..StatisticsOptions::full()
        },
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
            match options.compression {
                CompressionOptions::Zstd(level) => pages
                    .map(|p| compress_page(p?, level))
                    .collect::<std::result::Result<Vec<_>, _>>()
                    .map_err(PolarsError::from),
                other => Compressor::new_from_vec(pages, other, vec![])
                    .collect::<std::result::Result<Vec<_>, _>>()
                    .map_err(PolarsError::from),
            }
        })
        .collect()
}

thread_local! {
    /// Each worker's zstd context and its level, made at its first page and reused.
    static ZSTD: RefCell<Option<(i32, zstd::bulk::Compressor<'static>)>> =
        const { RefCell::new(None) };
}

/// `input` compressed by zstd at `level` (polars' level rule: none is zstd's default),
/// with the worker's context.
///
/// polars compresses each page with a new context (`zstd::bulk::compress_to_buffer`),
/// whose set-up costs more than a short page's compression: 6.7 % of a build's time on the
/// bulk set once the frames were cut per clip. A context compresses the same bytes to the
/// same output whether new or reused (zstd resets its session at every frame); the
/// tests compare the files with polars' own writer.
fn zstd_compress(input: &[u8], level: Option<ZstdLevel>) -> ParquetResult<Vec<u8>> {
    let level = level.map(|v| v.compression_level()).unwrap_or_default();
    ZSTD.with(|cell| {
        let mut cell = cell.borrow_mut();
        if cell.as_ref().is_none_or(|(l, _)| *l != level) {
            let c = zstd::bulk::Compressor::new(level)
                .map_err(|e| ParquetError::OutOfSpec(format!("zstd: {e}")))?;
            *cell = Some((level, c));
        }
        let Some((_, c)) = cell.as_mut() else {
            return Err(ParquetError::OutOfSpec("zstd: no context".into()));
        };
        let mut out = vec![0u8; zstd::zstd_safe::compress_bound(input.len())];
        let n = c
            .compress_to_buffer(input, &mut out[..])
            .map_err(|e| ParquetError::OutOfSpec(format!("zstd: {e}")))?;
        out.truncate(n);
        Ok(out)
    })
}

/// `page` compressed with zstd as polars' `Compressor` compresses it (V1 data pages and
/// dictionary pages; a V2 data page, which this crate does not write, goes to polars).
fn compress_page(page: Page, level: Option<ZstdLevel>) -> ParquetResult<CompressedPage> {
    match page {
        Page::Data(p) if matches!(p.header(), DataPageHeader::V1(_)) => {
            let buffer = zstd_compress(p.buffer(), level)?;
            let rows = p
                .num_rows()
                .ok_or_else(|| ParquetError::OutOfSpec("a data page without rows".into()))?;
            Ok(CompressedPage::Data(CompressedDataPage::new(
                p.header().clone(),
                CowBuffer::Owned(buffer),
                Compression::Zstd,
                p.buffer().len(),
                p.descriptor.clone(),
                rows,
            )))
        }
        Page::Dict(d) => {
            let buffer = zstd_compress(&d.buffer, level)?;
            Ok(CompressedPage::Dict(CompressedDictPage::new(
                CowBuffer::Owned(buffer),
                Compression::Zstd,
                d.buffer.len(),
                d.num_values,
                d.is_sorted,
            )))
        }
        other => {
            polars_parquet::write::compress(other, Vec::new(), CompressionOptions::Zstd(level))
        }
    }
}

/// The compressed pages of every column of one row group, in column order: each column is
/// made one Arrow array ([`column_array`]) and encoded ([`encode_column`]) on its own, in
/// parallel, so only the columns being encoded are copied into one buffer, never the group.
pub(super) fn encode_group(
    group: &[Column],
    columns: &[LeafType],
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
/// its table ([`encode_rows`]).
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

/// `df` as one row group for a file of `schema` (nothing for no rows), its columns encoded
/// by [`encode_group`]: the group polars' `BatchedWriter::write_batch` writes of a
/// one-chunk frame.
fn encode_rows(
    df: &DataFrame,
    schema: &GroupSchema,
    columns: &[LeafType],
) -> PolarsResult<Option<EncodedGroup>> {
    if df.height() == 0 {
        return Ok(None);
    }
    let pages = encode_group(df.columns(), columns)?;
    encode(schema, df.height() as u64, &pages)
        .map(Some)
        .map_err(PolarsError::from)
}

/// A top-level column's Parquet type and the encodings of its leaves.
pub(super) type LeafType = (ParquetType, Vec<Encoding>);

/// The schemas polars' batched writer derives from `schema`, and per column its Parquet
/// type and encodings.
pub(super) fn group_schema(schema: &Schema) -> PolarsResult<(GroupSchema, Vec<LeafType>)> {
    let arrow = schema.to_arrow(CompatLevel::newest());
    let parquet = to_parquet_schema(&arrow)?;
    let encodings = get_encodings(&arrow);
    let columns = parquet
        .fields()
        .iter()
        .cloned()
        .zip(encodings.iter().cloned())
        .collect();
    Ok((GroupSchema::new(arrow, parquet, write_options()), columns))
}

/// Encode the float columns of `schema` as plain values, not by polars' dictionary attempt.
///
/// For a float column polars tries a dictionary first and estimates the chunk's distinct
/// values (a HyperLogLog count, whose cost is fixed per column chunk, not per value); a
/// table cut into short groups (one per clip) paid it on every chunk: 7.5 % of a build's
/// time on the bulk set. Every float chunk of the frames of the bulk set had been written
/// plain anyway (positions and rates: far more than 75 % distinct values), so their bytes
/// did not change. Where polars would have chosen a dictionary (a chunk of at most 128
/// rows, or a float column constant over a clip) the file is larger than it would be;
/// zstd compresses the repeated values.
fn plain_floats(schema: &Schema, columns: &mut [LeafType]) {
    for ((_, dtype), (_, encodings)) in schema.iter().zip(columns.iter_mut()) {
        if matches!(dtype, DataType::Float64 | DataType::Float32) {
            *encodings = vec![Encoding::Plain];
        }
    }
}

/// Row counts of the groups `keys` (string columns of equal length) cut into: one per run
/// of rows with equal keys, a run of more than [`ROW_GROUP_ROWS`] in groups of that many.
/// Without `all`, the last run (whose key may go on in the next rows) gives only its full
/// groups.
fn keyed_group_sizes(keys: &[&Column], all: bool) -> PolarsResult<Vec<usize>> {
    let n = keys.first().map_or(0, |c| c.len());
    // A run starts at row 0 and wherever any key differs from the row before.
    let mut starts = vec![false; n];
    if let Some(first) = starts.first_mut() {
        *first = true;
    }
    for k in keys {
        let values = k.str()?;
        let mut last: Option<Option<&str>> = None;
        for (i, v) in values.iter().enumerate() {
            if last.is_some_and(|l| l != v) {
                starts[i] = true;
            }
            last = Some(v);
        }
    }
    let mut runs: Vec<usize> = Vec::new();
    for start in starts {
        match runs.last_mut() {
            Some(r) if !start => *r += 1,
            _ => runs.push(1),
        }
    }
    let n_runs = runs.len();
    let mut sizes = Vec::new();
    for (k, mut left) in runs.into_iter().enumerate() {
        let open = !all && k + 1 == n_runs;
        while left >= ROW_GROUP_ROWS || (!open && left > 0) {
            let n = left.min(ROW_GROUP_ROWS);
            sizes.push(n);
            left -= n;
        }
    }
    Ok(sizes)
}

/// The footer's key-value entries of a table of `schema`: `ARROW:schema` (the oldest
/// compatibility level, `string_hint`'s column typed `string`), then `kv`.
fn footer_entries(
    schema: &Schema,
    string_hint: Option<&PlSmallStr>,
    kv: &[(String, String)],
) -> Vec<KeyValue> {
    let mut arrow = Schema::from_iter(schema.iter().map(|(n, d)| (n.clone(), d.clone())))
        .to_arrow(CompatLevel::oldest());
    if let Some(f) = string_hint.and_then(|c| arrow.get_mut(c)) {
        if f.dtype == ArrowDataType::LargeUtf8 {
            f.dtype = ArrowDataType::Utf8;
        }
    }
    let (key, value) = arrow_schema_entry(&arrow, kv);
    let mut meta: Vec<KeyValue> = Vec::with_capacity(kv.len() + 1);
    meta.push(KeyValue {
        key,
        value: Some(value),
    });
    meta.extend(kv.iter().map(|(k, v)| KeyValue {
        key: k.clone(),
        value: Some(v.clone()),
    }));
    meta
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
        let schema = empty.schema().as_ref().clone();
        let group_keys = crate::library::codec::schema::group_keys(name);
        let (group_schema, mut columns) =
            group_schema(&schema).map_err(|e| io(&path, "cannot write parquet", e))?;
        if !group_keys.is_empty() {
            plain_floats(&schema, &mut columns);
        }
        let writer = GroupFileWriter::create(&tmp, name, &group_schema)
            .map_err(|e| io(&tmp, "cannot create", e))?;
        Ok(TableWriter {
            path,
            tmp,
            pending: empty.clear(),
            spilled: Vec::new(),
            spilled_rows: 0,
            spill: false,
            schema,
            writer: Some(writer),
            group_schema,
            columns,
            group_keys,
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
    /// Not for a table cut by keys (`schema::group_keys`), whose rows wait for one key.
    pub fn with_pending_spill(mut self) -> TableWriter {
        debug_assert!(
            self.group_keys.is_empty(),
            "a keyed table waits for one key"
        );
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
        if !self.group_keys.is_empty() {
            return self.write_keyed_groups(false);
        }
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
    /// The pages are those of [`encode_rows`] on the same rows.
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
            let g = encode(&self.group_schema, n as u64, &pages)
                .map_err(|e| io(&self.tmp, "cannot write parquet", e))?;
            self.append(&g)?;
        }
        self.pending = rest;
        self.spilled_rows = 0;
        // A part that cannot be removed now stays listed, for `Drop` to try again.
        self.spilled
            .retain(|part| std::fs::remove_file(part).is_err());
        Ok(())
    }

    fn write_group(&mut self, group: DataFrame) -> Result<()> {
        let encoded = encode_rows(&group, &self.group_schema, &self.columns)
            .map_err(|e| io(&self.tmp, "cannot write parquet", e))?;
        match encoded {
            Some(g) => self.append(&g),
            None => Ok(()),
        }
    }

    fn append(&mut self, g: &EncodedGroup) -> Result<()> {
        match self.writer.as_mut() {
            Some(w) => w
                .append(g)
                .map_err(|e| io(&self.tmp, "cannot write parquet", e)),
            None => Ok(()),
        }
    }

    /// Write the pending rows' complete groups of equal keys (all of them with `all`),
    /// encoded in parallel and appended in order; the rest stays pending.
    fn write_keyed_groups(&mut self, all: bool) -> Result<()> {
        let err = |e| io(&self.tmp, "cannot write parquet", e);
        let keys = self
            .group_keys
            .iter()
            .map(|k| self.pending.column(k))
            .collect::<PolarsResult<Vec<_>>>()
            .map_err(err)?;
        let sizes = keyed_group_sizes(&keys, all).map_err(err)?;
        let starts: Vec<usize> = sizes
            .iter()
            .scan(0, |at, n| {
                let s = *at;
                *at += n;
                Some(s)
            })
            .collect();
        let groups: Vec<Option<EncodedGroup>> = starts
            .par_iter()
            .zip(sizes.par_iter())
            .map(|(&at, &n)| {
                encode_rows(
                    &self.pending.slice(at as i64, n),
                    &self.group_schema,
                    &self.columns,
                )
            })
            .collect::<PolarsResult<_>>()
            .map_err(err)?;
        for g in groups.iter().flatten() {
            self.append(g)?;
        }
        let done: usize = sizes.iter().sum();
        if done > 0 {
            self.pending = self.pending.slice(done as i64, usize::MAX);
            self.pending.rechunk_mut();
        }
        Ok(())
    }

    /// Append `g`, a row group of the same table (a shard's, read by
    /// [`super::group_reader::GroupFileReader`]) after the rows pushed so far, as it is: its
    /// pages are not decoded. Only when no rows wait for their group.
    ///
    /// # Errors
    /// Rows are pending, or the write fails.
    pub fn push_group(&mut self, g: &EncodedGroup) -> Result<()> {
        if self.pending.height() > 0 || self.spilled_rows > 0 {
            return Err(io(
                &self.path,
                "cannot append a row group",
                std::io::Error::other("rows are waiting for their own group"),
            ));
        }
        self.append(g)?;
        self.rows += g.rows();
        Ok(())
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
        if !self.group_keys.is_empty() {
            self.write_keyed_groups(true)?;
        } else if !self.spilled.is_empty() {
            self.write_pending_by_column(usize::MAX)?;
        } else if self.pending.height() > 0 {
            let rest = std::mem::replace(&mut self.pending, DataFrame::empty());
            self.write_group(rest)?;
        }
        let meta = footer_entries(&self.schema, self.string_hint.as_ref(), kv);
        let Some(w) = self.writer.take() else {
            return Ok(());
        };
        let ended = w
            .finish(meta)
            .map(|_| ())
            .map_err(|e| io(&self.tmp, "cannot write parquet", e));
        if let Err(e) = ended.and_then(|()| super::generation::before_output()) {
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

/// Rows per Parquet row group.
pub const ROW_GROUP_ROWS: usize = 65_536;

/// The `ARROW:schema` key-value entry of `schema` (an Arrow schema of the oldest
/// compatibility level) whose schema metadata is `kv` itself.
///
/// pyarrow takes `read_table(f).schema.metadata` from this Arrow schema, not from the
/// file's key-value list, so the `stancelib.*` keys go into both.
pub(crate) fn arrow_schema_entry(
    schema: &polars_arrow::datatypes::ArrowSchema,
    kv: &[(String, String)],
) -> (String, String) {
    use polars_arrow::io::ipc::write::{default_ipc_fields, schema_to_bytes};
    let meta: polars_arrow::datatypes::Metadata = kv
        .iter()
        .map(|(k, v)| (PlSmallStr::from_str(k), PlSmallStr::from_str(v)))
        .collect();
    let ipc = schema_to_bytes(
        schema,
        &default_ipc_fields(schema.iter_values()),
        Some(&meta),
    );
    // The legacy IPC framing Arrow readers expect: continuation marker, length, message.
    let mut framed = Vec::with_capacity(ipc.len() + 8);
    framed.extend_from_slice(&[255, 255, 255, 255]);
    framed.extend_from_slice(&(ipc.len() as u32).to_le_bytes());
    framed.extend_from_slice(&ipc);
    ("ARROW:schema".to_string(), base64(&framed))
}

/// Standard base64 with padding (RFC 4648 §4), as the `ARROW:schema` value is written.
pub(crate) fn base64(bytes: &[u8]) -> String {
    const A: &[u8; 64] = b"ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    let mut out = String::with_capacity(bytes.len().div_ceil(3) * 4);
    for c in bytes.chunks(3) {
        let n = (u32::from(c[0]) << 16)
            | (u32::from(*c.get(1).unwrap_or(&0)) << 8)
            | u32::from(*c.get(2).unwrap_or(&0));
        for (i, shift) in [18, 12, 6, 0].into_iter().enumerate() {
            if i <= c.len() {
                out.push(char::from(A[((n >> shift) & 63) as usize]));
            } else {
                out.push('=');
            }
        }
    }
    out
}

#[cfg(test)]
mod tests;
