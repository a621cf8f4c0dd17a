//! Reading a Parquet file's row groups in order, one at a time, as [`EncodedGroup`]s to
//! append to another file ([`super::row_groups::GroupFileWriter`]): the footer is read as
//! the groups are, never held whole.

use std::fs::File;
use std::io::{BufReader, Seek, SeekFrom};
use std::path::{Path, PathBuf};

use polars_parquet_format::thrift::protocol::{TCompactInputProtocol, TInputProtocol, TType};
use polars_parquet_format::RowGroup;

use super::footer::*;
use super::row_groups::*;
use crate::error::{Error, Result};

/// The statistics (minimum, maximum) of the leaf column named `name` in a group's footer
/// entry, raw Parquet bytes (a string's UTF-8).
fn column_range<'a>(rg: &'a RowGroup, name: &str) -> Option<(&'a [u8], &'a [u8])> {
    rg.columns.iter().find_map(|c| {
        let m = c.meta_data.as_ref()?;
        if m.path_in_schema.len() != 1 || m.path_in_schema[0] != name {
            return None;
        }
        let st = m.statistics.as_ref()?;
        Some((st.min_value.as_deref()?, st.max_value.as_deref()?))
    })
}

/// The row groups of a Parquet file, read in order one at a time as [`EncodedGroup`]s.
/// The footer is read as the groups are, never held whole: a file of thousands of
/// groups (one per clip) costs one group's metadata in memory.
pub struct GroupFileReader {
    path: PathBuf,
    data: File,
    /// The footer, positioned at the next group's entry in its list of row groups.
    footer: BufReader<File>,
    /// Groups whose entries are not read yet.
    left: usize,
    /// The next group's entry, read ahead by [`GroupFileReader::peek_value`].
    pub(super) next: Option<RowGroup>,
}

fn io(path: &Path, what: &str, e: impl std::error::Error + Send + Sync + 'static) -> Error {
    Error::io(path, what, e)
}

/// Read a footer up to its list of row groups; the number of groups.
fn footer_to_groups(footer: &mut BufReader<File>, len: usize) -> std::io::Result<usize> {
    let mut p = TCompactInputProtocol::new(footer, len.saturating_mul(THRIFT_BUDGET_PER_BYTE));
    p.read_struct_begin().map_err(thrift_err)?;
    loop {
        let field = p.read_field_begin().map_err(thrift_err)?;
        match (field.field_type, field.id) {
            (TType::Stop, _) => return Err(malformed("footer without row groups")),
            (TType::List, Some(4)) => {
                let list = p.read_list_begin().map_err(thrift_err)?;
                return Ok(list.size as usize);
            }
            (t, _) => p.skip(t).map_err(thrift_err)?,
        }
        p.read_field_end().map_err(thrift_err)?;
    }
}

impl GroupFileReader {
    /// Open `path` and read its footer up to the first group's entry.
    ///
    /// # Errors
    /// The file cannot be read or is not Parquet.
    pub fn open(path: &Path) -> Result<GroupFileReader> {
        let err = |e| io(path, "cannot read parquet", e);
        let mut data = File::open(path).map_err(|e| io(path, "cannot open", e))?;
        let len = data.metadata().map_err(err)?.len();
        let (start, meta_len) = footer_span(&mut data, len).map_err(err)?;
        let mut footer = BufReader::new(File::open(path).map_err(|e| io(path, "cannot open", e))?);
        footer.seek(SeekFrom::Start(start)).map_err(err)?;
        let left = footer_to_groups(&mut footer, meta_len as usize).map_err(err)?;
        Ok(GroupFileReader {
            path: path.to_path_buf(),
            data,
            footer,
            left,
            next: None,
        })
    }

    /// The next group's entry, read from the footer if not read yet (`None` after the last).
    pub(super) fn peek(&mut self) -> Result<Option<&RowGroup>> {
        if self.next.is_none() && self.left > 0 {
            let rg = self
                .read_entry()
                .map_err(|e| io(&self.path, "cannot read parquet", e))?;
            self.left -= 1;
            self.next = Some(rg);
        }
        Ok(self.next.as_ref())
    }

    /// The next group's entry, read with the allocation budget of the longest entry
    /// accepted ([`MAX_GROUP_ENTRY_BYTES`]): whatever lengths a corrupt entry claims, it
    /// allocates a bounded amount (about 70 MB at most) before it is refused.
    fn read_entry(&mut self) -> std::io::Result<RowGroup> {
        let mut counted = CountedRead {
            inner: &mut self.footer,
            bytes: 0,
        };
        let budget = MAX_GROUP_ENTRY_BYTES * THRIFT_BUDGET_PER_BYTE;
        let rg =
            RowGroup::read_from_in_protocol(&mut TCompactInputProtocol::new(&mut counted, budget))
                .map_err(thrift_err)?;
        if counted.bytes > MAX_GROUP_ENTRY_BYTES {
            return Err(malformed(format!(
                "a row group entry of {} bytes",
                counted.bytes
            )));
        }
        Ok(rg)
    }

    /// The value of column `name` in the next group, when that group holds one value of it
    /// (its minimum and maximum statistics are equal); `None` after the last group.
    ///
    /// # Errors
    /// The footer cannot be read, or the group has no statistics for `name` or more than
    /// one value of it (not a table of one clip per group).
    pub fn peek_value(&mut self, name: &str) -> Result<Option<Vec<u8>>> {
        let path = self.path.clone();
        let Some(rg) = self.peek()? else {
            return Ok(None);
        };
        match column_range(rg, name) {
            Some((lo, hi)) if lo == hi => Ok(Some(lo.to_vec())),
            _ => Err(io(
                &path,
                "cannot read parquet",
                malformed(format!(
                    "a row group holds no single value of column {name}"
                )),
            )),
        }
    }

    /// The next row group with its pages; `None` after the last.
    ///
    /// # Errors
    /// Its entry or bytes cannot be read or are malformed.
    pub fn next_group(&mut self) -> Result<Option<EncodedGroup>> {
        self.peek()?;
        let Some(rg) = self.next.take() else {
            return Ok(None);
        };
        take_group(&mut self.data, &rg)
            .map(Some)
            .map_err(|e| io(&self.path, "cannot read parquet", e))
    }
}
