//! `stancelib equilibrium`: the static/dynamic equilibrium verdict and robustness margin
//! of one contact set at many COM states (spec two-pac §8.2, §9). The stage is
//! [`crate::pipeline::equilibrium`]; this command delegates and prints.

use super::super::args::EquilibriumArgs;
use super::super::Outcome;
use crate::pipeline::equilibrium::{run_equilibrium, EquilibriumJob};

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
    let [ok, closure, infeasible, failed] = r.n_status;
    crate::say!(
        "equilibrium: {} point(s), {} contact(s) ({} points), m = {} kg: {} in equilibrium; \
         status ok {ok}, force_closure {closure}, infeasible {infeasible}, solver_failed {failed}; {:.3} s",
        r.n_points,
        r.n_contacts,
        r.n_contact_points,
        r.mass_kg,
        r.n_in_equilibrium,
        r.elapsed_s
    );
    crate::say!("  → {}", job.out.display());
    if let Some(png) = &job.png {
        crate::say!("  → {}", png.display());
    }
    Ok(if failed == 0 {
        Outcome::Clean
    } else if failed == r.n_points {
        Outcome::AllFailed
    } else {
        Outcome::SomeFailed
    })
}
