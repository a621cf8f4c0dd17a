//! Reading the tables back (tests, later stages).

use std::path::Path;

use polars::prelude::*;

use crate::error::{Error, Result};

/// Read a Parquet file into a DataFrame.
///
/// # Errors
/// The file cannot be opened or is not valid Parquet.
pub fn read_parquet(path: &Path) -> Result<DataFrame> {
    let f = std::fs::File::open(path).map_err(|e| Error::io(path, "cannot open", e))?;
    ParquetReader::new(f)
        .finish()
        .map_err(|e| Error::io(path, "cannot read parquet", e))
}
