//! One generation of a library per read: a command that reads a library while a build
//! replaces it answers from the old library or the new one, never from tables of both,
//! or says that the library changed under it.
//!
//! # Model
//! ```text
//! generation(LIB) = SHA-256 of LIB/manifest.json   (none: no readable manifest)
//! ```
//! A build writes a new library into a temporary folder and swaps the whole folder into
//! place (`pipeline::engine::output::swap_into_place`), so every table a reader opens belongs to
//! the folder at `LIB` at that moment. Each build's manifest records its tables' SHA-256,
//! its creation time and its wall time in nanoseconds: two folders with the same manifest
//! bytes hold the same tables. A read pinned by [`read_consistently`] therefore
//! 1. takes the generation before it reads anything;
//! 2. takes it again before its first output (a file renamed into place by
//!    [`super::atomic::write_file_atomic`] or [`super::stream::TableWriter::finish`], a
//!    BVH, a line on stdout: [`before_output`], [`before_print`]): every table it read
//!    until then was of that generation, or the output is not made;
//! 3. when it made no output, takes it once more at the end.
//!
//! A generation that changed at 2 or 3 means the read may have mixed two libraries (once
//! 3 of about 450 reads during rebuilds failed with "rows out of step" or "clip X not in
//! clips.parquet", and `info` counted the clips of one build with the stances of the
//! other): the read is run once more, and if the library changes again the command fails
//! with [`ErrorKind::Changed`]. The pin is per thread (the thread that runs the command);
//! outputs written by other threads are not checked at 2, and the end check covers them.
//!
//! # Examples
//! ```
//! use stancelib::library::storage::generation::{generation, read_consistently};
//! let d = tempfile::tempdir().unwrap();
//! std::fs::write(d.path().join("manifest.json"), "{}").unwrap();
//! let before = generation(d.path());
//! let n: Result<usize, stancelib::error::Error> = read_consistently(d.path(), || Ok(3));
//! assert_eq!(n.unwrap(), 3);
//! assert_eq!(generation(d.path()), before);
//! ```

use std::cell::RefCell;
use std::path::{Path, PathBuf};

use sha2::{Digest, Sha256};

use crate::error::{Error, ErrorKind};

/// Reads of one library made by one command: the first, and the one more made when the
/// library changed during the first.
pub const MAX_READ_ATTEMPTS: usize = 2;

/// What names one generation of a library: the SHA-256 of its manifest's bytes, `None`
/// when it has no readable manifest.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Generation(Option<[u8; 32]>);

/// The generation of the library at `lib` now (module docs).
pub fn generation(lib: &Path) -> Generation {
    Generation(
        crate::library::codec::manifest::read_manifest_bytes(lib)
            .ok()
            .map(|b| Sha256::digest(&b).into()),
    )
}

/// The read pinned on this thread.
#[derive(Debug)]
struct Pin {
    lib: PathBuf,
    generation: Generation,
    /// The generation was found unchanged at the first output.
    verified: bool,
    /// The generation was found changed: no output may be made.
    stale: bool,
}

thread_local! {
    static PIN: RefCell<Option<Pin>> = const { RefCell::new(None) };
}

/// The error of a library that changed while it was read.
pub fn changed(lib: &Path) -> Error {
    ErrorKind::Changed {
        lib: lib.to_path_buf(),
    }
    .into()
}

/// Whether the pinned read may make an output: `Ok(true)` when the generation is the
/// one pinned (checked once, at the first output), `Ok(false)` when no read is pinned on
/// this thread, `Err` when it changed.
fn check_pin() -> Result<bool, Error> {
    PIN.with(|p| {
        let mut p = p.borrow_mut();
        let Some(pin) = p.as_mut() else {
            return Ok(false);
        };
        if !pin.stale && !pin.verified {
            if generation(&pin.lib) == pin.generation {
                pin.verified = true;
            } else {
                pin.stale = true;
            }
        }
        if pin.stale {
            Err(changed(&pin.lib))
        } else {
            Ok(true)
        }
    })
}

/// Called before an output file is put in place: an error when a read pinned on this
/// thread ([`read_consistently`]) finds its library changed since it began (the output
/// is then not made). Without a pinned read, nothing is checked.
///
/// # Errors
/// [`ErrorKind::Changed`].
pub fn before_output() -> Result<(), Error> {
    check_pin().map(|_| ())
}

/// Called before a line is printed on stdout: false when a read pinned on this thread
/// finds its library changed since it began (the line is dropped; the read is run again
/// or fails, see [`read_consistently`]).
pub fn before_print() -> bool {
    check_pin().is_ok()
}

/// Runs `read`, a command that reads the library at `lib`, on one generation of it
/// (module docs): run again once when the library changed while it ran, a
/// [`ErrorKind::Changed`] error when it changed again. An error of `read` on an
/// unchanged library is returned as it is.
///
/// # Errors
/// `read`'s, or [`ErrorKind::Changed`].
pub fn read_consistently<T, E: From<Error>>(
    lib: &Path,
    mut read: impl FnMut() -> Result<T, E>,
) -> Result<T, E> {
    for _ in 0..MAX_READ_ATTEMPTS {
        let before = generation(lib);
        PIN.with(|p| {
            *p.borrow_mut() = Some(Pin {
                lib: lib.to_path_buf(),
                generation: before,
                verified: false,
                stale: false,
            })
        });
        let result = read();
        let pin = PIN.with(|p| p.borrow_mut().take());
        let (verified, stale) = pin.map_or((false, false), |p| (p.verified, p.stale));
        if verified {
            // Outputs were made from one generation; an error after them is the
            // command's own unless the library changed (no second run: the outputs and
            // lines made would be made twice).
            return match result {
                Err(_) if generation(lib) != before => Err(changed(lib).into()),
                r => r,
            };
        }
        if !stale && generation(lib) == before {
            return result;
        }
    }
    Err(changed(lib).into())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn manifest(lib: &Path, text: &str) {
        std::fs::write(lib.join("manifest.json"), text).unwrap();
    }

    #[test]
    fn a_library_changed_during_both_reads_is_an_error_naming_it() {
        let d = tempfile::tempdir().unwrap();
        manifest(d.path(), "{\"n\": 0}");
        let mut runs = 0;
        let r: Result<(), Error> = read_consistently(d.path(), || {
            runs += 1;
            manifest(d.path(), &format!("{{\"n\": {runs}}}"));
            Ok(())
        });
        assert_eq!(runs, MAX_READ_ATTEMPTS);
        let e = r.unwrap_err().to_string();
        assert!(e.contains(&d.path().display().to_string()), "{e}");
        assert!(e.contains("changed while it was read"), "{e}");
    }

    #[test]
    fn a_library_changed_during_the_first_read_is_read_again() {
        let d = tempfile::tempdir().unwrap();
        manifest(d.path(), "{\"n\": 0}");
        let mut runs = 0;
        let r: Result<usize, Error> = read_consistently(d.path(), || {
            runs += 1;
            if runs == 1 {
                manifest(d.path(), "{\"n\": 1}");
                // What a mixed read gives: an error the library did not cause.
                return Err(Error::invalid("clip", "not in clips.parquet"));
            }
            Ok(runs)
        });
        assert_eq!(r.unwrap(), 2);
    }

    #[test]
    fn an_output_after_a_change_is_refused_and_not_retried_after_a_verified_one() {
        let d = tempfile::tempdir().unwrap();
        manifest(d.path(), "{\"n\": 0}");
        // Changed before the first output: the output is refused, the read runs again.
        let mut runs = 0;
        let r: Result<usize, Error> = read_consistently(d.path(), || {
            runs += 1;
            if runs == 1 {
                manifest(d.path(), "{\"n\": 1}");
            }
            before_output()?;
            assert!(before_print());
            Ok(runs)
        });
        assert_eq!(r.unwrap(), 2);
        // Changed after a verified output: that run's own answer stands.
        let r: Result<(), Error> = read_consistently(d.path(), || {
            before_output()?;
            manifest(d.path(), "{\"n\": 2}");
            Ok(())
        });
        assert!(r.is_ok());
        // Without a pinned read nothing is checked.
        assert!(before_output().is_ok() && before_print());
    }

    #[test]
    fn an_error_on_an_unchanged_library_is_returned_once() {
        let d = tempfile::tempdir().unwrap();
        manifest(d.path(), "{}");
        let mut runs = 0;
        let r: Result<(), Error> = read_consistently(d.path(), || {
            runs += 1;
            Err(Error::invalid("--stance", "no stance 'x'"))
        });
        assert_eq!(runs, 1);
        assert!(r.unwrap_err().to_string().contains("no stance 'x'"));
    }
}
