//! Reading a library table forward in clip order, a range of clips at a time
//! ([`ClipCursor`]): what an incremental build and a merge take rows from.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use polars::prelude::*;

use super::tables::strings;
use crate::error::{Error, Result};
use crate::library::codec::schema::frames;
use crate::library::codec::table::parquet_rows;
use crate::library::storage::layout::{locate_path, read_source, TableSource};
use crate::library::storage::stream::read_rows;
use crate::library::storage::stream::ROW_GROUP_ROWS;

/// A table sorted by clip, read forward in clip order: the rows of a range of clips at a
/// time, never the whole file (the last row group read is kept, as the next range of
/// clips usually starts in it).
pub(crate) struct ClipCursor {
    path: PathBuf,
    /// Consecutive rows per clip, in file order.
    runs: Vec<(String, usize)>,
    next: usize,
    offset: usize,
    /// The last row group read (its first row and rows): the next batches of clips
    /// usually lie in it, and decoding it again per batch dominated a merge of 8 shards.
    cache: Option<(usize, DataFrame)>,
    /// The whole table, when it is not one file (a partitioned table of a `dataset`
    /// library, read whole and put in file order).
    whole: Option<DataFrame>,
}

impl ClipCursor {
    /// Index the `clip` column of table `path` (a library table in its library's layout:
    /// one file is read a row group's worth at a time, a partitioned table whole).
    pub fn open(path: &Path) -> Result<ClipCursor> {
        let src = locate_path(path)?;
        let (path, whole) = match &src {
            TableSource::File(p) => (p.clone(), None),
            TableSource::Parts { dir, .. } => (dir.clone(), Some(read_source(&src, None)?)),
        };
        let mut runs: Vec<(String, usize)> = Vec::new();
        let mut add = |df: &DataFrame| {
            for c in strings(df, frames::CLIP) {
                match runs.last_mut() {
                    Some((last, n)) if *last == c => *n += 1,
                    _ => runs.push((c, 1)),
                }
            }
        };
        match &whole {
            Some(df) => add(df),
            None => index_clips(&path, &mut add)?,
        }
        Ok(ClipCursor {
            path,
            runs,
            next: 0,
            offset: 0,
            cache: None,
            whole,
        })
    }

    /// The clip of the next rows not read yet, if any are left.
    pub fn next_clip(&self) -> Option<&str> {
        self.runs.get(self.next).map(|(c, _)| c.as_str())
    }

    /// The table's rows per clip (all of them, read or not).
    pub fn rows_per_clip(&self) -> BTreeMap<&str, u64> {
        let mut out: BTreeMap<&str, u64> = BTreeMap::new();
        for (c, n) in &self.runs {
            *out.entry(c.as_str()).or_default() += *n as u64;
        }
        out
    }

    /// Rows `start .. start + len`, read a row group's worth at a time through the cache.
    fn rows(&mut self, start: usize, len: usize) -> Result<DataFrame> {
        if let Some(df) = &self.whole {
            return Ok(df.slice(start as i64, len));
        }
        let (end, mut at) = (start + len, start);
        let mut out: Option<DataFrame> = None;
        while at < end {
            let group = at / ROW_GROUP_ROWS * ROW_GROUP_ROWS;
            if self.cache.as_ref().map(|c| c.0) != Some(group) {
                self.cache = Some((group, read_rows(&self.path, group, ROW_GROUP_ROWS)?));
            }
            let Some((_, df)) = self.cache.as_ref() else {
                break;
            };
            let take = end.min(group + df.height()).saturating_sub(at);
            if take == 0 {
                break;
            }
            let part = df.slice((at - group) as i64, take);
            out = Some(match out {
                None => part,
                Some(mut o) => {
                    o.vstack_mut(&part)
                        .map_err(|e| Error::io(&self.path, "cannot stack rows", e))?;
                    o
                }
            });
            at += take;
        }
        match out {
            Some(mut o) => {
                o.rechunk_mut();
                Ok(o)
            }
            None => read_rows(&self.path, start, 0),
        }
    }

    /// The rows of every clip not read yet up to and including `last` (by name), keeping
    /// the clips `keep` accepts.
    pub fn take_through(
        &mut self,
        last: &str,
        keep: &dyn Fn(&str) -> bool,
    ) -> Result<Option<DataFrame>> {
        let start = self.offset;
        let mut wanted: Vec<bool> = Vec::new();
        while let Some((c, n)) = self.runs.get(self.next) {
            if c.as_str() > last {
                break;
            }
            wanted.extend(std::iter::repeat_n(keep(c), *n));
            self.offset += n;
            self.next += 1;
        }
        if wanted.iter().all(|w| !w) {
            return Ok(None);
        }
        let df = self.rows(start, self.offset - start)?;
        if wanted.iter().all(|w| *w) {
            return Ok(Some(df));
        }
        let mask: BooleanChunked = wanted.into_iter().collect();
        df.filter(&mask)
            .map(Some)
            .map_err(|e| Error::io(&self.path, "cannot filter rows", e))
    }
}

/// Call `add` on the `clip` column of the file `path`, a row group's worth at a time.
fn index_clips(path: &Path, add: &mut dyn FnMut(&DataFrame)) -> Result<()> {
    let total = parquet_rows(path)?;
    let mut at = 0;
    while at < total {
        let f = std::fs::File::open(path).map_err(|e| Error::io(path, "cannot open", e))?;
        let df = ParquetReader::new(f)
            .with_columns(Some(vec![frames::CLIP.into()]))
            .with_slice(Some((at, ROW_GROUP_ROWS)))
            .finish()
            .map_err(|e| Error::io(path, "cannot read parquet", e))?;
        if df.height() == 0 {
            break;
        }
        at += df.height();
        add(&df);
    }
    Ok(())
}

#[cfg(test)]
mod cursor_tests {
    use super::*;
    use crate::library::storage::stream::TableWriter;

    // See: issue 16 item 3 — a merge decoded a row group again for every batch of clips
    // that touched it; the cursor keeps the last one, and must still give the same rows.
    #[test]
    fn a_clip_cursor_gives_the_rows_of_the_file_across_row_groups() {
        let d = tempfile::tempdir().unwrap();
        let n = 2 * ROW_GROUP_ROWS + 999;
        // Clips of 1,000 rows each, named in order.
        let clip: Vec<String> = (0..n).map(|i| format!("c{:04}", i / 1000)).collect();
        let v: Vec<i64> = (0..n as i64).collect();
        let df = DataFrame::new_infer_height(vec![
            Column::new("clip".into(), clip.clone()),
            Column::new("v".into(), v),
        ])
        .unwrap();
        let mut w = TableWriter::create(d.path(), "t.parquet", &df).unwrap();
        w.push(&df).unwrap();
        w.finish(&[]).unwrap();
        let mut cur = ClipCursor::open(&d.path().join("t.parquet")).unwrap();
        let mut seen: Vec<i64> = Vec::new();
        // Batches of 7 clips (7,000 rows: some cross a row group); every third clip kept.
        for last in (6..=(n / 1000)).step_by(7).chain([n / 1000]) {
            let keep = |c: &str| c[1..].parse::<usize>().unwrap() % 3 == 0;
            if let Some(rows) = cur.take_through(&format!("c{last:04}"), &keep).unwrap() {
                seen.extend(rows.column("v").unwrap().i64().unwrap().into_no_null_iter());
            }
        }
        let want: Vec<i64> = (0..n as i64).filter(|i| (i / 1000) % 3 == 0).collect();
        assert_eq!(seen, want);
    }
}
