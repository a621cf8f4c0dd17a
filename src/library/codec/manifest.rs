//! Reading a library's `manifest.json`: the one bounded way every command takes it in.
//!
//! A manifest lists one hash per input and per table file (about 100 bytes per clip), so
//! even a million-clip library's stays far below [`MAX_MANIFEST_BYTES`]. A larger file is
//! no manifest this tool wrote: it is refused from its size before a byte is read (a
//! 300 MB manifest once took `info` to 1.19 GB), and a file that grows while it is read
//! is cut at the limit and refused too.
//!
//! # Examples
//! ```
//! use stancelib::library::codec::manifest::read_manifest;
//! let d = tempfile::tempdir().unwrap();
//! std::fs::write(d.path().join("manifest.json"), r#"{"schema_version": "4"}"#).unwrap();
//! assert_eq!(read_manifest(d.path()).unwrap()["schema_version"], "4");
//! ```

use std::io::Read;
use std::path::{Path, PathBuf};

use super::schema::MANIFEST_FILE;
use crate::error::{Error, InputProblem, Result};

/// Largest `manifest.json` read, bytes (64 MiB; a manifest lists one hash per input and
/// per table file: about 100 bytes per clip).
pub const MAX_MANIFEST_BYTES: u64 = 64 << 20;

/// The path of the manifest of the library at `lib`.
pub fn manifest_path(lib: &Path) -> PathBuf {
    lib.join(MANIFEST_FILE)
}

/// The bytes of the manifest of the library at `lib`, at most [`MAX_MANIFEST_BYTES`].
///
/// # Errors
/// The file cannot be opened or read (the OS reason in the chain), is not a regular
/// file, or is larger than [`MAX_MANIFEST_BYTES`] (the error names the cap).
pub fn read_manifest_bytes(lib: &Path) -> Result<Vec<u8>> {
    let path = manifest_path(lib);
    let what = "library manifest";
    let too_large = |bytes: u64| InputProblem::TooLarge {
        bytes,
        max: MAX_MANIFEST_BYTES,
        cap: "MAX_MANIFEST_BYTES",
    };
    // Inspected before it is opened: opening a FIFO would block.
    let meta = std::fs::metadata(&path).map_err(|e| Error::io(&path, "cannot read", e))?;
    if !meta.is_file() {
        let kind = if meta.is_dir() {
            "folder"
        } else {
            "special file"
        };
        let problem = InputProblem::NotRegular {
            kind,
            via_link: false,
        };
        return Err(Error::input(&path, what, problem));
    }
    if meta.len() > MAX_MANIFEST_BYTES {
        return Err(Error::input(&path, what, too_large(meta.len())));
    }
    let file = std::fs::File::open(&path).map_err(|e| Error::io(&path, "cannot read", e))?;
    let mut bytes = Vec::with_capacity(meta.len() as usize);
    file.take(MAX_MANIFEST_BYTES + 1)
        .read_to_end(&mut bytes)
        .map_err(|e| Error::io(&path, "cannot read", e))?;
    if bytes.len() as u64 > MAX_MANIFEST_BYTES {
        return Err(Error::input(&path, what, too_large(bytes.len() as u64)));
    }
    Ok(bytes)
}

/// The manifest of the library at `lib` as text ([`read_manifest_bytes`]).
///
/// # Errors
/// As [`read_manifest_bytes`], or the bytes are not UTF-8.
pub fn read_manifest_text(lib: &Path) -> Result<String> {
    let bytes = read_manifest_bytes(lib)?;
    String::from_utf8(bytes).map_err(|e| Error::io(manifest_path(lib), "not UTF-8 text", e))
}

/// The manifest of the library at `lib`, parsed.
///
/// # Errors
/// As [`read_manifest_text`], or the text is not JSON (the parser's line and column).
pub fn read_manifest(lib: &Path) -> Result<serde_json::Value> {
    let text = read_manifest_text(lib)?;
    serde_json::from_str(&text)
        .map_err(|e| Error::config(Some(manifest_path(lib)), None, e.to_string()))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_manifest_beyond_the_limit_is_refused_from_its_size() {
        let d = tempfile::tempdir().unwrap();
        let f = std::fs::File::create(d.path().join(MANIFEST_FILE)).unwrap();
        // Sparse: no disk or memory is used for it, and none must be for reading it.
        f.set_len(MAX_MANIFEST_BYTES + 1).unwrap();
        let e = read_manifest(d.path()).unwrap_err();
        let msg = format!("{:#}", anyhow::Error::new(e));
        assert!(msg.contains("MAX_MANIFEST_BYTES"), "{msg}");
        assert!(msg.contains(&(MAX_MANIFEST_BYTES + 1).to_string()), "{msg}");
        // At the limit it is read (and is no JSON).
        f.set_len(MAX_MANIFEST_BYTES).unwrap();
        let e = read_manifest(d.path()).unwrap_err().to_string();
        assert!(!e.contains("MAX_MANIFEST_BYTES"), "{e}");
    }
}
