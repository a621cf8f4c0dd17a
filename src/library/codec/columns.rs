//! Column builders shared by the table writers.

use polars::prelude::*;

/// A named column from anything a `Series` can be built from.
pub(crate) fn col<T, P>(name: &str, v: T) -> Column
where
    Series: NamedFrom<T, P>,
    P: ?Sized,
{
    Column::new(name.into(), v)
}

/// A list column from per-row vectors, with an explicit inner type (so an empty table
/// keeps its schema).
pub(crate) fn list_col<T, P>(name: &str, rows: Vec<Vec<T>>, inner: DataType) -> PolarsResult<Column>
where
    Series: NamedFrom<Vec<T>, P>,
    P: ?Sized,
{
    let lc: ListChunked = rows
        .into_iter()
        .map(|v| Some(Series::new("".into(), v)))
        .collect();
    Ok(lc
        .into_series()
        .cast(&DataType::List(Box::new(inner)))?
        .with_name(name.into())
        .into())
}
