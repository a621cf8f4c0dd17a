//! `stancelib equilibrium`: the static/dynamic equilibrium verdict and robustness margin
//! of one contact set at many COM states (spec two-pac §8.2, §9). The stage is
//! [`crate::pipeline::commands::equilibrium`]; this command delegates and prints.

use super::super::args::EquilibriumArgs;
use super::super::Outcome;
use crate::pipeline::commands::equilibrium::{run_equilibrium, EquilibriumJob, EquilibriumReport};

/// Run `equilibrium`.
///
/// # Errors
/// An unreadable or invalid contacts file, an unreadable points table or one without
/// `x_m`, `y_m`, `z_m` (float64, no nulls), an unwritable output.
pub fn run(a: EquilibriumArgs) -> anyhow::Result<Outcome> {
    let job = EquilibriumJob {
        contacts: a.contacts,
        points: a.points,
        out: a.out,
        png: a.png,
    };
    let r = run_equilibrium(&job)?;
    crate::say!("{}", summary(&r));
    crate::say!("  → {}", job.out.display());
    if let Some(png) = &job.png {
        crate::say!("  → {}", png.display());
    }
    let failed = r.n_status[3];
    Ok(if failed == 0 {
        Outcome::Clean
    } else if failed == r.n_points {
        Outcome::AllFailed
    } else {
        Outcome::SomeFailed
    })
}

/// The summary line: how many states are in equilibrium and why the others are not (the
/// `status` column says how each verdict was reached, not whether it is in equilibrium),
/// then the time of each stage, the picture included.
pub fn summary(r: &EquilibriumReport) -> String {
    let [_, closure, infeasible, failed] = r.n_status;
    let mut not = vec![format!("{} outside the region (margin ≤ 0)", r.n_outside)];
    if infeasible > 0 {
        not.push(format!("{infeasible} with no force distribution at all"));
    }
    if failed > 0 {
        not.push(format!("{failed} where the solver failed"));
    }
    let closure = if closure > 0 {
        format!(" ({closure} by force closure)")
    } else {
        String::new()
    };
    let time = match &r.slice {
        Some(s) => format!(
            "verdicts {:.2} s, region slice {} cells ({} LPs) {:.2} s, total {:.2} s",
            r.verdicts_s, s.cells, s.lps, s.elapsed_s, r.total_s
        ),
        None => format!("verdicts {:.2} s, total {:.2} s", r.verdicts_s, r.total_s),
    };
    format!(
        "equilibrium: {} of {} COM state(s) in equilibrium{closure}; not: {}; \
         {} contact(s) ({} points), m = {} kg; {time}",
        r.n_in_equilibrium,
        r.n_points,
        not.join(", "),
        r.n_contacts,
        r.n_contact_points,
        r.mass_kg,
    )
}
