//! The library opened by readers that are not ours: pyarrow and DuckDB (installed by
//! `.ci/run`; skipped with a printed reason where python3 lacks them).

use std::process::Command;

fn python_has(modules: &str) -> bool {
    Command::new("python3")
        .args(["-c", &format!("import {modules}")])
        .output()
        .is_ok_and(|o| o.status.success())
}

#[test]
fn pyarrow_and_duckdb_read_the_library() {
    if !python_has("pyarrow, duckdb, pandas") {
        // .ci/run installs them: there, their absence is a failure.
        crate::util::skip_or_fail(
            "pyarrow_and_duckdb_read_the_library",
            "python3 with pyarrow, pandas and duckdb not found (.ci/run installs them)",
        );
        return;
    }
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR"));
    let dir = tempfile::tempdir().unwrap();
    let lib = dir.path().join("lib");
    let mut args = vec!["build".to_string()];
    for f in ["run_120hz_m_yup", "run_60hz_cm_zup", "jump_120hz_cmu_yup"] {
        args.push(
            root.join("fixtures/bvh")
                .join(format!("{f}.bvh"))
                .display()
                .to_string(),
        );
    }
    args.extend(["--out".into(), lib.display().to_string()]);
    crate::util::ok(&args.iter().map(String::as_str).collect::<Vec<_>>());
    // Independent counts from our side: stances per clip from the in-process build.
    let files: Vec<std::path::PathBuf> = args[1..4].iter().map(std::path::PathBuf::from).collect();
    let report = stancelib::pipeline::engine::streaming::build(&files, &Default::default());
    let n_stances = report.stances.len();
    let first = &report.stances[0];
    let script = format!(
        r#"
import json, pyarrow.parquet as pq, duckdb
lib = {lib:?}
t = pq.read_table(lib + "/stances.parquet")
assert t.num_rows == {n_stances}, t.num_rows
meta = pq.ParquetFile(lib + "/stances.parquet").metadata.metadata
assert meta[b"stancelib.schema_version"] == {ver:?}.encode(), meta
row = t.slice(0, 1).to_pylist()[0]
assert row["stance_id"] == {sid:?}, row["stance_id"]
assert abs(row["dt_s"] - {dt}) < 1e-12, row["dt_s"]
assert abs(row["c0_v_n"] - {c0v}) < 1e-9 * max(1.0, abs({c0v})), row["c0_v_n"]
assert len(row["harmonic_v"]) == len(row["amp_v_n"]) == len(row["phase_v_rad"])
n = duckdb.sql(f"select count(*) from '{{lib}}/stances.parquet'").fetchall()[0][0]
assert n == {n_stances}, n
clips = duckdb.sql(f"select count(*) from '{{lib}}/clips.parquet' where status = 'ok'").fetchall()[0][0]
assert clips == 3, clips
frames = duckdb.sql(f"select count(*) from '{{lib}}/frames.parquet'").fetchall()[0][0]
assert frames == {frames}, frames
# pandas, through pyarrow: list<string> columns must not come back as string_view lists.
import pandas as pd
for name in ["stances", "clips", "frames", "contacts", "errors"]:
    df = pd.read_parquet(f"{{lib}}/{{name}}.parquet")
s = pd.read_parquet(lib + "/stances.parquet")
assert len(s) == {n_stances} and isinstance(s["effectors"].iloc[0][0], str), s["effectors"].iloc[0]
print("ok", n, frames)
"#,
        lib = lib.display().to_string(),
        ver = stancelib::library::codec::schema::SCHEMA_VERSION,
        sid = first.stance_id,
        dt = first.dt_s,
        c0v = first.model.axes[2].c0,
        frames = report
            .records
            .iter()
            .map(|r| r.summary.frames_kept)
            .sum::<i64>(),
    );
    let o = Command::new("python3")
        .args(["-c", &script])
        .output()
        .unwrap();
    assert!(
        o.status.success(),
        "{}{}",
        String::from_utf8_lossy(&o.stdout),
        String::from_utf8_lossy(&o.stderr)
    );
    println!("{}", String::from_utf8_lossy(&o.stdout));
}
