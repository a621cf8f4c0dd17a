//! The `equilibrium` stage (spec two-pac §8.2, §9): read a contact set and COM states,
//! give every state its static/dynamic equilibrium verdict and robustness margin (in
//! parallel), write `R.parquet` and, on request, a slice of the static-equilibrium region
//! as PNG.
//!
//! The slice needs one margin LP per cell ([`DEFAULT_SLICE_CELLS`]² of them); only the
//! cells within one cell diagonal of the static region's polygon (eq 2, `region.rs`, a few
//! dozen LPs) are solved, the rest are outside by construction. Both stages draw a
//! progress bar on a terminal, and the report times each, so the printed time includes
//! the picture.
//!
//! [`DEFAULT_SLICE_CELLS`]: crate::plot::equilibrium::DEFAULT_SLICE_CELLS

use std::path::{Path, PathBuf};
use std::time::Instant;

use anyhow::Context;
use rayon::prelude::*;

use super::split_out;
use super::twopac_tables::equilibrium_table;
use crate::error::Error;
use crate::library::codec::schema::com_state::{ACCELERATION, POSITION};
use crate::library::codec::table::OpenedParquet;
use crate::library::codec::write::write_atomic;
use crate::pipeline::engine::batch::progress;
use crate::pipeline::engine::inputs::{open_side_input, read_side_text, SideInput};
use crate::plot::write_png;
use crate::twopac::contact::{contact_points, min_mu, ContactPoint};
use crate::twopac::equilibrium::{
    EqualityForm, Status, Verdict, MAX_COM_STATES, MAX_CONTACT_STATES,
};
use crate::twopac::phases::{parse_contacts, within, MAX_ACC_MPS2, MAX_COORDINATE_M};
use crate::twopac::region::{static_region, RegionOptions, RegionStatus, StaticRegion};

/// An `equilibrium` job.
#[derive(Debug, Clone)]
pub struct EquilibriumJob {
    /// Contacts file (JSON, `stancelib.twopac.contacts/1`).
    pub contacts: PathBuf,
    /// COM states (Parquet: `x_m, y_m, z_m`, optional `ax_mps2, ay_mps2, az_mps2`).
    pub points: PathBuf,
    /// Output Parquet file.
    pub out: PathBuf,
    /// Optional PNG of the static-equilibrium region's slice.
    pub png: Option<PathBuf>,
}

/// What an `equilibrium` job found.
#[derive(Debug, Clone, PartialEq)]
pub struct EquilibriumReport {
    /// COM states evaluated.
    pub n_points: usize,
    /// Contacts of the set.
    pub n_contacts: usize,
    /// Contact points of the set.
    pub n_contact_points: usize,
    /// Body mass, kg.
    pub mass_kg: f64,
    /// States in equilibrium.
    pub n_in_equilibrium: usize,
    /// States per status: solved (margin LP; in equilibrium when the margin is > 0), force
    /// closure, infeasible, solver failed.
    pub n_status: [usize; 4],
    /// States whose margin LP was solved with a margin ≤ 0: outside the region.
    pub n_outside: usize,
    /// Wall time of the verdicts, s.
    pub verdicts_s: f64,
    /// What drawing the `--png` slice took (`None` without `--png`).
    pub slice: Option<SliceReport>,
    /// Wall time of the whole job (reading, verdicts, tables, picture), s.
    pub total_s: f64,
}

/// What drawing the `--png` slice took.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SliceReport {
    /// Cells of the slice.
    pub cells: usize,
    /// Margin LPs solved (cells near or inside the static region).
    pub lps: usize,
    /// Wall time (region, LPs and drawing), s.
    pub elapsed_s: f64,
}

/// COM positions (m) and accelerations (m/s²), one per row.
type ComStates = (Vec<[f64; 3]>, Vec<[f64; 3]>);

/// The COM positions and accelerations of `P.parquet` (`ax_mps2`, `ay_mps2`, `az_mps2` default 0),
/// opened as a side input ([`SideInput::Points`]); the row count is checked from the
/// footer before any row is decoded, against [`MAX_COM_STATES`] and, times the
/// `n_contacts` of the contact set (and with `slice_cells` more states for `--png`),
/// against [`MAX_CONTACT_STATES`].
fn read_points(path: &Path, n_contacts: usize, slice_cells: usize) -> anyhow::Result<ComStates> {
    let file = open_side_input(path, SideInput::Points)?.into_file();
    let mut table = OpenedParquet::new(path, file);
    let rows = table.rows()?;
    let work = n_contacts as f64 * (rows + slice_cells) as f64;
    let too_many = if rows > MAX_COM_STATES {
        Some(Error::cap(
            "--points",
            "rows",
            rows as f64,
            MAX_COM_STATES,
            "MAX_COM_STATES",
        ))
    } else if work > MAX_CONTACT_STATES as f64 {
        let png = if slice_cells > 0 {
            format!(" + {slice_cells} cells of the --png slice")
        } else {
            String::new()
        };
        Some(Error::cap(
            format!("--points ({rows} rows{png}) × --contacts ({n_contacts} contacts)"),
            "contact-states",
            work,
            MAX_CONTACT_STATES,
            "MAX_CONTACT_STATES",
        ))
    } else {
        None
    };
    if let Some(e) = too_many {
        return Err(anyhow::Error::from(e).context(path.display().to_string()));
    }
    let t = table.read()?;
    let xyz = |names: [&str; 3], optional: bool| -> anyhow::Result<Vec<[f64; 3]>> {
        let mut cols = Vec::with_capacity(3);
        for n in names {
            if optional && t.df.column(n).is_err() {
                cols.push(vec![0.0; t.height()]);
            } else {
                cols.push(t.f64s(n)?);
            }
        }
        Ok((0..t.height())
            .map(|i| [cols[0][i], cols[1][i], cols[2][i]])
            .collect())
    };
    let (com, acc) = (xyz(POSITION, false)?, xyz(ACCELERATION, true)?);
    for (rows, max, limit, unit) in [
        (&com, MAX_COORDINATE_M, "MAX_COORDINATE_M", "m"),
        (&acc, MAX_ACC_MPS2, "MAX_ACC_MPS2", "m/s²"),
    ] {
        if let Some((i, v)) = rows
            .iter()
            .enumerate()
            .find_map(|(i, r)| r.iter().find(|c| !within(**c, max)).map(|c| (i, *c)))
        {
            anyhow::bail!(
                "{}: row {i}: value {v} is beyond ±{max} {unit} ({limit})",
                path.display()
            );
        }
    }
    Ok((com, acc))
}

/// Runs an `equilibrium` job.
///
/// # Errors
/// An unreadable or invalid contacts file, an unreadable points table or one without
/// `x_m`, `y_m`, `z_m` (float64, no nulls) or with a value beyond its bound
/// (`MAX_COORDINATE_M`, `MAX_ACC_MPS2`), an unwritable output.
pub fn run_equilibrium(job: &EquilibriumJob) -> anyhow::Result<EquilibriumReport> {
    let start = Instant::now();
    let text = read_side_text(&job.contacts, SideInput::Contacts)?;
    let file = parse_contacts(&text).with_context(|| job.contacts.display().to_string())?;
    let slice_cells = if job.png.is_some() {
        crate::plot::equilibrium::DEFAULT_SLICE_CELLS.pow(2)
    } else {
        0
    };
    let (com, acc) = read_points(&job.points, file.contacts.len(), slice_cells)?;
    let form = EqualityForm::new(&file.contacts, file.mass_kg)
        .with_context(|| job.contacts.display().to_string())?;
    let t0 = Instant::now();
    form.force_closure();
    let bar = progress(com.len(), "COM states");
    let verdicts: Vec<Verdict> = com
        .par_iter()
        .zip(acc.par_iter())
        .map(|(c, a)| {
            let v = form.verdict(*c, *a);
            bar.inc(1);
            v
        })
        .collect();
    bar.finish_and_clear();
    let verdicts_s = t0.elapsed().as_secs_f64();
    let points = contact_points(&file.contacts);
    let options = serde_json::json!({
        "contacts_file_schema": crate::twopac::phases::CONTACTS_SCHEMA,
        "mass_kg": file.mass_kg,
        "n_contacts": file.contacts.len(),
        "n_contact_points": points.len(),
        "min_mu": min_mu(&points),
    });
    let kv = crate::library::codec::schema::command_kv(
        crate::library::codec::schema::EQUILIBRIUM_KEY,
        &options,
    );
    let (dir, name) = split_out(&job.out)?;
    std::fs::create_dir_all(dir).with_context(|| format!("cannot create {}", dir.display()))?;
    write_atomic(dir, &name, &mut equilibrium_table(&com, &verdicts)?, &kv)?;
    let slice_report = match &job.png {
        Some(png) => {
            let t = Instant::now();
            let (data, lps) = slice(&form, &points, &com, &verdicts, &job.contacts);
            write_png(png, |p| crate::plot::equilibrium::equilibrium_png(p, &data))?;
            Some(SliceReport {
                cells: data.margin_n.len(),
                lps,
                elapsed_s: t.elapsed().as_secs_f64(),
            })
        }
        None => None,
    };
    let count = |s: Status| verdicts.iter().filter(|v| v.status == s).count();
    Ok(EquilibriumReport {
        n_points: com.len(),
        n_contacts: file.contacts.len(),
        n_contact_points: points.len(),
        mass_kg: file.mass_kg,
        n_in_equilibrium: verdicts.iter().filter(|v| v.in_equilibrium).count(),
        n_status: [
            Status::Solved,
            Status::ForceClosure,
            Status::Infeasible,
            Status::SolverFailed,
        ]
        .map(count),
        n_outside: verdicts
            .iter()
            .filter(|v| v.status == Status::Solved && !v.in_equilibrium)
            .count(),
        verdicts_s,
        slice: slice_report,
        total_s: start.elapsed().as_secs_f64(),
    })
}

/// The `--png` slice: the region on a grid over the square around the contacts and the
/// states ([`crate::plot::equilibrium::square_box`]) at the median COM height, zero
/// acceleration; returns it with the number of margin LPs solved.
///
/// A cell farther than one cell diagonal outside the static region's polygon is outside
/// without an LP (the polygon is exact to `region::DEFAULT_TOL_M`); when the polygon cannot
/// be found every cell gets its LP.
fn slice(
    form: &EqualityForm,
    points: &[ContactPoint],
    com: &[[f64; 3]],
    verdicts: &[Verdict],
    file: &Path,
) -> (crate::plot::equilibrium::EquilibriumPlot, usize) {
    use crate::plot::equilibrium::{axis, square_box, EquilibriumPlot, DEFAULT_SLICE_CELLS};
    let contacts: Vec<[f64; 3]> = points.iter().map(|p| p.pos).collect();
    let ([x0, x1], [y0, y1]) = square_box(&contacts, com);
    let mut zs: Vec<f64> = com.iter().map(|c| c[2]).collect();
    zs.sort_by(f64::total_cmp);
    let z = zs.get(zs.len() / 2).copied().unwrap_or(1.0);
    let (xs, ys) = (
        axis(x0, x1, DEFAULT_SLICE_CELLS),
        axis(y0, y1, DEFAULT_SLICE_CELLS),
    );
    let cells: Vec<[f64; 3]> = ys
        .iter()
        .flat_map(|&y| xs.iter().map(move |&x| [x, y, z]))
        .collect();
    let region: Option<StaticRegion> = static_region(points, &RegionOptions::default()).ok();
    let step = |v: &[f64]| v.get(1).zip(v.first()).map_or(0.0, |(b, a)| b - a);
    let diagonal_m = step(&xs).hypot(step(&ys));
    let near = |c: &[f64; 3]| region.as_ref().is_none_or(|r| r.contains(*c, diagonal_m));
    let lps = cells.iter().filter(|c| near(c)).count();
    let bar = progress(lps, "margin LPs of the region slice");
    let margin_n = cells
        .par_iter()
        .map(|c| {
            if !near(c) {
                return None;
            }
            let v = form.verdict(*c, [0.0; 3]);
            bar.inc(1);
            match v.status {
                Status::ForceClosure => Some(f64::INFINITY),
                _ if v.in_equilibrium => v.margin_n,
                _ => None,
            }
        })
        .collect();
    bar.finish_and_clear();
    let n_in = verdicts.iter().filter(|v| v.in_equilibrium).count();
    let name = file.file_name().map_or(file.display().to_string(), |n| {
        n.to_string_lossy().into_owned()
    });
    let plot = EquilibriumPlot {
        title: format!(
            "Where do the contacts of {name} hold the COM at rest? Static region at z = {z:.2} m, zero acceleration"
        ),
        verdict: crate::plot::Verdict::new(
            format!(
                "{n_in} of {} evaluated COM states in equilibrium (each with its own acceleration), {} not",
                verdicts.len(),
                verdicts.len() - n_in
            ),
            n_in == verdicts.len(),
        ),
        xs,
        ys,
        margin_n,
        region: region
            .filter(|r| r.status == RegionStatus::Bounded)
            .map(|r| r.vertices)
            .unwrap_or_default(),
        contacts,
        points: com
            .iter()
            .zip(verdicts)
            .map(|(c, v)| (*c, v.in_equilibrium))
            .collect(),
    };
    (plot, lps)
}
