//! Inputs of a batch: the folder walk (links followed, each folder and file once) and the
//! check that an input is a regular file within [`MAX_BVH_BYTES`] before it is opened.
//! Whatever cannot be read becomes a per-input error with its reason ([`InputProblem`]).

use std::collections::HashSet;
use std::path::{Path, PathBuf};

use crate::error::Result;

/// Largest BVH file read, bytes (1 GiB). The biggest clips in common use are a few MB
/// (CMU: about 90 kB per second of 120 Hz capture of a 31-joint skeleton, so 1 GiB is
/// over three hours of one take), and ingest holds two to three bytes of memory per file
/// byte, so a larger file is not a clip to load whole; it is a per-input error.
pub const MAX_BVH_BYTES: u64 = 1 << 30;

/// Expand files and folders into a sorted list of inputs: folders are searched
/// recursively for `*.bvh` (case-insensitive), following folder links but entering each
/// folder (device, inode) once, so link cycles end. The same file reached twice (by links,
/// hard links or two arguments) is listed once, under its first path in sorted order.
///
/// Anything that is not a readable regular file stays in the list (an argument that does
/// not exist, a dangling link, a FIFO, a folder that cannot be listed): [`super::batch::ingest_file`]
/// turns it into a per-input error ([`check_input`] says why).
///
/// # Errors
/// None at present: every problem is one input's (kept as a `Result` for callers).
pub fn discover(inputs: &[PathBuf]) -> Result<Vec<PathBuf>> {
    let mut roots = inputs.to_vec();
    roots.sort();
    roots.dedup();
    let mut walk = Walk::default();
    for p in &roots {
        match std::fs::metadata(p) {
            Ok(m) if m.is_dir() => walk.folder(p, &m),
            _ => walk.found.push(p.clone()),
        }
    }
    Ok(once_per_file(walk.found))
}

/// The (device, inode) of a file or folder (0 off Unix: no deduplication there).
fn file_id(m: &std::fs::Metadata) -> (u64, u64) {
    #[cfg(unix)]
    {
        use std::os::unix::fs::MetadataExt;
        (m.dev(), m.ino())
    }
    #[cfg(not(unix))]
    {
        let _ = m;
        (0, 0)
    }
}

/// A folder walk: the folders entered and the inputs found.
#[derive(Default)]
struct Walk {
    seen: HashSet<(u64, u64)>,
    found: Vec<PathBuf>,
}

impl Walk {
    /// Search `dir` (whose metadata is `meta`) unless it was entered before.
    fn folder(&mut self, dir: &Path, meta: &std::fs::Metadata) {
        if cfg!(unix) && !self.seen.insert(file_id(meta)) {
            return;
        }
        let mut entries: Vec<PathBuf> = match std::fs::read_dir(dir) {
            Ok(rd) => match rd.map(|e| e.map(|e| e.path())).collect() {
                Ok(v) => v,
                Err(_) => return self.found.push(dir.to_path_buf()),
            },
            // Listed as an input: check_input reports why it cannot be read.
            Err(_) => return self.found.push(dir.to_path_buf()),
        };
        entries.sort();
        for p in entries {
            let named_bvh = p.extension().is_some_and(|e| e.eq_ignore_ascii_case("bvh"));
            match std::fs::metadata(&p) {
                Ok(m) if m.is_dir() => self.folder(&p, &m),
                _ if named_bvh => self.found.push(p),
                _ => {}
            }
        }
    }
}

/// Sorted, each path once and each file (device, inode) once; inputs without metadata
/// are kept (they are errors, reported per input).
fn once_per_file(mut found: Vec<PathBuf>) -> Vec<PathBuf> {
    found.sort();
    found.dedup();
    let mut seen = HashSet::new();
    found.retain(|p| match std::fs::metadata(p) {
        Ok(m) if cfg!(unix) && m.is_file() => seen.insert(file_id(&m)),
        _ => true,
    });
    found
}

/// Why an input cannot be read; every variant that comes from the system keeps its
/// error (the OS reason).
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum InputProblem {
    /// Nothing at that path.
    #[error("not found: {0}")]
    NotFound(std::io::Error),
    /// A symbolic link whose target does not exist.
    #[error("dangling symbolic link to {}: {err}", target.display())]
    DanglingLink {
        /// Where the link points.
        target: PathBuf,
        /// The system's error on following it.
        err: std::io::Error,
    },
    /// Too many levels of symbolic links.
    #[error("symbolic link loop: {0}")]
    LinkLoop(std::io::Error),
    /// The path or a folder on it is not accessible.
    #[error("permission denied: {0}")]
    PermissionDenied(std::io::Error),
    /// A folder that cannot be listed.
    #[error("folder cannot be listed: {0}")]
    UnlistableFolder(std::io::Error),
    /// A folder where a file is expected (listed, but gone before it was read).
    #[error("is a folder, not a file")]
    Folder,
    /// A FIFO, socket or device (never opened: reading one could block or never end).
    #[error("is a {}{kind}, not a regular file: only regular files are read", if *via_link { "symbolic link to a " } else { "" })]
    NotRegular {
        /// What it is.
        kind: &'static str,
        /// Reached through a symbolic link.
        via_link: bool,
    },
    /// Larger than [`MAX_BVH_BYTES`].
    #[error("{bytes} bytes is more than the limit of {MAX_BVH_BYTES} bytes (MAX_BVH_BYTES)")]
    TooLarge {
        /// Size of the file, bytes (or bytes read before the limit was passed).
        bytes: u64,
    },
    /// Any other failure to inspect, open or read.
    #[error("cannot read: {0}")]
    Other(std::io::Error),
}

impl InputProblem {
    /// The problem behind an error of the system on `path`.
    fn from_io(path: &Path, err: std::io::Error) -> InputProblem {
        let is_link = std::fs::symlink_metadata(path).is_ok_and(|m| m.file_type().is_symlink());
        match err.kind() {
            std::io::ErrorKind::NotFound if is_link => InputProblem::DanglingLink {
                target: std::fs::read_link(path).unwrap_or_default(),
                err,
            },
            std::io::ErrorKind::NotFound => InputProblem::NotFound(err),
            std::io::ErrorKind::PermissionDenied => InputProblem::PermissionDenied(err),
            _ if is_link && is_loop(&err) => InputProblem::LinkLoop(err),
            _ => InputProblem::Other(err),
        }
    }
}

#[cfg(target_os = "linux")]
fn is_loop(err: &std::io::Error) -> bool {
    err.raw_os_error() == Some(libc::ELOOP)
}

#[cfg(not(target_os = "linux"))]
fn is_loop(_: &std::io::Error) -> bool {
    false
}

/// What kind of file `t` is, in words.
pub fn file_kind(t: &std::fs::FileType) -> &'static str {
    #[cfg(unix)]
    {
        use std::os::unix::fs::FileTypeExt;
        if t.is_fifo() {
            return "FIFO (named pipe)";
        }
        if t.is_socket() {
            return "socket";
        }
        if t.is_char_device() {
            return "character device";
        }
        if t.is_block_device() {
            return "block device";
        }
    }
    if t.is_symlink() {
        "symbolic link"
    } else if t.is_dir() {
        "folder"
    } else if t.is_file() {
        "regular file"
    } else {
        "special file"
    }
}

/// Check an input before it is opened (links followed): a regular file of at most
/// [`MAX_BVH_BYTES`]; its size in bytes.
///
/// # Errors
/// Why it cannot be read.
pub fn check_input(path: &Path) -> std::result::Result<u64, InputProblem> {
    let meta = std::fs::metadata(path).map_err(|e| InputProblem::from_io(path, e))?;
    check_meta(path, &meta)
}

fn check_meta(path: &Path, meta: &std::fs::Metadata) -> std::result::Result<u64, InputProblem> {
    if meta.is_dir() {
        return Err(match std::fs::read_dir(path) {
            Err(e) => InputProblem::UnlistableFolder(e),
            Ok(_) => InputProblem::Folder,
        });
    }
    if !meta.is_file() {
        return Err(InputProblem::NotRegular {
            kind: file_kind(&meta.file_type()),
            via_link: std::fs::symlink_metadata(path).is_ok_and(|m| m.file_type().is_symlink()),
        });
    }
    if meta.len() > MAX_BVH_BYTES {
        return Err(InputProblem::TooLarge { bytes: meta.len() });
    }
    Ok(meta.len())
}

/// Open an input checked by [`check_input`], and check the opened file again (it may
/// have been replaced in between). On Linux the file is opened non-blocking, so a FIFO
/// put in its place cannot block the open.
pub(super) fn open_input(path: &Path) -> std::result::Result<std::fs::File, InputProblem> {
    check_input(path)?;
    let mut o = std::fs::OpenOptions::new();
    o.read(true);
    #[cfg(target_os = "linux")]
    {
        use std::os::unix::fs::OpenOptionsExt;
        o.custom_flags(libc::O_NONBLOCK);
    }
    let file = o.open(path).map_err(|e| InputProblem::from_io(path, e))?;
    let meta = file.metadata().map_err(InputProblem::Other)?;
    check_meta(path, &meta)?;
    Ok(file)
}

/// Inputs listed by name when none can be read (the rest are counted).
pub const MAX_LISTED_PROBLEMS: usize = 20;

/// When none of `files` can be read (nothing to do): one line per input saying why (at
/// most [`MAX_LISTED_PROBLEMS`], then a count). `None` when at least one can.
pub fn none_readable(files: &[PathBuf]) -> Option<String> {
    let problems: Vec<String> = files
        .iter()
        .map_while(|f| {
            check_input(f)
                .err()
                .map(|p| format!("{}: {p}", f.display()))
        })
        .collect();
    if files.is_empty() || problems.len() < files.len() {
        return None;
    }
    let mut text = problems[..problems.len().min(MAX_LISTED_PROBLEMS)].join("\n");
    if problems.len() > MAX_LISTED_PROBLEMS {
        text.push_str(&format!(
            "\n… and {} more",
            problems.len() - MAX_LISTED_PROBLEMS
        ));
    }
    Some(text)
}

/// Reads a UTF-8 text file (a phases or contacts file), naming it on failure.
///
/// # Errors
/// A missing or unreadable file, or one that is not UTF-8.
pub fn read_text(path: &Path) -> anyhow::Result<String> {
    use anyhow::Context;
    std::fs::read_to_string(path).with_context(|| format!("cannot read {}", path.display()))
}

/// `(folder, file name)` of an output file path given as `--out`.
///
/// # Errors
/// A path that does not end in a UTF-8 file name.
pub fn split_out(out: &Path) -> anyhow::Result<(&Path, String)> {
    use anyhow::Context;
    let name = out
        .file_name()
        .and_then(|n| n.to_str())
        .with_context(|| format!("--out {}: not a file name", out.display()))?
        .to_string();
    let dir = match out.parent() {
        Some(p) if !p.as_os_str().is_empty() => p,
        _ => Path::new("."),
    };
    Ok((dir, name))
}
