//! A catalogue of what a library holds (`stancelib list LIB`, issue 38 item 2): its
//! characters (clips, leg length, mass, stances), its recorded run cycles (speed, and
//! whether the default `query run` finds each feasible at its own speed) and its recorded
//! jumps (liftoff → landing pairs, height and distance).
//!
//! The catalogue is built by [`catalogue`] from an opened library, with the same rules the
//! queries use: run cycles by [`run_cycles`], clips whose time base is wrong by
//! [`time_scaled`], jumps by [`is_liftoff`] / [`is_landing`] / [`recorded_jump`]. It lives
//! here, at the edge, because it uses `query/` and reads `library/` (dependencies go one
//! way); [`read_catalogue`] is the only part that touches the filesystem.
//!
//! # Model
//! ```text
//! run cycle   = consecutive stances (S1, S2) of one clip chained by a flight (§6.8)
//! v_orig      = Σ x_k / Σ T_k                                  (m/s)
//! feasible    = run_at_speed(cycle, v = v_orig) under the defaults of `query run`:
//!               absolute limits (§7.5), λ_act = DEFAULT_QUERY_ACTIVE_FRACTION,
//!               gait law `auto` (the character's own law from its kept cycles)
//! jump        = consecutive stances (S1, S2) of one clip, S1 a liftoff, S2 a landing
//! h           = (ze1 + zs2 + z_c2 − z_c1)/2,   d = x1 + x2      (m, §6.9)
//! ```
//!
//! # Frames and units
//! SI: metres, kilograms, metres per second. Heights are above the stances' contact heights.
//!
//! # References
//! spec stance-model §6.8 (run cycles), §6.9 (recorded jumps), §7.5 (limits).

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use rayon::prelude::*;
use serde::Serialize;

use crate::error::{Error, Result};
use crate::library::codec::schema::{clips, CLIPS_FILE};
use crate::library::codec::table::Table;
use crate::library::readers::read::{open_library, StanceLibrary};
use crate::math::stats::median;
use crate::query::feasibility::{LimitForm, Limits, DEFAULT_QUERY_ACTIVE_FRACTION};
use crate::query::gait::{GaitLaw, LawChoice};
use crate::query::jump::{is_landing, is_liftoff, recorded_jump};
use crate::query::limits::{absolute_limits, left_out_clips, stance_limits, time_scaled};
use crate::query::pool::Prepared;
use crate::query::run::{character_laws, run_at_speed, run_cycles, RunCycle};

/// One character of a library.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct CatalogueCharacter {
    /// `character_id` (`sk-…`).
    pub character_id: String,
    /// Number of its clips (rows of `clips.parquet` with this `character_id`).
    pub n_clips: usize,
    /// Its clip names, sorted.
    pub clips: Vec<String>,
    /// Leg length `L_leg`, m: the median over its clips of `clips.parquet` `leg_length_m`
    /// (`None` when no clip records one).
    pub leg_length_m: Option<f64>,
    /// Body mass, kg: its stances' `mass_kg` (median), else its clips' `mass_kg`.
    pub mass_kg: Option<f64>,
    /// Number of its stances.
    pub n_stances: usize,
}

/// One recorded run cycle.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct CatalogueCycle {
    /// The clip.
    pub clip: String,
    /// Its character.
    pub character_id: String,
    /// The two stances, in time order (the first names the cycle in `query run`).
    pub stance_ids: [String; 2],
    /// Mean speed `Σx/ΣT` of the cycle as recorded, m/s (`v_orig_mps` of `query run`).
    pub v_orig_mps: f64,
    /// The clip's time base is wrong (`s_eff` outside the accepted range): `query run`
    /// leaves the cycle out.
    pub time_scaled: bool,
    /// Why `query run` leaves the cycle out (its clip's time base, or a copy of another
    /// clip's file), `None` when it answers.
    pub left_out: Option<String>,
    /// Feasible at its own speed under the default `query run` (`None` when left out).
    pub feasible_at_own_speed: Option<bool>,
}

/// One recorded jump: a liftoff stance followed by a landing stance of one clip.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct CatalogueJump {
    /// The clip.
    pub clip: String,
    /// Its character.
    pub character_id: String,
    /// The liftoff stance.
    pub liftoff: String,
    /// The landing stance.
    pub landing: String,
    /// Apex height of the recorded jump, m ([`recorded_jump`]).
    pub height_m: f64,
    /// Distance of the recorded jump `x1 + x2`, m.
    pub distance_m: f64,
}

/// What a library holds, item by item (`stancelib list`; its `--json` keys are the field
/// names).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Catalogue {
    /// The library folder as given.
    pub library: PathBuf,
    /// Characters, by `character_id`.
    pub characters: Vec<CatalogueCharacter>,
    /// Run cycles, by clip and time.
    pub run_cycles: Vec<CatalogueCycle>,
    /// Recorded jumps, by clip and time.
    pub jumps: Vec<CatalogueJump>,
}

/// Reads the catalogue of the library folder `dir`.
///
/// # Errors
/// A missing or malformed library (the error names the file and column, as
/// [`open_library`]).
pub fn read_catalogue(dir: &Path) -> Result<Catalogue> {
    let lib = open_library(dir)?;
    let t = Table::open_columns(&dir.join(CLIPS_FILE), &[clips::CLIP, clips::CHARACTER_ID])?;
    let names = t.strings(clips::CLIP)?;
    let ids =
        t.df.column(clips::CHARACTER_ID)
            .map_err(|_| Error::column(&t.path, clips::CHARACTER_ID, None, "missing"))?
            .str()
            .map_err(|_| Error::column(&t.path, clips::CHARACTER_ID, None, "expected string"))?
            .clone();
    // Clips that failed have no character.
    let characters: BTreeMap<String, String> = names
        .into_iter()
        .zip(ids.iter())
        .filter_map(|(clip, id)| id.map(|id| (clip, id.to_string())))
        .collect();
    Ok(catalogue(&lib, &characters))
}

/// The catalogue of an opened library; `character_of` maps each clip to its
/// `character_id` (`clips.parquet`; clips without one are not listed).
pub fn catalogue(lib: &StanceLibrary, character_of: &BTreeMap<String, String>) -> Catalogue {
    Catalogue {
        library: lib.dir.clone(),
        characters: characters(lib, character_of),
        run_cycles: cycles(lib),
        jumps: jumps(lib),
    }
}

fn characters(
    lib: &StanceLibrary,
    character_of: &BTreeMap<String, String>,
) -> Vec<CatalogueCharacter> {
    let mut clips_of: BTreeMap<&str, Vec<&str>> = BTreeMap::new();
    for (clip, ch) in character_of {
        clips_of.entry(ch).or_default().push(clip);
    }
    let mut masses: BTreeMap<&str, Vec<f64>> = BTreeMap::new();
    for s in &lib.stances {
        clips_of.entry(&s.character_id).or_default();
        masses
            .entry(&s.character_id)
            .or_default()
            .push(s.model.mass_kg);
    }
    let finite = |v: Vec<f64>| {
        let v: Vec<f64> = v.into_iter().filter(|x| x.is_finite()).collect();
        median(&v)
    };
    clips_of
        .into_iter()
        .map(|(ch, mut names)| {
            names.sort_unstable();
            let info: Vec<_> = names.iter().filter_map(|c| lib.clips.get(*c)).collect();
            let leg = finite(info.iter().filter_map(|c| c.leg_m).collect());
            let stance_mass = masses.get(ch).cloned().unwrap_or_default();
            let n_stances = stance_mass.len();
            let mass =
                finite(stance_mass).or_else(|| finite(info.iter().map(|c| c.mass_kg).collect()));
            CatalogueCharacter {
                character_id: ch.to_string(),
                n_clips: names.len(),
                clips: names.into_iter().map(str::to_string).collect(),
                leg_length_m: leg,
                mass_kg: mass,
                n_stances,
            }
        })
        .collect()
}

/// Every run cycle, with its verdict at its own speed as `query run --speed v_orig` gives
/// it with default options (`crate::pipeline::commands::query_run::run_query` at `L = M = 1`).
fn cycles(lib: &StanceLibrary) -> Vec<CatalogueCycle> {
    let active = DEFAULT_QUERY_ACTIVE_FRACTION;
    let all = run_cycles(&lib.stances);
    let left = left_out_clips(lib);
    let left_out = |c: &RunCycle| left.get(&lib.stances[c.stances[0]].clip);
    let kept: Vec<RunCycle> = all
        .iter()
        .filter(|c| left_out(c).is_none())
        .copied()
        .collect();
    let limits: BTreeMap<String, Limits> = absolute_limits(lib);
    let laws = character_laws(&lib.stances, &kept, LawChoice::Auto);
    all.par_iter()
        .map(|c| {
            let [a, b] = c.stances.map(|i| &lib.stances[i]);
            let skip = left_out(c);
            let feasible = skip.is_none().then(|| {
                let prep = c
                    .stances
                    .map(|i| Prepared::with_active_fraction(lib.stances[i].clone(), active));
                let lim =
                    [0, 1].map(|k| stance_limits(&prep[k], LimitForm::Absolute, &limits, None));
                let law = laws
                    .get(&a.character_id)
                    .copied()
                    .unwrap_or(GaitLaw::POPULATION);
                let cycle = [&prep[0], &prep[1]];
                run_at_speed(cycle, c.v_orig, c.v_orig, &law, [&lim[0], &lim[1]]).feasible()
            });
            CatalogueCycle {
                clip: a.clip.clone(),
                character_id: a.character_id.clone(),
                stance_ids: [a.stance_id.clone(), b.stance_id.clone()],
                v_orig_mps: c.v_orig,
                time_scaled: time_scaled(lib, &a.clip),
                left_out: skip.map(ToString::to_string),
                feasible_at_own_speed: feasible,
            }
        })
        .collect()
}

/// Every recorded jump: consecutive stances of one clip, a liftoff then a landing.
fn jumps(lib: &StanceLibrary) -> Vec<CatalogueJump> {
    lib.stances
        .windows(2)
        .filter(|w| w[0].clip == w[1].clip && is_liftoff(&w[0]) && is_landing(&w[1]))
        .map(|w| {
            let (h, d) = recorded_jump(&w[0], &w[1]);
            CatalogueJump {
                clip: w[0].clip.clone(),
                character_id: w[0].character_id.clone(),
                liftoff: w[0].stance_id.clone(),
                landing: w[1].stance_id.clone(),
                height_m: h,
                distance_m: d,
            }
        })
        .collect()
}
