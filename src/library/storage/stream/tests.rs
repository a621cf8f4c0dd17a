use super::*;

/// A table of `n` rows with strings, integers, floats, booleans and nulls.
fn table(n: usize) -> DataFrame {
    df! {
        "clip" => (0..n).map(|i| format!("clip_{:03}", i / 1000)).collect::<Vec<_>>(),
        "frame" => (0..n as i64).collect::<Vec<_>>(),
        "x" => (0..n).map(|i| (i as f64 * 0.37).sin()).collect::<Vec<_>>(),
        "flag" => (0..n).map(|i| i % 7 < 3).collect::<Vec<_>>(),
        "z" => (0..n).map(|i| (i % 5 != 0).then_some(i as f64)).collect::<Vec<_>>(),
    }
    .unwrap()
}

/// polars' own serial writer: one `write_batch` per group, the footer entries a
/// [`TableWriter`] writes.
fn serial_bytes(groups: &[DataFrame], kv: &[(String, String)]) -> Vec<u8> {
    let mut out = Vec::new();
    let schema = groups[0].schema().as_ref().clone();
    let mut w = ParquetWriter::new(&mut out)
        .with_compression(COMPRESSION)
        .with_statistics(write_options().statistics)
        .set_parallel(false)
        .batched(&schema)
        .unwrap();
    for g in groups {
        w.write_batch(&g.clone()).unwrap();
    }
    w.get_writer()
        .lock()
        .unwrap()
        .end(Some(footer_entries(&schema, None, kv)))
        .unwrap();
    drop(w);
    out
}

// See: issue 15 item 4 — Parquet written in parallel: the serial writer's bytes.
#[test]
fn parallel_encoding_gives_the_serial_writers_bytes() {
    let df = table(ROW_GROUP_ROWS + 1234);
    let groups = [
        df.slice(0, ROW_GROUP_ROWS),
        df.slice(ROW_GROUP_ROWS as i64, 1234),
    ];
    let kv = [("k".to_string(), "v".to_string())];
    let serial = serial_bytes(&groups, &kv);
    for threads in [1, 2] {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        let d = tempfile::tempdir().unwrap();
        pool.install(|| {
            let mut w = TableWriter::create(d.path(), "t.parquet", &df.clear()).unwrap();
            w.push(&df).unwrap();
            w.finish(&kv).unwrap();
        });
        let par = std::fs::read(d.path().join("t.parquet")).unwrap();
        assert!(par == serial, "{threads} threads: the bytes differ");
    }
}

/// A per-frame table is cut into one row group per clip (a long clip into groups of
/// `ROW_GROUP_ROWS`), whatever the pushes: polars' serial writer's bytes for those
/// groups.
#[test]
fn per_frame_tables_have_a_row_group_per_clip() {
    let clip = |name: &str, n: usize| {
        df! {
            "clip" => vec![name.to_string(); n],
            "frame" => (0..n as i64).collect::<Vec<_>>(),
            "x" => (0..n).map(|i| (i as f64 * 0.11).cos()).collect::<Vec<_>>(),
        }
        .unwrap()
    };
    let parts = [
        clip("a", 10),
        clip("b", ROW_GROUP_ROWS + 5),
        clip("c", 1),
        clip("d", 300),
    ];
    let mut all = parts[0].clone();
    for p in &parts[1..] {
        all.vstack_mut(p).unwrap();
    }
    let groups = [
        parts[0].clone(),
        parts[1].slice(0, ROW_GROUP_ROWS),
        parts[1].slice(ROW_GROUP_ROWS as i64, 5),
        parts[2].clone(),
        parts[3].clone(),
    ];
    let serial = serial_bytes(&groups, &[]);
    let name = crate::library::codec::schema::FRAMES_FILE;
    for cut in [usize::MAX, 7, 4000] {
        let d = tempfile::tempdir().unwrap();
        let mut w = TableWriter::create(d.path(), name, &all.clear()).unwrap();
        let mut at = 0;
        while at < all.height() {
            w.push(&all.slice(at as i64, cut)).unwrap();
            at = at.saturating_add(cut);
        }
        w.finish(&[]).unwrap();
        let bytes = std::fs::read(d.path().join(name)).unwrap();
        assert!(bytes == serial, "pushes of {cut} rows: the bytes differ");
    }
}

/// Runs of equal keys over several columns: a change in any key starts a group, the
/// open last run waits unless `all`, and a long run is cut at `ROW_GROUP_ROWS`.
#[test]
fn keyed_groups_follow_every_key() {
    let col = |name: &str, v: Vec<Option<&str>>| Column::new(name.into(), v);
    let a = col(
        "a",
        vec![Some("x"), Some("x"), Some("x"), Some("y"), Some("y"), None],
    );
    let b = col(
        "b",
        vec![Some("1"), Some("1"), Some("2"), Some("2"), Some("2"), None],
    );
    assert_eq!(keyed_group_sizes(&[&a, &b], true).unwrap(), [2, 1, 2, 1]);
    assert_eq!(keyed_group_sizes(&[&a, &b], false).unwrap(), [2, 1, 2]);
    assert_eq!(keyed_group_sizes(&[&a], true).unwrap(), [3, 2, 1]);
    let long = col("a", vec![Some("z"); 2 * ROW_GROUP_ROWS + 3]);
    assert_eq!(
        keyed_group_sizes(&[&long], false).unwrap(),
        [ROW_GROUP_ROWS, ROW_GROUP_ROWS]
    );
    assert_eq!(
        keyed_group_sizes(&[&long], true).unwrap(),
        [ROW_GROUP_ROWS, ROW_GROUP_ROWS, 3]
    );
    let empty = col("a", Vec::new());
    assert!(keyed_group_sizes(&[&empty], true).unwrap().is_empty());
}

/// A clip name longer than polars' 64-byte statistics cut keeps whole statistics, so
/// its row groups are still found by name.
#[test]
fn a_long_clip_name_keeps_whole_statistics() {
    let long = format!("subject_{}_take", "x".repeat(120));
    let df = df! {
        "clip" => [long.as_str(), long.as_str(), "z"],
        "frame" => [0i64, 1, 0],
    }
    .unwrap();
    let name = crate::library::codec::schema::FRAMES_FILE;
    let d = tempfile::tempdir().unwrap();
    let mut w = TableWriter::create(d.path(), name, &df.clear()).unwrap();
    w.push(&df).unwrap();
    w.finish(&[]).unwrap();
    let mut r = super::super::group_reader::GroupFileReader::open(&d.path().join(name)).unwrap();
    assert_eq!(r.peek_value("clip").unwrap(), Some(long.into_bytes()));
}

/// A group taken from one file and pushed into another table gives the bytes of its
/// rows pushed; a group cannot overtake rows still waiting for theirs.
#[test]
fn a_pushed_group_equals_its_rows() {
    let df = df! {
        "clip" => ["a", "a", "b", "b", "b", "c"],
        "frame" => [0i64, 1, 0, 1, 2, 0],
    }
    .unwrap();
    let name = crate::library::codec::schema::FRAMES_FILE;
    let d = tempfile::tempdir().unwrap();
    let rows = d.path().join("rows");
    let groups = d.path().join("groups");
    for dir in [&rows, &groups] {
        std::fs::create_dir(dir).unwrap();
    }
    let mut w = TableWriter::create(&rows, name, &df.clear()).unwrap();
    w.push(&df).unwrap();
    w.finish(&[]).unwrap();
    let open = || super::super::group_reader::GroupFileReader::open(&rows.join(name)).unwrap();
    let mut r = open();
    let mut w = TableWriter::create(&groups, name, &df.clear()).unwrap();
    w.push(&df.slice(0, 2)).unwrap();
    assert!(
        w.push_group(&r.next_group().unwrap().unwrap()).is_err(),
        "clip a waits"
    );
    w.finish(&[]).unwrap();
    let mut r = open();
    let mut w = TableWriter::create(&groups, name, &df.clear()).unwrap();
    let mut clips = Vec::new();
    while let Some(clip) = r.peek_value("clip").unwrap() {
        clips.push(String::from_utf8(clip).unwrap());
        w.push_group(&r.next_group().unwrap().unwrap()).unwrap();
    }
    assert_eq!(clips, ["a", "b", "c"]);
    assert_eq!(w.rows(), 6);
    w.finish(&[]).unwrap();
    assert!(std::fs::read(rows.join(name)).unwrap() == std::fs::read(groups.join(name)).unwrap());
}

/// `pieces` pushed one by one through a spilling writer of `template`'s columns into a
/// fresh folder: the file's bytes, the most scratch files and the most pending chunks
/// seen; asserts that no scratch file is left.
fn write_pieces(template: &DataFrame, pieces: &[DataFrame]) -> (Vec<u8>, usize, usize) {
    let d = tempfile::tempdir().unwrap();
    let mut w = TableWriter::create(d.path(), "t.parquet", &template.clear())
        .unwrap()
        .with_pending_spill();
    let (mut most_spilled, mut most_chunks) = (0, 0);
    for p in pieces {
        w.push(p).unwrap();
        most_spilled = most_spilled.max(w.spilled.len());
        most_chunks = most_chunks.max(w.pending.first_col_n_chunks());
    }
    w.finish(&[]).unwrap();
    let bytes = std::fs::read(d.path().join("t.parquet")).unwrap();
    let left: Vec<_> = std::fs::read_dir(d.path()).unwrap().collect();
    assert_eq!(left.len(), 1, "scratch files left: {left:?}");
    (bytes, most_spilled, most_chunks)
}

/// Many pushes of a few rows (far below the pending bytes) wait in scratch files once
/// they are more than `PENDING_SPILL_CHUNKS` chunks, and give the bytes of one push.
#[test]
fn many_small_pushes_spill_by_count_and_give_the_same_bytes() {
    let df = table(3 * (PENDING_SPILL_CHUNKS + 1) * 4);
    assert!(df.estimated_size() < PENDING_SPILL_BYTES);
    let (whole, none, _) = write_pieces(&df, std::slice::from_ref(&df));
    assert_eq!(none, 0);
    let pieces: Vec<DataFrame> = (0..df.height())
        .step_by(3)
        .map(|at| df.slice(at as i64, 3))
        .collect();
    let (pieced, spilled, chunks) = write_pieces(&df, &pieces);
    assert!(spilled >= 3, "{spilled} scratch files");
    assert!(chunks <= PENDING_SPILL_CHUNKS, "{chunks} chunks waited");
    assert!(pieced == whole, "the bytes differ");
}

/// Rows pushed in small pieces, past the pending limit so that they wait in scratch
/// files, give the bytes of one push; no scratch file is left.
#[test]
fn spilled_pending_rows_give_the_same_bytes() {
    let df = table(2 * ROW_GROUP_ROWS + 777);
    assert!(
        df.estimated_size() > 2 * PENDING_SPILL_BYTES,
        "the test must spill"
    );
    let (whole, _, _) = write_pieces(&df, std::slice::from_ref(&df));
    let pieces: Vec<DataFrame> = (0..df.height())
        .step_by(5000)
        .map(|at| df.slice(at as i64, 5000))
        .collect();
    let (pieced, spilled, _) = write_pieces(&df, &pieces);
    assert!(spilled > 0, "no piece waited in a scratch file");
    assert!(pieced == whole, "the bytes differ");
    // Small pieces that wait in scratch files, then one push of two groups' rows that
    // meets them, the total ending exactly on a group boundary.
    let exact = table(3 * ROW_GROUP_ROWS);
    let (whole, _, _) = write_pieces(&exact, std::slice::from_ref(&exact));
    let small = 40 * 1000;
    let mut pieces: Vec<DataFrame> = (0..small)
        .step_by(1000)
        .map(|at| exact.slice(at as i64, 1000))
        .collect();
    pieces.push(exact.slice(small as i64, 2 * ROW_GROUP_ROWS));
    pieces.push(exact.slice((small + 2 * ROW_GROUP_ROWS) as i64, usize::MAX));
    let (pieced, spilled, _) = write_pieces(&exact, &pieces);
    assert!(spilled > 0, "no piece waited in a scratch file");
    assert!(
        pieced == whole,
        "the bytes differ (a large push after spilled rows)"
    );
}
