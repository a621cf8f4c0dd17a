//! Reading the tables back: typed columns with errors that name the file, column and row,
//! and the stance pool of the queries (`stances.parquet` + `clips.parquet`).

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use polars::prelude::*;

use crate::error::{Error, Result};

use super::layout::{locate_path, read_source};
use super::stances::PoolStance;
pub use super::stances::{read_stance_timing, read_stances};

use super::schema::{clips, CLIPS_FILE, STANCES_FILE};

/// Read a Parquet file into a DataFrame; a library table's `file`-layout path
/// (`LIB/stances.parquet`) reads the table in the library's layout
/// ([`super::layout::locate_path`]).
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

    /// A list<float64> column without null lists or items; `len` fixes every list's length.
    ///
    /// # Errors
    /// Missing column, another type, a null, or a list of another length.
    pub fn f64_lists(&self, name: &str, len: Option<usize>) -> Result<Vec<Vec<f64>>> {
        self.lists(name, &DataType::Float64, len, |s| {
            s.f64().ok().map(|c| c.iter().collect())
        })
    }

    /// A list<int32> column without null lists or items.
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

/// Per-clip facts the queries need from `clips.parquet`.
#[derive(Debug, Clone, PartialEq)]
pub struct ClipInfo {
    /// Effective time scale of the clip's flights (`com-from-bvh.md` §7.7), when it has any.
    pub s_eff: Option<f64>,
    /// Leg length `L_leg`, m.
    pub leg_m: Option<f64>,
    /// Body mass, kg.
    pub mass_kg: f64,
    /// SHA-256 of the clip file's bytes, hex (empty when the file was not read).
    pub content_sha256: String,
}

/// Clips whose file content (SHA-256) repeats an earlier clip's, each mapped to the first
/// clip by name with that content; empty hashes (files never read) are not compared.
pub fn same_content<'a>(
    clips: impl IntoIterator<Item = (&'a str, &'a str)>,
) -> BTreeMap<String, String> {
    let mut sorted: Vec<(&str, &str)> = clips.into_iter().filter(|(_, h)| !h.is_empty()).collect();
    sorted.sort();
    let mut first: BTreeMap<&str, &str> = BTreeMap::new();
    let mut out = BTreeMap::new();
    for (name, hash) in sorted {
        match first.get(hash) {
            Some(of) => {
                out.insert(name.to_string(), of.to_string());
            }
            None => {
                first.insert(hash, name);
            }
        }
    }
    out
}

/// A library folder as the queries see it.
#[derive(Debug, Clone)]
pub struct StanceLibrary {
    /// The folder.
    pub dir: PathBuf,
    /// Every stance row, in file order (sorted by `stance_id`'s parts).
    pub stances: Vec<PoolStance>,
    /// Per-clip facts by clip name.
    pub clips: BTreeMap<String, ClipInfo>,
}

/// Reads the per-clip facts of `clips.parquet`.
///
/// # Errors
/// The file cannot be read, or a column is missing or mistyped.
pub fn read_clip_info(path: &Path) -> Result<BTreeMap<String, ClipInfo>> {
    let t = Table::open(path)?;
    let (names, s_eff, leg, mass) = (
        t.strings(clips::CLIP)?,
        t.opt_f64(clips::S_EFF)?,
        t.opt_f64(clips::LEG_LENGTH)?,
        t.opt_f64(clips::MASS)?,
    );
    let sha = t.strings(clips::CONTENT_SHA256)?;
    Ok(names
        .into_iter()
        .enumerate()
        .map(|(i, n)| {
            let info = ClipInfo {
                s_eff: s_eff[i],
                leg_m: leg[i],
                mass_kg: mass[i].unwrap_or(f64::NAN),
                content_sha256: sha[i].clone(),
            };
            (n, info)
        })
        .collect())
}

/// Opens a library folder: its stances and clips.
///
/// # Errors
/// A library of another table layout ([`super::provenance::check_layout`]), a missing or
/// unreadable `stances.parquet` or `clips.parquet` (the error names it).
pub fn open_library(dir: &Path) -> Result<StanceLibrary> {
    super::provenance::check_layout(dir)?;
    Ok(StanceLibrary {
        dir: dir.to_path_buf(),
        stances: read_stances(&dir.join(STANCES_FILE))?,
        clips: read_clip_info(&dir.join(CLIPS_FILE))?,
    })
}

/// A clip's source file as `clips.parquet` records it.
#[derive(Debug, Clone, PartialEq)]
pub struct ClipSource {
    /// The path as given to the build.
    pub path: String,
    /// SHA-256 of the file's bytes (hex).
    pub content_sha256: String,
    /// Metres per file unit.
    pub unit_scale: Option<f64>,
    /// Up axis (`+Y`, …).
    pub up_axis: Option<String>,
}

/// The source file of every clip of `clips.parquet`, by clip name.
///
/// # Errors
/// The file cannot be read, or a column is missing or mistyped.
pub fn read_clip_sources(path: &Path) -> Result<BTreeMap<String, ClipSource>> {
    let t = Table::open(path)?;
    let (names, paths, sha) = (
        t.strings(clips::CLIP)?,
        t.strings(clips::PATH)?,
        t.strings(clips::CONTENT_SHA256)?,
    );
    let (unit, up) = (
        t.opt_f64(clips::UNIT_SCALE)?,
        opt_strings(&t, clips::UP_AXIS)?,
    );
    Ok(names
        .into_iter()
        .enumerate()
        .map(|(i, n)| {
            let c = ClipSource {
                path: paths[i].clone(),
                content_sha256: sha[i].clone(),
                unit_scale: unit[i],
                up_axis: up[i].clone(),
            };
            (n, c)
        })
        .collect())
}

fn opt_strings(t: &Table, name: &str) -> Result<Vec<Option<String>>> {
    let s = t
        .column(name)?
        .str()
        .map_err(|_| t.wrong_type(name, "string"))?;
    Ok(s.iter().map(|v| v.map(str::to_string)).collect())
}
