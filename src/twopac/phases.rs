//! The JSON inputs of `twopac --phases` and `equilibrium --contacts` (two-pac §1.1, §8.2),
//! parsed from text into the core's [`Contact`]s and [`Phase`]s.
//!
//! # Model
//!
//! ```text
//! phases file:    {"schema": "stancelib.twopac.phases/1", "mass_kg": m, "start": {"vel", "acc"}?,
//!                  "effectors": {name: {"kinematics": "left_foot" | {"A": [[..]], "b": [..]}}},
//!                  "phases": [{"duration_s"?, "com"?, "contacts": [C, …]}, …]}
//! contacts file:  {"schema": "stancelib.twopac.contacts/1", "mass_kg": m, "contacts": [C, …]}
//! contact C:      {"effector", "position", "normal", "friction" = 0.7, "yaw_rad" = 0,
//!                  "surface"?: {"length_m", "width_m"}}
//! kinematics:     A ʳc ≤ b in the effector frame (§3: origin = position, yaw only, z up);
//!                 world rows K_w = K_e Rᵀ, k_w = k_e + K_e Rᵀ p
//! ```
//!
//! Unknown and duplicate keys are errors; consecutive phases differ by exactly one contact (§1: same
//! effector within [`SAME_CONTACT_TOL_M`]). Every error names its JSON path
//! (`phases[3].contacts[1].normal: zero length`) and, when serde can tell, the line and
//! column. This module takes text, never a file: the CLI reads the file and names it.
//!
//! # Frames and units
//!
//! World frame, Z up; m, s, kg, rad. The effector frame of an inline or named kinematic
//! polytope is yaw-only with `z` up (§3, com-from-bvh §7.5); its yaw is that of the
//! contact frame's `x` axis (§1.1) projected on the ground, or of `y − 90°` when `x` is
//! vertical (spec silent for tilted normals).
//!
//! # References
//!
//! Spec two-pac §1, §1.1, §3, §8.2; CORRECTIONS Issue 5 item 3.
//!
//! # Examples
//!
//! ```
//! use stancelib::twopac::phases::parse_contacts;
//!
//! let text = r#"{"schema": "stancelib.twopac.contacts/1", "mass_kg": 54.0,
//!   "contacts": [{"effector": "feet", "position": [0, 0, 0], "normal": [0, 0, 2]}]}"#;
//! let file = parse_contacts(text).unwrap();
//! assert_eq!(file.contacts[0].normal, [0.0, 0.0, 1.0]);
//! assert_eq!(file.contacts[0].mu, 0.7);
//! let bad = text.replace("[0, 0, 2]", "[0, 0, 0]");
//! assert!(parse_contacts(&bad).unwrap_err().to_string().starts_with("contacts[0].normal: "));
//! ```

use std::collections::BTreeMap;

use serde::de::DeserializeOwned;
use serde::Deserialize;
use serde_json::Value;

use super::bezier::ComState;
use super::contact::{Contact, ContactShape, DEFAULT_MU};
use super::equilibrium::MAX_CONTACTS;
use super::polytope::{Polytope, MAX_ROWS};
use super::trajectory::{Phase, MAX_PHASES, SAME_CONTACT_TOL_M};
use super::v3::{norm, sub};
use super::validate::{sample_count, DEFAULT_STEP_S, MAX_SAMPLES};

/// The `schema` value of a phases file (§1.1).
pub const PHASES_SCHEMA: &str = "stancelib.twopac.phases/1";
/// The `schema` value of a contacts file (§8.2).
pub const CONTACTS_SCHEMA: &str = "stancelib.twopac.contacts/1";
/// The named kinematic polytopes a library may hold (§1.1, §3).
pub const NAMED_KINEMATICS: [&str; 4] = ["left_foot", "right_foot", "left_hand", "right_hand"];
/// Horizontal length of the contact frame's `x` axis below which its yaw is taken from `y`.
pub const VERTICAL_AXIS_TOL: f64 = 1e-6;
/// Largest friction coefficient μ (`friction`) accepted: dry rubber on concrete is about 1,
/// so 10 leaves room for an idealised sticking contact; μ = 1e308 overflowed the friction
/// cone and called a feasible state infeasible.
pub const MAX_FRICTION: f64 = 10.0;
/// Largest |coordinate| of a contact position, a phase's `com` or an `equilibrium --points`
/// COM, m (10 km: a scene, not an overflow; `com` 1e308 gave 2,889 NaN rows).
pub const MAX_COORDINATE_M: f64 = 1e4;
/// Largest side of a contact's `surface`, m.
pub const MAX_SURFACE_M: f64 = 10.0;
/// Shortest non-zero phase `duration_s`, s (5e-324 s gave NaN accelerations; a phase of
/// 0 s is a contact change without time).
pub const MIN_PHASE_DURATION_S: f64 = 1e-3;
/// Largest |component| of a COM velocity given (`start.vel`), m/s.
pub const MAX_VEL_MPS: f64 = 100.0;
/// Largest |component| of a COM acceleration given (`start.acc`, the accelerations of
/// `equilibrium --points`), m/s² (100 g).
pub const MAX_ACC_MPS2: f64 = 1e3;

/// A JSON input error: the JSON path, what is wrong and, when known, where in the text.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("{path}{}{msg}{}", if path.is_empty() { "" } else { ": " }, at.map(|(l, c)| format!(" (line {l}, column {c})")).unwrap_or_default())]
pub struct JsonError {
    /// JSON path of the faulty value (`phases[3].contacts[1].normal`; empty: whole file).
    pub path: String,
    /// What is wrong.
    pub msg: String,
    /// 1-based `(line, column)` from serde, when known.
    pub at: Option<(usize, usize)>,
}

fn fail<T>(path: &str, msg: impl Into<String>) -> Result<T, JsonError> {
    Err(JsonError {
        path: path.to_string(),
        msg: msg.into(),
        at: None,
    })
}

/// `Err` at `path` when `found` exceeds `max` (the constant named `cap`): checked
/// before the work the count stands for.
fn check_cap(path: &str, what: &str, found: f64, max: usize, cap: &str) -> Result<(), JsonError> {
    if found <= max as f64 {
        return Ok(());
    }
    let found = if found < 1e15 {
        format!("{found:.0}")
    } else {
        format!("{found:.3e}")
    };
    fail(
        path,
        format!("{found} {what}, more than the limit of {max} ({cap})"),
    )
}

// Each level is generic in its children: with `Value` children it locates an error by
// path (level by level), with typed children it gives serde's line and column.

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawPhasesFile<E, P> {
    schema: String,
    mass_kg: f64,
    #[serde(default)]
    start: Option<RawStart>,
    effectors: BTreeMap<String, E>,
    phases: Vec<P>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawContactsFile<C> {
    schema: String,
    mass_kg: f64,
    contacts: Vec<C>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawStart {
    #[serde(default)]
    vel: Option<[f64; 3]>,
    #[serde(default)]
    acc: Option<[f64; 3]>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawEffector<K> {
    kinematics: K,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawInline {
    #[serde(rename = "A")]
    a: Vec<[f64; 3]>,
    b: Vec<f64>,
}

#[derive(Deserialize)]
#[serde(untagged)]
enum RawKinematics {
    Named(#[allow(dead_code)] String),
    Inline(#[allow(dead_code)] RawInline),
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawPhase<C> {
    #[serde(default)]
    duration_s: Option<f64>,
    #[serde(default)]
    com: Option<[f64; 3]>,
    contacts: Vec<C>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawContact {
    effector: String,
    position: [f64; 3],
    normal: [f64; 3],
    #[serde(default)]
    friction: Option<f64>,
    #[serde(default)]
    yaw_rad: Option<f64>,
    #[serde(default)]
    surface: Option<RawSurface>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawSurface {
    length_m: f64,
    width_m: f64,
}

type TypedPhases = RawPhasesFile<RawEffector<RawKinematics>, RawPhase<RawContact>>;

/// A serde error's message without serde's " at line L column C" suffix.
fn bare(e: &serde_json::Error) -> String {
    let s = e.to_string();
    match s.rfind(" at line ") {
        Some(i) if e.line() > 0 => s[..i].to_string(),
        _ => s,
    }
}

/// Deserialize one value at `path`; a type error inside one field of an object is
/// reported at that field's path.
fn at<T: DeserializeOwned>(v: &Value, path: &str) -> Result<T, JsonError> {
    T::deserialize(v).map_err(|e| {
        let path = match faulty_field::<T>(v) {
            Some(k) if path.is_empty() => k,
            Some(k) => format!("{path}.{k}"),
            None => path.to_string(),
        };
        JsonError {
            path,
            msg: bare(&e),
            at: None,
        }
    })
}

/// The key of an object whose value `T` fails on: the object is written compactly on one
/// line, parsed again, and serde's error column is found among the values' spans.
fn faulty_field<T: DeserializeOwned>(v: &Value) -> Option<String> {
    let Value::Object(map) = v else { return None };
    let mut text = String::from("{");
    let mut spans = Vec::with_capacity(map.len());
    for (i, (k, val)) in map.iter().enumerate() {
        if i > 0 {
            text.push(',');
        }
        text += &serde_json::to_string(k).ok()?;
        text.push(':');
        let start = text.len();
        text += &serde_json::to_string(val).ok()?;
        spans.push((k, start, text.len()));
    }
    text.push('}');
    let e = serde_json::from_str::<T>(&text).err()?;
    let col = e.column();
    (e.line() == 1)
        .then(|| spans.iter().find(|(_, a, b)| col > *a && col <= *b))
        .flatten()
        .map(|(k, _, _)| (*k).clone())
}

/// Parse `text` as JSON (syntax errors carry line and column). A key twice in one
/// object is an error at the duplicate's JSON path (serde_json would keep the last).
fn parse_value(text: &str) -> Result<Value, JsonError> {
    super::unique_keys::from_str(text).map_err(|(path, e)| JsonError {
        path: path.unwrap_or_default(),
        msg: bare(&e),
        at: Some((e.line(), e.column())),
    })
}

/// Add serde's line and column to a path-located error when the typed parse of the whole
/// text fails with the same message.
fn locate<T: DeserializeOwned>(text: &str, mut e: JsonError) -> JsonError {
    if let Err(t) = serde_json::from_str::<T>(text) {
        if t.line() > 0 && bare(&t) == e.msg {
            e.at = Some((t.line(), t.column()));
        }
    }
    e
}

fn check_schema(found: &str, want: &str) -> Result<(), JsonError> {
    if found == want {
        Ok(())
    } else {
        fail("schema", format!("expected \"{want}\", found \"{found}\""))
    }
}

/// Whether `c` is a number within ±`max` (NaN is not).
pub fn within(c: f64, max: f64) -> bool {
    c.abs() <= max
}

/// `v` at `path` when every component is finite and within `max` (unit `unit`).
fn check_vector(
    path: &str,
    v: [f64; 3],
    max: f64,
    cap: &str,
    unit: &str,
) -> Result<[f64; 3], JsonError> {
    match v.iter().find(|c| !within(**c, max)) {
        None => Ok(v),
        Some(c) => fail(
            path,
            format!("component {c} is beyond ±{max} {unit} ({cap})"),
        ),
    }
}

/// A body mass within the bounds every command applies
/// ([`crate::ingest::masses::check_body_mass`], [1, 1000] kg): mass 1e100 called a feasible
/// point infeasible.
fn check_mass(m: f64) -> Result<f64, JsonError> {
    match crate::ingest::masses::check_body_mass(m) {
        Ok(()) => Ok(m),
        Err(why) => fail("mass_kg", why),
    }
}

/// One §1.1 contact object at `path`.
fn contact(v: &Value, path: &str) -> Result<Contact, JsonError> {
    let c: RawContact = at(v, path)?;
    let sub_path = |k: &str| format!("{path}.{k}");
    if norm(c.normal) == 0.0 {
        return fail(&sub_path("normal"), "zero length");
    }
    let n = norm(c.normal);
    if !n.is_finite() {
        return fail(
            &sub_path("normal"),
            "length overflows f64: give a unit-scale normal",
        );
    }
    let position = check_vector(
        &sub_path("position"),
        c.position,
        MAX_COORDINATE_M,
        "MAX_COORDINATE_M",
        "m",
    )?;
    let mu = c.friction.unwrap_or(DEFAULT_MU);
    if !(0.0..=MAX_FRICTION).contains(&mu) {
        return fail(
            &sub_path("friction"),
            format!("must be in [0, {MAX_FRICTION}] (MAX_FRICTION), found {mu}"),
        );
    }
    if let Some(y) = c.yaw_rad.filter(|y| !y.is_finite()) {
        return fail(&sub_path("yaw_rad"), format!("must be finite, found {y}"));
    }
    if c.effector.is_empty() {
        return fail(&sub_path("effector"), "empty name");
    }
    let shape = match c.surface {
        None => ContactShape::Point,
        Some(s) => {
            for (k, v) in [("length_m", s.length_m), ("width_m", s.width_m)] {
                if !(0.0..=MAX_SURFACE_M).contains(&v) {
                    return fail(
                        &format!("{path}.surface.{k}"),
                        format!("must be in [0, {MAX_SURFACE_M}] m (MAX_SURFACE_M), found {v}"),
                    );
                }
            }
            ContactShape::Rectangle {
                length_m: s.length_m,
                width_m: s.width_m,
            }
        }
    };
    Contact::new(
        c.effector,
        position,
        c.normal,
        mu,
        c.yaw_rad.unwrap_or(0.0),
        shape,
    )
    .or_else(|e| fail(path, e.to_string()))
}

fn contacts(list: &[Value], path: &str) -> Result<Vec<Contact>, JsonError> {
    let n = list.len() as f64;
    check_cap(path, "contacts", n, MAX_CONTACTS, "MAX_CONTACTS")?;
    list.iter()
        .enumerate()
        .map(|(k, v)| contact(v, &format!("{path}[{k}]")))
        .collect()
}

/// A parsed §8.2 contacts file.
#[derive(Debug, Clone, PartialEq)]
pub struct ContactsFile {
    /// Total mass, kg.
    pub mass_kg: f64,
    /// The contact set.
    pub contacts: Vec<Contact>,
}

/// Parse a §8.2 contacts file (`equilibrium --contacts`).
///
/// # Errors
///
/// [`JsonError`] with the JSON path: bad syntax, unknown key, wrong schema, non-positive
/// mass, no contacts, zero normal, negative friction or surface side.
pub fn parse_contacts(text: &str) -> Result<ContactsFile, JsonError> {
    let v = parse_value(text)?;
    let raw: RawContactsFile<Value> =
        at(&v, "").map_err(|e| locate::<RawContactsFile<RawContact>>(text, e))?;
    check_schema(&raw.schema, CONTACTS_SCHEMA)?;
    let mass_kg = check_mass(raw.mass_kg)?;
    if raw.contacts.is_empty() {
        return fail("contacts", "empty: give at least one contact");
    }
    let contacts = contacts(&raw.contacts, "contacts")
        .map_err(|e| locate::<RawContactsFile<RawContact>>(text, e))?;
    Ok(ContactsFile { mass_kg, contacts })
}

/// An effector's kinematic polytope as written in the file (§1.1 `kinematics`).
#[derive(Debug, Clone, PartialEq)]
pub enum KinematicsRef {
    /// A library polytope (`left_foot`, …) from `kinematics.parquet`.
    Named(String),
    /// An inline `{"A", "b"}` in the effector frame (rows normalised).
    Inline(Polytope),
}

/// One phase as written in the file.
#[derive(Debug, Clone, PartialEq)]
pub struct PhaseSpec {
    /// Data duration, s.
    pub duration_s: Option<f64>,
    /// Data COM, m.
    pub com: Option<[f64; 3]>,
    /// Active contacts.
    pub contacts: Vec<Contact>,
}

/// A parsed §1.1 phases file.
#[derive(Debug, Clone, PartialEq)]
pub struct PhasesFile {
    /// Total mass, kg.
    pub mass_kg: f64,
    /// Start state: velocity and acceleration (the position is phase 0's state).
    pub start: ComState,
    /// Kinematic polytope of each effector.
    pub effectors: BTreeMap<String, KinematicsRef>,
    /// Phases in order.
    pub phases: Vec<PhaseSpec>,
}

fn kinematics(v: &Value, path: &str) -> Result<KinematicsRef, JsonError> {
    match v {
        Value::String(s) if NAMED_KINEMATICS.contains(&s.as_str()) => {
            Ok(KinematicsRef::Named(s.clone()))
        }
        Value::String(s) => fail(
            path,
            format!(
                "unknown polytope \"{s}\", expected one of {} or {{\"A\": [[…]], \"b\": […]}}",
                NAMED_KINEMATICS.join(", ")
            ),
        ),
        _ => {
            let k: RawInline = at(v, path)?;
            if k.a.len() != k.b.len() {
                return fail(
                    path,
                    format!("A has {} rows but b has {} values", k.a.len(), k.b.len()),
                );
            }
            if k.a.is_empty() {
                return fail(&format!("{path}.A"), "no rows");
            }
            let n = k.a.len() as f64;
            check_cap(&format!("{path}.A"), "rows", n, MAX_ROWS, "MAX_ROWS")?;
            if let Some(i) = k.a.iter().position(|r| norm(*r) == 0.0) {
                return fail(&format!("{path}.A[{i}]"), "zero row");
            }
            Ok(KinematicsRef::Inline(Polytope::new(k.a, k.b)))
        }
    }
}

fn same_contact(a: &Contact, b: &Contact) -> bool {
    a.effector == b.effector && norm(sub(a.position, b.position)) < SAME_CONTACT_TOL_M
}

/// Parse a §1.1 phases file (`twopac --phases`).
///
/// # Errors
///
/// [`JsonError`] with the JSON path: bad syntax, unknown key, wrong schema, non-positive
/// mass, no phases, a first phase without `com`, a negative duration, a contact whose
/// effector has no `effectors` entry, an effector twice in a phase, a bad contact or
/// polytope, or consecutive phases that do not differ by exactly one contact.
pub fn parse_phases(text: &str) -> Result<PhasesFile, JsonError> {
    let v = parse_value(text)?;
    let loc = |e: JsonError| locate::<TypedPhases>(text, e);
    let raw: RawPhasesFile<Value, Value> = at(&v, "").map_err(loc)?;
    check_schema(&raw.schema, PHASES_SCHEMA)?;
    let mass_kg = check_mass(raw.mass_kg)?;
    let start = match raw.start {
        None => ComState::default(),
        Some(s) => ComState {
            pos: [0.0; 3],
            vel: check_vector(
                "start.vel",
                s.vel.unwrap_or([0.0; 3]),
                MAX_VEL_MPS,
                "MAX_VEL_MPS",
                "m/s",
            )?,
            acc: check_vector(
                "start.acc",
                s.acc.unwrap_or([0.0; 3]),
                MAX_ACC_MPS2,
                "MAX_ACC_MPS2",
                "m/s²",
            )?,
        },
    };
    let mut effectors = BTreeMap::new();
    for (name, e) in &raw.effectors {
        let p = format!("effectors.{name}");
        let e: RawEffector<Value> = at(e, &p).map_err(loc)?;
        effectors.insert(
            name.clone(),
            kinematics(&e.kinematics, &format!("{p}.kinematics")).map_err(loc)?,
        );
    }
    if raw.phases.is_empty() {
        return fail("phases", "empty: give at least one phase");
    }
    let n = raw.phases.len() as f64;
    check_cap("phases", "phases", n, MAX_PHASES, "MAX_PHASES")?;
    let mut phases: Vec<PhaseSpec> = Vec::with_capacity(raw.phases.len());
    let mut total_s = 0.0;
    for (j, p) in raw.phases.iter().enumerate() {
        let path = format!("phases[{j}]");
        let p: RawPhase<Value> = at(p, &path).map_err(loc)?;
        if let Some(d) = p
            .duration_s
            .filter(|d| !(*d == 0.0 || *d >= MIN_PHASE_DURATION_S))
        {
            return fail(
                &format!("{path}.duration_s"),
                format!("must be 0 or at least {MIN_PHASE_DURATION_S} s (MIN_PHASE_DURATION_S), found {d}"),
            );
        }
        if let Some(com) = p.com {
            check_vector(
                &format!("{path}.com"),
                com,
                MAX_COORDINATE_M,
                "MAX_COORDINATE_M",
                "m",
            )?;
        }
        total_s += p.duration_s.unwrap_or(0.0);
        check_cap(
            &format!("{path}.duration_s"),
            &format!("validation samples (the phases up to here last {total_s} s, one sample every {DEFAULT_STEP_S} s)"),
            sample_count(0.0, total_s, DEFAULT_STEP_S),
            MAX_SAMPLES,
            "MAX_SAMPLES",
        )?;
        if j == 0 && p.com.is_none() {
            return fail(
                &format!("{path}.com"),
                "required in the first phase (the start position)",
            );
        }
        let cs = contacts(&p.contacts, &format!("{path}.contacts")).map_err(loc)?;
        if cs.is_empty() {
            return fail(
                &format!("{path}.contacts"),
                "empty: a phase needs a contact",
            );
        }
        for (k, c) in cs.iter().enumerate() {
            let cp = format!("{path}.contacts[{k}].effector");
            if !effectors.contains_key(&c.effector) {
                return fail(&cp, format!("\"{}\" has no entry in effectors", c.effector));
            }
            if cs[..k].iter().any(|d| d.effector == c.effector) {
                return fail(&cp, format!("\"{}\" twice in one phase", c.effector));
            }
        }
        if let Some(prev) = phases.last() {
            let added = cs
                .iter()
                .filter(|c| !prev.contacts.iter().any(|d| same_contact(c, d)));
            let removed = prev
                .contacts
                .iter()
                .filter(|d| !cs.iter().any(|c| same_contact(c, d)));
            let (n_add, n_rem) = (added.count(), removed.count());
            if n_add + n_rem != 1 {
                return fail(
                    &path,
                    format!(
                        "differs from phases[{}] by {n_add} added and {n_rem} removed contacts; \
                         exactly one change per boundary (insert phases: additions first, then removals)",
                        j - 1
                    ),
                );
            }
        }
        phases.push(PhaseSpec {
            duration_s: p.duration_s,
            com: p.com,
            contacts: cs,
        });
    }
    Ok(PhasesFile {
        mass_kg,
        start,
        effectors,
        phases,
    })
}

/// The yaw of the §3 effector frame of a contact: its frame `x` projected on the ground
/// (or `y − 90°` when `x` is vertical), rad.
pub fn effector_yaw(c: &Contact) -> f64 {
    let (x, y) = c.frame_axes();
    if x[0].hypot(x[1]) > VERTICAL_AXIS_TOL {
        x[1].atan2(x[0])
    } else {
        y[1].atan2(y[0]) - std::f64::consts::FRAC_PI_2
    }
}

impl PhasesFile {
    /// The named polytopes the file uses (sorted, each once).
    pub fn named_kinematics(&self) -> Vec<String> {
        let names: std::collections::BTreeSet<&String> = self
            .effectors
            .values()
            .filter_map(|k| match k {
                KinematicsRef::Named(n) => Some(n),
                KinematicsRef::Inline(_) => None,
            })
            .collect();
        names.into_iter().cloned().collect()
    }

    /// The core's phases, each contact's polytope moved to the world frame (§3).
    /// `named` gives a library polytope (effector frame) by name.
    ///
    /// # Errors
    ///
    /// [`JsonError`] at `effectors.<name>.kinematics` when `named` has no such polytope.
    pub fn to_phases(
        &self,
        named: &dyn Fn(&str) -> Option<Polytope>,
    ) -> Result<Vec<Phase>, JsonError> {
        let mut resolved: BTreeMap<&str, Polytope> = BTreeMap::new();
        for (name, k) in &self.effectors {
            let p = match k {
                KinematicsRef::Inline(p) => p.clone(),
                KinematicsRef::Named(n) => match named(n) {
                    Some(p) => p,
                    None => {
                        return fail(
                            &format!("effectors.{name}.kinematics"),
                            format!("no polytope \"{n}\" in the library"),
                        )
                    }
                },
            };
            resolved.insert(name, p);
        }
        Ok(self
            .phases
            .iter()
            .map(|p| Phase {
                kinematics: p
                    .contacts
                    .iter()
                    .map(|c| {
                        resolved[c.effector.as_str()].to_world_yaw(c.position, effector_yaw(c))
                    })
                    .collect(),
                contacts: p.contacts.clone(),
                duration_s: p.duration_s,
                com: p.com,
            })
            .collect())
    }
}

#[cfg(test)]
mod tests;
