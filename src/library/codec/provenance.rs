//! Provenance that is not part of the tables: when and how a library was written, and the
//! hash that names a library in the outputs of the queries on it.
//!
//! The Parquet files of a library stay byte-identical for the same inputs and options
//! (their key-value metadata holds only the schema and tool version, the options, the
//! input hashes and the per-character limits). What changes from run to run — the date,
//! the command line, the wall time — is written to `manifest.json` only. A query output
//! names its library by [`LIBRARY_MANIFEST_KEY`]: the SHA-256 of that library's
//! `manifest.json` bytes, so `sha256sum LIB/manifest.json` tells which build it came from.

use std::collections::BTreeMap;
use std::path::Path;
use std::time::{SystemTime, UNIX_EPOCH};

use sha2::{Digest, Sha256};

#[cfg(doc)]
use super::schema::LIBRARY_MANIFEST_KEY;
use super::schema::{MANIFEST_FILE, MANIFEST_SCHEMA_PREFIX, SCHEMA_VERSION};
use crate::error::{Error, Result};
use crate::skeleton::com::Sex;

/// `secs` seconds after 1970-01-01T00:00:00Z as RFC 3339 in UTC (`YYYY-MM-DDThh:mm:ssZ`).
///
/// The civil date comes from the day count by the proleptic Gregorian calendar (days
/// from civil, H. Hinnant's algorithm), so no time-zone database is needed.
///
/// # Examples
/// ```
/// use stancelib::library::codec::provenance::utc_rfc3339;
/// assert_eq!(utc_rfc3339(0), "1970-01-01T00:00:00Z");
/// assert_eq!(utc_rfc3339(951_782_400), "2000-02-29T00:00:00Z");
/// ```
pub fn utc_rfc3339(secs: u64) -> String {
    let (days, rem) = ((secs / 86_400) as i64, secs % 86_400);
    // Shift the epoch to 0000-03-01 so that leap days end each 400-year era's years.
    let z = days + 719_468;
    let era = z.div_euclid(146_097);
    let doe = z.rem_euclid(146_097);
    let yoe = (doe - doe / 1460 + doe / 36_524 - doe / 146_096) / 365;
    let doy = doe - (365 * yoe + yoe / 4 - yoe / 100);
    let mp = (5 * doy + 2) / 153;
    let day = doy - (153 * mp + 2) / 5 + 1;
    let month = if mp < 10 { mp + 3 } else { mp - 9 };
    let year = yoe + era * 400 + i64::from(month <= 2);
    format!(
        "{year:04}-{month:02}-{day:02}T{:02}:{:02}:{:02}Z",
        rem / 3600,
        rem / 60 % 60,
        rem % 60
    )
}

/// The current time as RFC 3339 UTC (see [`utc_rfc3339`]).
pub fn now_utc() -> String {
    let secs = SystemTime::now()
        .duration_since(UNIX_EPOCH)
        .map(|d| d.as_secs())
        .unwrap_or(0);
    utc_rfc3339(secs)
}

/// This process's command line, program name first (arguments that are not UTF-8 are
/// written lossily).
pub fn command_line() -> Vec<String> {
    std::env::args_os()
        .map(|a| a.to_string_lossy().into_owned())
        .collect()
}

/// SHA-256 (hex) of `lib/manifest.json`.
///
/// # Errors
/// The manifest cannot be read.
pub fn manifest_sha256(lib: &Path) -> Result<String> {
    let bytes = super::manifest::read_manifest_bytes(lib)?;
    Ok(Sha256::digest(&bytes)
        .iter()
        .map(|b| format!("{b:02x}"))
        .collect())
}

/// The table layout a library's manifest names (`schema`: `stancelib.library/<version>`;
/// in the manifests written before that key, `schema_version`), `None` when the folder
/// has no readable stancelib manifest.
pub fn library_layout(lib: &Path) -> Option<String> {
    let m = super::manifest::read_manifest(lib).ok()?;
    match m.get("schema") {
        Some(schema) => schema
            .as_str()?
            .strip_prefix(MANIFEST_SCHEMA_PREFIX)
            .map(str::to_string),
        None => m.get("schema_version")?.as_str().map(str::to_string),
    }
}

/// Refuses a library written with another table layout than this tool's
/// ([`SCHEMA_VERSION`]): its columns have other names (layout 4 renamed them to carry
/// their units), so reading it would fail column by column or, worse, half-succeed.
/// A folder without a stancelib manifest passes (its tables are checked as they are read).
///
/// # Errors
/// The manifest names another layout (the message says how to rebuild), or it exists
/// but cannot be taken in (larger than
/// [`MAX_MANIFEST_BYTES`](super::manifest::MAX_MANIFEST_BYTES), not a regular file).
pub fn check_layout(lib: &Path) -> Result<()> {
    if let Err(e) = super::manifest::read_manifest_bytes(lib) {
        if matches!(e.kind, crate::error::ErrorKind::Input { .. }) {
            return Err(e);
        }
    }
    match library_layout(lib) {
        Some(v) if v != SCHEMA_VERSION => Err(Error::config(
            Some(lib.join(MANIFEST_FILE)),
            None,
            format!(
                "the library was written with table layout {v}; this stancelib reads layout \
                 {SCHEMA_VERSION} (columns renamed with unit suffixes): rebuild it with \
                 `stancelib build`"
            ),
        )),
        _ => Ok(()),
    }
}

/// The body a library was built with: the de Leva column and the landmark overrides
/// (manifest `options.ingest.sex`, `options.ingest.landmarks`), so that an edit poses its
/// motion with the same segment model the library's COM was measured with. A manifest
/// without them (older libraries) gives the defaults (male, no overrides).
///
/// # Errors
/// The manifest cannot be read or parsed, or names an unknown sex (the field is named).
pub fn library_body(lib: &Path) -> Result<(Sex, BTreeMap<String, String>)> {
    check_layout(lib)?;
    let path = lib.join(MANIFEST_FILE);
    let m = super::manifest::read_manifest(lib)?;
    let ingest = &m["options"]["ingest"];
    let sex = match ingest["sex"].as_str() {
        None | Some("Male") => Sex::Male,
        Some("Female") => Sex::Female,
        Some(other) => {
            return Err(Error::config(
                Some(path),
                None,
                format!("options.ingest.sex: unknown value {other:?} (Male or Female)"),
            ))
        }
    };
    let landmarks = ingest["landmarks"]
        .as_object()
        .map(|o| {
            o.iter()
                .filter_map(|(k, v)| v.as_str().map(|v| (k.clone(), v.to_string())))
                .collect()
        })
        .unwrap_or_default();
    Ok((sex, landmarks))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn utc_dates_match_known_instants() {
        // Reference instants from `date -u -d @SECS`.
        for (secs, want) in [
            (0, "1970-01-01T00:00:00Z"),
            (86_399, "1970-01-01T23:59:59Z"),
            (951_782_400, "2000-02-29T00:00:00Z"),
            (951_868_800, "2000-03-01T00:00:00Z"),
            (1_709_164_800, "2024-02-29T00:00:00Z"),
            (1_735_689_599, "2024-12-31T23:59:59Z"),
            (4_107_542_400, "2100-03-01T00:00:00Z"),
        ] {
            assert_eq!(utc_rfc3339(secs), want, "{secs}");
        }
    }

    #[test]
    fn consecutive_days_never_repeat_or_skip_a_date() {
        // Day by day over 1970–2200 the date string increases strictly and the day of
        // month either grows by one or restarts at 1.
        let mut prev = utc_rfc3339(0);
        for d in 1..(230 * 366) {
            let cur = utc_rfc3339(d * 86_400);
            assert!(cur > prev, "{prev} then {cur}");
            let (pd, cd): (u32, u32) = (prev[8..10].parse().unwrap(), cur[8..10].parse().unwrap());
            assert!(cd == pd + 1 || cd == 1, "{prev} then {cur}");
            prev = cur;
        }
    }
}
