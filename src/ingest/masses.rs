//! Body masses per clip or subject from a table (`--masses FILE`, pipeline key `masses`).
//!
//! # Format
//! A CSV file with a header row naming the columns `clip`, `mass_kg` and, optionally,
//! `sex` (`male`, `female`, `average`), in any order; other columns are ignored:
//! ```text
//! clip,mass_kg,sex
//! subject01_*,72.8,male
//! s02_run,65.9,female
//! ```
//! `clip` is a clip name (the file name without `.bvh`) or a glob over clip names (`*`,
//! `?`, `[abc]`); the first row that matches a clip gives its mass (and sex), so specific
//! rows go before general ones. A clip no row matches keeps the mass of `--mass` /
//! `mass_kg` (and the sex of the body file), or the default 70 kg with a warning: forces
//! in newtons scale with the mass, so a folder of several subjects needs their masses.
//!
//! # Units
//! Masses in kilograms, within [[`MIN_BODY_MASS_KG`], [`MAX_BODY_MASS_KG`]].

use crate::error::{echo, Error, Result};
use crate::skeleton::com::Sex;

/// Smallest body mass accepted (`--mass`, `mass_kg`, a masses table), kg: below it a
/// "body" is not one a motion-capture suit fits (a newborn weighs about 3 kg).
pub const MIN_BODY_MASS_KG: f64 = 1.0;
/// Largest body mass accepted, kg: far above any person (the heaviest recorded ≈ 635 kg);
/// a larger creature is a query's `--mass-scale` of a recorded one, and 1e300 kg made
/// every force infinite.
pub const MAX_BODY_MASS_KG: f64 = 1000.0;
/// Most rows of a masses table (a row per clip of a very large collection).
pub const MAX_MASS_ROWS: usize = 1_000_000;

/// Checks a body mass against [`MIN_BODY_MASS_KG`] … [`MAX_BODY_MASS_KG`].
///
/// # Errors
/// The message (without the option's name) when the mass is outside the bounds.
pub fn check_body_mass(kg: f64) -> std::result::Result<(), String> {
    if (MIN_BODY_MASS_KG..=MAX_BODY_MASS_KG).contains(&kg) {
        Ok(())
    } else {
        Err(format!(
            "a body mass must lie in [{MIN_BODY_MASS_KG}, {MAX_BODY_MASS_KG}] kg, found {kg}"
        ))
    }
}

/// One row of a masses table.
#[derive(serde::Serialize, Debug, Clone, PartialEq)]
pub struct MassRow {
    /// The clip name or glob, as written.
    pub clip: String,
    /// Body mass, kg.
    pub mass_kg: f64,
    /// de Leva column, when the row gives one.
    pub sex: Option<Sex>,
    /// Line of the row in its file (1-based).
    pub line: usize,
    #[serde(skip)]
    pattern: glob::Pattern,
}

/// A parsed masses table (rows in file order).
#[derive(serde::Serialize, Debug, Clone, PartialEq, Default)]
pub struct MassTable {
    /// The file it came from (for messages and `mass_source`).
    pub file: String,
    /// Its rows, in file order.
    pub rows: Vec<MassRow>,
}

/// The columns of the header: positions of `clip`, `mass_kg` and `sex`.
fn header_columns(header: &str, file: &str) -> Result<(usize, usize, Option<usize>)> {
    let names: Vec<String> = header
        .split(',')
        .map(|c| c.trim().to_ascii_lowercase())
        .collect();
    let find = |n: &str| names.iter().position(|c| c == n);
    match (find("clip"), find("mass_kg")) {
        (Some(c), Some(m)) => Ok((c, m, find("sex"))),
        _ => Err(Error::config(
            Some(file.into()),
            Some(1),
            format!(
                "the header must name the columns clip and mass_kg (found: {})",
                echo(header)
            ),
        )),
    }
}

/// One data row at `line` (1-based) of `file`.
fn parse_row(
    fields: &[&str],
    cols: (usize, usize, Option<usize>),
    line: usize,
    file: &str,
) -> Result<MassRow> {
    let bad = |msg: String| Error::config(Some(file.into()), Some(line), msg);
    let field = |k: usize, name: &str| {
        fields
            .get(k)
            .map(|s| s.trim())
            .ok_or_else(|| bad(format!("missing field {name}")))
    };
    let clip = field(cols.0, "clip")?;
    let pattern = glob::Pattern::new(clip)
        .map_err(|e| bad(format!("clip '{}' is not a name or glob: {e}", echo(clip))))?;
    let raw = field(cols.1, "mass_kg")?;
    let mass_kg: f64 = raw
        .parse()
        .map_err(|_| bad(format!("mass_kg '{}' is not a number", echo(raw))))?;
    check_body_mass(mass_kg).map_err(|m| bad(format!("mass_kg: {m}")))?;
    // The sex column is optional per row: a short row leaves it empty.
    let sex = match cols.2.and_then(|k| fields.get(k)).map(|s| s.trim()) {
        None | Some("") => None,
        Some(s) => Some(
            Sex::parse(s)
                .ok_or_else(|| bad(format!("sex '{}' is not male, female or average", echo(s))))?,
        ),
    };
    Ok(MassRow {
        clip: clip.to_string(),
        mass_kg,
        sex,
        line,
        pattern,
    })
}

/// Parses a masses table (module docs) read from `file`.
///
/// # Errors
/// A config error naming the file, line and field: no header with `clip` and `mass_kg`,
/// a missing field, a mass that is not a number or outside the bounds, an unknown sex, a
/// bad glob, more than [`MAX_MASS_ROWS`] rows.
pub fn parse_masses(text: &str, file: &str) -> Result<MassTable> {
    let mut lines = text
        .lines()
        .enumerate()
        .filter(|(_, l)| !l.trim().is_empty() && !l.trim_start().starts_with('#'));
    let Some((_, header)) = lines.next() else {
        return Err(Error::config(
            Some(file.into()),
            None,
            "empty masses table".to_string(),
        ));
    };
    let cols = header_columns(header, file)?;
    let mut rows = Vec::new();
    for (i, l) in lines {
        if rows.len() == MAX_MASS_ROWS {
            return Err(Error::config(
                Some(file.into()),
                Some(i + 1),
                format!("more than {MAX_MASS_ROWS} rows (MAX_MASS_ROWS)"),
            ));
        }
        let fields: Vec<&str> = l.split(',').collect();
        rows.push(parse_row(&fields, cols, i + 1, file)?);
    }
    Ok(MassTable {
        file: file.to_string(),
        rows,
    })
}

/// Serializes the table of [`super::IngestOptions`] (the manifest's options: a changed
/// table changes the fingerprint) as its rows.
///
/// # Errors
/// Those of the serializer.
pub fn serialize_rows<S: serde::Serializer>(
    t: &Option<std::sync::Arc<MassTable>>,
    s: S,
) -> std::result::Result<S::Ok, S::Error> {
    use serde::Serialize;
    t.as_deref().serialize(s)
}

impl MassTable {
    /// The first row whose `clip` matches the clip name.
    pub fn lookup(&self, clip: &str) -> Option<&MassRow> {
        self.rows.iter().find(|r| r.pattern.matches(clip))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_first_matching_row_gives_the_mass() {
        let t = parse_masses(
            "# subjects\nmass_kg,clip,sex\n80,s01_jump,female\n72.5,s01_*,\n60,*,average\n",
            "m.csv",
        )
        .unwrap();
        let m = |c: &str| t.lookup(c).map(|r| (r.mass_kg, r.sex, r.line));
        assert_eq!(m("s01_jump"), Some((80.0, Some(Sex::Female), 3)));
        assert_eq!(m("s01_run"), Some((72.5, None, 4)));
        assert_eq!(m("other"), Some((60.0, Some(Sex::Average), 5)));
    }

    #[test]
    fn bad_rows_name_the_file_line_and_field() {
        let cases = [
            ("clip,mass\na,70\n", "clip and mass_kg"),
            ("clip,mass_kg\na,seventy\n", "m.csv:2"),
            ("clip,mass_kg\na,1e300\n", "[1, 1000] kg"),
            (
                "clip,mass_kg,sex\na,70,other\n",
                "not male, female or average",
            ),
            ("clip,mass_kg\na[,70\n", "not a name or glob"),
            ("clip,mass_kg,sex\na\n", "missing field mass_kg"),
            ("mass_kg,clip\n70\n", "missing field clip"),
        ];
        for (text, want) in cases {
            let e = parse_masses(text, "m.csv").unwrap_err().to_string();
            assert!(e.contains("m.csv") && e.contains(want), "{text:?}: {e}");
        }
    }

    #[test]
    fn body_masses_are_bounded() {
        assert!(check_body_mass(70.0).is_ok());
        for m in [0.0, 0.5, 1001.0, f64::NAN, f64::INFINITY, 1e300] {
            assert!(check_body_mass(m).is_err(), "{m}");
        }
    }
}
