//! Names of the temporaries the tool writes beside or inside an output, and the removal of
//! those left by killed runs.
//!
//! Every temporary is named `.<name>.<tag>-<pid>`: `<name>` is the file or folder it will
//! replace, `<tag>` says what it is ([`Scratch`]) and `<pid>` is the process that made it.
//! A killed run leaves its temporaries behind; the next run into the same output removes
//! those whose process is gone ([`remove_stale`]). Nothing that does not match this pattern
//! exactly is ever removed, and neither is the temporary of a live process.

use std::path::{Path, PathBuf};

/// What a temporary is.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Scratch {
    /// A file or folder being written (`.<name>.tmp-<pid>`).
    Tmp,
    /// A previous library moved aside during the swap (`.<name>.old-<pid>`).
    Old,
}

impl Scratch {
    fn tag(self) -> &'static str {
        match self {
            Scratch::Tmp => "tmp",
            Scratch::Old => "old",
        }
    }
}

/// `.<name>.<tag>-<pid>`, the name of a temporary of this process.
pub fn scratch_name(name: &str, kind: Scratch) -> String {
    scratch_name_of(name, kind, std::process::id())
}

/// `.<name>.<tag>-<pid>` for the process `pid`.
pub fn scratch_name_of(name: &str, kind: Scratch, pid: u32) -> String {
    format!(".{name}.{}-{pid}", kind.tag())
}

/// The process id in `file_name` when it is a temporary of `name` of this kind.
pub fn scratch_owner(file_name: &str, name: &str, kind: Scratch) -> Option<u32> {
    let rest = file_name
        .strip_prefix('.')?
        .strip_prefix(name)?
        .strip_prefix('.')?
        .strip_prefix(kind.tag())?
        .strip_prefix('-')?;
    if rest.is_empty() || !rest.bytes().all(|b| b.is_ascii_digit()) {
        return None;
    }
    rest.parse().ok()
}

/// Whether process `pid` exists (`kill(pid, 0)`: a process of another user counts as
/// alive). Off Linux every process counts as alive, so nothing is removed.
#[cfg(target_os = "linux")]
pub fn process_alive(pid: u32) -> bool {
    let Ok(pid) = libc::pid_t::try_from(pid) else {
        return true;
    };
    if pid <= 0 {
        return true;
    }
    // SAFETY: signal 0 sends nothing; kill only checks that the process exists.
    let rc = unsafe { libc::kill(pid, 0) };
    rc == 0 || std::io::Error::last_os_error().raw_os_error() != Some(libc::ESRCH)
}

/// Whether process `pid` exists (always true off Linux: nothing is removed).
#[cfg(not(target_os = "linux"))]
pub fn process_alive(_pid: u32) -> bool {
    true
}

/// Remove from `dir` the temporaries `.<name>.<tag>-<pid>` of `kind`, for each of `names`,
/// whose process is gone: folders with everything in them, files, never a symbolic link
/// (nor what it points to). Returns what was removed; a failure to remove is skipped (the
/// temporary is left for a later run).
pub fn remove_stale(dir: &Path, names: &[&str], kind: Scratch) -> Vec<PathBuf> {
    let Ok(entries) = std::fs::read_dir(dir) else {
        return Vec::new();
    };
    let mut removed = Vec::new();
    for entry in entries.flatten() {
        let file_name = entry.file_name();
        let Some(file_name) = file_name.to_str() else {
            continue;
        };
        let dead = names
            .iter()
            .filter_map(|n| scratch_owner(file_name, n, kind))
            .any(|pid| pid != std::process::id() && !process_alive(pid));
        if dead && remove_entry(&entry.path()) {
            removed.push(entry.path());
        }
    }
    removed.sort();
    removed
}

/// Remove a real folder (recursively) or a regular file; anything else is left alone.
fn remove_entry(path: &Path) -> bool {
    match std::fs::symlink_metadata(path) {
        Ok(m) if m.is_dir() => std::fs::remove_dir_all(path).is_ok(),
        Ok(m) if m.is_file() => std::fs::remove_file(path).is_ok(),
        _ => false,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_scratch_name_reads_back_its_owner() {
        let n = scratch_name_of("lib", Scratch::Tmp, 4242);
        assert_eq!(n, ".lib.tmp-4242");
        assert_eq!(scratch_owner(&n, "lib", Scratch::Tmp), Some(4242));
        assert_eq!(scratch_owner(&n, "lib", Scratch::Old), None);
        assert_eq!(scratch_owner(&n, "li", Scratch::Tmp), None);
    }

    #[test]
    fn names_that_only_look_like_scratch_are_not_ours() {
        for n in [
            ".lib.tmp-",
            ".lib.tmp-+12",
            ".lib.tmp-12x",
            "lib.tmp-12",
            ".lib.tmp-12.bak",
            ".lib.tmp12",
        ] {
            assert_eq!(scratch_owner(n, "lib", Scratch::Tmp), None, "{n}");
        }
    }

    #[cfg(target_os = "linux")]
    #[test]
    fn this_process_is_alive_and_a_reaped_child_is_not() {
        assert!(process_alive(std::process::id()));
        let mut child = std::process::Command::new("true").spawn().unwrap();
        let pid = child.id();
        child.wait().unwrap();
        assert!(!process_alive(pid));
    }
}
