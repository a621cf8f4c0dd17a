//! The body file (`--body`) and pipeline files (`pipelines/*.toml`): parsed, validated,
//! and resolved into [`IngestOptions`] with the precedence CLI > pipeline > body > default.
//!
//! Unknown keys are errors; every error is reported as `path:line: message`.
//!
//! # References
//! spec README "Configuration files".

use crate::force_model::ForceModelKind;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use serde::Deserialize;

use crate::contacts::ContactOptions;
use crate::error::{echo, Error, Result};
use crate::force_model::fit::{MAX_SAMPLES, MIN_SAMPLES};
use crate::ingest::{IngestOptions, DEFAULT_MASS_KG};
use crate::library::storage::layout::Layout;
use crate::pipeline::engine::batch::check_threads;
use crate::pipeline::engine::inputs::{read_side_text, SideInput};
use crate::query::feasibility::check_mu;
use crate::query::map::{check_grid, Axis, DEFAULT_HEIGHTS, DEFAULT_SPEEDS};
use crate::query::run::{check_scale, check_speed};
use crate::skeleton::com::Sex;
use crate::skeleton::landmarks::LANDMARK_KEYS;
use crate::skeleton::units::{parse_unit, UpAxis};
use crate::stances::StanceOptions;

/// A unit given as metres per file unit or by name.
#[derive(Debug, Clone, Deserialize, PartialEq)]
#[serde(untagged)]
pub enum UnitValue {
    /// Metres per file unit.
    Number(f64),
    /// `m`, `cm`, `mm`, `in`, `cmu`, …
    Name(String),
}

/// The body file.
#[derive(Debug, Clone, Default, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct BodyFile {
    /// Character id.
    pub id: Option<String>,
    /// Body mass, kg.
    pub mass_kg: Option<f64>,
    /// `male`, `female` or `average`.
    pub sex: Option<String>,
    /// Unit override.
    pub unit: Option<UnitValue>,
    /// Up-axis override.
    pub up_axis: Option<String>,
    /// Landmark → joint name.
    pub landmarks: Option<BTreeMap<String, String>>,
}

/// `[contacts]` of a pipeline file.
#[derive(Debug, Clone, Default, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
#[allow(missing_docs)]
pub struct ContactsTable {
    #[serde(rename = "static")]
    pub static_mode: Option<bool>,
    pub hands: Option<bool>,
    pub foot_h_on: Option<f64>,
    pub foot_h_off: Option<f64>,
    pub foot_v_on: Option<f64>,
    pub foot_v_off: Option<f64>,
    pub hand_h_on: Option<f64>,
    pub hand_h_off: Option<f64>,
    pub hand_v_on: Option<f64>,
    pub hand_v_off: Option<f64>,
    pub min_on_s: Option<f64>,
    pub min_gap_s: Option<f64>,
    pub floor_window_s: Option<f64>,
    pub support_check: Option<bool>,
}

/// `[fit]` of a pipeline file (stance-model stage; accepted and validated here).
#[derive(Debug, Clone, Default, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
#[allow(missing_docs)]
pub struct FitTable {
    pub model: Option<String>,
    pub vertical_degree: Option<u32>,
    pub ratio_degree_h: Option<u32>,
    pub ratio_degree_p: Option<u32>,
    pub leg_line_weight: Option<f64>,
    pub roll_fraction: Option<f64>,
    pub stage_b: Option<bool>,
    pub stage_b_time_refinement: Option<bool>,
    pub max_harmonics: Option<u32>,
    pub energy: Option<f64>,
    pub samples: Option<u32>,
}

/// `[constraints]` of a pipeline file (query stage; accepted and validated here).
#[derive(Debug, Clone, Default, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
#[allow(missing_docs)]
pub struct ConstraintsTable {
    pub mu: Option<f64>,
    pub limits: Option<String>,
    pub active_set: Option<f64>,
}

/// `[queries]` of a pipeline file: query stages run on the library after the build; their
/// outputs go to `<out>/queries/`.
#[derive(Debug, Clone, Default, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct QueriesTable {
    /// `query run` speeds, `start:stop:step` in m/s (→ `queries/runs.parquet`).
    pub run_speeds: Option<String>,
    /// Leg-length ratio of the run's target character (default 1).
    pub length_scale: Option<f64>,
    /// Body-mass ratio of the run's target character (default 1).
    pub mass_scale: Option<f64>,
    /// How the run's contact time and step period change with speed: `auto` (default),
    /// `population` or `paper`.
    pub gait_law: Option<String>,
    /// Run `map jumps` (→ `queries/jump_map/`).
    pub jump_map: Option<bool>,
    /// Map rows, `start:stop:step` in m (default 0.6:1.6:0.02).
    pub map_heights: Option<String>,
    /// Map columns, `start:stop:step` in m/s (default 0:5:0.05).
    pub map_speeds: Option<String>,
    /// Keep the clips the queries leave out (copies of another clip's file, clips whose
    /// time base is wrong); default false.
    pub keep_left_out: Option<bool>,
}

/// A pipeline file.
#[derive(Debug, Clone, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct PipelineFile {
    /// Globs of BVH files or folders, relative to the pipeline file.
    pub inputs: Vec<String>,
    /// Output folder, relative to the pipeline file.
    pub out: String,
    /// Body file, relative to the pipeline file.
    pub body: Option<String>,
    /// Body mass, kg.
    pub mass_kg: Option<f64>,
    /// Per-clip masses (CSV: `clip,mass_kg[,sex]`), relative to the pipeline file.
    pub masses: Option<String>,
    /// Unit override for every input.
    pub unit: Option<UnitValue>,
    /// Up-axis override for every input.
    pub up_axis: Option<String>,
    /// Rayon threads (0 = all cores).
    pub threads: Option<usize>,
    /// Library layout, `file` (default) or `dataset` ([`Layout`]).
    pub layout: Option<String>,
    /// Contact options.
    pub contacts: Option<ContactsTable>,
    /// Force-model options.
    pub fit: Option<FitTable>,
    /// Constraint options.
    pub constraints: Option<ConstraintsTable>,
    /// Query stages run after the build.
    pub queries: Option<QueriesTable>,
}

/// 1-based line of a byte offset.
fn line_of(text: &str, offset: usize) -> usize {
    text[..offset.min(text.len())].matches('\n').count() + 1
}

/// Line where `key = …` is written, for value errors.
fn key_line(text: &str, key: &str) -> Option<usize> {
    text.lines()
        .position(|l| {
            let t = l.trim_start();
            t.strip_prefix(key)
                .is_some_and(|r| r.trim_start().starts_with('='))
        })
        .map(|i| i + 1)
}

fn parse_toml<T: serde::de::DeserializeOwned>(path: &Path, text: &str) -> Result<T> {
    toml::from_str(text).map_err(|e| {
        let line = e.span().map(|s| line_of(text, s.start));
        Error::config(Some(path.to_path_buf()), line, e.message().to_string())
    })
}

/// Parse a body file.
///
/// # Errors
/// Unreadable file, TOML errors, unknown keys, invalid values (`path:line: message`).
pub fn parse_body(path: &Path, text: &str) -> Result<BodyFile> {
    let b: BodyFile = parse_toml(path, text)?;
    check_common(path, text, b.mass_kg, b.unit.as_ref(), b.up_axis.as_deref())?;
    if let Some(k) = b
        .landmarks
        .iter()
        .flat_map(|m| m.keys())
        .find(|k| !LANDMARK_KEYS.contains(&k.as_str()))
    {
        let msg = format!(
            "[landmarks] {k}: not a landmark (one of {})",
            LANDMARK_KEYS.join(", ")
        );
        return Err(Error::config(
            Some(path.to_path_buf()),
            key_line(text, k),
            msg,
        ));
    }
    if let Some(s) = &b.sex {
        if Sex::parse(s).is_none() {
            let msg = format!("sex must be male, female or average, found '{s}'");
            return Err(Error::config(
                Some(path.to_path_buf()),
                key_line(text, "sex"),
                msg,
            ));
        }
    }
    Ok(b)
}

/// Validate the keys the body and pipeline files share (`mass_kg`, `unit`, `up_axis`).
fn check_common(
    path: &Path,
    text: &str,
    mass_kg: Option<f64>,
    unit: Option<&UnitValue>,
    up_axis: Option<&str>,
) -> Result<()> {
    let bad =
        |key: &str, msg: String| Error::config(Some(path.to_path_buf()), key_line(text, key), msg);
    if let Some(m) = mass_kg {
        crate::ingest::masses::check_body_mass(m)
            .map_err(|e| bad("mass_kg", format!("mass_kg: {e}")))?;
    }
    if let Some(u) = unit {
        if unit_value(u).is_none() {
            return Err(bad(
                "unit",
                format!("invalid unit {u:?}: m, cm, mm, in, cmu or metres per unit"),
            ));
        }
    }
    if let Some(a) = up_axis {
        if UpAxis::parse(a).is_none() {
            return Err(bad(
                "up_axis",
                format!("up_axis must be one of +X -X +Y -Y +Z -Z, found '{a}'"),
            ));
        }
    }
    Ok(())
}

/// Metres per file unit of a unit value.
pub fn unit_value(u: &UnitValue) -> Option<f64> {
    match u {
        UnitValue::Number(v) => (v.is_finite() && *v > 0.0).then_some(*v),
        UnitValue::Name(s) => parse_unit(s),
    }
}

/// Parse a pipeline file.
///
/// # Errors
/// TOML errors, unknown keys, invalid values (`path:line: message`).
pub fn parse_pipeline(path: &Path, text: &str) -> Result<PipelineFile> {
    let p: PipelineFile = parse_toml(path, text)?;
    let bad =
        |key: &str, msg: String| Error::config(Some(path.to_path_buf()), key_line(text, key), msg);
    if p.inputs.is_empty() {
        return Err(bad("inputs", "inputs must list at least one glob".into()));
    }
    if let Some(e) = too_many_inputs(&p) {
        return Err(bad("inputs", e.to_string()));
    }
    check_common(path, text, p.mass_kg, p.unit.as_ref(), p.up_axis.as_deref())?;
    if let Some(a) = p.constraints.as_ref().and_then(|c| c.active_set) {
        if !(a.is_finite() && (0.0..1.0).contains(&a)) {
            return Err(bad(
                "active_set",
                format!("active_set = {a} must lie in [0, 1)"),
            ));
        }
    }
    if let Some(f) = &p.fit {
        for (key, set) in [
            ("stage_b", f.stage_b.is_some()),
            (
                "stage_b_time_refinement",
                f.stage_b_time_refinement.is_some(),
            ),
        ] {
            if set {
                return Err(bad(
                    key,
                    format!("{key} was removed: Stage B made every force-plate figure worse; the ratio model (fit.model = \"ratio\") takes its edge states from the flights"),
                ));
            }
        }
        if let Some(m) = &f.model {
            if ForceModelKind::parse(m).is_none() {
                return Err(bad(
                    "model",
                    format!("model = \"{m}\" is not ratio or fourier"),
                ));
            }
        }
        let ratio = resolve_fit(Some(&p), None).fit.ratio;
        if let Err(e) = ratio.check() {
            return Err(bad("degree", e.to_string()));
        }
        if f.energy.is_some_and(|e| !(0.0..=1.0).contains(&e)) {
            return Err(bad("energy", "energy must lie in [0, 1]".into()));
        }
        if f.samples
            .is_some_and(|n| !(MIN_SAMPLES..=MAX_SAMPLES).contains(&(n as usize)))
        {
            return Err(bad(
                "samples",
                format!("samples must lie in [{MIN_SAMPLES}, {MAX_SAMPLES}] (MAX_SAMPLES)"),
            ));
        }
        if f.max_harmonics == Some(0) {
            return Err(bad(
                "max_harmonics",
                "max_harmonics must be at least 1".into(),
            ));
        }
    }
    if let Some(l) = p.layout.as_deref().filter(|l| Layout::parse(l).is_none()) {
        return Err(bad(
            "layout",
            format!("layout must be file or dataset, found '{l}'"),
        ));
    }
    if let Some(l) = p.constraints.as_ref().and_then(|c| c.limits.as_ref()) {
        if !["per_query", "absolute", "relative"].contains(&l.as_str()) {
            return Err(bad(
                "limits",
                format!("limits must be per_query, absolute or relative, found '{l}'"),
            ));
        }
    }
    check_values(&p).map_err(|(key, e)| bad(key, e.to_string()))?;
    Ok(p)
}

/// Range checks of every value the serde types let through (issue 11 item 10): the whole
/// file is valid before any work starts. On failure: the key (for its line) and why.
fn check_values(p: &PipelineFile) -> std::result::Result<(), (&'static str, Error)> {
    let at = |key: &'static str| move |e: Error| (key, e);
    if let Some(t) = p.threads {
        check_threads("threads", t).map_err(at("threads"))?;
    }
    if let Some(c) = &p.contacts {
        for (key, v, positive) in [
            ("foot_h_on", c.foot_h_on, false),
            ("foot_h_off", c.foot_h_off, false),
            ("foot_v_on", c.foot_v_on, false),
            ("foot_v_off", c.foot_v_off, false),
            ("hand_h_on", c.hand_h_on, false),
            ("hand_h_off", c.hand_h_off, false),
            ("hand_v_on", c.hand_v_on, false),
            ("hand_v_off", c.hand_v_off, false),
            ("min_on_s", c.min_on_s, false),
            ("min_gap_s", c.min_gap_s, false),
            ("floor_window_s", c.floor_window_s, true),
        ] {
            let Some(v) = v else { continue };
            if !(v.is_finite() && (v > 0.0 || (!positive && v == 0.0))) {
                let want = if positive { "> 0" } else { "≥ 0" };
                let msg = format!("must be a finite number {want}, found {v}");
                return Err((key, Error::invalid(format!("[contacts] {key}"), msg)));
            }
        }
    }
    let has_queries = p
        .queries
        .as_ref()
        .is_some_and(|q| q.run_speeds.is_some() || q.jump_map == Some(true));
    if let Some(c) = &p.constraints {
        if let Some(mu) = c.mu {
            check_mu(mu).map_err(|m| ("mu", Error::invalid("[constraints] mu", m)))?;
        }
        if !has_queries && (c.mu.is_some() || c.limits.is_some()) {
            let key = if c.mu.is_some() { "mu" } else { "limits" };
            let msg = "has no effect: no [queries] stage runs (give run_speeds or jump_map = true)";
            return Err((key, Error::invalid(format!("[constraints] {key}"), msg)));
        }
    }
    if let Some(q) = &p.queries {
        check_queries(q)?;
    }
    Ok(())
}

/// `[queries]`: ranges within the grid limits, positive scales, no key without its stage.
fn check_queries(q: &QueriesTable) -> std::result::Result<(), (&'static str, Error)> {
    let unused = |key: &'static str, stage: &str| {
        let msg = format!("has no effect without {stage}");
        Err((key, Error::invalid(format!("[queries] {key}"), msg)))
    };
    match &q.run_speeds {
        Some(r) => {
            let axis = Axis::parse("[queries] run_speeds", r).map_err(|e| ("run_speeds", e))?;
            check_speed("[queries] run_speeds", axis.start).map_err(|e| ("run_speeds", e))?;
        }
        None if q.length_scale.is_some() => return unused("length_scale", "run_speeds"),
        None if q.mass_scale.is_some() => return unused("mass_scale", "run_speeds"),
        None if q.gait_law.is_some() => return unused("gait_law", "run_speeds"),
        None => {}
    }
    if let Some(name) = &q.gait_law {
        if crate::query::gait::LawChoice::parse(name).is_none() {
            let msg = format!(
                "unknown law '{name}' (give {})",
                crate::query::gait::LawChoice::NAMES
            );
            return Err(("gait_law", Error::invalid("[queries] gait_law", msg)));
        }
    }
    for (key, v) in [
        ("length_scale", q.length_scale),
        ("mass_scale", q.mass_scale),
    ] {
        if let Some(v) = v {
            check_scale(&format!("[queries] {key}"), v).map_err(|e| (key, e))?;
        }
    }
    if q.jump_map != Some(true) {
        if q.map_heights.is_some() {
            return unused("map_heights", "jump_map = true");
        }
        if q.map_speeds.is_some() {
            return unused("map_speeds", "jump_map = true");
        }
        return Ok(());
    }
    let axis = |key: &'static str, v: &Option<String>, default: Axis| match v {
        Some(r) => Axis::parse(&format!("[queries] {key}"), r).map_err(|e| (key, e)),
        None => Ok(default),
    };
    let h = axis("map_heights", &q.map_heights, DEFAULT_HEIGHTS)?;
    let u = axis("map_speeds", &q.map_speeds, DEFAULT_SPEEDS)?;
    let key = if q.map_speeds.is_some() {
        "map_speeds"
    } else {
        "map_heights"
    };
    check_grid("[queries] map_heights × map_speeds", h.len(), u.len()).map_err(|e| (key, e))
}

/// Values given on the command line (each wins over the files).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Overrides {
    /// `--mass`.
    pub mass_kg: Option<f64>,
    /// `--unit`, metres per unit.
    pub unit_m: Option<f64>,
    /// `--up-axis`.
    pub up_axis: Option<UpAxis>,
    /// `--static-contacts`.
    pub static_contacts: bool,
    /// `--no-hands`.
    pub no_hands: bool,
    /// `--joints`.
    pub joints: bool,
    /// `--masses`: a per-clip masses table (read by [`with_masses`]).
    pub masses: Option<std::path::PathBuf>,
}

/// Resolve options: CLI > pipeline > body > default.
pub fn resolve(
    body: Option<&BodyFile>,
    pipe: Option<&PipelineFile>,
    cli: &Overrides,
) -> IngestOptions {
    let mut o = IngestOptions::default();
    if let Some(b) = body {
        o.mass_kg = b.mass_kg.unwrap_or(DEFAULT_MASS_KG);
        o.sex = b.sex.as_deref().and_then(Sex::parse).unwrap_or_default();
        o.unit_m = b.unit.as_ref().and_then(unit_value);
        o.up_axis = b.up_axis.as_deref().and_then(UpAxis::parse);
        o.landmarks = b.landmarks.clone().unwrap_or_default();
        o.character_id = b.id.clone();
    }
    if let Some(p) = pipe {
        o.mass_kg = p.mass_kg.unwrap_or(o.mass_kg);
        o.unit_m = p.unit.as_ref().and_then(unit_value).or(o.unit_m);
        o.up_axis = p.up_axis.as_deref().and_then(UpAxis::parse).or(o.up_axis);
        if let Some(c) = &p.contacts {
            apply_contacts(&mut o.contacts, c);
        }
    }
    o.mass_kg = cli.mass_kg.unwrap_or(o.mass_kg);
    o.mass_given = cli.mass_kg.is_some()
        || pipe.is_some_and(|p| p.mass_kg.is_some())
        || body.is_some_and(|b| b.mass_kg.is_some());
    o.unit_m = cli.unit_m.or(o.unit_m);
    o.up_axis = cli.up_axis.or(o.up_axis);
    o.contacts.static_mode |= cli.static_contacts;
    o.contacts.hands &= !cli.no_hands;
    o.joints = cli.joints;
    o
}

fn apply_contacts(o: &mut ContactOptions, c: &ContactsTable) {
    let set = |dst: &mut f64, v: Option<f64>| {
        if let Some(v) = v {
            *dst = v
        }
    };
    o.static_mode = c.static_mode.unwrap_or(o.static_mode);
    o.hands = c.hands.unwrap_or(o.hands);
    set(&mut o.foot.h_on, c.foot_h_on);
    set(&mut o.foot.h_off, c.foot_h_off);
    set(&mut o.foot.v_on, c.foot_v_on);
    set(&mut o.foot.v_off, c.foot_v_off);
    set(&mut o.hand.h_on, c.hand_h_on);
    set(&mut o.hand.h_off, c.hand_h_off);
    set(&mut o.hand.v_on, c.hand_v_on);
    set(&mut o.hand.v_off, c.hand_v_off);
    set(&mut o.min_on_s, c.min_on_s);
    set(&mut o.min_gap_s, c.min_gap_s);
    set(&mut o.floor_window_s, c.floor_window_s);
    o.support_check = c.support_check.unwrap_or(o.support_check);
}

/// Stance options from a pipeline's `[fit]` table and the command line (`--force-model`).
pub fn resolve_fit(
    pipe: Option<&PipelineFile>,
    cli_model: Option<ForceModelKind>,
) -> StanceOptions {
    let mut o = StanceOptions::default();
    if let Some(f) = pipe.and_then(|p| p.fit.as_ref()) {
        if let Some(m) = f.model.as_deref().and_then(ForceModelKind::parse) {
            o.fit.model = m;
        }
        let deg = |v: Option<u32>, d: usize| v.map_or(d, |v| v as usize);
        o.fit.ratio.vertical_degree = deg(f.vertical_degree, o.fit.ratio.vertical_degree);
        o.fit.ratio.ratio_degree_h = deg(f.ratio_degree_h, o.fit.ratio.ratio_degree_h);
        o.fit.ratio.ratio_degree_p = deg(f.ratio_degree_p, o.fit.ratio.ratio_degree_p);
        o.fit.max_harmonics = f.max_harmonics.map_or(o.fit.max_harmonics, |v| v as usize);
        o.fit.energy = f.energy.unwrap_or(o.fit.energy);
        o.fit.ratio.leg_line_weight = f.leg_line_weight.unwrap_or(o.fit.ratio.leg_line_weight);
        o.fit.ratio.roll_fraction = f.roll_fraction.unwrap_or(o.fit.ratio.roll_fraction);
        o.fit.samples = f.samples.map_or(o.fit.samples, |v| v as usize);
    }
    if let Some(m) = cli_model {
        o.fit.model = m;
    }
    o
}

/// `o` with the per-clip masses table at `path` (`--masses`, or a pipeline's `masses`),
/// when one is given.
///
/// # Errors
/// The file cannot be read as a side input (regular file, size bound) or is not a masses
/// table (the error names the file, line and field).
pub fn with_masses(mut o: IngestOptions, path: Option<&Path>) -> Result<IngestOptions> {
    if let Some(p) = path {
        let text = read_side_text(p, SideInput::Masses)?;
        let table = crate::ingest::masses::parse_masses(&text, &p.display().to_string())?;
        o.masses = Some(std::sync::Arc::new(table));
    }
    Ok(o)
}

/// Most globs of a pipeline's `inputs` (count). Each is expanded by listing folders, so
/// the work grows with the globs times the files they list; a pipeline lists a few (those
/// in `pipelines/` one or two). A list of 10⁶ repeats of one glob once held 723 MB of
/// paths and was still expanding after 60 s. Repeated globs are expanded once, and a file
/// matched by several globs is held once. Each distinct glob lists its folders again:
/// 10,000 distinct globs over a folder of 3,000 files took 34.7 s to expand (one glob:
/// 0.6 s), so the bound is 1,000 (about 3.5 s there; the time grows with the files listed).
pub const MAX_INPUT_PATTERNS: usize = 1_000;

/// The limit error when the pipeline lists more than [`MAX_INPUT_PATTERNS`] globs.
fn too_many_inputs(p: &PipelineFile) -> Option<Error> {
    (p.inputs.len() > MAX_INPUT_PATTERNS).then(|| {
        Error::cap(
            "inputs",
            "globs",
            p.inputs.len() as f64,
            MAX_INPUT_PATTERNS,
            "MAX_INPUT_PATTERNS",
        )
    })
}

/// Expand a pipeline's input globs (relative to the pipeline file's folder): each
/// distinct glob once, each file once, in the order first found.
///
/// # Errors
/// An invalid glob pattern, a glob that matches nothing, or more than
/// [`MAX_INPUT_PATTERNS`] globs.
pub fn expand_inputs(pipeline_path: &Path, p: &PipelineFile) -> Result<Vec<PathBuf>> {
    if let Some(e) = too_many_inputs(p) {
        return Err(Error::config(
            Some(pipeline_path.to_path_buf()),
            None,
            e.to_string(),
        ));
    }
    let mut out = Vec::new();
    let mut seen_globs = std::collections::HashSet::new();
    let mut seen_files = std::collections::HashSet::new();
    for g in &p.inputs {
        if !seen_globs.insert(g.as_str()) {
            continue;
        }
        let pat = relative_to(pipeline_path, g);
        let pat_s = pat.to_string_lossy();
        let matches = glob::glob(&pat_s).map_err(|e| {
            Error::config(
                Some(pipeline_path.to_path_buf()),
                None,
                format!("inputs: bad glob '{}': {e}", echo(g)),
            )
        })?;
        let found: Vec<PathBuf> = matches.filter_map(|m| m.ok()).collect();
        if found.is_empty() {
            return Err(Error::config(
                Some(pipeline_path.to_path_buf()),
                None,
                format!("inputs: '{}' matches nothing", echo(g)),
            ));
        }
        out.extend(found.into_iter().filter(|f| seen_files.insert(f.clone())));
    }
    Ok(out)
}

/// The pipeline's output and body paths, resolved against its folder, with `.` and `..`
/// folded lexically (`pipelines/../out/demo` → `out/demo`).
pub fn relative_to(pipeline_path: &Path, p: &str) -> PathBuf {
    use std::path::Component;
    let joined = pipeline_path.parent().unwrap_or(Path::new(".")).join(p);
    let mut out = PathBuf::new();
    for c in joined.components() {
        match c {
            Component::CurDir => {}
            Component::ParentDir
                if matches!(out.components().next_back(), Some(Component::Normal(_))) =>
            {
                out.pop();
            }
            other => out.push(other),
        }
    }
    if out.as_os_str().is_empty() {
        out.push(".");
    }
    out
}

/// Reads and parses a pipeline file through [`read_side_text`].
///
/// # Errors
/// As [`read_side_text`] and [`super::spec::parse_pipeline`].
pub fn read_pipeline(path: &Path) -> Result<PipelineFile> {
    parse_pipeline(path, &read_side_text(path, SideInput::Pipeline)?)
}

/// Reads and parses a body file through [`read_side_text`].
///
/// # Errors
/// As [`read_side_text`] and [`super::spec::parse_body`].
pub fn read_body(path: &Path) -> Result<BodyFile> {
    parse_body(path, &read_side_text(path, SideInput::Body)?)
}

#[cfg(test)]
mod tests;
