//! The library's one error type: `Error { kind }` with a non-exhaustive [`ErrorKind`].
//!
//! Every variant says where the failure happened (file, line, field, column) so that a
//! batch run can report it per clip and go on with the rest.

use std::path::PathBuf;

/// Result alias used across the library.
pub type Result<T> = std::result::Result<T, Error>;

/// A library error: what went wrong and where. Display and `source()` are those of the
/// kind, so the cause of an I/O error (the OS reason) stays in the chain that `{:#}` prints.
#[derive(Debug, thiserror::Error)]
#[error(transparent)]
pub struct Error {
    /// What went wrong, with its location.
    pub kind: ErrorKind,
}

/// The kinds of library error.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum ErrorKind {
    /// A BVH file is malformed. `line` is 1-based; 0 when the error concerns the whole file.
    #[error("{}: line {line}: {msg}", path.as_ref().map(|p| p.display().to_string()).unwrap_or_else(|| "<bvh>".into()))]
    Bvh {
        /// The file, when known.
        path: Option<PathBuf>,
        /// 1-based line number (0: whole file).
        line: usize,
        /// What is wrong.
        msg: String,
    },
    /// The skeleton could not be mapped onto body landmarks.
    #[error("skeleton: {msg}")]
    Skeleton {
        /// What is missing or inconsistent.
        msg: String,
    },
    /// A configuration file or value is invalid.
    #[error("{}{}: {msg}", path.as_ref().map(|p| p.display().to_string()).unwrap_or_else(|| "<config>".into()), line.map(|l| format!(":{l}")).unwrap_or_default())]
    Config {
        /// The file, when known.
        path: Option<PathBuf>,
        /// 1-based line number, when known.
        line: Option<usize>,
        /// What is wrong.
        msg: String,
    },
    /// Input arrays have inconsistent sizes (a programmer error at a public entry point).
    #[error("argument {name}: expected {expected}, found {found}")]
    Shape {
        /// The argument.
        name: &'static str,
        /// Expected size.
        expected: usize,
        /// Size found.
        found: usize,
    },
    /// A library table lacks a column, has it with the wrong type, or holds a null or
    /// invalid value where the schema forbids one.
    #[error("{}: column '{column}'{}: {msg}", path.display(), row.map(|r| format!(", row {r}")).unwrap_or_default())]
    Column {
        /// The table file.
        path: PathBuf,
        /// The column.
        column: String,
        /// 0-based row, when one value is at fault.
        row: Option<usize>,
        /// What is wrong.
        msg: String,
    },
    /// A numerical step failed (a solver, a fit); `msg` names the step and the cause.
    /// (An iteration that stops at its cap is typed where one exists: the static-region
    /// LPs' [`crate::twopac::TwopacError::NotConverged`]; the editor's pose iteration
    /// reports its unconverged frames in the plan's `converged` column instead of failing.)
    #[error("numeric: {msg}")]
    Numeric {
        /// The step and what failed.
        msg: String,
    },
    /// The Savitzky–Golay smoothing filter of a clip cannot be built (for example a frame
    /// time so short that the window exceeds `math::savgol::MAX_SAVGOL_WINDOW`).
    #[error("smoothing window of {window} frames{}: {msg}", frame_time_s.map(|dt| format!(" ({:.6} s at frame time {dt} s)", dt * *window as f64)).unwrap_or_default())]
    Smoothing {
        /// The clip's frame time, s, when the window came from it.
        frame_time_s: Option<f64>,
        /// The window, frames.
        window: usize,
        /// What is wrong.
        msg: String,
    },
    /// A computed position or derivative is NaN or infinite (OFFSETs or channel values so
    /// large that f64 overflows).
    #[error("non-finite {quantity}{}{}: offsets or channel values too large for f64", joint.as_ref().map(|j| format!(" of '{j}'")).unwrap_or_default(), frame.map(|f| format!(" at frame {f}")).unwrap_or_default())]
    NonFinite {
        /// What overflowed (`position`, `COM`, `leg length`, …).
        quantity: String,
        /// The first bad frame (0-based file row), when per frame.
        frame: Option<usize>,
        /// The joint or point concerned, when one is.
        joint: Option<String>,
    },
    /// A columnar (Parquet) file could not be written or read.
    #[error("{}: {msg}", path.display())]
    Io {
        /// The file.
        path: PathBuf,
        /// What failed.
        msg: String,
        /// The underlying cause.
        #[source]
        source: Option<Box<dyn std::error::Error + Send + Sync>>,
    },
    /// An option or value is malformed or out of its range.
    #[error("{field}: {msg}")]
    Invalid {
        /// The option, key or path (`--speeds`, `mu`).
        field: String,
        /// What is wrong, with the value found.
        msg: String,
    },
    /// A file the tool reads cannot be read at all (a side input: a pipeline, body,
    /// phases, contacts, points or plates file, `twopac --clip`): `problem` says why,
    /// with the OS reason, in the error's chain (`{:#}`).
    #[error("{}: cannot read {what}", path.display())]
    Input {
        /// The file.
        path: PathBuf,
        /// What the file is (`body file`, `--points table`).
        what: &'static str,
        /// Why it cannot be read.
        #[source]
        problem: InputProblem,
    },
    /// An input asks for more work or memory than a documented work cap allows; checked
    /// before the work starts (README "Work caps").
    #[error("{field}: {found} {what}, more than the limit of {max} ({cap})")]
    Cap {
        /// The option, key or path that asks for it (`--speeds`, `[queries] map_heights`).
        field: String,
        /// What is counted (`grid values`, `rows`).
        what: &'static str,
        /// The amount asked for (formatted: it may not fit an integer).
        found: String,
        /// The cap.
        max: usize,
        /// The name of the constant that defines the cap (`MAX_AXIS_VALUES`).
        cap: &'static str,
    },
    /// A library was replaced (rebuilt) while a command read it, twice
    /// ([`crate::library::storage::generation`]): what was read may mix two builds, so nothing
    /// was answered.
    #[error("library {} changed while it was read (a build replaced it); retry", lib.display())]
    Changed {
        /// The library folder.
        lib: PathBuf,
    },
}

impl Error {
    /// A failed numerical step (solver, fit).
    pub fn numeric(msg: impl Into<String>) -> Self {
        Error {
            kind: ErrorKind::Numeric { msg: msg.into() },
        }
    }

    /// A BVH error at a line, without a path yet (see [`Error::with_path`]).
    pub fn bvh(line: usize, msg: impl Into<String>) -> Self {
        ErrorKind::Bvh {
            path: None,
            line,
            msg: msg.into(),
        }
        .into()
    }

    /// A skeleton-mapping error.
    pub fn skeleton(msg: impl Into<String>) -> Self {
        ErrorKind::Skeleton { msg: msg.into() }.into()
    }

    /// A configuration error.
    pub fn config(path: Option<PathBuf>, line: Option<usize>, msg: impl Into<String>) -> Self {
        ErrorKind::Config {
            path,
            line,
            msg: msg.into(),
        }
        .into()
    }

    /// An I/O error on a file, keeping its cause.
    pub fn io(
        path: impl Into<PathBuf>,
        msg: impl Into<String>,
        source: impl std::error::Error + Send + Sync + 'static,
    ) -> Self {
        ErrorKind::Io {
            path: path.into(),
            msg: msg.into(),
            source: Some(Box::new(source)),
        }
        .into()
    }

    /// A non-finite-value error (see [`ErrorKind::NonFinite`]).
    pub fn non_finite(quantity: &str, frame: Option<usize>, joint: Option<String>) -> Self {
        ErrorKind::NonFinite {
            quantity: quantity.to_string(),
            frame,
            joint,
        }
        .into()
    }

    /// A column error in a library table.
    pub fn column(
        path: impl Into<PathBuf>,
        column: &str,
        row: Option<usize>,
        msg: impl Into<String>,
    ) -> Self {
        ErrorKind::Column {
            path: path.into(),
            column: column.to_string(),
            row,
            msg: msg.into(),
        }
        .into()
    }

    /// A malformed or out-of-range value of `field`.
    pub fn invalid(field: impl Into<String>, msg: impl Into<String>) -> Self {
        ErrorKind::Invalid {
            field: field.into(),
            msg: msg.into(),
        }
        .into()
    }

    /// A work-cap error: `found` of `what` asked for by `field`, above `max` (the constant
    /// named `cap`).
    pub fn cap(
        field: impl Into<String>,
        what: &'static str,
        found: f64,
        max: usize,
        cap: &'static str,
    ) -> Self {
        ErrorKind::Cap {
            field: field.into(),
            what,
            found: count_text(found),
            max,
            cap,
        }
        .into()
    }

    /// An input error: the file at `path`, read as `what`, cannot be read because of
    /// `problem`.
    pub fn input(path: impl Into<PathBuf>, what: &'static str, problem: InputProblem) -> Self {
        ErrorKind::Input {
            path: path.into(),
            what,
            problem,
        }
        .into()
    }

    /// Attach a file path to a BVH or configuration error that has none.
    pub fn with_path(mut self, p: &std::path::Path) -> Self {
        match &mut self.kind {
            ErrorKind::Bvh { path, .. } | ErrorKind::Config { path, .. } if path.is_none() => {
                *path = Some(p.to_path_buf())
            }
            _ => {}
        }
        self
    }
}

/// Why an input cannot be read; every variant that comes from the system keeps its
/// error (the OS reason). Found by `pipeline::engine::inputs` (the only place that inspects
/// inputs), for BVH clips and side inputs alike.
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
    /// Larger than the cap of its kind (`MAX_BVH_BYTES` for a clip, README "Inputs").
    #[error("{bytes} bytes is more than the limit of {max} bytes ({cap})")]
    TooLarge {
        /// Size of the file, bytes (or bytes read before the cap was passed).
        bytes: u64,
        /// The cap, bytes.
        max: u64,
        /// The name of the constant that defines the cap (`MAX_BVH_BYTES`).
        cap: &'static str,
    },
    /// Any other failure to inspect, open or read.
    #[error("cannot read: {0}")]
    Other(std::io::Error),
}

/// Longest excerpt of raw input echoed in an error message, characters; longer excerpts
/// are cut there and end in `…`.
pub const MAX_ECHO_CHARS: usize = 80;

/// Raw input made safe to print in an error message: control characters (ANSI escapes,
/// NUL, …) and bidirectional-text controls are written as `\x1b` or `\u{202e}`, and the
/// text is cut after [`MAX_ECHO_CHARS`] characters with `…`.
///
/// # Examples
/// ```
/// assert_eq!(stancelib::error::echo("a\x1b[31mb"), "a\\x1b[31mb");
/// assert_eq!(stancelib::error::echo(&"x".repeat(100)).chars().count(), 81);
/// ```
pub fn echo(raw: &str) -> String {
    match raw.char_indices().nth(MAX_ECHO_CHARS) {
        Some((cut, _)) => escape(&raw[..cut]) + "…",
        None => escape(raw),
    }
}

/// Text read from data (a clip name, a character id, a manifest value) made safe to print
/// whole: every control character (ESC, newline, NUL, DEL, C1) and bidirectional-text
/// control written as `\x1b` or `\u{202e}`, the rest as it is (see [`echo`] for input
/// echoed in an error, which is also cut).
///
/// # Examples
/// ```
/// assert_eq!(stancelib::error::escape("a\nb\x1b[2J"), "a\\x0ab\\x1b[2J");
/// ```
pub fn escape(raw: &str) -> String {
    escape_but(raw, &[])
}

/// [`escape`], except the characters of `keep` (the line breaks of a multi-line report).
pub fn escape_but(raw: &str, keep: &[char]) -> String {
    let mut out = String::with_capacity(raw.len());
    for c in raw.chars() {
        let bidi = matches!(c, '\u{200b}'..='\u{200f}' | '\u{202a}'..='\u{202e}' | '\u{2066}'..='\u{2069}' | '\u{feff}');
        if keep.contains(&c) {
            out.push(c);
        } else if c.is_control() && (c as u32) < 0x100 {
            out.push_str(&format!("\\x{:02x}", c as u32));
        } else if c.is_control() || bidi {
            out.push_str(&format!("\\u{{{:x}}}", c as u32));
        } else {
            out.push(c);
        }
    }
    out
}

/// A count for a message: an integer while it is one, else in scientific notation.
pub fn count_text(n: f64) -> String {
    if n.is_finite() && n.abs() < 1e15 {
        format!("{n:.0}")
    } else {
        format!("{n:.3e}")
    }
}

impl From<ErrorKind> for Error {
    fn from(kind: ErrorKind) -> Self {
        Error { kind }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn an_io_error_keeps_the_os_reason_in_its_chain() {
        let os = std::io::Error::from_raw_os_error(2);
        let reason = os.to_string();
        let e = Error::io("/x/lib", "cannot create folder", os);
        assert_eq!(e.to_string(), "/x/lib: cannot create folder");
        let chain = format!("{:#}", anyhow::Error::new(e));
        assert!(chain.ends_with(&reason), "{chain}");
    }
}
