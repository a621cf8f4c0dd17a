//! The jump feasibility map over a stance pool (spec stance-model §6.10, Figures 3–5).
//!
//! # Model
//! ```text
//! grid: rows h_r (apex height above the liftoff contact, m), columns u_q (u_apex, m/s)
//! per stance and row (once): T(h_r), β_v, β_p; per column: β_h affine in u_q,
//!     approx bit = eq 5 ∧ eq 10 ∧ eq 12 ∧ unilateral_ok ∧ §6.5 rules
//!     exact bit  = the §7.4 check at the re-solved contact point ∧ §6.5 rules
//! per pair (S1 liftoff, S2 landing, same character_id) and cell:
//!     feasible_approx = A1 ∧ A2,   feasible_exact = E1 ∧ E2
//!     d_jump = u_q·D(h_r) + C(h_r),  flight_time = (T1 − τ1 − Δt1) + t_TD2
//! IoU = |A ∩ E| / |A ∪ E|   (1 when both are empty)
//! ```
//! Cost: `O((n1 + n2)·n_h·n_u·N_s)` for the per-stance work, `O(n1·n2·n_h·n_u)` bit
//! operations for the pairs. Limits are relative per stance (§7.5) unless given.
//! [`stance_relative_limits`] is the default `limits` argument of [`jump_map`].
//!
//! # References
//! spec stance-model §6.9–§6.10, §7.3–§7.5; CORRECTIONS Issue 4 items 1, 3, 6.

use rayon::prelude::*;

use crate::error::{Error, Result};

use super::feasibility::{relative_limits, Limits};
use super::jump::Side;
use super::jump::{
    distance_map, is_landing, is_liftoff, landing_side, liftoff_side, side_solution,
};
use super::pool::Prepared;
use super::run::verdicts;

/// Most values on one grid axis: `query run --speeds`, `map jumps --heights` and
/// `--speeds`, and the pipeline's `run_speeds`, `map_heights`, `map_speeds` (count).
pub const MAX_AXIS_VALUES: usize = 10_000;
/// Most cells of a jump-map grid, heights × speeds (count).
pub const MAX_GRID_CELLS: usize = 1_000_000;
/// Most verdict cells of a whole jump map: grid cells × (pairs + stance grids), count.
/// Each pair cell is one row of `jump_map.parquet`: about 80 bytes at the peak while the
/// table is built (measured), so 1.6 GB at the limit.
pub const MAX_MAP_CELLS: usize = 20_000_000;

/// An inclusive grid `start, start + step, …, ≤ stop` (with a 1e-9·step slack on `stop`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Axis {
    /// First value.
    pub start: f64,
    /// Last value (inclusive when on the grid).
    pub stop: f64,
    /// Step (> 0).
    pub step: f64,
}

impl Axis {
    /// Parses `start:stop:step` (inclusive) given as `field` (an option or key name).
    ///
    /// # Errors
    /// [`ErrorKind::Invalid`](crate::error::ErrorKind::Invalid): not three finite numbers,
    /// a step ≤ 0 or stop < start; [`ErrorKind::Cap`](crate::error::ErrorKind::Cap):
    /// more than [`MAX_AXIS_VALUES`] values.
    pub fn parse(field: &str, s: &str) -> Result<Axis> {
        let nums: Option<Vec<f64>> = s.split(':').map(|p| p.trim().parse().ok()).collect();
        let axis = match nums.as_deref() {
            Some(&[start, stop, step])
                if [start, stop, step].iter().all(|v| v.is_finite())
                    && step > 0.0
                    && stop >= start =>
            {
                Axis { start, stop, step }
            }
            _ => {
                return Err(Error::invalid(
                    field,
                    format!(
                        "expected start:stop:step (finite numbers, step > 0, stop ≥ start), \
                         found '{s}'"
                    ),
                ))
            }
        };
        let n = axis.count_f64();
        if n > MAX_AXIS_VALUES as f64 {
            return Err(Error::cap(
                field,
                "grid values",
                n,
                MAX_AXIS_VALUES,
                "MAX_AXIS_VALUES",
            ));
        }
        Ok(axis)
    }

    /// Number of values, as a float (no overflow for any step; 0 for an invalid axis).
    fn count_f64(&self) -> f64 {
        if !(self.step > 0.0 && self.start.is_finite() && self.stop.is_finite()) {
            return 0.0;
        }
        let n = ((self.stop - self.start) / self.step + 1e-9).floor();
        if n < 0.0 {
            0.0
        } else {
            n + 1.0
        }
    }

    /// Number of values, at most [`MAX_AXIS_VALUES`] + 1 (an axis beyond the limit
    /// reports one more than it, so that checks against the limit fail).
    pub fn len(&self) -> usize {
        self.count_f64().min(MAX_AXIS_VALUES as f64 + 1.0) as usize
    }

    /// True when the axis has no value.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// The values of the axis, at most [`MAX_AXIS_VALUES`] + 1 of them (see
    /// [`Axis::parse`], which refuses longer axes).
    pub fn values(&self) -> Vec<f64> {
        (0..self.len())
            .map(|i| self.start + i as f64 * self.step)
            .collect()
    }
}

/// Checks a grid of `n_heights × n_speeds` cells against [`MAX_GRID_CELLS`].
///
/// # Errors
/// [`ErrorKind::Cap`](crate::error::ErrorKind::Cap) naming `field`.
pub fn check_grid(field: &str, n_heights: usize, n_speeds: usize) -> Result<()> {
    let n = n_heights as f64 * n_speeds as f64;
    if n > MAX_GRID_CELLS as f64 {
        return Err(Error::cap(
            field,
            "grid cells (heights × speeds)",
            n,
            MAX_GRID_CELLS,
            "MAX_GRID_CELLS",
        ));
    }
    Ok(())
}

/// Default rows: apex height 0.60 to 1.60 m in 0.02 m steps (§6.10).
pub const DEFAULT_HEIGHTS: Axis = Axis {
    start: 0.60,
    stop: 1.60,
    step: 0.02,
};
/// Default columns: `u_apex` 0 to 5 m/s in 0.05 m/s steps (§6.10).
pub const DEFAULT_SPEEDS: Axis = Axis {
    start: 0.0,
    stop: 5.0,
    step: 0.05,
};
/// [`DEFAULT_HEIGHTS`] as `map jumps --heights` writes it (the option's default; a unit
/// test checks that it parses to the constant).
pub const DEFAULT_HEIGHTS_ARG: &str = "0.6:1.6:0.02";
/// [`DEFAULT_SPEEDS`] as `map jumps --speeds` writes it.
pub const DEFAULT_SPEEDS_ARG: &str = "0:5:0.05";

/// One stance's verdicts over the grid (row-major, `n_h × n_u`) and its per-row side.
#[derive(Debug, Clone, PartialEq)]
pub struct StanceGrid {
    /// Per row: the `u_apex`-independent side, or `None` when the row has no solution.
    pub sides: Vec<Option<Side>>,
    /// Approximate verdict per cell.
    pub approx: Vec<bool>,
    /// Exact verdict per cell.
    pub exact: Vec<bool>,
}

/// The verdicts of one stance over the grid (§6.10 steps 1–2).
///
/// `liftoff` selects pin_start (rows are `h_r`) or pin_end (rows are `h_r + z_c1 − z_c2`
/// with `dz = z_c1 − z_c2` of the pair: pass `dz = 0` for a pool on level ground; a pair with
/// another `dz` needs its own grid).
pub fn stance_grid(
    p: &Prepared,
    liftoff: bool,
    heights: &[f64],
    speeds: &[f64],
    dz: f64,
    lim: &Limits,
) -> StanceGrid {
    let n = heights.len() * speeds.len();
    let mut out = StanceGrid {
        sides: Vec::with_capacity(heights.len()),
        approx: vec![false; n],
        exact: vec![false; n],
    };
    for (r, &h) in heights.iter().enumerate() {
        let side = if liftoff {
            liftoff_side(p, h)
        } else {
            landing_side(p, h + dz)
        }
        .ok();
        out.sides.push(side);
        let Some(side) = side else { continue };
        for (q, &u) in speeds.iter().enumerate() {
            let Ok((req, sol)) = side_solution(p, &side, liftoff, u) else {
                continue;
            };
            let (a, e) = verdicts(p, &req, &sol, lim);
            out.approx[r * speeds.len() + q] = a;
            out.exact[r * speeds.len() + q] = e;
        }
    }
    out
}

/// A stance's relative limits (§7.5), the default of [`jump_map`].
pub fn stance_relative_limits(p: &Prepared) -> Limits {
    relative_limits(&p.stance.coef)
}

/// Counts of one pair's cells: approximate, exact, both, either.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct Agreement {
    /// Cells feasible by the approximate verdict.
    pub approx: usize,
    /// Cells feasible by the exact verdict.
    pub exact: usize,
    /// Cells feasible by both.
    pub both: usize,
    /// Cells feasible by either.
    pub either: usize,
}

impl Agreement {
    /// `|A ∩ E| / |A ∪ E|`, 1 when both are empty.
    pub fn iou(&self) -> f64 {
        if self.either == 0 {
            1.0
        } else {
            self.both as f64 / self.either as f64
        }
    }

    fn add(&mut self, o: &Agreement) {
        self.approx += o.approx;
        self.exact += o.exact;
        self.both += o.both;
        self.either += o.either;
    }
}

/// One liftoff/landing pair of the map.
#[derive(Debug, Clone, PartialEq)]
pub struct PairMap {
    /// Index of the liftoff stance in the pool.
    pub liftoff: usize,
    /// Index of the landing stance in the pool.
    pub landing: usize,
    /// Per row: `(D, C, flight_time)`, `None` when either side has no solution.
    pub rows: Vec<Option<(f64, f64, f64)>>,
    /// Approximate verdict per cell (row-major).
    pub approx: Vec<bool>,
    /// Exact verdict per cell.
    pub exact: Vec<bool>,
    /// The pair's agreement counts.
    pub agreement: Agreement,
}

/// The whole map: the grid, the per-stance grids and the pairs.
#[derive(Debug, Clone, PartialEq)]
pub struct JumpMap {
    /// Row values `h_r`, m.
    pub heights: Vec<f64>,
    /// Column values `u_q`, m/s.
    pub speeds: Vec<f64>,
    /// Pool indices of the liftoff stances.
    pub liftoffs: Vec<usize>,
    /// Pool indices of the landing stances.
    pub landings: Vec<usize>,
    /// Every pair of one character.
    pub pairs: Vec<PairMap>,
    /// Library-wide counts over all pairs and cells.
    pub agreement: Agreement,
}

/// Combines two stance grids into a pair's verdicts (§6.10 step 3).
fn pair_map(
    (i1, p1, g1): (usize, &Prepared, &StanceGrid),
    (i2, p2, g2): (usize, &Prepared, &StanceGrid),
    n_u: usize,
) -> PairMap {
    let rows: Vec<Option<(f64, f64, f64)>> = g1
        .sides
        .iter()
        .zip(&g2.sides)
        .map(|(a, b)| {
            let (a, b) = (a.as_ref()?, b.as_ref()?);
            let (d, c) = distance_map(p1, a, p2, b);
            Some((d, c, a.flight_part + b.flight_part))
        })
        .collect();
    let mut approx = vec![false; g1.approx.len()];
    let mut exact = vec![false; g1.exact.len()];
    let mut agreement = Agreement::default();
    for (r, row) in rows.iter().enumerate() {
        if row.is_none_or(|(d, _, _)| d.is_nan() || d <= 0.0) {
            continue; // no distance for this row: its cells stay infeasible
        }
        for k in r * n_u..(r + 1) * n_u {
            let a = g1.approx[k] && g2.approx[k];
            let e = g1.exact[k] && g2.exact[k];
            approx[k] = a;
            exact[k] = e;
            agreement.add(&Agreement {
                approx: usize::from(a),
                exact: usize::from(e),
                both: usize::from(a && e),
                either: usize::from(a || e),
            });
        }
    }
    PairMap {
        liftoff: i1,
        landing: i2,
        rows,
        approx,
        exact,
        agreement,
    }
}

/// The jump map of a pool (§6.10): every liftoff paired with every landing of the same
/// `character_id`, each stance checked against `limits(stance)` (§7.5: its relative
/// limits by default, [`relative_limits`]). Parallel over stances and pairs.
///
/// Landings whose contact height differs from their liftoff's get their own grid per
/// distinct height offset (level ground, the common case, shares one grid per stance).
///
/// # Errors
/// [`ErrorKind::Cap`](crate::error::ErrorKind::Cap) before any work when the grid
/// has more than [`MAX_GRID_CELLS`] cells or the map more than [`MAX_MAP_CELLS`]
/// (cells × (pairs + stance grids)).
pub fn jump_map(
    pool: &[Prepared],
    heights: &[f64],
    speeds: &[f64],
    limits: &(dyn Fn(&Prepared) -> Limits + Sync),
) -> Result<JumpMap> {
    check_grid("jump map grid", heights.len(), speeds.len())?;
    let liftoffs: Vec<usize> = (0..pool.len())
        .filter(|&i| is_liftoff(&pool[i].stance))
        .collect();
    let landings: Vec<usize> = (0..pool.len())
        .filter(|&i| is_landing(&pool[i].stance))
        .collect();
    let lim = |i: usize| limits(&pool[i]);
    let up: Vec<StanceGrid> = liftoffs
        .par_iter()
        .map(|&i| stance_grid(&pool[i], true, heights, speeds, 0.0, &lim(i)))
        .collect();
    let pair_list: Vec<(usize, usize)> = (0..liftoffs.len())
        .flat_map(|a| (0..landings.len()).map(move |b| (a, b)))
        .filter(|&(a, b)| {
            pool[liftoffs[a]].stance.character_id == pool[landings[b]].stance.character_id
        })
        .collect();
    // Landing grids per (landing, contact-height offset to its liftoff), level ground → 0.
    let dz = |a: usize, b: usize| pool[liftoffs[a]].stance.z_c - pool[landings[b]].stance.z_c;
    let mut keys: Vec<(usize, u64)> = pair_list
        .iter()
        .map(|&(a, b)| (b, dz(a, b).to_bits()))
        .collect();
    keys.sort_unstable();
    keys.dedup();
    let cells = heights.len() as f64 * speeds.len() as f64;
    let n = cells * (pair_list.len() + liftoffs.len() + keys.len()) as f64;
    if n > MAX_MAP_CELLS as f64 {
        return Err(Error::cap(
            format!(
                "jump map ({} pairs and {} stance grids of {} × {} cells)",
                pair_list.len(),
                liftoffs.len() + keys.len(),
                heights.len(),
                speeds.len()
            ),
            "verdict cells",
            n,
            MAX_MAP_CELLS,
            "MAX_MAP_CELLS",
        ));
    }
    let down: Vec<StanceGrid> = keys
        .par_iter()
        .map(|&(b, bits)| {
            let i = landings[b];
            stance_grid(
                &pool[i],
                false,
                heights,
                speeds,
                f64::from_bits(bits),
                &lim(i),
            )
        })
        .collect();
    let n_u = speeds.len();
    let pairs: Vec<PairMap> = pair_list
        .par_iter()
        .map(|&(a, b)| {
            let k = keys
                .binary_search(&(b, dz(a, b).to_bits()))
                .unwrap_or_default();
            let (i1, i2) = (liftoffs[a], landings[b]);
            pair_map((i1, &pool[i1], &up[a]), (i2, &pool[i2], &down[k]), n_u)
        })
        .collect();
    let mut agreement = Agreement::default();
    for p in &pairs {
        agreement.add(&p.agreement);
    }
    Ok(JumpMap {
        heights: heights.to_vec(),
        speeds: speeds.to_vec(),
        liftoffs,
        landings,
        pairs,
        agreement,
    })
}

#[cfg(test)]
mod tests;
