//! Reading a table back: a Parquet file or a library table in its library's layout,
//! whole, by columns or by row count, with typed column access whose errors name the file,
//! column and row ([`Table`]).

use std::path::{Path, PathBuf};

use polars::prelude::*;

use crate::error::{Error, Result};
use crate::library::storage::layout::{locate_path, read_source};

/// Read a Parquet file into a DataFrame; a library table's `file`-layout path
/// (`LIB/stances.parquet`) reads the table in the library's layout
/// ([`crate::library::storage::layout::locate_path`]).
///
/// # Errors
/// The file cannot be opened or is not valid Parquet.
pub fn read_parquet(path: &Path) -> Result<DataFrame> {
    read_source(&locate_path(path)?, None)
}

/// The number of rows of a Parquet file (or of a library table, as [`read_parquet`]), from
/// the footers (nothing else is read).
///
/// # Errors
/// The file cannot be opened or is not valid Parquet.
pub fn parquet_rows(path: &Path) -> Result<usize> {
    let mut n = 0;
    for p in locate_path(path)?.files() {
        let f = std::fs::File::open(&p).map_err(|e| Error::io(&p, "cannot open", e))?;
        n += ParquetReader::new(f)
            .num_rows()
            .map_err(|e| Error::io(&p, "cannot read parquet", e))?;
    }
    Ok(n)
}

/// A Parquet file already opened (by the caller's input checks): its row count from the
/// footer, then, if the caller goes on, its rows. Nothing is read again by path.
pub struct OpenedParquet {
    path: PathBuf,
    reader: ParquetReader<std::fs::File>,
}

impl OpenedParquet {
    /// Wraps `file`, opened from `path` (named in errors).
    pub fn new(path: &Path, file: std::fs::File) -> Self {
        OpenedParquet {
            path: path.to_path_buf(),
            reader: ParquetReader::new(file),
        }
    }

    /// The number of rows, from the footer (no row is decoded).
    ///
    /// # Errors
    /// Not valid Parquet.
    pub fn rows(&mut self) -> Result<usize> {
        let path = &self.path;
        self.reader
            .num_rows()
            .map_err(|e| Error::io(path, "cannot read parquet", e))
    }

    /// Every row, as a [`Table`].
    ///
    /// # Errors
    /// Not valid Parquet.
    pub fn read(self) -> Result<Table> {
        let df = self
            .reader
            .finish()
            .map_err(|e| Error::io(&self.path, "cannot read parquet", e))?;
        Ok(Table {
            path: self.path,
            df,
        })
    }
}

/// A table read from a file: typed column access whose errors name the file and column.
pub struct Table {
    /// The file it came from.
    pub path: PathBuf,
    /// Its rows.
    pub df: DataFrame,
}

impl Table {
    /// Reads `path` (a library table in its library's layout, as [`read_parquet`]).
    ///
    /// # Errors
    /// The file cannot be opened or is not valid Parquet.
    pub fn open(path: &Path) -> Result<Self> {
        let src = locate_path(path)?;
        Ok(Table {
            path: src.path().to_path_buf(),
            df: read_source(&src, None)?,
        })
    }

    /// Reads only the columns `names` of `path` (the rest of the file is not decoded).
    ///
    /// # Errors
    /// The file cannot be opened, is not valid Parquet, or lacks one of `names`.
    pub fn open_columns(path: &Path, names: &[&str]) -> Result<Self> {
        let src = locate_path(path)?;
        Ok(Table {
            path: src.path().to_path_buf(),
            df: read_source(&src, Some(names))?,
        })
    }

    /// Number of rows.
    pub fn height(&self) -> usize {
        self.df.height()
    }

    fn column(&self, name: &str) -> Result<&Column> {
        self.df
            .column(name)
            .map_err(|_| Error::column(&self.path, name, None, "missing"))
    }

    fn wrong_type(&self, name: &str, want: &str) -> Error {
        let found = self
            .df
            .column(name)
            .map(|c| c.dtype().to_string())
            .unwrap_or_default();
        Error::column(
            &self.path,
            name,
            None,
            format!("expected {want}, found {found}"),
        )
    }

    fn null(&self, name: &str, row: usize) -> Error {
        Error::column(
            &self.path,
            name,
            Some(row),
            "null where a value is required",
        )
    }

    /// A float64 column, nulls kept.
    ///
    /// # Errors
    /// Missing column or another type.
    pub fn opt_f64(&self, name: &str) -> Result<Vec<Option<f64>>> {
        let c = self.column(name)?;
        let s = c.f64().map_err(|_| self.wrong_type(name, "float64"))?;
        Ok(s.iter().collect())
    }

    /// A float64 column added to the layout after some libraries were written: all null
    /// when the table has no such column (an older library), else [`Table::opt_f64`].
    ///
    /// # Errors
    /// The column exists with another type.
    pub fn added_f64(&self, name: &str) -> Result<Vec<Option<f64>>> {
        if self.df.column(name).is_err() {
            return Ok(vec![None; self.height()]);
        }
        self.opt_f64(name)
    }

    /// A float64 column without nulls.
    ///
    /// # Errors
    /// Missing column, another type, or a null.
    pub fn f64s(&self, name: &str) -> Result<Vec<f64>> {
        self.opt_f64(name)?
            .into_iter()
            .enumerate()
            .map(|(i, v)| v.ok_or_else(|| self.null(name, i)))
            .collect()
    }

    /// An int64 column without nulls.
    ///
    /// # Errors
    /// Missing column, another type, or a null.
    pub fn i64s(&self, name: &str) -> Result<Vec<i64>> {
        let c = self.column(name)?;
        let s = c.i64().map_err(|_| self.wrong_type(name, "int64"))?;
        s.iter()
            .enumerate()
            .map(|(i, v)| v.ok_or_else(|| self.null(name, i)))
            .collect()
    }

    /// A boolean column without nulls.
    ///
    /// # Errors
    /// Missing column, another type, or a null.
    pub fn bools(&self, name: &str) -> Result<Vec<bool>> {
        let c = self.column(name)?;
        let s = c.bool().map_err(|_| self.wrong_type(name, "boolean"))?;
        s.iter()
            .enumerate()
            .map(|(i, v)| v.ok_or_else(|| self.null(name, i)))
            .collect()
    }

    /// A string column without nulls.
    ///
    /// # Errors
    /// Missing column, another type, or a null.
    pub fn strings(&self, name: &str) -> Result<Vec<String>> {
        let c = self.column(name)?;
        let s = c.str().map_err(|_| self.wrong_type(name, "string"))?;
        s.iter()
            .enumerate()
            .map(|(i, v)| v.map(str::to_string).ok_or_else(|| self.null(name, i)))
            .collect()
    }

    /// A `list<float64>` column without null lists or items; `len` fixes every list's length.
    ///
    /// # Errors
    /// Missing column, another type, a null, or a list of another length.
    pub fn f64_lists(&self, name: &str, len: Option<usize>) -> Result<Vec<Vec<f64>>> {
        self.lists(name, &DataType::Float64, len, |s| {
            s.f64().ok().map(|c| c.iter().collect())
        })
    }

    /// A `list<int32>` column without null lists or items.
    ///
    /// # Errors
    /// Missing column, another type or a null.
    pub fn i32_lists(&self, name: &str) -> Result<Vec<Vec<i32>>> {
        self.lists(name, &DataType::Int32, None, |s| {
            s.i32().ok().map(|c| c.iter().collect())
        })
    }

    fn lists<T>(
        &self,
        name: &str,
        inner: &DataType,
        len: Option<usize>,
        items: impl Fn(&Series) -> Option<Vec<Option<T>>>,
    ) -> Result<Vec<Vec<T>>> {
        let c = self.column(name)?;
        let want = format!("list<{inner}>");
        let l = c.list().map_err(|_| self.wrong_type(name, &want))?;
        if l.inner_dtype() != inner {
            return Err(self.wrong_type(name, &want));
        }
        (0..l.len())
            .map(|i| {
                let v = l.get_as_series(i).ok_or_else(|| self.null(name, i))?;
                let vals = items(&v).ok_or_else(|| self.wrong_type(name, &want))?;
                let vals: Vec<T> = vals
                    .into_iter()
                    .collect::<Option<_>>()
                    .ok_or_else(|| self.null(name, i))?;
                match len {
                    Some(n) if vals.len() != n => Err(Error::column(
                        &self.path,
                        name,
                        Some(i),
                        format!("expected {n} values, found {}", vals.len()),
                    )),
                    _ => Ok(vals),
                }
            })
            .collect()
    }
}

pub(crate) fn opt_strings(t: &Table, name: &str) -> Result<Vec<Option<String>>> {
    let s = t
        .column(name)?
        .str()
        .map_err(|_| t.wrong_type(name, "string"))?;
    Ok(s.iter().map(|v| v.map(str::to_string)).collect())
}
