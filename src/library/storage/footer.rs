//! Writing a Parquet footer from the row groups' entries kept in scratch streams: the
//! thrift compact encoding of `FileMetaData`, list by list, with byte counts.

use std::io::{Read, Write};

use polars_parquet_format::thrift::protocol::{
    TCompactOutputProtocol, TFieldIdentifier, TListIdentifier, TOutputProtocol, TStructIdentifier,
    TType,
};

use polars_parquet_format::{FileMetaData, RowGroup};

/// A writer that counts the bytes written through it.
pub(super) struct Counted<'a, W: Write> {
    pub(super) inner: &'a mut W,
    pub(super) bytes: usize,
}

impl<W: Write> Write for Counted<'_, W> {
    fn write(&mut self, buf: &[u8]) -> std::io::Result<usize> {
        let n = self.inner.write(buf)?;
        self.bytes += n;
        Ok(n)
    }

    fn flush(&mut self) -> std::io::Result<()> {
        self.inner.flush()
    }
}

/// A reader that counts the bytes read through it.
pub(super) struct CountedRead<'a, R: Read> {
    pub(super) inner: &'a mut R,
    pub(super) bytes: usize,
}

impl<R: Read> Read for CountedRead<'_, R> {
    fn read(&mut self, buf: &mut [u8]) -> std::io::Result<usize> {
        let n = self.inner.read(buf)?;
        self.bytes += n;
        Ok(n)
    }
}

pub(super) fn len_i32(n: usize) -> std::io::Result<i32> {
    i32::try_from(n).map_err(|_| malformed(format!("{n} bytes: over a thrift length")))
}

/// List field `id` of `n` structs, each written by `item(p, k)`, as the generated thrift
/// code writes a list field.
pub(super) fn write_struct_list<P: TOutputProtocol>(
    p: &mut P,
    name: &str,
    id: i16,
    n: usize,
    mut item: impl FnMut(&mut P, usize) -> std::io::Result<usize>,
) -> std::io::Result<()> {
    let size = u32::try_from(n).map_err(|_| malformed("list too long"))?;
    p.write_field_begin(&TFieldIdentifier::new(name, TType::List, id))
        .map_err(thrift_err)?;
    p.write_list_begin(&TListIdentifier::new(TType::Struct, size))
        .map_err(thrift_err)?;
    for k in 0..n {
        item(p, k)?;
    }
    p.write_list_end().map_err(thrift_err)?;
    p.write_field_end().map_err(thrift_err)?;
    Ok(())
}

/// `footer` as polars writes it (`FileMetaData::write_to_out_protocol`, field for field),
/// its `groups` row groups taken one at a time from `next_group` instead of its own list.
pub(super) fn write_footer(
    out: &mut impl Write,
    footer: &FileMetaData,
    groups: usize,
    next_group: &mut dyn FnMut() -> std::io::Result<RowGroup>,
) -> std::io::Result<()> {
    let e = thrift_err;
    let mut p = TCompactOutputProtocol::new(out);
    p.write_struct_begin(&TStructIdentifier::new("FileMetaData"))
        .map_err(e)?;
    p.write_field_begin(&TFieldIdentifier::new("version", TType::I32, 1))
        .map_err(e)?;
    p.write_i32(footer.version).map_err(e)?;
    p.write_field_end().map_err(e)?;
    let schema = &footer.schema;
    write_struct_list(&mut p, "schema", 2, schema.len(), |p, k| {
        schema[k].write_to_out_protocol(p).map_err(e)
    })?;
    p.write_field_begin(&TFieldIdentifier::new("num_rows", TType::I64, 3))
        .map_err(e)?;
    p.write_i64(footer.num_rows).map_err(e)?;
    p.write_field_end().map_err(e)?;
    write_struct_list(&mut p, "row_groups", 4, groups, |p, _| {
        next_group()?.write_to_out_protocol(p).map_err(e)
    })?;
    // The fields after the groups, written by a copy of the footer without groups, would
    // restart the field numbering; they are written here in polars' order instead.
    if let Some(kv) = &footer.key_value_metadata {
        write_struct_list(&mut p, "key_value_metadata", 5, kv.len(), |p, k| {
            kv[k].write_to_out_protocol(p).map_err(e)
        })?;
    }
    if let Some(by) = &footer.created_by {
        p.write_field_begin(&TFieldIdentifier::new("created_by", TType::String, 6))
            .map_err(e)?;
        p.write_string(by).map_err(e)?;
        p.write_field_end().map_err(e)?;
    }
    if let Some(orders) = &footer.column_orders {
        write_struct_list(&mut p, "column_orders", 7, orders.len(), |p, k| {
            orders[k].write_to_out_protocol(p).map_err(e)
        })?;
    }
    if footer.encryption_algorithm.is_some() || footer.footer_signing_key_metadata.is_some() {
        return Err(malformed("encrypted footers are not supported"));
    }
    p.write_field_stop().map_err(e)?;
    p.write_struct_end().map_err(e)?;
    Ok(())
}

/// What a malformed file or buffer is reported as.
pub(super) fn malformed(why: impl Into<String>) -> std::io::Error {
    std::io::Error::new(std::io::ErrorKind::InvalidData, why.into())
}

pub(super) fn thrift_err(e: polars_parquet_format::thrift::Error) -> std::io::Error {
    malformed(format!("parquet metadata: {e}"))
}
