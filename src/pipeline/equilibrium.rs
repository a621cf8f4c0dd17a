//! The `equilibrium` stage (spec two-pac §8.2, §9): read a contact set and COM states,
//! give every state its static/dynamic equilibrium verdict and robustness margin (in
//! parallel), write `R.parquet` and, on request, a slice of the static-equilibrium region
//! as PNG.

use std::path::{Path, PathBuf};
use std::time::Instant;

use anyhow::Context;
use rayon::prelude::*;

use super::inputs::{open_side_input, read_side_text, split_out, SideInput};
use super::twopac_tables::equilibrium_table;
use crate::error::Error;
use crate::library::read::OpenedParquet;
use crate::library::schema::com_state::{ACCELERATION, POSITION};
use crate::library::write::write_atomic;
use crate::plot::write_png;
use crate::twopac::contact::{contact_points, min_mu, ContactPoint};
use crate::twopac::equilibrium::{EqualityForm, Status, Verdict, MAX_COM_STATES};
use crate::twopac::phases::{parse_contacts, within, MAX_ACC_MPS2, MAX_COORDINATE_M};

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
    /// States per status: ok, force closure, infeasible, solver failed.
    pub n_status: [usize; 4],
    /// Wall time of the verdicts, s.
    pub elapsed_s: f64,
}

/// COM positions (m) and accelerations (m/s²), one per row.
type ComStates = (Vec<[f64; 3]>, Vec<[f64; 3]>);

/// The COM positions and accelerations of `P.parquet` (`ax_mps2`, `ay_mps2`, `az_mps2` default 0),
/// opened as a side input ([`SideInput::Points`]); the row count is checked from the
/// footer before any row is decoded.
fn read_points(path: &Path) -> anyhow::Result<ComStates> {
    let file = open_side_input(path, SideInput::Points)?.into_file();
    let mut table = OpenedParquet::new(path, file);
    let rows = table.rows()?;
    if rows > MAX_COM_STATES {
        let e = Error::limit(
            "--points",
            "rows",
            rows as f64,
            MAX_COM_STATES,
            "MAX_COM_STATES",
        );
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
    let text = read_side_text(&job.contacts, SideInput::Contacts)?;
    let file = parse_contacts(&text).with_context(|| job.contacts.display().to_string())?;
    let (com, acc) = read_points(&job.points)?;
    let form = EqualityForm::new(&file.contacts, file.mass_kg)
        .with_context(|| job.contacts.display().to_string())?;
    let t0 = Instant::now();
    form.force_closure();
    let verdicts: Vec<Verdict> = com
        .par_iter()
        .zip(acc.par_iter())
        .map(|(c, a)| form.verdict(*c, *a))
        .collect();
    let elapsed_s = t0.elapsed().as_secs_f64();
    let points = contact_points(&file.contacts);
    let options = serde_json::json!({
        "contacts_file_schema": crate::twopac::phases::CONTACTS_SCHEMA,
        "mass_kg": file.mass_kg,
        "n_contacts": file.contacts.len(),
        "n_contact_points": points.len(),
        "min_mu": min_mu(&points),
    });
    let kv = crate::library::schema::command_kv(crate::library::schema::EQUILIBRIUM_KEY, &options);
    let (dir, name) = split_out(&job.out)?;
    std::fs::create_dir_all(dir).with_context(|| format!("cannot create {}", dir.display()))?;
    write_atomic(dir, &name, &mut equilibrium_table(&com, &verdicts)?, &kv)?;
    if let Some(png) = &job.png {
        let data = slice(&form, &points, &com, &verdicts, &job.contacts);
        write_png(png, |p| crate::plot::equilibrium::equilibrium_png(p, &data))?;
    }
    let count = |s: Status| verdicts.iter().filter(|v| v.status == s).count();
    Ok(EquilibriumReport {
        n_points: com.len(),
        n_contacts: file.contacts.len(),
        n_contact_points: points.len(),
        mass_kg: file.mass_kg,
        n_in_equilibrium: verdicts.iter().filter(|v| v.in_equilibrium).count(),
        n_status: [
            Status::Ok,
            Status::ForceClosure,
            Status::Infeasible,
            Status::SolverFailed,
        ]
        .map(count),
        elapsed_s,
    })
}

/// The `--png` slice: the region on a grid over the contacts' box at the median COM
/// height, zero acceleration.
fn slice(
    form: &EqualityForm,
    points: &[ContactPoint],
    com: &[[f64; 3]],
    verdicts: &[Verdict],
    file: &Path,
) -> crate::plot::equilibrium::EquilibriumPlot {
    use crate::plot::equilibrium::{axis, EquilibriumPlot, DEFAULT_SLICE_CELLS};
    let span = |k: usize| {
        points
            .iter()
            .map(|p| p.pos[k])
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), v| {
                (a.min(v), b.max(v))
            })
    };
    let ((x0, x1), (y0, y1)) = (span(0), span(1));
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
    let margin_n = cells
        .par_iter()
        .map(|c| {
            let v = form.verdict(*c, [0.0; 3]);
            match v.status {
                Status::ForceClosure => Some(f64::INFINITY),
                _ if v.in_equilibrium => v.margin_n,
                _ => None,
            }
        })
        .collect();
    EquilibriumPlot {
        title: format!(
            "{}: static-equilibrium region at z = {z:.2} m (c̈ = 0)",
            file.display()
        ),
        xs,
        ys,
        margin_n,
        contacts: points.iter().map(|p| p.pos).collect(),
        points: com
            .iter()
            .zip(verdicts)
            .map(|(c, v)| (*c, v.in_equilibrium))
            .collect(),
    }
}
