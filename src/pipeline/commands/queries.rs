//! What the query stages share at the I/O edge: the limit options, reading a library's
//! pool (and naming the clips left out), writing a query table with its provenance, and
//! safe file names from ids. The stages themselves are [`super::query_run`],
//! [`super::query_jump`] and [`super::map_jumps`]; the command line and the `[queries]`
//! stages of a pipeline file ([`crate::pipeline::job`]) both run them; what they print is
//! the caller's.
//!
//! # References
//! spec stance-model §6.8 (run), §6.10 (map), §7.5 (limits), §9 (new characters).

use std::collections::BTreeMap;
use std::path::Path;

use anyhow::Context;
use polars::prelude::DataFrame;
use rayon::prelude::*;

use crate::library::codec::write::write_atomic;
use crate::library::readers::read::{open_library, StanceLibrary};
use crate::query::feasibility::{check_mu, LimitForm, DEFAULT_QUERY_ACTIVE_FRACTION};
use crate::query::gait::LawChoice;
use crate::query::limits::{left_out_clips, left_out_line, LeftOut};
use crate::query::map::Axis;
use crate::query::pool::Prepared;
use crate::query::run::check_speed;

/// The limit options of a query (§7.5), as given: each `None` takes the query's default.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct LimitOptions {
    /// Limit form (`None`: the query's own default).
    pub form: Option<LimitForm>,
    /// Friction limit μ under either form.
    pub mu: Option<f64>,
    /// Active fraction of the friction check (`None`: [`DEFAULT_QUERY_ACTIVE_FRACTION`]).
    pub active_set: Option<f64>,
}

impl LimitOptions {
    /// The limit form (else `default`) and the given μ.
    ///
    /// # Errors
    /// A μ that is not a positive finite number.
    pub fn form(&self, default: LimitForm) -> anyhow::Result<(LimitForm, Option<f64>)> {
        if let Some(m) = self.mu {
            check_mu(m).map_err(|msg| crate::error::Error::invalid("--mu", msg))?;
        }
        Ok((self.form.unwrap_or(default), self.mu))
    }

    /// The friction check's active fraction `λ_act`.
    ///
    /// # Errors
    /// A fraction outside `[0, 1)` or not finite.
    pub fn active_fraction(&self) -> anyhow::Result<f64> {
        let v = self.active_set.unwrap_or(DEFAULT_QUERY_ACTIVE_FRACTION);
        anyhow::ensure!(
            v.is_finite() && (0.0..1.0).contains(&v),
            "--active-set must lie in [0, 1), found {v}"
        );
        Ok(v)
    }
}

/// The speeds of a `start:stop:step` range given as `flag`, each checked.
///
/// # Errors
/// A bad range, or a negative or non-finite speed.
pub fn speed_range(flag: &str, range: &str) -> anyhow::Result<Vec<f64>> {
    let v = Axis::parse(flag, range)?.values();
    for s in &v {
        check_speed(flag, *s)?;
    }
    Ok(v)
}

/// Opens a library and prepares every stance (tables built in parallel), the friction
/// check on the active set `f_v ≥ active_fraction · max f_v`.
///
/// # Errors
/// A missing or malformed library table.
pub fn load_pool(
    lib: &Path,
    active_fraction: f64,
) -> anyhow::Result<(StanceLibrary, Vec<Prepared>)> {
    let library = open_library(lib).with_context(|| format!("library {}", lib.display()))?;
    let pool = library
        .stances
        .par_iter()
        .map(|s| Prepared::with_active_fraction(s.clone(), active_fraction))
        .collect();
    Ok((library, pool))
}

/// Prints (stderr) which clips a query left out and why ([`left_out_line`]): the clips of
/// `dropped` (one per dropped item, repeats allowed), `count` items of kind `what`.
pub(super) fn report_left_out<'a>(
    command: &str,
    count: usize,
    what: &str,
    left: &BTreeMap<String, LeftOut>,
    dropped: impl Iterator<Item = &'a String>,
) {
    let clips: std::collections::BTreeSet<&String> = dropped.collect();
    let named: Vec<(&String, &LeftOut)> = clips
        .into_iter()
        .filter_map(|c| left.get_key_value(c))
        .collect();
    if let Some(line) = left_out_line(command, count, what, &named) {
        eprintln!("{line}");
    }
}

/// The pool without the stances of left-out clips (unless `keep`), with the report line.
pub(super) fn pool_without_left_out(
    command: &str,
    lib: &StanceLibrary,
    pool: Vec<Prepared>,
    keep: bool,
) -> Vec<Prepared> {
    if keep {
        return pool;
    }
    let left = left_out_clips(lib);
    let (kept, dropped): (Vec<Prepared>, Vec<Prepared>) = pool
        .into_iter()
        .partition(|p| !left.contains_key(&p.stance.clip));
    report_left_out(
        command,
        dropped.len(),
        "stance(s)",
        &left,
        dropped.iter().map(|p| &p.stance.clip),
    );
    kept
}

/// Writes `df` to the file `out` atomically (parent folder created).
///
/// # Errors
/// An unwritable folder or file.
pub fn write_table(out: &Path, df: &mut DataFrame, kv: &[(String, String)]) -> anyhow::Result<()> {
    let dir = match out.parent() {
        Some(p) if !p.as_os_str().is_empty() => p.to_path_buf(),
        _ => std::path::PathBuf::from("."),
    };
    std::fs::create_dir_all(&dir).with_context(|| format!("cannot create {}", dir.display()))?;
    let name = out
        .file_name()
        .and_then(|n| n.to_str())
        .with_context(|| format!("--out {}: not a file name", out.display()))?;
    write_atomic(&dir, name, df, kv)?;
    Ok(())
}

/// Key-value metadata of a query output: the tool version, the query's options and its
/// library (the folder as given and the SHA-256 of its `manifest.json`).
///
/// # Errors
/// The library's manifest cannot be read.
pub fn query_kv(lib: &Path, options: serde_json::Value) -> anyhow::Result<Vec<(String, String)>> {
    use crate::library::codec::provenance::manifest_sha256;
    use crate::library::codec::schema::{
        command_kv, LIBRARY_MANIFEST_KEY, LIBRARY_PATH_KEY, QUERY_KEY,
    };
    let hash = manifest_sha256(lib).with_context(|| format!("library {}", lib.display()))?;
    let mut kv = command_kv(QUERY_KEY, &options);
    kv.push((LIBRARY_PATH_KEY.into(), lib.display().to_string()));
    kv.push((LIBRARY_MANIFEST_KEY.into(), hash));
    Ok(kv)
}

/// Longest part of a file name made from an id ([`file_safe`]), bytes: with its prefix
/// and extension far below the 255 bytes of a file name on common file systems.
pub const MAX_ID_FILE_BYTES: usize = 64;

/// The part of a file name that stands for `id` (a character id): one name per id, never
/// the same for two, never longer than [`MAX_ID_FILE_BYTES`].
///
/// # Model
/// ```text
/// ASCII letters, digits, '-', '_', '.'   as they are
/// any other byte of the UTF-8 text       %XX (upper-case hex; '%' itself is %25)
/// longer than MAX_ID_FILE_BYTES, or       the first bytes of that, then '~' and 16 hex
/// the name of another output of the map   digits of the id's SHA-256
/// ```
/// The escaped text alone is injective, and it never holds `~` (`%7E`), so a cut name
/// cannot equal a whole one. (Before, `a/b` and `a.b` both gave `a_b`, and a 300-character
/// id a file name the system refused after four outputs were written.)
///
/// # Examples
/// ```
/// use stancelib::pipeline::commands::queries::file_safe;
/// assert_eq!(file_safe("sk-9f71a3e6fbd4"), "sk-9f71a3e6fbd4");
/// assert_ne!(file_safe("a/b"), file_safe("a.b"));
/// assert!(file_safe(&"x".repeat(300)).len() <= 64);
/// ```
pub fn file_safe(id: &str) -> String {
    let mut out = String::with_capacity(id.len());
    for b in id.bytes() {
        if b.is_ascii_alphanumeric() || b"-_.".contains(&b) {
            out.push(b as char);
        } else {
            out.push_str(&format!("%{b:02X}"));
        }
    }
    let reserved = out == "agreement" || out == "pairs";
    if out.len() <= MAX_ID_FILE_BYTES && !reserved {
        return out;
    }
    use sha2::{Digest, Sha256};
    let hash: String = Sha256::digest(id.as_bytes())[..8]
        .iter()
        .map(|b| format!("{b:02x}"))
        .collect();
    let mut cut = out.len().min(MAX_ID_FILE_BYTES - 1 - hash.len());
    // Never keep half of a %XX.
    if let Some(p) = out[..cut].rfind('%').filter(|&p| p + 3 > cut) {
        cut = p;
    }
    format!("{}~{hash}", &out[..cut])
}

/// The gait law named by `[queries] gait_law` (`auto` when absent).
///
/// # Errors
/// An unknown name.
pub fn gait_law_choice(name: Option<&str>) -> anyhow::Result<LawChoice> {
    match name {
        None => Ok(LawChoice::Auto),
        Some(n) => LawChoice::parse(n).ok_or_else(|| {
            anyhow::anyhow!("gait_law: unknown law '{n}' (give {})", LawChoice::NAMES)
        }),
    }
}
