//! Parquet files assembled from encoded row groups that can be moved between files: a
//! group encoded for one file (a shard library's) is appended to another (the merged
//! library's) as it was, its compressed pages copied, never decoded.
//!
//! # Layout (what polars' `FileWriter` writes, byte for byte)
//! ```text
//! PAR1
//! per row group, per column chunk: its pages, then its ColumnMetaData (thrift compact)
//! per row group, per column chunk: its ColumnIndex          (page statistics)
//! per row group, per column chunk: its OffsetIndex          (page offsets in the file)
//! FileMetaData (thrift compact), its length (u32 LE), PAR1
//! ```
//! Every offset in a group's metadata is a byte position in the file, so a group is kept
//! here with its offsets counted from the start of each column chunk ([`EncodedGroup`]);
//! [`GroupFileWriter::append`] adds the chunk's position in the new file. The footer
//! entries and page indexes of the groups written so far wait in memory up to 1 MiB each,
//! then in scratch files: a file of many small groups (one per clip) holds at most 3 MiB
//! of them until the footer is written, however many groups it has.
//!
//! A group is encoded by polars' own writer into a one-group file in memory and read back
//! from it as from any file ([`encode`]), so the pages, statistics and indexes are
//! polars'; only the file's assembly is done here.

use std::fs::File;
use std::io::{BufReader, BufWriter, Read, Seek, SeekFrom, Write};
use std::ops::Range;
use std::path::{Path, PathBuf};

use polars::prelude::ArrowSchema;
use polars_parquet::write::{
    CompressedPage, DynIter, DynStreamingIterator, FileWriter, SchemaDescriptor, WriteOptions,
};
use polars_parquet_format::thrift::protocol::{TCompactInputProtocol, TCompactOutputProtocol};
use polars_parquet_format::{ColumnChunk, FileMetaData, KeyValue, OffsetIndex, RowGroup};

use super::footer::*;
use super::scratch::{scratch_name, Scratch};

/// The Parquet magic bytes, at the start and the end of a file.
pub(super) const MAGIC: &[u8; 4] = b"PAR1";

/// The thrift reader's allocation budget per byte of the structure read. The reader
/// charges 8 bytes per claimed list element when it reads the list's header (2 per
/// struct, 1 per string byte) and stops past its budget; the largest element it allocates
/// (a column chunk) is about 544 bytes, so a structure read with a budget of `b` bytes
/// allocates at most about 68 × `b` bytes however its lengths lie. The structures this tool writes fit the budget: every
/// group written is read back through it (`encode`), and so is every footer entry.
pub(super) const THRIFT_BUDGET_PER_BYTE: usize = 4;

/// The longest footer entry of one row group read (bytes): a group of this tool's tables
/// (at most about 50 columns) takes about 4 kB; a longer entry is refused (when read
/// back from a file, once it has been parsed within the budget of this length).
pub(super) const MAX_GROUP_ENTRY_BYTES: usize = 256 << 10;

/// The most bytes between two column chunks of a group (the first one's metadata): a
/// chunk's metadata is a few hundred bytes, longer only by its string statistics (values
/// of more than about 30 kB in a column would not be read back).
pub(super) const CHUNK_GAP_BYTES: i64 = 64 * 1024;

/// The longest column or offset index of one column chunk read (bytes): an offset index
/// takes about 12 bytes a page, a column index a page's statistics.
pub(super) const MAX_INDEX_BYTES: i32 = 16 << 20;

/// The longest whole footer read at once (only footers this tool just wrote in memory are).
pub(super) const MAX_FOOTER_BYTES: usize = 64 << 20;

/// One column chunk of an [`EncodedGroup`].
#[derive(Debug, Clone, PartialEq)]
pub(super) struct Chunk {
    /// Its pages (headers and compressed data): a range of the group's bytes.
    pages: Range<usize>,
    /// Its footer entry, every offset counted from the chunk's first page; no page index
    /// offsets (set when the group is appended).
    meta: ColumnChunk,
    /// Its ColumnIndex, thrift-encoded (no offsets in it), if the file writes one.
    column_index: Option<Vec<u8>>,
    /// Its OffsetIndex, page offsets counted from the chunk's first page.
    offset_index: OffsetIndex,
}

/// A row group that can be appended to any file of its schema: its pages and its
/// metadata with offsets relative to each column chunk (module docs).
#[derive(Debug, Clone, PartialEq)]
pub struct EncodedGroup {
    /// The group's column chunks as they lay in their file, from its first page to its
    /// last chunk's end.
    bytes: Vec<u8>,
    chunks: Vec<Chunk>,
    /// The group's footer entry without its columns (set when appended).
    group: RowGroup,
}

impl EncodedGroup {
    /// Rows of the group.
    pub fn rows(&self) -> usize {
        self.group.num_rows.max(0) as usize
    }
}

/// Where a column chunk's pages start: its dictionary page, else its first data page.
pub(super) fn chunk_start(c: &ColumnChunk) -> Option<i64> {
    let m = c.meta_data.as_ref()?;
    Some(m.dictionary_page_offset.unwrap_or(m.data_page_offset))
}

/// `o + by`, or an error where a corrupt offset overflows.
pub(super) fn moved(o: i64, by: i64) -> std::io::Result<i64> {
    o.checked_add(by)
        .ok_or_else(|| malformed(format!("offset {o} + {by} overflows")))
}

/// Move every byte position of a column chunk's footer entry by `by` bytes.
pub(super) fn shift_chunk(c: &mut ColumnChunk, by: i64) -> std::io::Result<()> {
    c.file_offset = moved(c.file_offset, by)?;
    if let Some(m) = c.meta_data.as_mut() {
        m.data_page_offset = moved(m.data_page_offset, by)?;
        m.dictionary_page_offset = m.dictionary_page_offset.map(|o| moved(o, by)).transpose()?;
        m.index_page_offset = m.index_page_offset.map(|o| moved(o, by)).transpose()?;
    }
    Ok(())
}

/// Move every page position of an offset index by `by` bytes.
pub(super) fn shift_offsets(index: &mut OffsetIndex, by: i64) -> std::io::Result<()> {
    for p in &mut index.page_locations {
        p.offset = moved(p.offset, by)?;
    }
    Ok(())
}

/// Read a thrift structure from `bytes`, with an allocation budget in proportion to them
/// ([`THRIFT_BUDGET_PER_BYTE`]).
pub(super) fn read_thrift<'b, T>(
    bytes: &'b [u8],
    read: impl FnOnce(&mut TCompactInputProtocol<&'b [u8]>) -> polars_parquet_format::thrift::Result<T>,
) -> std::io::Result<T> {
    let budget = bytes.len().saturating_mul(THRIFT_BUDGET_PER_BYTE);
    let mut p = TCompactInputProtocol::new(bytes, budget);
    read(&mut p).map_err(thrift_err)
}

/// The thrift bytes of a structure.
pub(super) fn thrift_bytes(
    write: impl FnOnce(
        &mut TCompactOutputProtocol<&mut Vec<u8>>,
    ) -> polars_parquet_format::thrift::Result<usize>,
) -> std::io::Result<Vec<u8>> {
    let mut out = Vec::new();
    write(&mut TCompactOutputProtocol::new(&mut out)).map_err(thrift_err)?;
    Ok(out)
}

/// `range` of `bytes`, or an error if it lies outside.
pub(super) fn slice(bytes: &[u8], start: i64, len: i64) -> std::io::Result<&[u8]> {
    let (Ok(start), Ok(len)) = (usize::try_from(start), usize::try_from(len)) else {
        return Err(malformed("negative offset or length"));
    };
    start
        .checked_add(len)
        .and_then(|end| bytes.get(start..end))
        .ok_or_else(|| malformed(format!("range {start}+{len} outside {} bytes", bytes.len())))
}

/// A source of a file's bytes by position.
pub(super) trait ReadAt {
    fn read_at(&mut self, start: i64, len: i64) -> std::io::Result<Vec<u8>>;
}

impl ReadAt for &[u8] {
    fn read_at(&mut self, start: i64, len: i64) -> std::io::Result<Vec<u8>> {
        slice(self, start, len).map(<[u8]>::to_vec)
    }
}

impl ReadAt for File {
    fn read_at(&mut self, start: i64, len: i64) -> std::io::Result<Vec<u8>> {
        let (Ok(start), Ok(len)) = (u64::try_from(start), usize::try_from(len)) else {
            return Err(malformed("negative offset or length"));
        };
        let end = start.saturating_add(len as u64);
        if end > self.metadata()?.len() {
            return Err(malformed(format!(
                "range {start}+{len} past the file's end"
            )));
        }
        let mut out = vec![0; len];
        self.seek(SeekFrom::Start(start))?;
        self.read_exact(&mut out)?;
        Ok(out)
    }
}

/// Group `rg` of a file read through `src`: its pages and its metadata made relative to
/// each column chunk (module docs). The chunks' pages are read in one span.
pub(super) fn take_group(src: &mut impl ReadAt, rg: &RowGroup) -> std::io::Result<EncodedGroup> {
    let mut spans = Vec::with_capacity(rg.columns.len());
    for c in &rg.columns {
        let start = chunk_start(c).ok_or_else(|| malformed("column chunk without metadata"))?;
        let len = c.meta_data.as_ref().map_or(0, |m| m.total_compressed_size);
        if c.meta_data
            .as_ref()
            .is_some_and(|m| m.bloom_filter_offset.is_some())
        {
            return Err(malformed("bloom filters are not supported"));
        }
        if c.file_path.is_some()
            || c.crypto_metadata.is_some()
            || c.encrypted_column_metadata.is_some()
        {
            return Err(malformed(
                "column chunks in other files or encrypted are not supported",
            ));
        }
        let end = start
            .checked_add(len)
            .filter(|_| start >= 0 && len >= 0)
            .ok_or_else(|| malformed(format!("column chunk at {start}, {len} bytes")))?;
        spans.push((start, len, end));
    }
    // The chunks follow each other in column order, each after the metadata of the one
    // before (a few hundred bytes): chunks that overlap, or a span much wider than the
    // chunks, are a corrupt entry, not read (each chunk's bytes are then read once).
    if spans.windows(2).any(|w| w[1].0 < w[0].2) {
        return Err(malformed(
            "a row group's column chunks overlap or are out of order",
        ));
    }
    let lo = spans.first().map_or(0, |s| s.0);
    let hi = spans.last().map_or(0, |s| s.2);
    let pages = spans
        .iter()
        .try_fold(0i64, |sum, s| sum.checked_add(s.1))
        .ok_or_else(|| malformed("a row group's chunk sizes overflow"))?;
    let slack = CHUNK_GAP_BYTES.saturating_mul(spans.len() as i64 + 1);
    if hi - lo > pages.saturating_add(slack) {
        return Err(malformed(format!(
            "a row group's chunks spread over {} bytes for {pages} bytes of pages",
            hi - lo
        )));
    }
    // The group's bytes are the span as read (the chunks' inline metadata between them is
    // left unused): each chunk is a range of it, not a copy.
    let bytes = src.read_at(lo, hi - lo)?;
    let mut chunks = Vec::with_capacity(rg.columns.len());
    for (c, (start, len, _)) in rg.columns.iter().zip(spans) {
        let at = (start - lo) as usize;
        let pages = at..at + slice(&bytes, start - lo, len)?.len();
        let mut meta = c.clone();
        shift_chunk(&mut meta, -start)?;
        let column_index = match (
            meta.column_index_offset.take(),
            meta.column_index_length.take(),
        ) {
            (Some(o), Some(l)) => Some(src.read_at(o, i64::from(index_len(l)?))?),
            _ => None,
        };
        let offset_index = match (
            meta.offset_index_offset.take(),
            meta.offset_index_length.take(),
        ) {
            (Some(o), Some(l)) => {
                let raw = src.read_at(o, i64::from(index_len(l)?))?;
                let mut index = read_thrift(&raw, OffsetIndex::read_from_in_protocol)?;
                shift_offsets(&mut index, -start)?;
                index
            }
            _ => return Err(malformed("column chunk without an offset index")),
        };
        chunks.push(Chunk {
            pages,
            meta,
            column_index,
            offset_index,
        });
    }
    let mut group = rg.clone();
    group.columns.clear();
    group.file_offset = None;
    group.ordinal = None;
    Ok(EncodedGroup {
        bytes,
        chunks,
        group,
    })
}

/// `l`, the length of a page index, if it is at most [`MAX_INDEX_BYTES`].
pub(super) fn index_len(l: i32) -> std::io::Result<i32> {
    if (0..=MAX_INDEX_BYTES).contains(&l) {
        Ok(l)
    } else {
        Err(malformed(format!("a page index of {l} bytes")))
    }
}

/// Where the footer of a Parquet file of `len` bytes starts, and its length: from its last
/// 8 bytes (the footer's length, `PAR1`).
pub(super) fn footer_span(src: &mut impl ReadAt, len: u64) -> std::io::Result<(u64, u64)> {
    if len < 12 {
        return Err(malformed("too short for a parquet file"));
    }
    let tail = src.read_at(len as i64 - 8, 8)?;
    if &tail[4..] != MAGIC {
        return Err(malformed("no parquet magic at the end"));
    }
    let meta_len = u64::from(u32::from_le_bytes([tail[0], tail[1], tail[2], tail[3]]));
    let start = (len - 8)
        .checked_sub(meta_len)
        .ok_or_else(|| malformed("footer longer than the file"))?;
    Ok((start, meta_len))
}

/// The whole footer of a Parquet file held in `bytes` or read from `file`.
pub(super) fn read_footer(src: &mut impl ReadAt, len: u64) -> std::io::Result<FileMetaData> {
    let (start, meta_len) = footer_span(src, len)?;
    if meta_len as usize > MAX_FOOTER_BYTES {
        return Err(malformed(format!("a footer of {meta_len} bytes")));
    }
    let raw = src.read_at(start as i64, meta_len as i64)?;
    read_thrift(&raw, FileMetaData::read_from_in_protocol)
}

/// The schema and options every group of one table is encoded with.
#[derive(Debug, Clone)]
pub struct GroupSchema {
    arrow: ArrowSchema,
    parquet: SchemaDescriptor,
    options: WriteOptions,
}

impl GroupSchema {
    /// The table's Arrow schema (the newest compatibility level, as polars' batched writer
    /// takes it), its Parquet schema and the page options.
    pub fn new(arrow: ArrowSchema, parquet: SchemaDescriptor, options: WriteOptions) -> Self {
        GroupSchema {
            arrow,
            parquet,
            options,
        }
    }

    fn writer(&self) -> FileWriter<Vec<u8>> {
        FileWriter::new_with_parquet_schema(
            Vec::new(),
            self.arrow.clone(),
            self.parquet.clone(),
            self.options,
        )
    }

    /// The footer polars writes for a file of no rows and no key-value pairs: the schema,
    /// the writer's name, the column orders.
    fn empty_footer(&self) -> std::io::Result<FileMetaData> {
        let mut w = self.writer();
        w.end(Some(Vec::new())).map_err(std::io::Error::other)?;
        Ok(w.into_inner_and_metadata().1)
    }
}

/// The bytes of a one-group Parquet file polars writes for `pages` (one `Vec` per leaf
/// column, in order) of `rows` rows.
pub(super) fn encode_group_bytes(
    schema: &GroupSchema,
    rows: u64,
    pages: &[Vec<CompressedPage>],
) -> std::io::Result<Vec<u8>> {
    let mut w = schema.writer();
    let group = DynIter::new(pages.iter().map(|col| {
        Ok(DynStreamingIterator::new(
            polars_parquet::write::fallible_streaming_iterator::convert(
                col.iter().map(polars::prelude::PolarsResult::Ok),
            ),
        ))
    }));
    w.write(rows, group).map_err(std::io::Error::other)?;
    w.end(Some(Vec::new())).map_err(std::io::Error::other)?;
    Ok(w.into_inner())
}

/// The one row group of a Parquet file held in `bytes`.
pub(super) fn group_from_bytes(bytes: &[u8]) -> std::io::Result<EncodedGroup> {
    let mut src = bytes;
    let footer = read_footer(&mut src, bytes.len() as u64)?;
    match footer.row_groups.as_slice() {
        [rg] => take_group(&mut src, rg),
        groups => Err(malformed(format!("{} row groups, not one", groups.len()))),
    }
}

/// `rows` rows encoded as `pages` (polars' compressed pages, one `Vec` per leaf column) as
/// a group that can be appended to any file of `schema`.
///
/// # Errors
/// polars cannot write the pages (a page of another schema).
pub fn encode(
    schema: &GroupSchema,
    rows: u64,
    pages: &[Vec<CompressedPage>],
) -> std::io::Result<EncodedGroup> {
    group_from_bytes(&encode_group_bytes(schema, rows, pages)?)
}

/// Bytes a [`ScratchStream`] holds in memory before it moves them to its file: a small
/// table (a query's output) writes no scratch file at all; the frames of a large build
/// (about 4 kB of footer entry and 2 kB of page index a clip) go to disk.
pub(super) const SCRATCH_MEMORY_BYTES: usize = 1 << 20;

/// A stream written in order and read back once: in memory up to
/// [`SCRATCH_MEMORY_BYTES`], then in a scratch file at `path`, removed when dropped.
pub(super) struct ScratchStream {
    path: PathBuf,
    held: Vec<u8>,
    out: Option<BufWriter<File>>,
    len: u64,
    read: bool,
}

impl ScratchStream {
    fn new(path: PathBuf) -> ScratchStream {
        ScratchStream {
            path,
            held: Vec::new(),
            out: None,
            len: 0,
            read: false,
        }
    }

    fn write(&mut self, bytes: &[u8]) -> std::io::Result<u64> {
        if self.read {
            return Err(std::io::Error::other("scratch stream already read"));
        }
        let at = self.len;
        if self.out.is_none() && self.held.len() + bytes.len() > SCRATCH_MEMORY_BYTES {
            let file = File::options()
                .read(true)
                .write(true)
                .create(true)
                .truncate(true)
                .open(&self.path)?;
            // Kept before it is written to, so that `Drop` removes it whatever fails.
            let out = self.out.insert(BufWriter::new(file));
            out.write_all(&std::mem::take(&mut self.held))?;
        }
        match self.out.as_mut() {
            Some(out) => out.write_all(bytes)?,
            None => self.held.extend_from_slice(bytes),
        }
        self.len += bytes.len() as u64;
        Ok(at)
    }

    /// The stream's bytes, from the start.
    fn reader(&mut self) -> std::io::Result<Box<dyn Read + '_>> {
        if std::mem::replace(&mut self.read, true) {
            return Err(std::io::Error::other("scratch stream already read"));
        }
        match self.out.take() {
            Some(out) => {
                let mut file = out.into_inner().map_err(|e| e.into_error())?;
                file.seek(SeekFrom::Start(0))?;
                Ok(Box::new(BufReader::new(file)))
            }
            None => Ok(Box::new(std::io::Cursor::new(std::mem::take(
                &mut self.held,
            )))),
        }
    }
}

impl Drop for ScratchStream {
    fn drop(&mut self) {
        if self.out.take().is_some() || self.read {
            let _ = std::fs::remove_file(&self.path);
        }
    }
}

/// A Parquet file written group by group ([`GroupFileWriter::append`]) and finished with
/// its footer ([`GroupFileWriter::finish`]): the bytes polars' `FileWriter` writes for the
/// same groups (module docs).
pub struct GroupFileWriter {
    path: PathBuf,
    file: BufWriter<File>,
    offset: u64,
    /// The footer without its groups, rows and key-value pairs.
    footer: FileMetaData,
    rows: i64,
    groups: usize,
    /// Each appended group's footer entry, thrift-encoded, its page index offsets counted
    /// from the start of the column and offset index streams.
    entries: ScratchStream,
    column_indexes: ScratchStream,
    offset_indexes: ScratchStream,
    /// Per leaf column of the schema: its path and physical type, which an appended
    /// group's chunks must have.
    leaves: Vec<(Vec<String>, Option<polars_parquet_format::Type>)>,
    /// A write failed part-way: the file is not finished.
    failed: bool,
}

/// The names (`<table>.<what>`, before [`scratch_name`]) of the scratch files a
/// [`GroupFileWriter`] of table `table` makes beside it, for the removal of those a killed
/// run left ([`super::scratch::remove_stale`]).
pub fn scratch_stems(table: &str) -> [String; 3] {
    ["groups", "column-index", "offset-index"].map(|what| format!("{table}.{what}"))
}

/// Per leaf column of a footer's schema (depth-first, the root left out): its path and
/// physical type.
pub(super) fn leaf_columns(
    schema: &[polars_parquet_format::SchemaElement],
) -> Vec<(Vec<String>, Option<polars_parquet_format::Type>)> {
    fn walk(
        els: &[polars_parquet_format::SchemaElement],
        at: &mut usize,
        path: &mut Vec<String>,
        out: &mut Vec<(Vec<String>, Option<polars_parquet_format::Type>)>,
    ) {
        let Some(e) = els.get(*at) else { return };
        *at += 1;
        path.push(e.name.clone());
        match e.num_children {
            Some(n) => (0..n).for_each(|_| walk(els, at, path, out)),
            None => out.push((path.clone(), e.type_)),
        }
        path.pop();
    }
    let mut out = Vec::new();
    let mut at = 1;
    let mut path = Vec::new();
    let children = schema.first().and_then(|r| r.num_children).unwrap_or(0);
    for _ in 0..children {
        walk(schema, &mut at, &mut path, &mut out);
    }
    out
}

impl GroupFileWriter {
    /// Start `path` (created or truncated) for groups of `schema`; its scratch files, if
    /// the groups' footer entries and page indexes grow past 1 MiB, are
    /// made beside it, named after `table` ([`scratch_stems`]).
    pub fn create(
        path: &Path,
        table: &str,
        schema: &GroupSchema,
    ) -> std::io::Result<GroupFileWriter> {
        let footer = schema.empty_footer()?;
        let dir = path.parent().unwrap_or(Path::new("."));
        let [groups, column_index, offset_index] =
            scratch_stems(table).map(|stem| dir.join(scratch_name(&stem, Scratch::Tmp)));
        let entries = ScratchStream::new(groups);
        let column_indexes = ScratchStream::new(column_index);
        let offset_indexes = ScratchStream::new(offset_index);
        let mut file = BufWriter::with_capacity(1 << 20, File::create(path)?);
        file.write_all(MAGIC)?;
        Ok(GroupFileWriter {
            path: path.to_path_buf(),
            file,
            offset: MAGIC.len() as u64,
            leaves: leaf_columns(&footer.schema),
            footer,
            rows: 0,
            groups: 0,
            entries,
            column_indexes,
            offset_indexes,
            failed: false,
        })
    }

    /// A group of other columns (their count, paths or physical types) is refused. Logical
    /// types and repetition are not compared: a merge has already required the shards'
    /// schema and tool version to be the running tool's.
    fn check_schema(&self, g: &EncodedGroup) -> std::io::Result<()> {
        if g.chunks.len() != self.leaves.len() {
            return Err(malformed(format!(
                "a row group of {} columns for a table of {}",
                g.chunks.len(),
                self.leaves.len()
            )));
        }
        for (c, (path, type_)) in g.chunks.iter().zip(&self.leaves) {
            let m = c.meta.meta_data.as_ref();
            if m.map(|m| &m.path_in_schema) != Some(path) || m.map(|m| m.type_) != *type_ {
                return Err(malformed(format!(
                    "a row group's column {:?} where the table has {}",
                    m.map(|m| m.path_in_schema.join(".")),
                    path.join(".")
                )));
            }
        }
        Ok(())
    }

    /// Append `g` after the groups written so far.
    ///
    /// # Errors
    /// `g` has other columns than the table, a write fails, or one failed before (the
    /// file is then not finished).
    pub fn append(&mut self, g: &EncodedGroup) -> std::io::Result<()> {
        if self.failed {
            return Err(std::io::Error::other("an earlier write failed"));
        }
        self.check_schema(g)?;
        self.failed = true;
        self.append_checked(g)?;
        self.failed = false;
        Ok(())
    }

    fn append_checked(&mut self, g: &EncodedGroup) -> std::io::Result<()> {
        let mut rg = g.group.clone();
        rg.columns = Vec::with_capacity(g.chunks.len());
        for c in &g.chunks {
            let start = self.offset as i64;
            self.file.write_all(&g.bytes[c.pages.clone()])?;
            self.offset += c.pages.len() as u64;
            let mut meta = c.meta.clone();
            shift_chunk(&mut meta, start)?;
            if let Some(m) = meta.meta_data.as_ref() {
                let inline = thrift_bytes(|p| m.write_to_out_protocol(p))?;
                self.file.write_all(&inline)?;
                self.offset += inline.len() as u64;
            }
            if let Some(ci) = &c.column_index {
                meta.column_index_offset = Some(self.column_indexes.write(ci)? as i64);
                meta.column_index_length = Some(len_i32(ci.len())?);
            }
            let mut oi = c.offset_index.clone();
            shift_offsets(&mut oi, start)?;
            let oi = thrift_bytes(|p| oi.write_to_out_protocol(p))?;
            meta.offset_index_offset = Some(self.offset_indexes.write(&oi)? as i64);
            meta.offset_index_length = Some(len_i32(oi.len())?);
            rg.columns.push(meta);
        }
        rg.file_offset = rg.columns.first().and_then(|c| {
            let m = c.meta_data.as_ref()?;
            m.dictionary_page_offset
                .filter(|o| *o > 0)
                .or(Some(m.data_page_offset))
        });
        rg.ordinal = i16::try_from(self.groups).ok();
        let rows = self
            .rows
            .checked_add(rg.num_rows)
            .ok_or_else(|| malformed("row count overflows"))?;
        let entry = thrift_bytes(|p| rg.write_to_out_protocol(p))?;
        self.entries.write(&(entry.len() as u64).to_le_bytes())?;
        self.entries.write(&entry)?;
        self.rows = rows;
        self.groups += 1;
        Ok(())
    }

    /// Write the page indexes and the footer with `kv`; returns the file's length.
    ///
    /// # Errors
    /// A write fails.
    pub fn finish(mut self, kv: Vec<KeyValue>) -> std::io::Result<u64> {
        if self.failed {
            return Err(std::io::Error::other("an earlier write failed"));
        }
        let column_base = self.offset as i64;
        self.offset += std::io::copy(&mut self.column_indexes.reader()?, &mut self.file)?;
        let offset_base = self.offset as i64;
        self.offset += std::io::copy(&mut self.offset_indexes.reader()?, &mut self.file)?;
        let mut entries = self.entries.reader()?;
        let mut footer = self.footer.clone();
        footer.num_rows = self.rows;
        footer.key_value_metadata = Some(kv);
        let groups = self.groups;
        let mut next_group = || -> std::io::Result<RowGroup> {
            let mut len = [0u8; 8];
            entries.read_exact(&mut len)?;
            let len = u64::from_le_bytes(len) as usize;
            if len > MAX_GROUP_ENTRY_BYTES {
                return Err(malformed(format!("a row group entry of {len} bytes")));
            }
            let mut raw = vec![0; len];
            entries.read_exact(&mut raw)?;
            let mut rg = read_thrift(&raw, RowGroup::read_from_in_protocol)?;
            for c in &mut rg.columns {
                c.column_index_offset = c.column_index_offset.map(|o| o + column_base);
                c.offset_index_offset = c.offset_index_offset.map(|o| o + offset_base);
            }
            Ok(rg)
        };
        // Streamed to the file: a footer grows with the groups (about 4 kB each).
        let mut out = Counted {
            inner: &mut self.file,
            bytes: 0,
        };
        write_footer(&mut out, &footer, groups, &mut next_group)?;
        let meta_len = out.bytes;
        self.file.write_all(&len_i32(meta_len)?.to_le_bytes())?;
        self.file.write_all(MAGIC)?;
        self.file.flush()?;
        self.offset += meta_len as u64 + 8;
        Ok(self.offset)
    }

    /// The file being written.
    pub fn path(&self) -> &Path {
        &self.path
    }
}

#[cfg(test)]
mod tests;
