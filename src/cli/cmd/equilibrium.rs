//! `stancelib equilibrium`: the static/dynamic equilibrium verdict and robustness margin
//! of one contact set at many COM states (spec two-pac §8.2, §9).

use std::path::Path;
use std::time::Instant;

use anyhow::Context;
use rayon::prelude::*;

use super::super::args::EquilibriumArgs;
use super::super::Outcome;
use crate::error::Error;
use crate::library::read::{parquet_rows, Table};
use crate::library::write::write_atomic;
use crate::pipeline::twopac_tables::equilibrium_table;
use crate::twopac::contact::{contact_points, min_mu};
use crate::twopac::equilibrium::{EqualityForm, Status, Verdict, MAX_COM_STATES};
use crate::twopac::phases::parse_contacts;

/// Reads a UTF-8 text file, naming it on failure.
pub(crate) fn read_text(path: &Path) -> anyhow::Result<String> {
    std::fs::read_to_string(path).with_context(|| format!("cannot read {}", path.display()))
}

/// COM positions (m) and accelerations (m/s²), one per row.
type ComStates = (Vec<[f64; 3]>, Vec<[f64; 3]>);

/// The COM positions and accelerations of `P.parquet` (`ax_mps2`, `ay_mps2`, `az_mps2` default 0).
fn read_points(path: &Path) -> anyhow::Result<ComStates> {
    let rows = parquet_rows(path)?;
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
    let t = Table::open(path)?;
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
    let pos = ["x_m", "y_m", "z_m"];
    let acc = ["ax_mps2", "ay_mps2", "az_mps2"];
    Ok((xyz(pos, false)?, xyz(acc, true)?))
}

/// Run `equilibrium`.
///
/// # Errors
/// An unreadable or invalid contacts file, an unreadable points table or one without
/// `x_m`, `y_m`, `z_m` (float64, no nulls), an unwritable output.
pub fn run(a: EquilibriumArgs) -> anyhow::Result<Outcome> {
    let text = read_text(&a.contacts)?;
    let file = parse_contacts(&text).with_context(|| a.contacts.display().to_string())?;
    let (com, acc) = read_points(&a.points)?;
    let form = EqualityForm::new(&file.contacts, file.mass_kg)
        .with_context(|| a.contacts.display().to_string())?;
    let t0 = Instant::now();
    form.force_closure();
    let verdicts: Vec<Verdict> = com
        .par_iter()
        .zip(acc.par_iter())
        .map(|(c, a)| form.verdict(*c, *a))
        .collect();
    let elapsed = t0.elapsed().as_secs_f64();
    let points = contact_points(&file.contacts);
    let options = serde_json::json!({
        "contacts_file_schema": crate::twopac::phases::CONTACTS_SCHEMA,
        "mass_kg": file.mass_kg,
        "n_contacts": file.contacts.len(),
        "n_contact_points": points.len(),
        "min_mu": min_mu(&points),
    });
    let kv = crate::library::schema::command_kv(crate::library::schema::EQUILIBRIUM_KEY, &options);
    let (dir, name) = split_out(&a.out)?;
    std::fs::create_dir_all(dir).with_context(|| format!("cannot create {}", dir.display()))?;
    write_atomic(dir, &name, &mut equilibrium_table(&com, &verdicts)?, &kv)?;
    let count = |s: Status| verdicts.iter().filter(|v| v.status == s).count();
    let n_in = verdicts.iter().filter(|v| v.in_equilibrium).count();
    let failed = count(Status::SolverFailed);
    crate::say!(
        "equilibrium: {} point(s), {} contact(s) ({} points), m = {} kg: {n_in} in equilibrium; \
         status ok {}, force_closure {}, infeasible {}, solver_failed {failed}; {:.3} s",
        com.len(),
        file.contacts.len(),
        points.len(),
        file.mass_kg,
        count(Status::Ok),
        count(Status::ForceClosure),
        count(Status::Infeasible),
        elapsed
    );
    crate::say!("  → {}", a.out.display());
    if let Some(png) = &a.png {
        let data = slice(&form, &points, &com, &verdicts, &a.contacts);
        super::write_png(png, |p| crate::plot::equilibrium::equilibrium_png(p, &data))?;
        crate::say!("  → {}", png.display());
    }
    Ok(if failed == 0 {
        Outcome::Clean
    } else if failed == verdicts.len() {
        Outcome::AllFailed
    } else {
        Outcome::SomeFailed
    })
}

/// `(folder, file name)` of an output file path.
pub(crate) fn split_out(out: &Path) -> anyhow::Result<(&Path, String)> {
    let name = out
        .file_name()
        .and_then(|n| n.to_str())
        .with_context(|| format!("--out {}: not a file name", out.display()))?
        .to_string();
    let dir = match out.parent() {
        Some(p) if !p.as_os_str().is_empty() => p,
        _ => Path::new("."),
    };
    Ok((dir, name))
}

/// The `--png` slice: the region on a grid over the contacts' box at the median COM
/// height, zero acceleration.
fn slice(
    form: &EqualityForm,
    points: &[crate::twopac::contact::ContactPoint],
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
