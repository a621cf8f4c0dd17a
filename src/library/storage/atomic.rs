//! The one way every output file is written: under a temporary name beside it
//! (`.<name>.tmp-<pid>`, see [`super::scratch`]), then renamed into place, so a reader
//! never sees a half-written file and an earlier file survives a failed write.
//!
//! Parquet tables go through [`super::stream::TableWriter`] (which streams row groups into
//! its temporary and renames on `finish`); text (JSON) and images (PNG) through
//! [`write_file_atomic`] and [`write_text_atomic`].

use std::path::{Path, PathBuf};

use super::scratch::{scratch_name, Scratch};
use crate::error::{Error, Result};

/// The temporary beside `path` that [`write_file_atomic`] writes: `.<name>.tmp-<pid>`, with
/// `path`'s extension repeated at the end (image backends pick the format from it).
///
/// # Errors
/// `path` has no file name.
pub fn temporary_beside(path: &Path) -> Result<PathBuf> {
    let name = path
        .file_name()
        .and_then(|n| n.to_str())
        .ok_or_else(|| Error::invalid("--out", format!("{}: not a file name", path.display())))?;
    let mut tmp = scratch_name(name, Scratch::Tmp);
    if let Some(ext) = path.extension().and_then(|e| e.to_str()) {
        tmp = format!("{tmp}.{ext}");
    }
    Ok(path.with_file_name(tmp))
}

/// Writes `path` by `write` (given the temporary's path), then renames the temporary into
/// place; on any failure the temporary is removed and an earlier `path` is untouched.
///
/// # Errors
/// `path` has no file name, `write` fails (its error is returned as is), or the rename
/// fails.
pub fn write_file_atomic<E: From<Error>>(
    path: &Path,
    write: impl FnOnce(&Path) -> std::result::Result<(), E>,
) -> std::result::Result<(), E> {
    let tmp = temporary_beside(path)?;
    let result = write(&tmp).and_then(|()| {
        super::generation::before_output()?;
        std::fs::rename(&tmp, path)
            .map_err(|e| E::from(Error::io(path, "cannot rename into place", e)))
    });
    if result.is_err() {
        let _ = std::fs::remove_file(&tmp);
    }
    result
}

/// Writes `text` to `path` atomically (see [`write_file_atomic`]).
///
/// # Errors
/// The folder is not writable; the error names the file.
pub fn write_text_atomic(path: &Path, text: &str) -> Result<()> {
    write_file_atomic(path, |tmp| {
        std::fs::write(tmp, text).map_err(|e| Error::io(tmp, "cannot write", e))
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_failed_write_keeps_the_earlier_file_and_leaves_no_temporary() {
        let d = tempfile::tempdir().unwrap();
        let p = d.path().join("a.json");
        write_text_atomic(&p, "old").unwrap();
        let r: Result<()> = write_file_atomic(&p, |tmp| {
            std::fs::write(tmp, "half").unwrap();
            Err(Error::invalid("x", "failed"))
        });
        assert!(r.is_err());
        assert_eq!(std::fs::read_to_string(&p).unwrap(), "old");
        let names: Vec<_> = std::fs::read_dir(d.path())
            .unwrap()
            .map(|e| e.unwrap().file_name())
            .collect();
        assert_eq!(names, vec![std::ffi::OsString::from("a.json")]);
    }

    #[test]
    fn the_temporary_keeps_the_extension_last() {
        let t = temporary_beside(Path::new("/x/map.png")).unwrap();
        let name = t.file_name().unwrap().to_str().unwrap().to_string();
        assert!(
            name.starts_with(".map.png.tmp-") && name.ends_with(".png"),
            "{name}"
        );
    }
}
