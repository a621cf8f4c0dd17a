//! What a library's tables held when they were written, and the check that they still do.
//!
//! A finished library's `manifest.json` records the SHA-256 of every Parquet file of its
//! tables ([`TABLES_KEY`]) and, per clip, its rows in each per-clip table
//! ([`CLIP_ROWS_KEY`]). Whatever reads a library's rows to write them again (`build
//! --incremental`, `merge`) checks the files it takes rows from against the first and the
//! clips it takes against the second: a table copied in from another library, one of
//! other options, or a flipped bit is then found before any of its rows is reused.
//!
//! # Model
//! ```text
//! tables:    { "<path in the library>": { "sha256": hex of the file's bytes, "bytes": n } }
//!            every *.parquet file of the library (dataset layout: one per part file)
//! clip_rows: { "<clip>": { "<table>": rows } }   tables without .parquet; 0 rows omitted
//! ```
//! A file layout table is one entry (`stances.parquet`); a dataset table one per part
//! (`stances/character_id=sk-…/part-0.parquet`), and a part the manifest does not list,
//! or a listed one that is gone, is a mismatch as well.

use std::collections::BTreeMap;
use std::io::Read;
use std::path::{Path, PathBuf};

use rayon::prelude::*;
use sha2::{Digest, Sha256};

use super::layout::{locate, table_name};
use crate::error::{Error, Result};

/// Manifest key of the tables' content hashes ([`Digests`]).
pub const TABLES_KEY: &str = "tables";
/// Manifest key of the rows per clip and table ([`ClipRows`]).
pub const CLIP_ROWS_KEY: &str = "clip_rows";
/// Bytes read at a time while a file is hashed.
const HASH_BUFFER_BYTES: usize = 1 << 20;

/// The hash and size of one written file.
#[derive(serde::Serialize, serde::Deserialize, Debug, Clone, PartialEq, Eq)]
pub struct FileDigest {
    /// SHA-256 of the file's bytes, hex.
    pub sha256: String,
    /// The file's size, bytes.
    pub bytes: u64,
}

/// Per file of a library (its path inside the library, `/`-separated): its digest.
pub type Digests = BTreeMap<String, FileDigest>;

/// Per clip: its rows in each per-clip table (the table's name without `.parquet`).
pub type ClipRows = BTreeMap<String, BTreeMap<String, u64>>;

/// How a library's table or clip differs from what its manifest recorded at write time.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[non_exhaustive]
pub enum Mismatch {
    /// The manifest has no content hashes (a library written before they were recorded).
    #[error("manifest.json records no content hashes (a library written before they were)")]
    NoHashes,
    /// A file of the table that the manifest does not list.
    #[error("{file} is not among the files manifest.json records")]
    Unlisted {
        /// The file, inside the library.
        file: String,
    },
    /// A file the manifest lists that is gone.
    #[error("{file} is missing (manifest.json records it)")]
    Missing {
        /// The file, inside the library.
        file: String,
    },
    /// A file whose bytes are not those written.
    #[error("{file} is not the file that was written (SHA-256 {}, manifest.json: {}…)", short(found), &expected[..expected.len().min(16)])]
    Changed {
        /// The file, inside the library.
        file: String,
        /// The recorded hash.
        expected: String,
        /// The hash of the file now.
        found: String,
    },
    /// A file that cannot be read to be hashed.
    #[error("{file} cannot be read: {reason}")]
    Unreadable {
        /// The file, inside the library.
        file: String,
        /// The OS reason.
        reason: String,
    },
    /// A clip's rows in a table are not as many as recorded.
    #[error("{table} holds {found} rows of clip {clip}, manifest.json records {expected}")]
    Rows {
        /// The clip.
        clip: String,
        /// The table (without `.parquet`).
        table: String,
        /// Rows recorded.
        expected: u64,
        /// Rows found.
        found: u64,
    },
}

/// A found hash as a message shows it: its first 16 hex digits (anything else whole).
fn short(found: &str) -> String {
    match found.get(..16) {
        Some(head) if found.bytes().all(|b| b.is_ascii_hexdigit()) => format!("{head}…"),
        _ => found.to_string(),
    }
}

/// The digest of the file at `path`.
///
/// # Errors
/// The file cannot be opened or read.
pub fn file_digest(path: &Path) -> std::io::Result<FileDigest> {
    let mut f = std::fs::File::open(path)?;
    let mut h = Sha256::new();
    let mut buf = vec![0u8; HASH_BUFFER_BYTES];
    let mut bytes = 0u64;
    loop {
        let n = f.read(&mut buf)?;
        if n == 0 {
            break;
        }
        h.update(&buf[..n]);
        bytes += n as u64;
    }
    Ok(FileDigest {
        sha256: format!("{:x}", h.finalize()),
        bytes,
    })
}

/// `path` inside `lib`, `/`-separated (the key of [`Digests`]).
fn key_of(lib: &Path, path: &Path) -> String {
    let rel = path.strip_prefix(lib).unwrap_or(path);
    rel.components()
        .map(|c| c.as_os_str().to_string_lossy())
        .collect::<Vec<_>>()
        .join("/")
}

/// The Parquet files below `dir` (names starting with `.` — temporaries — skipped).
fn parquet_files(dir: &Path, out: &mut Vec<PathBuf>) -> Result<()> {
    let entries = std::fs::read_dir(dir).map_err(|e| Error::io(dir, "cannot list folder", e))?;
    for entry in entries {
        let entry = entry.map_err(|e| Error::io(dir, "cannot list folder", e))?;
        let name = entry.file_name().to_string_lossy().into_owned();
        if name.starts_with('.') {
            continue;
        }
        let kind = entry
            .file_type()
            .map_err(|e| Error::io(entry.path(), "cannot inspect", e))?;
        if kind.is_dir() {
            parquet_files(&entry.path(), out)?;
        } else if kind.is_file() && name.ends_with(".parquet") {
            out.push(entry.path());
        }
    }
    Ok(())
}

/// The digest of every Parquet file of the library folder `lib` (hashed in parallel on
/// the worker pool), keyed by its path inside `lib`.
///
/// # Errors
/// A folder that cannot be listed or a file that cannot be read.
pub fn library_digests(lib: &Path) -> Result<Digests> {
    let mut files = Vec::new();
    parquet_files(lib, &mut files)?;
    files
        .par_iter()
        .map(|p| {
            file_digest(p)
                .map(|d| (key_of(lib, p), d))
                .map_err(|e| Error::io(p, "cannot hash", e))
        })
        .collect()
}

/// The digests a manifest records ([`TABLES_KEY`]), if it records any.
pub fn recorded_digests(manifest: &serde_json::Value) -> Option<Digests> {
    serde_json::from_value(manifest.get(TABLES_KEY)?.clone()).ok()
}

/// The rows per clip a manifest records ([`CLIP_ROWS_KEY`]; none recorded: empty).
pub fn recorded_clip_rows(manifest: &serde_json::Value) -> ClipRows {
    manifest
        .get(CLIP_ROWS_KEY)
        .and_then(|v| serde_json::from_value(v.clone()).ok())
        .unwrap_or_default()
}

/// Check table `file` (a name of `schema::TABLE_FILES`) of the library at `lib`, in its
/// layout, against the digests `recorded` (from its manifest; `None`: none recorded):
/// every file of the table is listed and has its recorded bytes, and every file listed
/// for the table is there. The files are read whole.
///
/// # Errors
/// The first [`Mismatch`] found.
pub fn check_table(
    lib: &Path,
    file: &'static str,
    recorded: Option<&Digests>,
) -> std::result::Result<(), Mismatch> {
    let recorded = recorded.ok_or(Mismatch::NoHashes)?;
    let files = match locate(lib, file) {
        Ok(src) => src.files(),
        Err(e) => {
            return Err(Mismatch::Unreadable {
                file: file.to_string(),
                reason: e.to_string(),
            })
        }
    };
    let present: Vec<String> = files.iter().map(|p| key_of(lib, p)).collect();
    let table = table_name(file);
    let listed = recorded
        .keys()
        .filter(|k| *k == file || k.starts_with(&format!("{table}/")));
    for k in listed {
        if !present.contains(k) {
            return Err(Mismatch::Missing { file: k.clone() });
        }
    }
    for (path, key) in files.iter().zip(present) {
        check_file(path, key, recorded)?;
    }
    Ok(())
}

/// Check one file of a table (`key`: its path in the library) against `recorded`.
fn check_file(path: &Path, key: String, recorded: &Digests) -> std::result::Result<(), Mismatch> {
    let unreadable = |key: &str, e: std::io::Error| Mismatch::Unreadable {
        file: key.to_string(),
        reason: e.to_string(),
    };
    let len = match std::fs::metadata(path) {
        Ok(m) => m.len(),
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => {
            return Err(Mismatch::Missing { file: key });
        }
        Err(e) => return Err(unreadable(&key, e)),
    };
    let Some(want) = recorded.get(&key) else {
        return Err(Mismatch::Unlisted { file: key });
    };
    // Another size is another file: no need to read it.
    let found = if len == want.bytes {
        file_digest(path).map_err(|e| unreadable(&key, e))?.sha256
    } else {
        format!("({len} bytes, {} recorded)", want.bytes)
    };
    if found != want.sha256 {
        return Err(Mismatch::Changed {
            file: key,
            expected: want.sha256.clone(),
            found,
        });
    }
    Ok(())
}

/// Check that clip `clip` has `found` rows in table `table` (a name of
/// `schema::TABLE_FILES`) as `recorded` says (a clip or table not recorded: 0 rows).
///
/// # Errors
/// [`Mismatch::Rows`] when the counts differ.
pub fn check_clip_rows(
    recorded: &ClipRows,
    clip: &str,
    table: &str,
    found: u64,
) -> std::result::Result<(), Mismatch> {
    let t = table_name(table);
    let expected = recorded
        .get(clip)
        .and_then(|m| m.get(t))
        .copied()
        .unwrap_or(0);
    if expected != found {
        return Err(Mismatch::Rows {
            clip: clip.to_string(),
            table: t.to_string(),
            expected,
            found,
        });
    }
    Ok(())
}

/// Add `n` rows of `clip` in table `table` (a file name) to `rows` (0 adds nothing).
pub fn add_clip_rows(rows: &mut ClipRows, clip: &str, table: &str, n: u64) {
    if n == 0 {
        return;
    }
    *rows
        .entry(clip.to_string())
        .or_default()
        .entry(table_name(table).to_string())
        .or_default() += n;
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_changed_byte_a_missing_and_an_unlisted_file_are_mismatches() {
        let d = tempfile::tempdir().unwrap();
        let lib = d.path();
        std::fs::write(lib.join("stances.parquet"), b"PAR1 some bytes PAR1").unwrap();
        std::fs::write(lib.join("clips.parquet"), b"PAR1 other bytes PAR1").unwrap();
        std::fs::write(lib.join(".x.parquet.tmp-1"), b"scratch").unwrap();
        let recorded = library_digests(lib).unwrap();
        assert_eq!(recorded.len(), 2, "{recorded:?}");
        assert_eq!(check_table(lib, "stances.parquet", Some(&recorded)), Ok(()));
        assert_eq!(
            check_table(lib, "stances.parquet", None),
            Err(Mismatch::NoHashes)
        );
        // One bit flipped: same size, other hash.
        let mut b = std::fs::read(lib.join("stances.parquet")).unwrap();
        b[7] ^= 0x10;
        std::fs::write(lib.join("stances.parquet"), &b).unwrap();
        let e = check_table(lib, "stances.parquet", Some(&recorded)).unwrap_err();
        assert!(matches!(e, Mismatch::Changed { .. }), "{e}");
        assert!(e.to_string().starts_with("stances.parquet is not"), "{e}");
        // Another size is found without reading the file.
        std::fs::write(lib.join("stances.parquet"), b"short").unwrap();
        let e = check_table(lib, "stances.parquet", Some(&recorded)).unwrap_err();
        assert!(e.to_string().contains("5 bytes, 20 recorded"), "{e}");
        std::fs::remove_file(lib.join("stances.parquet")).unwrap();
        assert_eq!(
            check_table(lib, "stances.parquet", Some(&recorded)),
            Err(Mismatch::Missing {
                file: "stances.parquet".into()
            })
        );
        assert_eq!(
            check_table(lib, "frames.parquet", Some(&recorded)),
            Err(Mismatch::Missing {
                file: "frames.parquet".into()
            })
        );
    }

    #[test]
    fn clip_rows_add_up_and_check() {
        let mut rows = ClipRows::new();
        add_clip_rows(&mut rows, "a", "frames.parquet", 10);
        add_clip_rows(&mut rows, "a", "frames.parquet", 5);
        add_clip_rows(&mut rows, "b", "stances.parquet", 0);
        assert_eq!(rows["a"]["frames"], 15);
        assert!(!rows.contains_key("b"));
        assert_eq!(check_clip_rows(&rows, "a", "frames.parquet", 15), Ok(()));
        assert_eq!(check_clip_rows(&rows, "b", "stances.parquet", 0), Ok(()));
        let e = check_clip_rows(&rows, "a", "stances.parquet", 3).unwrap_err();
        assert_eq!(
            e.to_string(),
            "stances holds 3 rows of clip a, manifest.json records 0"
        );
    }
}
