//! Every file the tool reads: the folder walk of a batch (links followed, each folder and
//! file once), the check that a BVH input is a regular file within [`MAX_BVH_BYTES`] before
//! it is opened, and the same check for the side inputs ([`SideInput`]: pipeline, body,
//! phases, contacts, points and plates files, `twopac --clip`), each kind with its own
//! size bound. Whatever cannot be read becomes an error with its reason
//! ([`InputProblem`]): per input in a batch, [`crate::ErrorKind::Input`] for a side input.

use std::collections::HashSet;
use std::io::Read;

use sha2::{Digest, Sha256};
use std::path::{Path, PathBuf};

pub use crate::error::InputProblem;
use crate::error::{Error, Result};

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
    check_bounded(path, BVH_BOUND)
}

/// A size cap: bytes, and the name of the constant that defines it.
#[derive(Debug, Clone, Copy)]
struct Bound {
    max: u64,
    cap: &'static str,
}

const BVH_BOUND: Bound = Bound {
    max: MAX_BVH_BYTES,
    cap: "MAX_BVH_BYTES",
};

impl Bound {
    fn too_large(self, bytes: u64) -> InputProblem {
        InputProblem::TooLarge {
            bytes,
            max: self.max,
            cap: self.cap,
        }
    }
}

/// [`check_input`] under `bound`.
fn check_bounded(path: &Path, bound: Bound) -> std::result::Result<u64, InputProblem> {
    let meta = std::fs::metadata(path).map_err(|e| InputProblem::from_io(path, e))?;
    check_meta(path, &meta, bound)
}

fn check_meta(
    path: &Path,
    meta: &std::fs::Metadata,
    bound: Bound,
) -> std::result::Result<u64, InputProblem> {
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
    if meta.len() > bound.max {
        return Err(bound.too_large(meta.len()));
    }
    Ok(meta.len())
}

/// Open a BVH input checked by [`check_input`] (see [`open_bounded`]).
pub(super) fn open_input(path: &Path) -> std::result::Result<std::fs::File, InputProblem> {
    open_bounded(path, BVH_BOUND)
}

/// Open an input checked under `bound`, and check the opened file again (it may have been
/// replaced in between). On Linux the file is opened non-blocking, so a FIFO put in its
/// place cannot block the open.
fn open_bounded(path: &Path, bound: Bound) -> std::result::Result<std::fs::File, InputProblem> {
    check_bounded(path, bound)?;
    let mut o = std::fs::OpenOptions::new();
    o.read(true);
    #[cfg(target_os = "linux")]
    {
        use std::os::unix::fs::OpenOptionsExt;
        o.custom_flags(libc::O_NONBLOCK);
    }
    let file = o.open(path).map_err(|e| InputProblem::from_io(path, e))?;
    let meta = file.metadata().map_err(InputProblem::Other)?;
    check_meta(path, &meta, bound)?;
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

/// Largest pipeline or body file read (TOML), bytes (1 MiB). These files list a few dozen
/// keys and landmark names (those in `pipelines/` and `fixtures/body/` are under 1 kB),
/// and the TOML parser holds several bytes of memory per file byte, so a larger file is
/// no configuration: it is refused before it is read (a 3 GB sparse file once asked for
/// 3 GB at once).
pub const MAX_TOML_BYTES: u64 = 1 << 20;

/// Largest phases or contacts file read (JSON), bytes (64 MiB). The files in
/// `fixtures/twopac/` are under 5 kB; a phases file within its own limits
/// (`twopac::trajectory::MAX_PHASES`, `twopac::equilibrium::MAX_CONTACTS`) and with
/// ordinary polytopes stays far below this. The parsed values take about as much memory
/// as the text, which is read whole.
pub const MAX_JSON_BYTES: u64 = 64 << 20;

/// Largest `--points` table read (Parquet), bytes (256 MiB). Its limit of
/// `twopac::equilibrium::MAX_COM_STATES` rows of six float64 columns is 48 MB
/// uncompressed; the rest leaves room for other columns and less compact encodings, and
/// bounds what the reader decodes (every column is read).
pub const MAX_POINTS_BYTES: u64 = 256 << 20;

/// Largest force-plate file read (CSV), bytes (256 MiB). Two plates at 1 kHz take about
/// 120 bytes per row (17 columns), so this is over half an hour of one recording, longer
/// than any clip it goes with (the force-plate recordings the tests use are under 100 kB).
/// The text is read whole and its samples take 32 bytes per row.
pub const MAX_PLATES_BYTES: u64 = 256 << 20;

/// Largest masses table read (CSV), bytes (64 MiB): a row per clip of a million-clip
/// collection at about 40 bytes a row, read whole ([`crate::ingest::masses::MAX_MASS_ROWS`]).
pub const MAX_MASSES_BYTES: u64 = 64 << 20;

/// A file the tool reads besides the BVH inputs of a batch. Every kind is read through
/// [`open_side_input`] with the rules of a BVH input: regular files only (a FIFO, socket
/// or device is never opened), at most the kind's size bound ([`SideInput::max_bytes`]),
/// and an unreadable file is an error naming it and the OS reason.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[non_exhaustive]
pub enum SideInput {
    /// `run`'s pipeline file (TOML, [`MAX_TOML_BYTES`]).
    Pipeline,
    /// A body file: `--body` or a pipeline's `body` (TOML, [`MAX_TOML_BYTES`]).
    Body,
    /// `twopac --phases` (JSON, [`MAX_JSON_BYTES`]).
    Phases,
    /// `equilibrium --contacts` (JSON, [`MAX_JSON_BYTES`]).
    Contacts,
    /// `equilibrium --points` (Parquet, [`MAX_POINTS_BYTES`]).
    Points,
    /// `plot stance --plates` (CSV, [`MAX_PLATES_BYTES`]).
    Plates,
    /// `twopac --clip` (BVH, [`MAX_BVH_BYTES`] as every clip).
    Clip,
    /// `--masses` or a pipeline's `masses` (CSV, [`MAX_MASSES_BYTES`]).
    Masses,
}

impl SideInput {
    /// What the file is, for messages (`body file`).
    pub fn what(self) -> &'static str {
        match self {
            SideInput::Pipeline => "pipeline file",
            SideInput::Body => "body file",
            SideInput::Phases => "phases file",
            SideInput::Contacts => "contacts file",
            SideInput::Points => "points table",
            SideInput::Plates => "plates file",
            SideInput::Clip => "clip",
            SideInput::Masses => "masses table",
        }
    }

    /// The largest file of this kind read, bytes.
    pub fn max_bytes(self) -> u64 {
        self.bound().max
    }

    fn bound(self) -> Bound {
        let (max, cap) = match self {
            SideInput::Pipeline | SideInput::Body => (MAX_TOML_BYTES, "MAX_TOML_BYTES"),
            SideInput::Phases | SideInput::Contacts => (MAX_JSON_BYTES, "MAX_JSON_BYTES"),
            SideInput::Points => (MAX_POINTS_BYTES, "MAX_POINTS_BYTES"),
            SideInput::Plates => (MAX_PLATES_BYTES, "MAX_PLATES_BYTES"),
            SideInput::Masses => (MAX_MASSES_BYTES, "MAX_MASSES_BYTES"),
            SideInput::Clip => return BVH_BOUND,
        };
        Bound { max, cap }
    }

    fn error(self, path: &Path, problem: InputProblem) -> Error {
        Error::input(path, self.what(), problem)
    }
}

/// A side input opened by [`open_side_input`]: reads stop one byte past its kind's bound,
/// so a file that grows after it was checked is caught by [`SideFile::finish`].
#[derive(Debug)]
pub struct SideFile {
    path: PathBuf,
    kind: SideInput,
    inner: std::io::Take<std::fs::File>,
}

impl Read for SideFile {
    fn read(&mut self, buf: &mut [u8]) -> std::io::Result<usize> {
        self.inner.read(buf)
    }
}

impl SideFile {
    /// After reading to the end: an error when more than the kind's bound was read (the
    /// file grew after it was opened).
    ///
    /// # Errors
    /// [`InputProblem::TooLarge`].
    pub fn finish(&self) -> Result<()> {
        if self.inner.limit() == 0 {
            let bound = self.kind.bound();
            return Err(self.kind.error(&self.path, bound.too_large(bound.max + 1)));
        }
        Ok(())
    }

    /// The opened file, for readers that seek (Parquet); its size was checked on the
    /// opened file.
    pub fn into_file(self) -> std::fs::File {
        self.inner.into_inner()
    }
}

/// Open the side input at `path` of kind `kind`, as a BVH input is opened: it must be a
/// regular file (links followed; a FIFO, socket or device is never opened, so nothing
/// blocks) of at most `kind.max_bytes()`, checked before the open and again on the opened
/// file. The one way every side input is opened.
///
/// # Errors
/// [`crate::ErrorKind::Input`] naming the file, what it was read as, and why it cannot be
/// read (with the OS reason).
pub fn open_side_input(path: &Path, kind: SideInput) -> Result<SideFile> {
    let bound = kind.bound();
    let file = open_bounded(path, bound).map_err(|p| kind.error(path, p))?;
    Ok(SideFile {
        path: path.to_path_buf(),
        kind,
        inner: file.take(bound.max + 1),
    })
}

/// Reads a UTF-8 side input (pipeline, body, phases, contacts, plates file) whole, through
/// [`open_side_input`].
///
/// # Errors
/// As [`open_side_input`]; a read error or text that is not UTF-8 (as
/// [`InputProblem::Other`]).
pub fn read_side_text(path: &Path, kind: SideInput) -> Result<String> {
    let mut f = open_side_input(path, kind)?;
    let mut bytes = Vec::new();
    f.read_to_end(&mut bytes)
        .map_err(|e| kind.error(path, InputProblem::Other(e)))?;
    f.finish()?;
    String::from_utf8(bytes).map_err(|e| {
        let e = std::io::Error::new(std::io::ErrorKind::InvalidData, e);
        kind.error(path, InputProblem::Other(e))
    })
}

/// Parses a BVH side input (`twopac --clip`) through [`open_side_input`].
///
/// # Errors
/// As [`open_side_input`]; as [`crate::bvh::parse_reader`], with the path.
pub fn read_side_bvh(path: &Path) -> Result<crate::bvh::Bvh> {
    let mut f = open_side_input(path, SideInput::Clip)?;
    let parsed = crate::bvh::parse_reader(&mut f).map_err(|e| e.with_path(path));
    f.finish()?;
    parsed
}

/// A BVH input that grew past [`MAX_BVH_BYTES`] while it was read.
pub(super) fn bvh_too_large(bytes: u64) -> InputProblem {
    BVH_BOUND.too_large(bytes)
}

/// SHA-256 of an input's bytes, hex (`None` when it is not a readable regular file of at
/// most [`MAX_BVH_BYTES`]).
pub fn file_sha256(path: &Path) -> Option<String> {
    let f = open_input(path).ok()?;
    let mut h = Sha256::new();
    let n = std::io::copy(&mut f.take(MAX_BVH_BYTES + 1), &mut h).ok()?;
    (n <= MAX_BVH_BYTES).then(|| hex(&h.finalize()))
}

pub(crate) fn hex(bytes: &[u8]) -> String {
    bytes.iter().map(|b| format!("{b:02x}")).collect()
}
