//! Issue 40 item 11: messages and names. A merge refusal names the key that differs and
//! both values; echoed input is cut; values read from data reach the terminal escaped; a
//! library of an older layout says "rebuild" from every command that reads it (`forces`
//! and `plot stance` included); per-character file names are one per id and fit a file
//! name; `edit jump --pair` addresses clips whose name holds `:`; the manifest read is
//! bounded.

use std::path::{Path, PathBuf};

use polars::prelude::*;
use stancelib::library::codec::manifest::MAX_MANIFEST_BYTES;
use stancelib::library::codec::table::read_parquet;
use stancelib::library::codec::write::write_atomic;
use stancelib::library::storage::layout::file_kv;

use crate::util::{fixture_clips, fixture_library, ok, refused, reseal, root, s, stancelib};

/// A copy of the fixture library in `dir/lib`.
fn library_copy(dir: &Path) -> PathBuf {
    let lib = dir.join("lib");
    std::fs::create_dir(&lib).unwrap();
    for e in std::fs::read_dir(fixture_library()).unwrap() {
        let e = e.unwrap();
        std::fs::copy(e.path(), lib.join(e.file_name())).unwrap();
    }
    lib
}

/// Runs the binary from the repository root (the fixture library records its clips'
/// paths relative to it): `(exit code, stdout, stderr)`.
fn at_root(args: &[&str]) -> (i32, String, String) {
    let o = std::process::Command::new(env!("CARGO_BIN_EXE_stancelib"))
        .args(args)
        .current_dir(root())
        .output()
        .unwrap();
    (
        o.status.code().unwrap_or(-1),
        String::from_utf8_lossy(&o.stdout).into_owned(),
        String::from_utf8_lossy(&o.stderr).into_owned(),
    )
}

// See: issue 40 item 11 — a merge options mismatch printed two identical truncated JSON
// prefixes instead of the key that differs.
#[test]
fn issue40_item11_merge_options_mismatch_names_the_differing_key_and_both_values() {
    let dir = tempfile::tempdir().unwrap();
    let clips = fixture_clips();
    let mut shards = Vec::new();
    for (i, mass) in [(1, "70"), (2, "83")] {
        let out = dir.path().join(format!("shard-{i}"));
        let spec = format!("{i}/2");
        let mut args: Vec<&str> = vec!["build"];
        args.extend(clips.iter().map(String::as_str));
        let o = s(&out);
        args.extend(["--out", &o, "--shard", &spec, "--mass", mass]);
        let (code, _, err) = stancelib(&args);
        assert!(code <= 1, "{err}");
        shards.push(o);
    }
    let merged = s(&dir.path().join("merged"));
    let err = refused(
        &["merge", &shards[0], &shards[1], "--out", &merged],
        &["options.", "mass_kg", "70", "83"],
    );
    let line = err.lines().find(|l| l.contains("mass_kg")).unwrap();
    assert!(line.len() < 600, "{line}");
    assert!(!Path::new(&merged).exists());
}

// See: issue 40 item 11 — a 50 MB `inputs` string was echoed whole (2 GB RSS).
#[test]
fn issue40_item11_a_long_inputs_glob_is_echoed_cut() {
    let dir = tempfile::tempdir().unwrap();
    let p = dir.path().join("p.toml");
    // Within the pipeline file's size bound (1 MiB).
    let glob = "x".repeat(500_000);
    std::fs::write(&p, format!("inputs = [\"{glob}\"]\nout = \"lib\"\n")).unwrap();
    let err = refused(&["run", &s(&p)], &["inputs", "matches nothing", "…"]);
    assert!(err.len() < 2_000, "{} bytes of stderr", err.len());
}

// See: issue 40 item 11 — an ESC or a newline in a body `id` reached the terminal from
// `info`.
#[test]
fn issue40_item11_control_characters_of_a_body_id_are_escaped_by_info() {
    let dir = tempfile::tempdir().unwrap();
    let body = dir.path().join("body.toml");
    std::fs::write(&body, "id = \"evil\\u001b[2J\\nfake line\"\n").unwrap();
    let lib = dir.path().join("lib");
    ok(&[
        "build",
        &fixture_clips()[0],
        "--out",
        &s(&lib),
        "--body",
        &s(&body),
    ]);
    let printed = ok(&["info", &s(&lib)]);
    assert!(!printed.contains('\u{1b}'), "{printed:?}");
    assert!(
        !printed.lines().any(|l| l.starts_with("fake line")),
        "{printed}"
    );
    assert!(printed.contains("evil\\x1b[2J\\x0afake line"), "{printed}");
    // `list` and the JSON form too.
    let listed = ok(&["list", &s(&lib)]);
    assert!(!listed.contains('\u{1b}'), "{listed:?}");
    let json = ok(&["info", "--json", &s(&lib)]);
    assert!(!json.contains('\u{1b}'), "{json:?}");
}

/// The library at `lib` with the manifest of a build before the `schema` key (layout 3).
fn make_pre_schema(lib: &Path) {
    let p = lib.join("manifest.json");
    let mut m: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&p).unwrap()).unwrap();
    let o = m.as_object_mut().unwrap();
    o.remove("schema");
    o.insert("schema_version".into(), "3".into());
    std::fs::write(&p, serde_json::to_string_pretty(&m).unwrap()).unwrap();
}

// See: issue 40 item 11 — a pre-schema manifest said "column 'z_c_m': missing" instead
// of "rebuild"; `forces` and `plot stance` skipped the layout check.
#[test]
fn issue40_item11_a_pre_schema_library_says_rebuild_from_every_reading_command() {
    let dir = tempfile::tempdir().unwrap();
    let lib = library_copy(dir.path());
    make_pre_schema(&lib);
    let l = s(&lib);
    let out = dir.path().join("out");
    let o = |name: &str| s(&out.join(name));
    let stance = "run_120hz_m_yup:L:95";
    for args in [
        vec!["info", &l],
        vec!["list", &l],
        vec![
            "query",
            "run",
            "--lib",
            &l,
            "--speed",
            "3",
            "--out",
            &o("r.parquet"),
        ],
        vec!["forces", "--lib", &l, "--out", &o("f.parquet")],
        vec![
            "plot",
            "stance",
            "--lib",
            &l,
            "--stance",
            stance,
            "--out",
            &o("s.png"),
        ],
        vec![
            "plot",
            "clip",
            "--lib",
            &l,
            "--clip",
            "run_120hz_m_yup",
            "--out",
            &o("c.png"),
        ],
        vec![
            "edit",
            "run",
            "--lib",
            &l,
            "--speed",
            "3.5",
            "--out",
            &o("e.bvh"),
        ],
    ] {
        let (code, _, err) = at_root(&args);
        assert_eq!(code, 2, "{args:?}: {err}");
        assert!(
            err.contains("table layout 3") && err.contains("rebuild"),
            "{args:?}: {err}"
        );
    }
    assert!(!out.exists());
}

/// Gives the stances and clips of `clip` the character id `id` (tables rewritten with
/// their key-value metadata, the manifest's limits copied to the new id, resealed).
fn rename_character(lib: &Path, clip: &str, id: &str) {
    let mut old = String::new();
    for table in ["stances.parquet", "clips.parquet"] {
        let path = lib.join(table);
        let kv = file_kv(&path).unwrap();
        let mut df = read_parquet(&path).unwrap();
        let clips: Vec<String> = df
            .column("clip")
            .unwrap()
            .str()
            .unwrap()
            .iter()
            .map(|v| v.unwrap_or_default().to_string())
            .collect();
        let ids: Vec<Option<String>> = df
            .column("character_id")
            .unwrap()
            .str()
            .unwrap()
            .iter()
            .zip(&clips)
            .map(|(v, c)| {
                if c == clip {
                    old = v.unwrap_or_default().to_string();
                    Some(id.to_string())
                } else {
                    v.map(str::to_string)
                }
            })
            .collect();
        df.with_column(Column::new("character_id".into(), ids))
            .unwrap();
        write_atomic(lib, table, &mut df, &kv).unwrap();
    }
    let p = lib.join("manifest.json");
    let mut m: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&p).unwrap()).unwrap();
    let limits = m["limits"][&old].clone();
    assert!(!limits.is_null(), "no limits for {old}");
    m["limits"][id] = limits;
    std::fs::write(&p, serde_json::to_string_pretty(&m).unwrap()).unwrap();
    reseal(lib);
}

// See: issue 40 item 11 — ids `a/b` and `a.b` both wrote `jump_map_a_b.png`; a
// 300-character id exited 2 after four map outputs were written.
#[test]
fn issue40_item11_per_character_map_files_are_one_per_id_and_fit_a_file_name() {
    let long = "c".repeat(300);
    for (first, second) in [("a/b", "a.b"), ("a.b", long.as_str())] {
        let dir = tempfile::tempdir().unwrap();
        let lib = library_copy(dir.path());
        rename_character(&lib, "jump_100hz_m_zup", first);
        rename_character(&lib, "jump_120hz_cmu_yup", second);
        let out = dir.path().join("map");
        ok(&[
            "map",
            "jumps",
            "--lib",
            &s(&lib),
            "--heights",
            "0.8:1.4:0.1",
            "--speeds",
            "0:2:0.5",
            "--out",
            &s(&out),
        ]);
        let names: Vec<String> = std::fs::read_dir(&out)
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .filter(|n| n.starts_with("jump_map_") && n.ends_with(".png"))
            .collect();
        let want: Vec<String> = [first, second]
            .iter()
            .map(|id| {
                format!(
                    "jump_map_{}.png",
                    stancelib::pipeline::commands::queries::file_safe(id)
                )
            })
            .collect();
        for w in &want {
            assert!(names.contains(w), "{w} not in {names:?}");
            assert!(w.len() < 100, "{w}");
        }
        assert_ne!(want[0], want[1]);
        for table in [
            "jump_map.parquet",
            "jump_map_pairs.parquet",
            "jump_map.json",
        ] {
            assert!(out.join(table).is_file(), "{table}");
        }
    }
}

// See: issue 40 item 11 — `edit jump --pair` could not address a clip whose name holds ':'.
#[test]
fn issue40_item11_edit_jump_pair_addresses_a_clip_whose_name_holds_a_colon() {
    let dir = tempfile::tempdir().unwrap();
    let clip = dir.path().join("take:1.bvh");
    std::fs::copy(root().join("fixtures/bvh/jump_100hz_m_zup.bvh"), &clip).unwrap();
    let lib = dir.path().join("lib");
    ok(&["build", &s(&clip), "--out", &s(&lib)]);
    let listed = ok(&["list", "--json", &s(&lib)]);
    let v: serde_json::Value = serde_json::from_str(&listed).unwrap();
    let jump = &v["jumps"][0];
    let (up, down) = (
        jump["liftoff"].as_str().unwrap(),
        jump["landing"].as_str().unwrap(),
    );
    assert!(
        up.starts_with("take:1:") && down.starts_with("take:1:"),
        "{jump}"
    );
    let out = dir.path().join("jump.bvh");
    let pair = format!("{up}:{down}");
    let printed = ok(&[
        "edit",
        "jump",
        "--lib",
        &s(&lib),
        "--pair",
        &pair,
        "--out",
        &s(&out),
    ]);
    assert!(out.is_file(), "{printed}");
    // An unknown landing is still named, with its nearest ids.
    let bad = format!("{up}:take:1:LR:9999");
    refused(
        &[
            "edit",
            "jump",
            "--lib",
            &s(&lib),
            "--pair",
            &bad,
            "--out",
            &s(&out),
        ],
        &["--pair", "no stance 'take:1:LR:9999'", down],
    );
}

// See: issue 40 item 11 — `info` read a 300 MB manifest into 1.19 GB.
#[test]
fn issue40_item11_a_manifest_beyond_max_manifest_bytes_is_refused_by_size() {
    let dir = tempfile::tempdir().unwrap();
    let lib = library_copy(dir.path());
    let f = std::fs::OpenOptions::new()
        .write(true)
        .open(lib.join("manifest.json"))
        .unwrap();
    // Sparse: 300 MB that take no disk.
    f.set_len(300 << 20).unwrap();
    for args in [vec!["info", &s(&lib)], vec!["list", &s(&lib)]] {
        refused(
            &args,
            &[
                "manifest.json",
                &(300u64 << 20).to_string(),
                &MAX_MANIFEST_BYTES.to_string(),
                "MAX_MANIFEST_BYTES",
            ],
        );
    }
}
