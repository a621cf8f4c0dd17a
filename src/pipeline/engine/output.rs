//! The output folder of `build` and `run`: what `--out` may name, the lock that keeps two
//! builds out of one library, the removal of temporaries of killed runs, and the swap that
//! puts a new library in place. The policy lives here and nowhere else.
//!
//! # Policy
//! - `--out` never equals, contains or lies inside an input (a file or folder given, or a
//!   file found in one), compared as canonical paths; for an `--out` that does not exist yet,
//!   the canonical path of its nearest existing ancestor. `--force` does not lift this.
//! - An existing `--out` that is not a folder (a file, a symbolic link, a FIFO…) is
//!   refused, with or without `--force`.
//! - An existing folder is replaced when it is a stancelib library ([`is_library`]) or
//!   empty; any other folder only with `--force`.
//! - The lock is `.<name>.lock` beside `--out` (`flock`, Linux): a second build into the
//!   same folder stops at once with the holder's process id. The file is removed when the
//!   build ends; one left by a killed build holds no lock and is reused.
//! - Temporaries `.<name>.tmp-<pid>` of dead processes beside `--out` are removed before
//!   the build (see [`crate::library::storage::scratch`]); so is `.<name>.old-<pid>` once `--out` is a
//!   library again.

use std::path::{Component, Path, PathBuf};

use super::inputs::file_kind;
use crate::error::{Error, Result};
use crate::library::codec::schema::{MANIFEST_FILE, MANIFEST_SCHEMA_PREFIX};
use crate::library::storage::scratch::{remove_stale, scratch_name, Scratch};

pub use crate::library::codec::manifest::MAX_MANIFEST_BYTES;

/// Whether a JSON value has the expected type.
type JsonTypeCheck = fn(&serde_json::Value) -> bool;

/// Keys and JSON types of the manifests written before the `schema` key: a folder whose
/// manifest has all of them is a library too.
const LEGACY_MANIFEST_KEYS: [(&str, JsonTypeCheck); 8] = [
    ("schema_version", serde_json::Value::is_string),
    ("tool_version", serde_json::Value::is_string),
    ("options", serde_json::Value::is_object),
    ("inputs", serde_json::Value::is_object),
    ("limits", serde_json::Value::is_object),
    ("counts", serde_json::Value::is_object),
    ("failures", serde_json::Value::is_array),
    ("wall_time_s", serde_json::Value::is_number),
];

/// What a build may do to its output besides the fixed rules (module docs).
#[derive(Debug, Clone, Default)]
pub struct OutputRules {
    /// The inputs as given (files and folders); the files found in them are checked too.
    pub inputs: Vec<PathBuf>,
    /// Replace an existing folder that is neither a library nor empty (`--force`).
    pub force: bool,
}

/// An output checked, locked and cleaned of stale temporaries; the lock is held until this
/// is dropped.
#[derive(Debug)]
pub struct OutputClaim {
    _lock: lock::LockFile,
}

/// Check `out` against the policy (module docs), take its lock and remove the stale
/// temporaries beside it.
///
/// # Errors
/// An `--out` the policy refuses, a lock held by another build, or a parent folder that
/// cannot be created.
pub fn claim(out: &Path, files: &[PathBuf], rules: &OutputRules) -> Result<OutputClaim> {
    let name = name_of(out)?;
    refuse_overlap(out, rules.inputs.iter().chain(files))?;
    let parent = parent_of(out);
    std::fs::create_dir_all(parent).map_err(|e| Error::io(parent, "cannot create folder", e))?;
    let lock = lock::LockFile::acquire(&parent.join(format!(".{name}.lock")), out)?;
    check_existing(out, rules.force)?;
    remove_stale(parent, &[&name], Scratch::Tmp);
    if is_library(out) {
        remove_stale(parent, &[&name], Scratch::Old);
    }
    Ok(OutputClaim { _lock: lock })
}

/// The folder that holds `out` (`.` for a bare name).
pub fn parent_of(out: &Path) -> &Path {
    out.parent()
        .filter(|p| !p.as_os_str().is_empty())
        .unwrap_or(Path::new("."))
}

/// The last part of `out`, which names the temporaries and the lock beside it.
///
/// # Errors
/// `out` ends in `.`, `..` or a root.
pub fn name_of(out: &Path) -> Result<String> {
    match out.components().next_back() {
        Some(Component::Normal(n)) => Ok(n.to_string_lossy().into_owned()),
        _ => Err(refused(
            out,
            "must end in a folder name (not '.', '..' or '/')",
        )),
    }
}

fn refused(out: &Path, why: impl std::fmt::Display) -> Error {
    Error::config(Some(out.to_path_buf()), None, format!("--out {why}"))
}

/// Whether `dir` holds a stancelib library: its `manifest.json` (a regular file of at most
/// [`MAX_MANIFEST_BYTES`]) has `schema` = `stancelib.library/…`, or every key of the
/// manifests written before that key.
pub fn is_library(dir: &Path) -> bool {
    crate::library::codec::manifest::read_manifest(dir).is_ok_and(|m| manifest_says_library(&m))
}

/// Refuse a folder of tables `out` (`frames --out`) that holds a stancelib library
/// ([`is_library`]): writing its frames, clips and contacts tables there would leave the
/// library's other tables and manifest describing clips it no longer holds.
///
/// # Errors
/// `out` is a library.
pub fn refuse_library(out: &Path) -> Result<()> {
    if !is_library(out) {
        return Ok(());
    }
    Err(refused(
        out,
        format!(
            "holds a stancelib library ({MANIFEST_FILE}): `frames` would replace its frames, \
             clips and contacts tables under its other tables; give another folder, or \
             rebuild the library with `build`"
        ),
    ))
}

fn manifest_says_library(m: &serde_json::Value) -> bool {
    match m.get("schema") {
        Some(s) => s
            .as_str()
            .is_some_and(|s| s.starts_with(MANIFEST_SCHEMA_PREFIX)),
        None => LEGACY_MANIFEST_KEYS
            .iter()
            .all(|(k, is_type)| m.get(k).is_some_and(is_type)),
    }
}

/// Refuse an `out` that is, contains or lies inside one of `inputs` (canonical paths;
/// inputs that do not resolve are reported per input by the batch, not here).
fn refuse_overlap<'a>(out: &Path, inputs: impl Iterator<Item = &'a PathBuf>) -> Result<()> {
    let o = resolve(out).map_err(|e| Error::io(out, "cannot resolve the output path", e))?;
    for input in inputs {
        let Ok(i) = std::fs::canonicalize(input) else {
            continue;
        };
        let why = if o == i {
            "is"
        } else if o.starts_with(&i) {
            "lies inside"
        } else if i.starts_with(&o) {
            "contains"
        } else {
            continue;
        };
        return Err(refused(
            out,
            format!(
                "{why} the input {}: a library is never written over its inputs \
                 (--force does not change this)",
                input.display()
            ),
        ));
    }
    Ok(())
}

/// The canonical form of `p`: its longest existing leading part canonicalised, the rest
/// appended with `.` and `..` folded lexically.
fn resolve(p: &Path) -> std::io::Result<PathBuf> {
    let abs = std::env::current_dir()?.join(p);
    let parts: Vec<Component> = abs.components().collect();
    for k in (1..=parts.len()).rev() {
        let head: PathBuf = parts[..k].iter().collect();
        if let Ok(mut out) = std::fs::canonicalize(&head) {
            for c in &parts[k..] {
                match c {
                    Component::ParentDir => {
                        out.pop();
                    }
                    Component::Normal(n) => out.push(n),
                    _ => {}
                }
            }
            return Ok(out);
        }
    }
    Ok(abs)
}

/// An existing `out` must be a real folder that is a library, empty, or `force`d.
fn check_existing(out: &Path, force: bool) -> Result<()> {
    let meta = match std::fs::symlink_metadata(out) {
        Ok(m) => m,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(()),
        Err(e) => return Err(Error::io(out, "cannot inspect the output", e)),
    };
    if !meta.is_dir() {
        return Err(refused(
            out,
            format!(
                "is a {}, not a folder: it is never replaced (not even with --force)",
                file_kind(&meta.file_type())
            ),
        ));
    }
    if force || is_library(out) || is_empty(out)? {
        return Ok(());
    }
    Err(refused(
        out,
        format!(
            "is a folder that is not a stancelib library (no {MANIFEST_FILE} of one): \
             refusing to replace it and everything in it; give another --out, or --force \
             to replace it"
        ),
    ))
}

fn is_empty(dir: &Path) -> Result<bool> {
    let mut rd =
        std::fs::read_dir(dir).map_err(|e| Error::io(dir, "cannot list the output folder", e))?;
    Ok(rd.next().is_none())
}

/// Put `tmp` in the place of `out`. On Linux the two folders are exchanged in one step
/// (`renameat2` with `RENAME_EXCHANGE`), so `out` always names a complete library; the old
/// one, now at `tmp`, is then removed. Elsewhere (or on a file system without the flag) the
/// old library is renamed aside first: a run killed between the two renames leaves it
/// intact at `.<name>.old-<pid>` beside `out`.
///
/// # Errors
/// A rename that fails.
pub fn swap_into_place(tmp: &Path, out: &Path) -> Result<()> {
    if std::fs::symlink_metadata(out).is_err() {
        return std::fs::rename(tmp, out)
            .map_err(|e| Error::io(out, "cannot move the new library into place", e));
    }
    if exchange(tmp, out) {
        let _ = std::fs::remove_dir_all(tmp);
        return Ok(());
    }
    let old = parent_of(out).join(scratch_name(&name_of(out)?, Scratch::Old));
    std::fs::rename(out, &old)
        .map_err(|e| Error::io(out, "cannot move the previous library aside", e))?;
    std::fs::rename(tmp, out)
        .map_err(|e| Error::io(out, "cannot move the new library into place", e))?;
    let _ = std::fs::remove_dir_all(&old);
    Ok(())
}

/// Atomically exchange two paths (Linux `renameat2(RENAME_EXCHANGE)`); false when the
/// system or file system cannot.
#[cfg(target_os = "linux")]
fn exchange(a: &Path, b: &Path) -> bool {
    use std::ffi::CString;
    use std::os::unix::ffi::OsStrExt;
    let (Ok(ca), Ok(cb)) = (
        CString::new(a.as_os_str().as_bytes()),
        CString::new(b.as_os_str().as_bytes()),
    ) else {
        return false;
    };
    // SAFETY: both arguments are valid NUL-terminated paths that outlive the call;
    // renameat2 reads them and touches no other memory.
    let rc = unsafe {
        libc::renameat2(
            libc::AT_FDCWD,
            ca.as_ptr(),
            libc::AT_FDCWD,
            cb.as_ptr(),
            libc::RENAME_EXCHANGE,
        )
    };
    rc == 0
}

#[cfg(not(target_os = "linux"))]
fn exchange(_: &Path, _: &Path) -> bool {
    false
}

/// The advisory lock beside an output (Linux `flock`; elsewhere no lock is taken).
#[cfg(target_os = "linux")]
mod lock {
    use std::fs::File;
    use std::io::{Read, Write};
    use std::os::unix::fs::{MetadataExt, OpenOptionsExt};
    use std::os::unix::io::AsRawFd;
    use std::path::{Path, PathBuf};

    use crate::error::{Error, Result};

    /// Attempts to lock a file that another build removes at the same time (each removal
    /// makes the next attempt lock a new file).
    pub const MAX_LOCK_ATTEMPTS: usize = 8;

    /// A held lock on a file; released and removed on drop.
    #[derive(Debug)]
    pub struct LockFile {
        path: PathBuf,
        file: File,
    }

    impl LockFile {
        /// Lock `path` (created if absent) without waiting; `out` names the output in
        /// the message when another process holds it.
        pub fn acquire(path: &Path, out: &Path) -> Result<LockFile> {
            for _ in 0..MAX_LOCK_ATTEMPTS {
                let file = std::fs::OpenOptions::new()
                    .read(true)
                    .write(true)
                    .create(true)
                    .truncate(false)
                    .custom_flags(libc::O_NOFOLLOW)
                    .open(path)
                    .map_err(|e| Error::io(path, "cannot open the lock file", e))?;
                // SAFETY: the descriptor is open for the duration of the call.
                if unsafe { libc::flock(file.as_raw_fd(), libc::LOCK_EX | libc::LOCK_NB) } != 0 {
                    let e = std::io::Error::last_os_error();
                    if e.raw_os_error() == Some(libc::EWOULDBLOCK) {
                        return Err(held(path, out, holder(file)));
                    }
                    return Err(Error::io(path, "cannot lock", e));
                }
                let lock = LockFile {
                    path: path.to_path_buf(),
                    file,
                };
                // A build that finished between our open and our flock removed the file
                // we locked: lock the path's new file instead.
                if lock.still_at_path() {
                    lock.write_pid(path)?;
                    return Ok(lock);
                }
                drop(lock); // not at the path any more: nothing is removed
            }
            Err(Error::config(
                Some(path.to_path_buf()),
                None,
                format!("lock file replaced {MAX_LOCK_ATTEMPTS} times while locking it"),
            ))
        }

        fn still_at_path(&self) -> bool {
            let (Ok(held), Ok(now)) = (self.file.metadata(), std::fs::symlink_metadata(&self.path))
            else {
                return false;
            };
            held.dev() == now.dev() && held.ino() == now.ino()
        }

        fn write_pid(&self, path: &Path) -> Result<()> {
            self.file
                .set_len(0)
                .and_then(|_| {
                    (&self.file).write_all(format!("{}\n", std::process::id()).as_bytes())
                })
                .map_err(|e| Error::io(path, "cannot write the lock file", e))
        }
    }

    impl Drop for LockFile {
        fn drop(&mut self) {
            // Removed while still locked: a build waiting on this file sees it is gone.
            if self.still_at_path() {
                let _ = std::fs::remove_file(&self.path);
            }
        }
    }

    /// The process id written in a lock file by its holder, if it reads as one.
    fn holder(file: File) -> Option<u32> {
        let mut text = String::new();
        file.take(32).read_to_string(&mut text).ok()?;
        text.trim().parse().ok()
    }

    fn held(path: &Path, out: &Path, pid: Option<u32>) -> Error {
        let who = pid.map_or_else(|| "another process".to_string(), |p| format!("process {p}"));
        Error::config(
            Some(path.to_path_buf()),
            None,
            format!(
                "locked by {who}, which is building into {}; wait for it to finish, or give \
                 another --out",
                out.display()
            ),
        )
    }
}

/// No lock off Linux.
#[cfg(not(target_os = "linux"))]
mod lock {
    use std::path::Path;

    use crate::error::Result;

    /// No lock (only Linux has one).
    #[derive(Debug)]
    pub struct LockFile;

    impl LockFile {
        /// Nothing to lock.
        pub fn acquire(_path: &Path, _out: &Path) -> Result<LockFile> {
            Ok(LockFile)
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::library::codec::schema::SCHEMA_VERSION;

    #[test]
    fn the_manifest_schema_names_the_table_schema_version() {
        let m =
            serde_json::json!({ "schema": format!("{MANIFEST_SCHEMA_PREFIX}{SCHEMA_VERSION}") });
        assert!(manifest_says_library(&m));
        assert!(!manifest_says_library(
            &serde_json::json!({ "schema": "stancelib.twopac.phases/1" })
        ));
    }

    #[test]
    fn a_legacy_manifest_needs_every_key_with_its_type() {
        let mut m = serde_json::json!({
            "schema_version": "1", "tool_version": "0.1.0", "options": {}, "inputs": {},
            "limits": {}, "counts": {}, "failures": [], "wall_time_s": 1.5,
        });
        assert!(manifest_says_library(&m));
        m["failures"] = serde_json::json!("none");
        assert!(!manifest_says_library(&m));
        m.as_object_mut().unwrap().remove("failures");
        assert!(!manifest_says_library(&m));
        assert!(!manifest_says_library(
            &serde_json::json!({ "name": "my-app" })
        ));
    }

    #[test]
    fn a_path_that_does_not_exist_resolves_under_its_existing_ancestor() {
        let d = tempfile::tempdir().unwrap();
        let real = std::fs::canonicalize(d.path()).unwrap();
        let p = d.path().join("a/b/../c/./d");
        assert_eq!(resolve(&p).unwrap(), real.join("a/c/d"));
        assert_eq!(resolve(d.path()).unwrap(), real);
    }

    #[test]
    fn an_out_without_a_folder_name_is_refused() {
        for p in [".", "a/..", "/"] {
            assert!(name_of(Path::new(p)).is_err(), "{p}");
        }
        assert_eq!(name_of(Path::new("x/lib/")).unwrap(), "lib");
    }
}
