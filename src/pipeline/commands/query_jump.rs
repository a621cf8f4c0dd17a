//! `query jump` at the I/O edge: every liftoff × landing pair of a library at one apex
//! height and distance, ranked, its table written atomically.
//!
//! # References
//! spec stance-model §6.9 (jump), §7.5 (limits).

use std::path::PathBuf;

use super::queries::{load_pool, pool_without_left_out, query_kv, write_table, LimitOptions};
use crate::query::feasibility::LimitForm;
use crate::query::jump::recorded_jump;
use crate::query::limits::{absolute_limits, jump_limits};
use crate::query::pairs::ranked_jump_pairs;
use crate::query::pool::Prepared;
use crate::query::run::check_scale;
use crate::query::tables::jump_table;

/// `query jump`: every liftoff × landing pair of a library at one apex height and distance.
#[derive(Debug, Clone)]
pub struct JumpQuery {
    /// Library folder.
    pub lib: PathBuf,
    /// The jump asked of every pair.
    pub target: JumpTarget,
    /// Limit options (default form: relative).
    pub limits: LimitOptions,
    /// Keep the clips the queries leave out ([`left_out_clips`](crate::query::limits::left_out_clips)).
    pub keep_left_out: bool,
    /// Build each pair's whole explanation ([`JumpLine::full`]) for `--explain`.
    pub explain: bool,
    /// Output Parquet file.
    pub out: PathBuf,
}

/// The jump `query jump` asks of each pair: absolute, or relative to the pair's recorded
/// jump ([`recorded_jump`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum JumpTarget {
    /// Apex height above the liftoff contact and distance, m, the same for every pair.
    Absolute {
        /// m.
        height_m: f64,
        /// m.
        distance_m: f64,
    },
    /// The pair's recorded apex height and distance times these.
    Scaled {
        /// Factor on the recorded apex height.
        height: f64,
        /// Factor on the recorded distance.
        distance: f64,
    },
}

impl JumpTarget {
    /// `(height, distance)` asked of the pair (liftoff `p1`, landing `p2`), m.
    pub fn of(&self, p1: &Prepared, p2: &Prepared) -> (f64, f64) {
        match *self {
            JumpTarget::Absolute {
                height_m,
                distance_m,
            } => (height_m, distance_m),
            JumpTarget::Scaled { height, distance } => {
                let (h0, d0) = recorded_jump(&p1.stance, &p2.stance);
                (h0 * height, d0 * distance)
            }
        }
    }

    /// Each number finite, and the scales positive.
    ///
    /// # Errors
    /// The option that is not.
    pub fn check(&self) -> anyhow::Result<()> {
        let (a, b, scaled) = match *self {
            JumpTarget::Absolute {
                height_m,
                distance_m,
            } => (height_m, distance_m, false),
            JumpTarget::Scaled { height, distance } => (height, distance, true),
        };
        let names = if scaled {
            ["--height-scale", "--distance-scale"]
        } else {
            ["--height", "--distance"]
        };
        for (n, v) in names.iter().zip([a, b]) {
            anyhow::ensure!(v.is_finite(), "{n} must be a number, found {v}");
        }
        if scaled {
            check_scale(names[0], a)?;
            anyhow::ensure!(
                b >= 0.0,
                "{} must be ≥ 0 (0: a jump in place), found {b}",
                names[1]
            );
        }
        Ok(())
    }

    /// The target for the query's options JSON.
    fn json(&self) -> serde_json::Value {
        match *self {
            JumpTarget::Absolute {
                height_m,
                distance_m,
            } => serde_json::json!({"height_m": height_m, "distance_m": distance_m}),
            JumpTarget::Scaled { height, distance } => {
                serde_json::json!({"height_scale": height, "distance_scale": distance})
            }
        }
    }
}

/// One ranked pair of `query jump`.
#[derive(Debug, Clone, PartialEq)]
pub struct JumpLine {
    /// Liftoff stance id.
    pub liftoff: String,
    /// Landing stance id.
    pub landing: String,
    /// Apex speed, m/s (a solved pair).
    pub u_apex_mps: Option<f64>,
    /// `[β_h, β_v]` of the liftoff and of the landing (a solved pair).
    pub beta: Option<[[f64; 2]; 2]>,
    /// Feasible by the exact check.
    pub feasible: bool,
    /// Why not, with the deciding value, limit and margin
    /// ([`crate::query::tables::JumpRow::explain`]).
    pub why: Option<String>,
    /// Apex height (m) and distance (m) asked of this pair.
    pub asked: (f64, f64),
    /// The whole answer ([`crate::query::tables::JumpRow::full_explanation`]); empty
    /// unless [`JumpQuery::explain`].
    pub full: Vec<String>,
}

/// Runs `query jump`: ranks every pair (feasible first, then the least force change),
/// writes the table and returns the pairs in rank order.
///
/// # Errors
/// A height or distance that is not a number, bad limit options, an unreadable library,
/// an unwritable output.
pub fn jump_query(q: &JumpQuery) -> anyhow::Result<Vec<JumpLine>> {
    q.target.check()?;
    let (form, mu) = q.limits.form(LimitForm::Absolute)?;
    let active = q.limits.active_fraction()?;
    let (lib, pool) = load_pool(&q.lib, active)?;
    let pool = pool_without_left_out("query jump", &lib, pool, q.keep_left_out);
    let absolute = absolute_limits(&lib);
    let lim = |p: &Prepared| jump_limits(p, form, &absolute, mu, &lib.clips);
    let rows = ranked_jump_pairs(&pool, |a, b| q.target.of(a, b), lim);
    let mut df = jump_table(&rows)?;
    let kv = query_kv(
        &q.lib,
        serde_json::json!({
            "query": "jump", "lib": q.lib, "target": q.target.json(),
            "limits": form.name(), "mu": mu, "active_set": active,
        }),
    )?;
    write_table(&q.out, &mut df, &kv)?;
    Ok(rows
        .iter()
        .map(|r| JumpLine {
            liftoff: r.liftoff.stance.stance_id.clone(),
            landing: r.landing.stance.stance_id.clone(),
            u_apex_mps: r.jump.as_ref().ok().map(|j| j.u_apex),
            beta: r.jump.as_ref().ok().map(|j| {
                [0, 1].map(|k| {
                    let b = j.sides[k].1.solution.beta;
                    [b[0], b[2]]
                })
            }),
            feasible: r.jump.as_ref().is_ok_and(|j| j.feasible()),
            why: r.explain(),
            asked: (r.height, r.distance),
            full: if q.explain {
                r.full_explanation()
            } else {
                Vec::new()
            },
        })
        .collect())
}
