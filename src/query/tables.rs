//! The query outputs as tables: `query run`, `query jump` and `map jumps` (spec
//! stance-model §6.8–§6.10). Column names carry their unit (`_m`, `_s`, `_mps`, `_n`);
//! stance times (`td_stance_s`, …) are on the scaled stance's clock, from its start apex.
//!
//! Per-stance values of a run cycle are lists in the order of `stance_ids`; a stance
//! without an admissible solution has nulls there and its reason in `violated`.

use polars::prelude::*;

use super::feasibility::{Limits, Verdict, Violation};
use super::jump::Jump;
use super::map::{Agreement, JumpMap};
use super::pool::Prepared;
use super::run::{RunCandidate, ScaledStance};
use crate::library::codec::columns::{col, list_col};
use crate::library::codec::schema::stances as S;

/// Name of a violated constraint in the `violated` columns.
pub fn violation_name(v: Violation) -> &'static str {
    match v {
        Violation::Beta => "beta_negative",
        Violation::Force => "force",
        Violation::Friction => "friction",
        Violation::Unilateral => "unilateral",
        Violation::ExtensionMin => "extension_min",
        Violation::ExtensionMax => "extension_max",
    }
}

/// One limit of the exact check (§7.4) applied to a scaled stance: the stance's value, the
/// limit as the check applies it ([`Limits::effective`]) and which side of it is allowed.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LimitCheck {
    /// The constraint ([`violation_name`]).
    pub violation: Violation,
    /// The scaled stance's value (`F_peak` N, `μ_req`, `ext_min`/`ext_max` m).
    pub value: f64,
    /// The limit, same unit.
    pub limit: f64,
    /// `true`: the value must not exceed the limit (eq 6, 7, 8 upper); `false`: not fall
    /// below it (eq 8 lower).
    pub upper: bool,
}

impl LimitCheck {
    /// `(unit, decimals)` of the value and limit.
    fn unit(&self) -> (&'static str, usize) {
        match self.violation {
            Violation::Force => (" N", 0),
            Violation::Friction => ("", 3),
            _ => (" m", 3),
        }
    }

    /// Room left before the limit, in its unit: negative when the value is beyond it.
    pub fn margin(&self) -> f64 {
        if self.upper {
            self.limit - self.value
        } else {
            self.value - self.limit
        }
    }

    /// `force 1812 N > 1750 N (by 62 N)` when beyond the limit, `force 1543 N ≤ 1750 N
    /// (margin 207 N)` within it.
    pub fn line(&self) -> String {
        let (unit, d) = self.unit();
        let (name, value, limit, m) = (
            violation_name(self.violation),
            self.value,
            self.limit,
            self.margin(),
        );
        let (op, word) = match (self.upper, m < 0.0) {
            (true, true) => ('>', "by"),
            (true, false) => ('≤', "margin"),
            (false, true) => ('<', "by"),
            (false, false) => ('≥', "margin"),
        };
        let m = m.abs();
        format!("{name} {value:.d$}{unit} {op} {limit:.d$}{unit} ({word} {m:.d$}{unit})")
    }
}

/// The four limits of the exact check of a scaled stance, in the order of [`Violation`]:
/// peak force (eq 6), friction on the active set (eq 7), shortest and longest extension
/// (eq 8).
pub fn limit_checks(verdict: &Verdict, lim: &Limits) -> [LimitCheck; 4] {
    let l = lim.effective();
    let c = |violation, value, limit, upper| LimitCheck {
        violation,
        value,
        limit,
        upper,
    };
    [
        c(Violation::Force, verdict.f_peak, l.f_max, true),
        c(Violation::Friction, verdict.mu_req, l.mu, true),
        c(Violation::ExtensionMin, verdict.ext_min, l.chi_min, false),
        c(Violation::ExtensionMax, verdict.ext_max, l.chi_max, true),
    ]
}

/// The deciding constraint of an infeasible scaled stance, with its value, its limit (as
/// the exact check applies it, [`Limits::effective`]) and the margin in units:
/// `force 1812 N > 1750 N (by 62 N)`. `None` when feasible.
pub fn violation_detail(verdict: &Verdict, lim: &Limits) -> Option<String> {
    let v = verdict.violated?;
    Some(
        limit_checks(verdict, lim)
            .iter()
            .find(|c| c.violation == v)
            .map_or_else(|| violation_name(v).to_string(), LimitCheck::line),
    )
}

/// The constraint a feasible scaled stance is nearest to breaking (least margin as a
/// fraction of its limit), as its [`LimitCheck::line`] (`extension_max 1.012 m ≤ 1.050 m
/// (margin 0.038 m)`), and that fraction (0.036 there). `None` when infeasible or no value
/// is finite.
pub fn tightest_detail(verdict: &Verdict, lim: &Limits) -> Option<(f64, String)> {
    if !verdict.feasible {
        return None;
    }
    let relative = |c: &LimitCheck| c.margin() / c.limit.abs().max(f64::MIN_POSITIVE);
    limit_checks(verdict, lim)
        .iter()
        .filter(|c| c.value.is_finite() && c.limit.is_finite())
        .min_by(|a, b| relative(a).total_cmp(&relative(b)))
        .map(|c| (relative(c), c.line()))
}

/// Every check of one scaled stance, one line each, the deciding one marked: what
/// `--explain` prints under the stance's scaling.
pub fn stance_explanation(verdict: &Verdict, lim: &Limits) -> Vec<String> {
    let mut lines: Vec<String> = limit_checks(verdict, lim)
        .iter()
        .map(|c| {
            let mark = if verdict.violated == Some(c.violation) {
                "   ← deciding"
            } else {
                ""
            };
            format!("{}{mark}", c.line())
        })
        .collect();
    lines.push(match verdict.violated {
        None => "exact check: feasible (β ≥ 0 and f_v ≥ 0 throughout as well)".to_string(),
        Some(v @ (Violation::Beta | Violation::Unilateral)) => {
            format!("{}   ← deciding", violation_name(v))
        }
        Some(v) => format!("exact check: infeasible, first by {}", violation_name(v)),
    });
    lines
}

/// One scaled stance of an explanation: `  stance ID: β_h …, β_p …, β_v …; touchdown …
/// s, liftoff … s, end apex … s` and its checks, or why it has no scaling.
fn scaled_stance_lines<E: std::fmt::Display>(
    id: &str,
    s: Result<&ScaledStance, E>,
    lim: &Limits,
) -> Vec<String> {
    match s {
        Err(e) => vec![format!("  stance {id}: no admissible scaling: {e}")],
        Ok(s) => {
            let (b, so) = (s.solution.beta, &s.solution);
            let mut out = vec![format!(
                "  stance {id}: β_h {:.3}, β_p {:.3}, β_v {:.3}; touchdown {:.3} s, liftoff \
                 {:.3} s, end apex {:.3} s (from the start apex)",
                b[0], b[1], b[2], so.t_td, so.t_lo, so.t_e
            )];
            out.extend(
                stance_explanation(&s.verdict, lim)
                    .into_iter()
                    .map(|l| format!("    {l}")),
            );
            out
        }
    }
}

/// One `query run` row: a cycle at one speed for one character.
pub struct RunRow<'a> {
    /// Length scale `L` of the target character.
    pub length_scale: f64,
    /// Mass scale `M`.
    pub mass_scale: f64,
    /// The cycle's two stances (character-scaled).
    pub stances: [&'a Prepared; 2],
    /// The outcome.
    pub candidate: RunCandidate,
    /// The limits each stance was checked against.
    pub limits: [Limits; 2],
    /// The cycle answers this speed for its character (recorded nearest in speed,
    /// [`super::run::nearest_in_speed`]).
    pub used: bool,
}

impl RunRow<'_> {
    fn solved(&self) -> [Option<&ScaledStance>; 2] {
        self.candidate.stances.each_ref().map(|s| s.as_ref().ok())
    }

    /// First problem: `<stance_id>: <reason>`, or `None` when feasible.
    pub fn violated(&self) -> Option<String> {
        self.candidate
            .stances
            .iter()
            .zip(self.stances)
            .find_map(|(s, p)| {
                let id = &p.stance.stance_id;
                match s {
                    Err(e) => Some(format!("{id}: {e}")),
                    Ok(s) => s
                        .verdict
                        .violated
                        .map(|v| format!("{id}: {}", violation_name(v))),
                }
            })
    }

    /// First problem with its value, limit and margin (`<stance_id>: force 1812 N > 1750 N
    /// (by 62 N)`, [`violation_detail`]), or the solver's reason; `None` when feasible.
    pub fn explain(&self) -> Option<String> {
        self.candidate
            .stances
            .iter()
            .zip(self.stances)
            .zip(&self.limits)
            .find_map(|((s, p), lim)| {
                let id = &p.stance.stance_id;
                match s {
                    Err(e) => Some(format!("{id}: {e}")),
                    Ok(s) => violation_detail(&s.verdict, lim).map(|d| format!("{id}: {d}")),
                }
            })
    }

    /// The whole answer, for `--explain`: the cycle at its speed, the gait law's times, and
    /// per stance its scaling and every limit with value, limit and margin
    /// ([`stance_explanation`]).
    pub fn full_explanation(&self) -> Vec<String> {
        let c = &self.candidate;
        let t = &c.timing;
        let mut out = vec![
            format!(
                "cycle {} at {:.2} m/s (recorded {:.2} m/s): {}",
                self.stances[0].stance.stance_id,
                c.speed,
                c.v_orig,
                if c.feasible() {
                    "feasible"
                } else {
                    "infeasible"
                }
            ),
            format!(
                "  gait law {}: contact time × {:.3} (σ_c), step period × {:.3} (σ_T), speed \
                 change × {:.3} (κ)",
                t.law.source.name(),
                t.sigma_c,
                t.sigma_t,
                t.kappa
            ),
        ];
        for ((s, p), lim) in c.stances.iter().zip(self.stances).zip(&self.limits) {
            out.extend(scaled_stance_lines(&p.stance.stance_id, s.as_ref(), lim));
        }
        out
    }

    /// A cycle aggregate over its solved stances; `None` unless both solved.
    fn agg(&self, get: impl Fn(&Verdict) -> f64, max: bool) -> Option<f64> {
        let [a, b] = self.solved();
        let (a, b) = (get(&a?.verdict), get(&b?.verdict));
        Some(if max { a.max(b) } else { a.min(b) })
    }
}

fn per_stance(rows: &[RunRow], get: impl Fn(&ScaledStance) -> f64) -> Vec<Vec<Option<f64>>> {
    rows.iter()
        .map(|r| r.solved().iter().map(|s| s.map(&get)).collect())
        .collect()
}

/// The `query run` table (rows in the given order).
///
/// # Errors
/// A column cannot be built.
pub fn run_table(rows: &[RunRow]) -> PolarsResult<DataFrame> {
    let f = |g: &dyn Fn(&RunRow) -> f64| -> Vec<f64> { rows.iter().map(g).collect() };
    let o =
        |g: &dyn Fn(&RunRow) -> Option<f64>| -> Vec<Option<f64>> { rows.iter().map(g).collect() };
    let first = |r: &RunRow| r.stances[0].stance.clone();
    let lists = |name: &str, g: &dyn Fn(&ScaledStance) -> f64| {
        list_col(name, per_stance(rows, g), DataType::Float64)
    };
    let lim_list = |name: &str, g: &dyn Fn(&Limits) -> f64| {
        let v: Vec<Vec<f64>> = rows
            .iter()
            .map(|r| r.limits.iter().map(g).collect())
            .collect();
        list_col(name, v, DataType::Float64)
    };
    DataFrame::new_infer_height(vec![
        col("speed_mps", f(&|r| r.candidate.speed)),
        col("length_scale", f(&|r| r.length_scale)),
        col("mass_scale", f(&|r| r.mass_scale)),
        col(
            "character_id",
            rows.iter()
                .map(|r| first(r).character_id)
                .collect::<Vec<_>>(),
        ),
        col(
            "clip",
            rows.iter().map(|r| first(r).clip).collect::<Vec<_>>(),
        ),
        list_col(
            "stance_ids",
            rows.iter()
                .map(|r| {
                    r.stances
                        .iter()
                        .map(|p| p.stance.stance_id.clone())
                        .collect()
                })
                .collect(),
            DataType::String,
        )?,
        col("v_orig_mps", f(&|r| r.candidate.v_orig)),
        col("used", rows.iter().map(|r| r.used).collect::<Vec<_>>()),
        col(
            "gait_law",
            rows.iter()
                .map(|r| r.candidate.timing.law.source.name())
                .collect::<Vec<_>>(),
        ),
        col(
            "contact_exponent",
            f(&|r| r.candidate.timing.law.contact_exponent),
        ),
        col(
            "step_exponent",
            f(&|r| r.candidate.timing.law.step_exponent),
        ),
        col("sigma_contact", f(&|r| r.candidate.timing.sigma_c)),
        col("sigma_step", f(&|r| r.candidate.timing.sigma_t)),
        col("kappa", f(&|r| r.candidate.timing.kappa)),
        col("k", f(&|r| r.candidate.k)),
        lists("contact_time_s", &|s| s.solution.t_lo - s.solution.t_td)?,
        lists("step_period_s", &|s| s.solution.t_e)?,
        lists("peak_force_stance_n", &|s| s.verdict.f_peak)?,
        lists("mu_req", &|s| s.verdict.mu_req)?,
        lists("beta_h", &|s| s.solution.beta[0])?,
        lists("beta_v", &|s| s.solution.beta[2])?,
        lists("beta_p", &|s| s.solution.beta[1])?,
        lists(S::TD_STANCE, &|s| s.solution.t_td)?,
        lists(S::LO_STANCE, &|s| s.solution.t_lo)?,
        lists(S::END_APEX_STANCE, &|s| s.solution.t_e)?,
        col("mu_min", o(&|r| r.agg(|v| v.mu_req, true))),
        col("peak_force_n", o(&|r| r.agg(|v| v.f_peak, true))),
        col("ext_min_m", o(&|r| r.agg(|v| v.ext_min, false))),
        col("ext_max_m", o(&|r| r.agg(|v| v.ext_max, true))),
        lists("cp_h_m", &|s| s.cp[0])?,
        lists("cp_p_m", &|s| s.cp[1])?,
        col(
            "feasible_approx",
            rows.iter()
                .map(|r| r.candidate.feasible_approx())
                .collect::<Vec<_>>(),
        ),
        col(
            "feasible",
            rows.iter()
                .map(|r| r.candidate.feasible())
                .collect::<Vec<_>>(),
        ),
        col(
            "violated",
            rows.iter().map(RunRow::violated).collect::<Vec<_>>(),
        ),
        lim_list("limit_mu", &|l| l.mu)?,
        lim_list("limit_f_max_n", &|l| l.f_max)?,
        lim_list("limit_chi_min_m", &|l| l.chi_min)?,
        lim_list("limit_chi_max_m", &|l| l.chi_max)?,
    ])
}

/// One `query jump` row: a liftoff/landing pair, solved or not.
pub struct JumpRow<'a> {
    /// Liftoff stance.
    pub liftoff: &'a Prepared,
    /// Landing stance.
    pub landing: &'a Prepared,
    /// Requested apex height above the liftoff contact, m.
    pub height: f64,
    /// Requested distance, m.
    pub distance: f64,
    /// The limits each side was checked against (liftoff, landing).
    pub limits: [Limits; 2],
    /// The jump, or why it has no admissible scaling.
    pub jump: Result<Jump, String>,
}

impl JumpRow<'_> {
    /// First problem with its value, limit and margin (`liftoff: force 1812 N > 1750 N
    /// (by 62 N)`, [`violation_detail`]), or the solver's reason; `None` when feasible.
    pub fn explain(&self) -> Option<String> {
        match &self.jump {
            Err(e) => Some(e.clone()),
            Ok(j) => ["liftoff", "landing"]
                .iter()
                .zip(&j.sides)
                .zip(&self.limits)
                .find_map(|((n, (_, s)), lim)| {
                    violation_detail(&s.verdict, lim).map(|d| format!("{n}: {d}"))
                }),
        }
    }

    /// The whole answer, for `--explain`: the pair, the requested and achieved flight, and
    /// per side its scaling and every limit with value, limit and margin.
    pub fn full_explanation(&self) -> Vec<String> {
        let (up, down) = (
            &self.liftoff.stance.stance_id,
            &self.landing.stance.stance_id,
        );
        let mut out = vec![format!(
            "pair {up} → {down}: apex {:.3} m above the liftoff contact, distance {:.3} m: {}",
            self.height,
            self.distance,
            match &self.jump {
                Ok(j) if j.feasible() => "feasible",
                _ => "infeasible",
            }
        )];
        match &self.jump {
            Err(e) => out.push(format!("  no admissible scaling: {e}")),
            Ok(j) => {
                out.push(format!(
                    "  flight {:.3} s at apex speed {:.3} m/s ({:.3} m in the air)",
                    j.flight_time, j.u_apex, j.d_flight
                ));
                for (((_, s), p), lim) in j.sides.iter().zip([up, down]).zip(&self.limits) {
                    out.extend(scaled_stance_lines::<String>(p, Ok(s), lim));
                }
            }
        }
        out
    }

    /// First problem, `liftoff: force`, or the solver's reason.
    pub fn violated(&self) -> Option<String> {
        match &self.jump {
            Err(e) => Some(e.clone()),
            Ok(j) => ["liftoff", "landing"]
                .iter()
                .zip(&j.sides)
                .find_map(|(n, (_, s))| {
                    s.verdict
                        .violated
                        .map(|v| format!("{n}: {}", violation_name(v)))
                }),
        }
    }
}

/// The `query jump` table (rows in the given order: the caller ranks them).
///
/// # Errors
/// A column cannot be built.
pub fn jump_table(rows: &[JumpRow]) -> PolarsResult<DataFrame> {
    let o = |g: &dyn Fn(&Jump) -> f64| -> Vec<Option<f64>> {
        rows.iter().map(|r| r.jump.as_ref().ok().map(g)).collect()
    };
    let side = |k: usize, g: &dyn Fn(&ScaledStance) -> f64| -> Vec<Option<f64>> {
        rows.iter()
            .map(|r| r.jump.as_ref().ok().map(|j| g(&j.sides[k].1)))
            .collect()
    };
    let ids = |g: &dyn Fn(&JumpRow) -> String| -> Vec<String> { rows.iter().map(g).collect() };
    let mut cols = vec![
        col("rank", (1..=rows.len() as i64).collect::<Vec<_>>()),
        col(
            "liftoff_stance_id",
            ids(&|r| r.liftoff.stance.stance_id.clone()),
        ),
        col(
            "landing_stance_id",
            ids(&|r| r.landing.stance.stance_id.clone()),
        ),
        col(
            "character_id",
            ids(&|r| r.liftoff.stance.character_id.clone()),
        ),
        col(
            "height_m",
            rows.iter().map(|r| r.height).collect::<Vec<_>>(),
        ),
        col(
            "distance_m",
            rows.iter().map(|r| r.distance).collect::<Vec<_>>(),
        ),
        col("u_apex_mps", o(&|j| j.u_apex)),
        col("flight_time_s", o(&|j| j.flight_time)),
        col("d_flight_m", o(&|j| j.d_flight)),
        col("force_change", o(&Jump::force_change)),
    ];
    // Slack to each limit the side was checked against, as the exact check applies it
    // (`Limits::effective`: ≥ 0 exactly where met).
    let margin = |k: usize, g: &dyn Fn(&ScaledStance, &Limits) -> f64| -> Vec<Option<f64>> {
        rows.iter()
            .map(|r| {
                let lim = r.limits[k].effective();
                r.jump.as_ref().ok().map(|j| g(&j.sides[k].1, &lim))
            })
            .collect()
    };
    for (k, n) in [(0, "1"), (1, "2")] {
        let x = |j: &Jump| j.sides[k].0.x;
        cols.extend([
            col(&format!("beta_h{n}"), side(k, &|s| s.solution.beta[0])),
            col(&format!("beta_v{n}"), side(k, &|s| s.solution.beta[2])),
            col(&format!("beta_p{n}"), side(k, &|s| s.solution.beta[1])),
            col(&format!("td{n}_stance_s"), side(k, &|s| s.solution.t_td)),
            col(&format!("lo{n}_stance_s"), side(k, &|s| s.solution.t_lo)),
            col(
                &format!("end_apex{n}_stance_s"),
                side(k, &|s| s.solution.t_e),
            ),
            col(&format!("x{n}_m"), o(&x)),
            col(&format!("peak_force{n}_n"), side(k, &|s| s.verdict.f_peak)),
            col(&format!("mu_req{n}"), side(k, &|s| s.verdict.mu_req)),
            col(&format!("ext_min{n}_m"), side(k, &|s| s.verdict.ext_min)),
            col(&format!("ext_max{n}_m"), side(k, &|s| s.verdict.ext_max)),
            col(&format!("cp_h{n}_m"), side(k, &|s| s.cp[0])),
            col(&format!("cp_p{n}_m"), side(k, &|s| s.cp[1])),
            col(
                &format!("margin_force{n}_n"),
                margin(k, &|s, l| l.f_max - s.verdict.f_peak),
            ),
            col(
                &format!("margin_mu{n}"),
                margin(k, &|s, l| l.mu - s.verdict.mu_req),
            ),
            col(
                &format!("margin_ext_min{n}_m"),
                margin(k, &|s, l| s.verdict.ext_min - l.chi_min),
            ),
            col(
                &format!("margin_ext_max{n}_m"),
                margin(k, &|s, l| l.chi_max - s.verdict.ext_max),
            ),
        ]);
    }
    let flag = |g: &dyn Fn(&Jump) -> bool| -> Vec<bool> {
        rows.iter().map(|r| r.jump.as_ref().is_ok_and(g)).collect()
    };
    cols.extend([
        col("feasible_approx", flag(&Jump::feasible_approx)),
        col("feasible", flag(&Jump::feasible)),
        col(
            "violated",
            rows.iter().map(JumpRow::violated).collect::<Vec<_>>(),
        ),
    ]);
    DataFrame::new_infer_height(cols)
}

/// `jump_map.parquet`: one row per pair and cell, pairs in (liftoff, landing) pool order,
/// cells row-major (height, then `u_apex`).
///
/// # Errors
/// A column cannot be built.
pub fn jump_map_table(map: &JumpMap, pool: &[Prepared]) -> PolarsResult<DataFrame> {
    let (n_h, n_u) = (map.heights.len(), map.speeds.len());
    let n = map.pairs.len() * n_h * n_u;
    let mut lift = Vec::with_capacity(n);
    let mut land = Vec::with_capacity(n);
    let (mut u, mut h) = (Vec::with_capacity(n), Vec::with_capacity(n));
    let (mut dist, mut flight) = (Vec::with_capacity(n), Vec::with_capacity(n));
    let (mut ap, mut ex) = (Vec::with_capacity(n), Vec::with_capacity(n));
    for p in &map.pairs {
        let (a, b) = (
            pool[p.liftoff].stance.stance_id.as_str(),
            pool[p.landing].stance.stance_id.as_str(),
        );
        for (r, &hr) in map.heights.iter().enumerate() {
            let row = p.rows[r];
            for (q, &uq) in map.speeds.iter().enumerate() {
                lift.push(a);
                land.push(b);
                u.push(uq);
                h.push(hr);
                dist.push(row.map(|(d, c, _)| uq * d + c));
                flight.push(row.map(|(_, _, t)| t));
                ap.push(p.approx[r * n_u + q]);
                ex.push(p.exact[r * n_u + q]);
            }
        }
    }
    DataFrame::new_infer_height(vec![
        col("liftoff_stance_id", lift),
        col("landing_stance_id", land),
        col("u_apex_mps", u),
        col("height_m", h),
        col("distance_m", dist),
        col("flight_time_s", flight),
        col("feasible_approx", ap),
        col("feasible_exact", ex),
    ])
}

/// `jump_map_pairs.parquet`: one row per pair with its cell counts and IoU.
///
/// # Errors
/// A column cannot be built.
pub fn jump_pairs_table(map: &JumpMap, pool: &[Prepared]) -> PolarsResult<DataFrame> {
    let p = &map.pairs;
    let id = |i: usize| pool[i].stance.stance_id.clone();
    let count = |g: &dyn Fn(&Agreement) -> usize| -> Vec<i64> {
        p.iter().map(|x| g(&x.agreement) as i64).collect()
    };
    DataFrame::new_infer_height(vec![
        col(
            "liftoff_stance_id",
            p.iter().map(|x| id(x.liftoff)).collect::<Vec<_>>(),
        ),
        col(
            "landing_stance_id",
            p.iter().map(|x| id(x.landing)).collect::<Vec<_>>(),
        ),
        col(
            "character_id",
            p.iter()
                .map(|x| pool[x.liftoff].stance.character_id.clone())
                .collect::<Vec<_>>(),
        ),
        col("n_approx", count(&|a| a.approx)),
        col("n_exact", count(&|a| a.exact)),
        col("n_both", count(&|a| a.both)),
        col(
            "iou",
            p.iter().map(|x| x.agreement.iou()).collect::<Vec<_>>(),
        ),
    ])
}
