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
    #[error("numeric: {msg}")]
    Numeric {
        /// The step and what failed.
        msg: String,
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
