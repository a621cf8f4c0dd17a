use super::*;
use crate::library::storage::group_reader::GroupFileReader;
use polars::prelude::*;

/// A table of `n` rows: strings (dictionary pages), integers, floats, nulls, lists.
fn table(n: usize) -> DataFrame {
    let mut df = df! {
        "clip" => (0..n).map(|i| format!("clip_{:03}", i / 700)).collect::<Vec<_>>(),
        "frame" => (0..n as i64).collect::<Vec<_>>(),
        "x" => (0..n).map(|i| (i as f64 * 0.37).sin()).collect::<Vec<_>>(),
        "z" => (0..n).map(|i| (i % 5 != 0).then_some(i as f64)).collect::<Vec<_>>(),
    }
    .unwrap();
    let lists: Vec<Series> = (0..n)
        .map(|i| Series::new("".into(), vec![i as f64; i % 3]))
        .collect();
    df.with_column(Series::new("l".into(), lists).into_column())
        .unwrap();
    df
}

fn schema_of(
    df: &DataFrame,
) -> (
    GroupSchema,
    Vec<(
        polars_parquet::write::ParquetType,
        Vec<polars_parquet::write::Encoding>,
    )>,
) {
    super::super::stream::group_schema(df.schema()).unwrap()
}

fn pages(
    df: &DataFrame,
    columns: &[(
        polars_parquet::write::ParquetType,
        Vec<polars_parquet::write::Encoding>,
    )],
) -> Vec<Vec<CompressedPage>> {
    super::super::stream::encode_group(df.columns(), columns).unwrap()
}

/// Groups appended one by one give the bytes polars' own writer gives for the same
/// groups; the file reads back as the table.
#[test]
fn appended_groups_give_polars_bytes() {
    let df = table(5000);
    let cuts = [(0, 1400), (1400, 2100), (3500, 1500)];
    let (schema, columns) = schema_of(&df);
    let kv = vec![KeyValue {
        key: "k".into(),
        value: Some("v".into()),
    }];
    let mut theirs = schema.writer();
    for (at, n) in cuts {
        let p = pages(&df.slice(at, n), &columns);
        let it = DynIter::new(p.iter().map(|col| {
            Ok(DynStreamingIterator::new(
                polars_parquet::write::fallible_streaming_iterator::convert(
                    col.iter().map(PolarsResult::Ok),
                ),
            ))
        }));
        theirs.write(n as u64, it).unwrap();
    }
    theirs.end(Some(kv.clone())).unwrap();
    let theirs = theirs.into_inner();

    let d = tempfile::tempdir().unwrap();
    let path = d.path().join("t.parquet");
    let mut w = GroupFileWriter::create(&path, "t.parquet", &schema).unwrap();
    for (at, n) in cuts {
        let g = encode(&schema, n as u64, &pages(&df.slice(at, n), &columns)).unwrap();
        assert_eq!(g.rows(), n);
        w.append(&g).unwrap();
    }
    w.finish(kv).unwrap();
    let ours = std::fs::read(&path).unwrap();
    assert!(
        ours == theirs,
        "the bytes differ ({} against {})",
        ours.len(),
        theirs.len()
    );
    let left: Vec<_> = std::fs::read_dir(d.path()).unwrap().collect();
    assert_eq!(left.len(), 1, "scratch files left: {left:?}");
    let back = ParquetReader::new(std::io::Cursor::new(ours))
        .finish()
        .unwrap();
    assert!(back.equals_missing(&df));
}

/// A group read from one file and appended to another at another position gives the
/// bytes of the same group encoded for that file, and no group gives an empty file.
#[test]
fn a_group_moved_between_files_keeps_its_bytes() {
    let df = table(4000);
    let (schema, columns) = schema_of(&df);
    let d = tempfile::tempdir().unwrap();
    let write = |name: &str, cuts: &[(i64, usize)]| {
        let path = d.path().join(name);
        let mut w = GroupFileWriter::create(&path, "t.parquet", &schema).unwrap();
        for &(at, n) in cuts {
            w.append(&encode(&schema, n as u64, &pages(&df.slice(at, n), &columns)).unwrap())
                .unwrap();
        }
        w.finish(Vec::new()).unwrap();
        path
    };
    let shard = write("shard.parquet", &[(0, 300), (300, 3700)]);
    let direct = write("direct.parquet", &[(300, 3700), (0, 300)]);
    let mut r = GroupFileReader::open(&shard).unwrap();
    assert_eq!(r.peek_value("frame").ok(), None, "300 frames in a group");
    assert_eq!(r.peek_value("clip").unwrap(), Some(b"clip_000".to_vec()));
    let first = r.next_group().unwrap().unwrap();
    assert!(r.peek_value("clip").is_err(), "clips 0 to 5 in a group");
    let second = r.next_group().unwrap().unwrap();
    assert_eq!((first.rows(), second.rows()), (300, 3700));
    assert_eq!(r.peek_value("clip").unwrap(), None);
    assert!(r.next_group().unwrap().is_none());
    let moved = d.path().join("moved.parquet");
    let mut w = GroupFileWriter::create(&moved, "moved.parquet", &schema).unwrap();
    w.append(&second).unwrap();
    w.append(&first).unwrap();
    w.finish(Vec::new()).unwrap();
    assert!(std::fs::read(&moved).unwrap() == std::fs::read(&direct).unwrap());
    let empty = write("empty.parquet", &[]);
    let back = ParquetReader::new(File::open(empty).unwrap())
        .finish()
        .unwrap();
    assert_eq!(back.height(), 0);
    assert_eq!(back.schema(), df.schema());
}

/// A footer whose row group claims 2^27 − 1 column chunks in a few bytes is an error,
/// not a 73 GB allocation; so is a group of another table's columns.
#[test]
fn lying_lengths_and_foreign_groups_are_errors() {
    let d = tempfile::tempdir().unwrap();
    let path = d.path().join("bad.parquet");
    // FileMetaData field 4 (row_groups): a list of 1 struct whose field 1 (columns)
    // is a list of structs of varint length 2^27 − 1, then nothing.
    let mut footer = vec![0x49u8, 0x1C, 0x19, 0xFC];
    let mut n: u32 = (1 << 27) - 1;
    loop {
        let b = (n & 0x7f) as u8;
        n >>= 7;
        if n == 0 {
            footer.push(b);
            break;
        }
        footer.push(b | 0x80);
    }
    footer.push(0);
    let mut bytes = MAGIC.to_vec();
    bytes.extend_from_slice(&footer);
    bytes.extend_from_slice(&(footer.len() as u32).to_le_bytes());
    bytes.extend_from_slice(MAGIC);
    std::fs::write(&path, &bytes).unwrap();
    let mut r = GroupFileReader::open(&path).unwrap();
    let e = r.peek_value("clip").unwrap_err();
    assert!(e.to_string().contains("bad.parquet"), "{e}");
    // Refused by the allocation budget (not by the end of the data, which a machine
    // that granted the allocation would only meet after it).
    let why = format!("{e:?}");
    assert!(why.contains("message too long"), "{why}"); // thrift SizeLimit

    // A group of a two-column table appended to a five-column one.
    let df = table(100);
    let (schema, columns) = schema_of(&df);
    let narrow = df.select(["clip", "frame"]).unwrap();
    let (narrow_schema, narrow_columns) = schema_of(&narrow);
    let g = encode(&narrow_schema, 100, &pages(&narrow, &narrow_columns)).unwrap();
    let mut w = GroupFileWriter::create(&d.path().join("t.parquet"), "t.parquet", &schema).unwrap();
    let e = w.append(&g).unwrap_err().to_string();
    assert!(e.contains("2 columns"), "{e}");
    // The table's own groups still go in.
    w.append(&encode(&schema, 100, &pages(&df, &columns)).unwrap())
        .unwrap();
    w.finish(Vec::new()).unwrap();
}

/// A file that is not Parquet, or is cut short, is an error naming it, not a panic.
#[test]
fn a_damaged_file_is_an_error() {
    let df = table(800);
    let (schema, columns) = schema_of(&df);
    let d = tempfile::tempdir().unwrap();
    let path = d.path().join("t.parquet");
    let mut w = GroupFileWriter::create(&path, "t.parquet", &schema).unwrap();
    w.append(&encode(&schema, 800, &pages(&df, &columns)).unwrap())
        .unwrap();
    w.finish(Vec::new()).unwrap();
    let bytes = std::fs::read(&path).unwrap();
    for cut in [0, 5, bytes.len() / 2, bytes.len() - 1] {
        let bad = d.path().join(format!("cut{cut}.parquet"));
        std::fs::write(&bad, &bytes[..cut]).unwrap();
        let e = GroupFileReader::open(&bad)
            .err()
            .expect("a cut file is refused");
        assert!(e.to_string().contains(&format!("cut{cut}")), "{e}");
    }
    // A footer whose offsets point past the end: the group read is refused.
    let mut r = GroupFileReader::open(&path).unwrap();
    r.peek().unwrap();
    let m = r.next.as_mut().unwrap().columns[0]
        .meta_data
        .as_mut()
        .unwrap();
    m.data_page_offset = 1 << 40;
    m.dictionary_page_offset = None;
    assert!(r.next_group().is_err());
}
