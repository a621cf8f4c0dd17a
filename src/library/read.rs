//! Reading the tables back: typed columns with errors that name the file, column and row,
//! and the stance pool of the queries (`stances.parquet` + `clips.parquet`).

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use polars::prelude::*;

use crate::constraints::Coefficients;
use crate::error::{Error, Result};
use crate::force_model::{AxisModel, ForceModel};
use crate::query::pool::PoolStance;
use crate::stances::params::StanceParams;
use crate::stances::segment::Boundary;

use super::schema::{CLIPS_FILE, STANCES_FILE};

/// Read a Parquet file into a DataFrame.
///
/// # Errors
/// The file cannot be opened or is not valid Parquet.
pub fn read_parquet(path: &Path) -> Result<DataFrame> {
    let f = std::fs::File::open(path).map_err(|e| Error::io(path, "cannot open", e))?;
    ParquetReader::new(f)
        .finish()
        .map_err(|e| Error::io(path, "cannot read parquet", e))
}

/// The number of rows of a Parquet file, from its footer (nothing else is read).
///
/// # Errors
/// The file cannot be opened or is not valid Parquet.
pub fn parquet_rows(path: &Path) -> Result<usize> {
    let f = std::fs::File::open(path).map_err(|e| Error::io(path, "cannot open", e))?;
    ParquetReader::new(f)
        .num_rows()
        .map_err(|e| Error::io(path, "cannot read parquet", e))
}

/// A table read from a file: typed column access whose errors name the file and column.
pub struct Table {
    /// The file it came from.
    pub path: PathBuf,
    /// Its rows.
    pub df: DataFrame,
}

impl Table {
    /// Reads `path`.
    ///
    /// # Errors
    /// The file cannot be opened or is not valid Parquet.
    pub fn open(path: &Path) -> Result<Self> {
        Ok(Table {
            path: path.to_path_buf(),
            df: read_parquet(path)?,
        })
    }

    /// Reads only the columns `names` of `path` (the rest of the file is not decoded).
    ///
    /// # Errors
    /// The file cannot be opened, is not valid Parquet, or lacks one of `names`.
    pub fn open_columns(path: &Path, names: &[&str]) -> Result<Self> {
        let f = std::fs::File::open(path).map_err(|e| Error::io(path, "cannot open", e))?;
        let df = ParquetReader::new(f)
            .with_columns(Some(names.iter().map(|n| n.to_string()).collect()))
            .finish()
            .map_err(|e| Error::io(path, "cannot read parquet", e))?;
        Ok(Table {
            path: path.to_path_buf(),
            df,
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

fn boundary(t: &Table, name: &str, row: usize, v: &str) -> Result<Boundary> {
    Boundary::parse(v).ok_or_else(|| {
        Error::column(
            &t.path,
            name,
            Some(row),
            format!("unknown boundary kind '{v}'"),
        )
    })
}

fn fixed<const N: usize>(v: &[f64]) -> [f64; N] {
    let mut out = [0.0; N];
    out.copy_from_slice(&v[..N]);
    out
}

/// One stance axis's model columns: `c0_*`, `harmonic_*`, `amp_*`, `phase_*`, `fit_rms_*`,
/// `poly_*`.
type AxisColumns = (
    Vec<f64>,
    Vec<Vec<i32>>,
    Vec<Vec<f64>>,
    Vec<Vec<f64>>,
    Vec<f64>,
    Vec<Vec<f64>>,
);

/// The force model of row `i` from one axis's columns.
fn axis_model(t: &Table, name: &str, i: usize, cols: &AxisColumns) -> Result<AxisModel> {
    let (c0, h, a, p, rms, poly) = cols;
    if h[i].len() != a[i].len() || h[i].len() != p[i].len() {
        return Err(Error::column(
            &t.path,
            &format!("harmonic_{name}"),
            Some(i),
            "harmonic, amp and phase lists differ in length",
        ));
    }
    let harmonics = h[i]
        .iter()
        .map(|&j| u32::try_from(j).ok().filter(|&j| j >= 1))
        .collect::<Option<Vec<u32>>>()
        .ok_or_else(|| {
            Error::column(
                &t.path,
                &format!("harmonic_{name}"),
                Some(i),
                "harmonics must be integers ≥ 1",
            )
        })?;
    Ok(AxisModel {
        c0: c0[i],
        harmonics,
        amps: a[i].clone(),
        phases: p[i].clone(),
        poly: poly[i].clone(),
        fit_rms: rms[i],
    })
}

/// Reads the stance rows of `stances.parquet` as query stances.
///
/// # Errors
/// The file cannot be read, or a column is missing, mistyped or null (the error names the
/// file, column and row).
pub fn read_stances(path: &Path) -> Result<Vec<PoolStance>> {
    let t = Table::open(path)?;
    let s = |n: &str| t.strings(n);
    let f = |n: &str| t.f64s(n);
    let (ids, clips, chars, labels) =
        (s("stance_id")?, s("clip")?, s("character_id")?, s("label")?);
    let (b0, b1) = (s("boundary_start")?, s("boundary_end")?);
    let first = t.i64s("first_frame")?;
    let names = [
        "z_c",
        "zs",
        "vs",
        "ze",
        "ve",
        "vp",
        "vps",
        "x",
        "z_td",
        "z_lo",
        "t_td_s",
        "t_lo_s",
        "t_e_s",
        "dt_s",
        "mass_kg",
        "cp_h",
        "cp_p",
        "min_f_v",
        "f_peak",
        "mu_req",
        "mu_req_robust",
        "ext_min",
        "ext_max",
    ];
    let cols: BTreeMap<&str, Vec<f64>> = names
        .iter()
        .map(|&n| Ok((n, f(n)?)))
        .collect::<Result<_>>()?;
    let v = |n: &str, i: usize| cols[n][i];
    let axis_cols = ["h", "p", "v"]
        .map(|a| {
            Ok((
                f(&format!("c0_{a}"))?,
                t.i32_lists(&format!("harmonic_{a}"))?,
                t.f64_lists(&format!("amp_{a}"), None)?,
                t.f64_lists(&format!("phase_{a}"), None)?,
                f(&format!("fit_rms_{a}"))?,
                t.f64_lists(&format!("poly_{a}"), None)?,
            ))
        })
        .into_iter()
        .collect::<Result<Vec<AxisColumns>>>()?;
    let l3 = |n: &str| t.f64_lists(n, Some(3));
    let (a_f, a_mu) = (l3("a_f")?, t.f64_lists("a_mu", Some(2))?);
    let (ang, h0) = (l3("ang_impulse")?, l3("ang_impulse_h0")?);
    let (r0, r1, s0, s1) = (
        l3("ell_r_min")?,
        l3("ell_r_max")?,
        l3("ell_s_min")?,
        l3("ell_s_max")?,
    );
    let (support, unilateral) = (t.bools("support_ok")?, t.bools("unilateral_ok")?);
    (0..t.height())
        .map(|i| {
            let mut axes: [AxisModel; 3] = Default::default();
            for (a, name) in ["h", "p", "v"].iter().enumerate() {
                let c = &axis_cols[a];
                axes[a] = axis_model(&t, name, i, c)?;
            }
            let params = StanceParams {
                zs: v("zs", i),
                vs: v("vs", i),
                ze: v("ze", i),
                ve: v("ve", i),
                vp: v("vp", i),
                vps: v("vps", i),
                x: v("x", i),
                z_td: v("z_td", i),
                z_lo: v("z_lo", i),
                t_td: v("t_td_s", i),
                t_lo: v("t_lo_s", i),
                t_e: v("t_e_s", i),
            };
            Ok(PoolStance {
                stance_id: ids[i].clone(),
                clip: clips[i].clone(),
                character_id: chars[i].clone(),
                label: labels[i].clone(),
                first_frame: first[i],
                boundary_start: boundary(&t, "boundary_start", i, &b0[i])?,
                boundary_end: boundary(&t, "boundary_end", i, &b1[i])?,
                z_c: v("z_c", i),
                params,
                model: ForceModel {
                    mass_kg: v("mass_kg", i),
                    dt_s: v("dt_s", i),
                    axes,
                },
                cp: [v("cp_h", i), v("cp_p", i)],
                coef: Coefficients {
                    a_f: fixed(&a_f[i]),
                    a_mu: fixed(&a_mu[i]),
                    min_f_v: v("min_f_v", i),
                    unilateral_ok: unilateral[i],
                    support_ok: support[i],
                    f_peak: v("f_peak", i),
                    mu_req: v("mu_req", i),
                    mu_req_robust: v("mu_req_robust", i),
                    ext_min: v("ext_min", i),
                    ext_max: v("ext_max", i),
                    ang_impulse: fixed(&ang[i]),
                    ang_impulse_h0: fixed(&h0[i]),
                    ell_r_min: fixed(&r0[i]),
                    ell_r_max: fixed(&r1[i]),
                    ell_s_min: fixed(&s0[i]),
                    ell_s_max: fixed(&s1[i]),
                },
            })
        })
        .collect()
}

/// Reads the per-clip facts of `clips.parquet`.
///
/// # Errors
/// The file cannot be read, or a column is missing or mistyped.
pub fn read_clip_info(path: &Path) -> Result<BTreeMap<String, ClipInfo>> {
    let t = Table::open(path)?;
    let (names, s_eff, leg, mass) = (
        t.strings("clip")?,
        t.opt_f64("s_eff")?,
        t.opt_f64("leg_length_m")?,
        t.opt_f64("mass_kg")?,
    );
    Ok(names
        .into_iter()
        .enumerate()
        .map(|(i, n)| {
            let info = ClipInfo {
                s_eff: s_eff[i],
                leg_m: leg[i],
                mass_kg: mass[i].unwrap_or(f64::NAN),
            };
            (n, info)
        })
        .collect())
}

/// Opens a library folder: its stances and clips.
///
/// # Errors
/// A missing or unreadable `stances.parquet` or `clips.parquet` (the error names it).
pub fn open_library(dir: &Path) -> Result<StanceLibrary> {
    Ok(StanceLibrary {
        dir: dir.to_path_buf(),
        stances: read_stances(&dir.join(STANCES_FILE))?,
        clips: read_clip_info(&dir.join(CLIPS_FILE))?,
    })
}

/// Where each stance of `stances.parquet` sits in its clip, in file order (the order of
/// [`read_stances`]): touchdown, liftoff and heading.
///
/// # Errors
/// The file cannot be read, or a column is missing, mistyped or null.
pub fn read_stance_timing(path: &Path) -> Result<Vec<crate::edit::plan::StanceTiming>> {
    let t = Table::open(path)?;
    let (td, lo) = (t.f64s("td_clip_s")?, t.f64s("lo_clip_s")?);
    let (hx, hy) = (t.f64s("heading_x")?, t.f64s("heading_y")?);
    Ok((0..t.height())
        .map(|i| crate::edit::plan::StanceTiming {
            td_clip_s: td[i],
            lo_clip_s: lo[i],
            heading: [hx[i], hy[i]],
        })
        .collect())
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
        t.strings("clip")?,
        t.strings("path")?,
        t.strings("content_sha256")?,
    );
    let (unit, up) = (t.opt_f64("unit_scale")?, opt_strings(&t, "up_axis")?);
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
