//! Issue 17: the analyst's first hour. The README's demo commands run and answer with
//! numbers (issue 38 item 6: not all zero or null, queries with feasible rows), the README
//! stays a manual of at most 300 lines, `docs/first-hour.md` runs as written,
//! `docs/tables.md` is the written schemas, the library's provenance (manifest date,
//! command line, tool version; `stancelib.*` Parquet metadata; query outputs naming their
//! library), `info`, and the options a newcomer tries first.

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::SystemTime;

use crate::util::{root, Demo};

fn readme() -> String {
    std::fs::read_to_string(root().join("README.md")).unwrap()
}

/// A page of `docs/`.
fn docs_page(name: &str) -> String {
    let path = root().join("docs").join(name);
    std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

/// The fenced code blocks of `text` in order: each block's info string and its lines.
fn blocks(text: &str) -> Vec<(String, Vec<String>)> {
    let mut blocks = Vec::new();
    let mut cur: Option<(String, Vec<String>)> = None;
    for line in text.lines() {
        let t = line.trim_start();
        match &mut cur {
            None if t.starts_with("```") => cur = Some((t[3..].trim().to_string(), Vec::new())),
            Some(_) if t.starts_with("```") => blocks.extend(cur.take()),
            Some((_, b)) => b.push(line.to_string()),
            None => {}
        }
    }
    blocks
}

/// The fenced code blocks of `text` with info string `lang`, each as its lines.
fn fenced_blocks(text: &str, lang: &str) -> Vec<Vec<String>> {
    blocks(text)
        .into_iter()
        .filter(|(l, _)| l == lang)
        .map(|(_, b)| b)
        .collect()
}

/// A shell line without its comment (a `#` at the start or after a space).
fn without_comment(line: &str) -> &str {
    let t = line.trim();
    if t.starts_with('#') {
        return "";
    }
    t.find(" #").map_or(t, |i| t[..i].trim_end())
}

/// The commands of the README's `sh` blocks that use the demo outputs (`out/demo` outside a
/// comment), in README order.
fn demo_commands(text: &str) -> Vec<String> {
    fenced_blocks(text, "sh")
        .into_iter()
        .filter(|b| b.iter().any(|l| without_comment(l).contains("out/demo")))
        .flatten()
        .map(|l| without_comment(&l).to_string())
        .filter(|l| !l.is_empty())
        .collect()
}

#[test]
fn demo_commands_are_found_outside_comments_only() {
    let text = "```sh\nmake demo   # into out/demo/\n```\n\n```sh\n# out/demo first\n\
                stancelib info out/demo\nstancelib x --out out/demo/a  # note\n```\n\
                ```python\nopen('out/demo/x')\n```\n";
    assert_eq!(
        demo_commands(text),
        vec!["stancelib info out/demo", "stancelib x --out out/demo/a"]
    );
}

/// Every file under `dir` (symbolic links not followed) with its modification time and size.
fn stamps(dir: &Path) -> BTreeMap<PathBuf, (SystemTime, u64)> {
    let mut out = BTreeMap::new();
    let mut todo = vec![dir.to_path_buf()];
    while let Some(d) = todo.pop() {
        for e in std::fs::read_dir(&d).unwrap() {
            let p = e.unwrap().path();
            let m = std::fs::symlink_metadata(&p).unwrap();
            if m.is_dir() {
                todo.push(p);
            } else if m.is_file() {
                out.insert(p, (m.modified().unwrap(), m.len()));
            }
        }
    }
    out
}

/// The files of `after` that are new or changed since `before`.
fn written_since(
    before: &BTreeMap<PathBuf, (SystemTime, u64)>,
    after: &BTreeMap<PathBuf, (SystemTime, u64)>,
) -> Vec<PathBuf> {
    after
        .iter()
        .filter(|(p, s)| before.get(*p) != Some(s))
        .map(|(p, _)| p.clone())
        .collect()
}

/// The finite values of a Parquet table's numeric columns and numeric lists (nulls and
/// NaN left out).
fn table_numbers(path: &Path) -> Vec<f64> {
    use polars::prelude::DataType;
    let t = stancelib::library::codec::table::Table::open(path)
        .unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    let mut out = Vec::new();
    for c in t.df.columns() {
        let values = match c.dtype() {
            d if d.is_primitive_numeric() => c.as_materialized_series().clone(),
            DataType::List(inner) if inner.is_primitive_numeric() => c.list().unwrap().get_inner(),
            _ => continue,
        };
        let values = values.cast(&DataType::Float64).unwrap();
        out.extend(values.f64().unwrap().iter().flatten());
    }
    out.retain(|v| v.is_finite());
    out
}

/// The numbers a command printed: whitespace-separated words that parse as finite numbers
/// once brackets and separators around them are dropped (`(17`, `0.70,`, `1.5:` …).
fn printed_numbers(text: &str) -> Vec<f64> {
    text.split(|c: char| c.is_whitespace() || "()[]{},;=".contains(c))
        .filter_map(|w| w.trim_end_matches([':', '.']).parse::<f64>().ok())
        .filter(|v| v.is_finite())
        .collect()
}

#[test]
fn printed_numbers_are_the_numeric_words_of_the_output() {
    let line = "  sk-1: mu 0.70, F_max 2403 N (17 stances; tool 0.1.0) -0.000 run_120hz:R:51";
    assert_eq!(printed_numbers(line), [0.70, 2403.0, 17.0, -0.0]);
    assert!(printed_numbers("plot stance: run_120hz_m_yup:L:95 → a.png").is_empty());
}

/// Whether a written table answers: the rows of its verdict column (`feasible`, or a jump
/// map's `feasible_exact`), any of them true; `None` when it has no verdict column.
fn any_feasible(path: &Path) -> Option<bool> {
    let t = stancelib::library::codec::table::Table::open(path).unwrap();
    ["feasible", "feasible_exact"]
        .iter()
        .find(|c| t.df.column(c).is_ok())
        .map(|c| t.bools(c).unwrap().into_iter().any(|f| f))
}

/// Checks what a documented command gave: every Parquet table it wrote (but a library's
/// `errors.parquet`) holds a finite non-zero number (and, with `answers`, a feasible row when it has a verdict column); a
/// command that wrote no table printed a finite non-zero number, or drew a picture.
fn check_numbers(cmd: &str, written: &[PathBuf], stdout: &str, answers: bool) {
    // A library's `errors.parquet` lists failed inputs: empty is the good answer.
    let tables: Vec<&PathBuf> = written
        .iter()
        .filter(|p| p.extension().is_some_and(|e| e == "parquet"))
        .filter(|p| !p.ends_with("errors.parquet"))
        .collect();
    for t in &tables {
        let n = table_numbers(t);
        assert!(
            n.iter().any(|v| *v != 0.0),
            "`{cmd}` wrote {} whose numbers are all zero or null ({} finite values)",
            t.display(),
            n.len()
        );
        if answers {
            assert_ne!(
                any_feasible(t),
                Some(false),
                "`{cmd}`: no feasible row in {}; a README example must answer",
                t.display()
            );
        }
    }
    if !tables.is_empty() {
        return;
    }
    let printed = printed_numbers(stdout);
    if !printed.is_empty() {
        assert!(
            printed.iter().any(|v| *v != 0.0),
            "`{cmd}` printed only zeros:\n{stdout}"
        );
        return;
    }
    let pictures: Vec<&PathBuf> = written
        .iter()
        .filter(|p| p.extension().is_some_and(|e| e == "png"))
        .collect();
    assert!(
        !pictures.is_empty(),
        "`{cmd}` wrote no table, printed no number and drew no picture:\n{stdout}"
    );
    for p in pictures {
        assert!(png_size(p).0 > 0, "{}", p.display());
    }
}

// See: issue 17 item 1 — the README's query examples pointed to paths `make demo` does not
// write, and called built commands "not built yet". Issue 38 item 6 — an example that runs
// must also answer: its tables and printed numbers are not all zero or null, and a query's
// table has a feasible row.
#[test]
fn readme_sh_blocks_that_use_the_demo_outputs_run() {
    let commands = demo_commands(&readme());
    assert!(
        commands.len() >= 5,
        "the README shows too few demo commands: {commands:?}"
    );
    let demo = Demo::build();
    for c in &commands {
        let before = stamps(demo.dir.path());
        let (code, out, err) = demo.sh(c);
        assert_eq!(code, 0, "README command `{c}` failed:\n{out}\n{err}");
        let written = written_since(&before, &stamps(demo.dir.path()));
        check_numbers(c, &written, &out, true);
    }
}

// See: issue 38 item 6 — the README is a user's manual; column tables, method and
// measurement history live in docs/.
#[test]
fn readme_is_a_manual_of_at_most_300_lines() {
    let text = readme();
    let lines = text.lines().count();
    assert!(lines <= 300, "README.md has {lines} lines (at most 300)");
    // It points to the pages that took its reference material, and they exist.
    for page in [
        "first-hour.md",
        "tables.md",
        "library.md",
        "queries.md",
        "editing.md",
        "decisions.md",
    ] {
        assert!(
            text.contains(&format!("(docs/{page})")),
            "the README does not link docs/{page}"
        );
        assert!(root().join("docs").join(page).is_file(), "no docs/{page}");
    }
}

/// The value after `flag` in a command line.
fn arg<'a>(cmd: &'a str, flag: &str) -> Option<&'a str> {
    let words: Vec<&str> = cmd.split_whitespace().collect();
    words.windows(2).find(|w| w[0] == flag).map(|w| w[1])
}

/// The stance ids and clip names a command takes (`--stance`, `--clip`, and the two ids of
/// `--pair LIFTOFF:LANDING`, each `clip:label:frame`).
fn ids_taken(cmd: &str) -> Vec<String> {
    let mut ids: Vec<String> = ["--stance", "--clip"]
        .iter()
        .filter_map(|f| arg(cmd, f))
        .map(str::to_string)
        .collect();
    if let Some(pair) = arg(cmd, "--pair") {
        let cut = pair
            .match_indices(':')
            .nth(2)
            .map_or(pair.len(), |(i, _)| i);
        ids.push(pair[..cut].to_string());
        ids.push(pair[(cut + 1).min(pair.len())..].to_string());
    }
    ids
}

#[test]
fn ids_taken_splits_a_pair_into_its_two_stance_ids() {
    assert_eq!(
        ids_taken("stancelib edit jump --lib l --pair a_1:LR:35:b:LR:125 --out x.bvh"),
        ["a_1:LR:35", "b:LR:125"]
    );
    assert_eq!(
        ids_taken("stancelib plot clip --lib l --clip jump_1.3m --out p.png"),
        ["jump_1.3m"]
    );
}

/// Whitespace runs as one space, the ends trimmed.
fn squeeze(line: &str) -> String {
    line.split_whitespace().collect::<Vec<_>>().join(" ")
}

// See: issue 38 item 6 — "a written walkthrough docs/first-hour.md follows a new user from
// `make demo` to a feasible scaled run, a feasible higher jump and an edited BVH, using
// only what the terminal prints". Every `sh` command of the page runs (its `make demo`
// block is the demo library), its numbers are not all zero, the ids it takes were printed
// by an earlier command, the output the page quotes is what the tool prints, and the
// three answers are reached.
#[test]
fn first_hour_walkthrough_commands_run() {
    let page = docs_page("first-hour.md");
    let demo = Demo::build();
    // The recorded jumps' heights, as `list` reports them.
    let (code, json, err) = demo.sh("stancelib list out/demo --json");
    assert_eq!(code, 0, "{err}");
    let list: serde_json::Value = serde_json::from_str(json.trim()).unwrap();
    let recorded = list["jumps"]
        .as_array()
        .unwrap()
        .iter()
        .map(|j| j["height_m"].as_f64().unwrap())
        .fold(f64::NEG_INFINITY, f64::max);
    assert!(
        recorded.is_finite(),
        "the demo library lists no jump: {list}"
    );
    let (mut run, mut jump, mut edit) = (false, false, false);
    let mut seen = String::new();
    let mut last: Option<String> = None;
    let mut n = 0;
    for (lang, lines) in blocks(&page) {
        match lang.as_str() {
            "sh" => {
                let commands: Vec<String> = lines
                    .iter()
                    .map(|l| without_comment(l).to_string())
                    .filter(|l| !l.is_empty())
                    .collect();
                if commands == ["make demo"] {
                    last = None;
                    continue;
                }
                let mut output = String::new();
                for c in &commands {
                    assert!(
                        c.starts_with("stancelib "),
                        "not a stancelib command: `{c}`"
                    );
                    for id in ids_taken(c) {
                        assert!(
                            seen.contains(&id),
                            "`{c}` takes `{id}`, which no earlier command printed"
                        );
                    }
                    let before = stamps(demo.dir.path());
                    let (code, out, err) = demo.sh(c);
                    assert_eq!(code, 0, "docs/first-hour.md: `{c}` failed:\n{out}\n{err}");
                    let written = written_since(&before, &stamps(demo.dir.path()));
                    check_numbers(c, &written, &out, false);
                    let out_file = arg(c, "--out").map(|o| demo.dir.path().join(o));
                    let out_file = out_file.as_deref();
                    if c.starts_with("stancelib query run") {
                        run |= any_feasible(out_file.unwrap()) == Some(true);
                    }
                    if c.starts_with("stancelib query jump") {
                        let t = stancelib::library::codec::table::Table::open(out_file.unwrap())
                            .unwrap();
                        let feasible = t.bools("feasible").unwrap();
                        let heights = t.f64s("height_m").unwrap();
                        jump |= feasible
                            .iter()
                            .zip(&heights)
                            .any(|(f, h)| *f && *h > recorded + 0.05);
                    }
                    if c.starts_with("stancelib edit") {
                        let bvh = out_file.unwrap();
                        edit |= std::fs::metadata(bvh).is_ok_and(|m| m.len() > 0);
                    }
                    output.push_str(&out);
                    output.push_str(&err);
                    n += 1;
                }
                seen.push_str(&output);
                last = Some(output);
            }
            "text" => {
                // The terminal output quoted after a command block, trimmed with `…`.
                let Some(output) = last.take() else { continue };
                let printed: Vec<String> = output.lines().map(squeeze).collect();
                for want in lines.iter().map(|l| squeeze(l)) {
                    if want.is_empty() || want == "…" {
                        continue;
                    }
                    assert!(
                        printed.iter().any(|p| p.contains(&want)),
                        "docs/first-hour.md quotes a line the tool does not print:\n{want}\n\
                         it printed:\n{output}"
                    );
                }
            }
            _ => last = None,
        }
    }
    assert!(n >= 6, "docs/first-hour.md shows only {n} commands");
    assert!(
        run,
        "no `query run` of docs/first-hour.md answers with a feasible run"
    );
    assert!(
        jump,
        "no `query jump` of docs/first-hour.md answers a feasible jump higher than the \
         recorded {recorded:.3} m"
    );
    assert!(edit, "no `edit` of docs/first-hour.md wrote a BVH file");
}

/// Expands a README column token: `a_{x,y,z}`, `<e>` (the four effectors) and
/// `c0_h/p/v` (alternatives for the last `_` part).
fn expand(token: &str) -> Vec<String> {
    if let Some(i) = token.find("<e>") {
        return ["left_foot", "right_foot", "left_hand", "right_hand"]
            .iter()
            .flat_map(|e| expand(&format!("{}{e}{}", &token[..i], &token[i + 3..])))
            .collect();
    }
    if let (Some(a), Some(b)) = (token.find('{'), token.find('}')) {
        return token[a + 1..b]
            .split(',')
            .flat_map(|alt| expand(&format!("{}{alt}{}", &token[..a], &token[b + 1..])))
            .collect();
    }
    let mut parts = token.split('/');
    let first = parts.next().unwrap_or_default().to_string();
    let stem = first.rfind('_').map_or("", |i| &first[..=i]).to_string();
    std::iter::once(first)
        .chain(parts.map(|p| format!("{stem}{p}")))
        .collect()
}

#[test]
fn column_tokens_expand_as_the_readme_writes_them() {
    assert_eq!(expand("c0_h/p/v"), ["c0_h", "c0_p", "c0_v"]);
    assert_eq!(expand("ell_r_min/max"), ["ell_r_min", "ell_r_max"]);
    assert_eq!(
        expand("com_v{x,y,z}_mps"),
        ["com_vx_mps", "com_vy_mps", "com_vz_mps"]
    );
    assert_eq!(expand("contact_<e>").len(), 4);
    assert_eq!(expand("<e>_{x,y,z}").len(), 12);
    assert_eq!(
        expand("{left,right}_toe_{x,y}_m"),
        [
            "left_toe_x_m",
            "left_toe_y_m",
            "right_toe_x_m",
            "right_toe_y_m"
        ]
    );
}

/// The backticked names of a table cell, parenthesised remarks left out.
fn cell_columns(cell: &str) -> Vec<String> {
    let mut plain = String::new();
    let mut depth = 0usize;
    for ch in cell.chars() {
        match ch {
            '(' => depth += 1,
            ')' => depth = depth.saturating_sub(1),
            c if depth == 0 => plain.push(c),
            _ => {}
        }
    }
    plain
        .split('`')
        .skip(1)
        .step_by(2)
        .flat_map(expand)
        .collect()
}

/// The columns a page documents per file: rows of a table whose first cell is a
/// backticked `*.parquet` name (columns in its last cell), and tables after a
/// `<!-- columns: FILE -->` marker (columns in the first cell of each row).
fn documented_columns(text: &str) -> BTreeMap<String, BTreeSet<String>> {
    let mut out: BTreeMap<String, BTreeSet<String>> = BTreeMap::new();
    let mut marker: Option<String> = None;
    for line in text.lines() {
        let t = line.trim();
        if let Some(rest) = t.strip_prefix("<!-- columns:") {
            marker = Some(rest.trim_end_matches("-->").trim().to_string());
            continue;
        }
        if !t.starts_with('|') {
            if !t.is_empty() {
                marker = None;
            }
            continue;
        }
        let cells: Vec<&str> = t.trim_matches('|').split('|').map(str::trim).collect();
        if cells
            .iter()
            .all(|c| c.chars().all(|ch| ch == '-' || ch == ':'))
        {
            continue;
        }
        if let Some(file) = &marker {
            out.entry(file.clone())
                .or_default()
                .extend(cell_columns(cells[0]));
        } else if let Some(file) = cells[0]
            .strip_prefix('`')
            .and_then(|c| c.strip_suffix('`'))
            .filter(|c| c.ends_with(".parquet"))
        {
            out.entry(file.to_string())
                .or_default()
                .extend(cell_columns(cells[cells.len() - 1]));
        }
    }
    out
}

fn parquet_columns(path: &Path) -> BTreeSet<String> {
    let mut f = std::fs::File::open(path).unwrap();
    let meta = polars_parquet::read::read_metadata(&mut f).unwrap();
    meta.schema()
        .fields()
        .iter()
        .map(|f| f.name().to_string())
        .collect()
}

// See: issue 17 item 1 — columns were missing from the README's tables
// (`clips.frame_time_s`, `handedness_ok`, `character_id`, `flight_az_median`,
// `contacts.normal_x/y/z`). Issue 38 item 6 — the tables moved to docs/tables.md, which
// also documents the query, forces and edit-plan outputs.
#[test]
fn docs_tables_are_the_written_schemas() {
    let documented = documented_columns(&docs_page("tables.md"));
    let demo = Demo::build();
    // Outputs the demo job does not write: `joints.parquet` (needs `--joints`), a jump
    // query, the forces (per stance and per contact) and an edit's plan, written beside
    // the demo library.
    for c in [
        "stancelib frames fixtures/bvh/run_120hz_m_yup.bvh --joints --out joints",
        "stancelib query jump --lib out/demo --height 1.2 --distance 0 --out q/jump.parquet",
        "stancelib forces --lib out/demo --out q/forces.parquet",
        "stancelib forces --lib out/demo --per-contact --clip run_120hz_m_yup --out q/per_contact.parquet",
        "stancelib edit jump --lib out/demo --out q/edit.bvh",
    ] {
        let (code, out, err) = demo.sh(c);
        assert_eq!(code, 0, "`{c}`: {out}{err}");
    }
    let lib = demo.lib();
    let q = demo.dir.path().join("q");
    let files = [
        ("frames.parquet", lib.join("frames.parquet")),
        ("clips.parquet", lib.join("clips.parquet")),
        ("contacts.parquet", lib.join("contacts.parquet")),
        ("stances.parquet", lib.join("stances.parquet")),
        ("errors.parquet", lib.join("errors.parquet")),
        ("kinematics.parquet", lib.join("kinematics.parquet")),
        (
            "kinematics_points.parquet",
            lib.join("kinematics_points.parquet"),
        ),
        (
            "joints.parquet",
            demo.dir.path().join("joints/joints.parquet"),
        ),
        ("runs.parquet", lib.join("queries/runs.parquet")),
        (
            "jump_map.parquet",
            lib.join("queries/jump_map/jump_map.parquet"),
        ),
        (
            "jump_map_pairs.parquet",
            lib.join("queries/jump_map/jump_map_pairs.parquet"),
        ),
        ("jump.parquet", q.join("jump.parquet")),
        ("forces.parquet", q.join("forces.parquet")),
        ("per_contact.parquet", q.join("per_contact.parquet")),
        ("plan.parquet", q.join("edit.plan.parquet")),
    ];
    for (file, path) in &files {
        let written = parquet_columns(path);
        let doc = documented
            .get(*file)
            .unwrap_or_else(|| panic!("docs/tables.md has no column table for {file}"));
        let missing: Vec<_> = written.difference(doc).collect();
        let extra: Vec<_> = doc.difference(&written).collect();
        assert!(
            missing.is_empty() && extra.is_empty(),
            "{file}: written but not in docs/tables.md: {missing:?}; in docs/tables.md but \
             not written: {extra:?}"
        );
    }
    // And nothing documented goes unchecked.
    let checked: BTreeSet<&str> = files.iter().map(|(f, _)| *f).collect();
    let unchecked: Vec<_> = documented
        .keys()
        .filter(|f| !checked.contains(f.as_str()))
        .collect();
    assert!(
        unchecked.is_empty(),
        "docs/tables.md documents tables this test does not compare: {unchecked:?}"
    );
}

fn manifest(lib: &Path) -> serde_json::Value {
    serde_json::from_str(&std::fs::read_to_string(lib.join("manifest.json")).unwrap()).unwrap()
}

fn kv(path: &Path) -> BTreeMap<String, String> {
    super::util::parquet_kv(path)
}

fn sha256_hex(bytes: &[u8]) -> String {
    use sha2::{Digest, Sha256};
    Sha256::digest(bytes)
        .iter()
        .map(|b| format!("{b:02x}"))
        .collect()
}

// See: issue 17 item 5 — the manifest had no date or command line, and query outputs did
// not say which library they came from.
#[test]
fn manifest_records_date_command_line_and_tool_version_and_queries_name_their_library() {
    let demo = Demo::build();
    let lib = demo.lib();
    let m = manifest(&lib);
    assert_eq!(m["tool_version"], env!("CARGO_PKG_VERSION"));
    let date = m["created_utc"].as_str().expect("created_utc");
    // RFC 3339 UTC, and today (the test's own clock, within a day).
    assert_eq!(date.len(), 20, "{date}");
    assert!(date.ends_with('Z') && &date[10..11] == "T", "{date}");
    let now = stancelib::library::codec::provenance::now_utc();
    let days = |d: &str| -> i64 {
        let (y, mo, da): (i64, i64, i64) = (
            d[0..4].parse().unwrap(),
            d[5..7].parse().unwrap(),
            d[8..10].parse().unwrap(),
        );
        y * 372 + mo * 31 + da
    };
    assert!((days(&now) - days(date)).abs() <= 1, "{date} vs {now}");
    let cmd: Vec<String> = serde_json::from_value(m["command_line"].clone()).unwrap();
    assert!(cmd[0].ends_with("stancelib"), "{cmd:?}");
    assert_eq!(cmd[1..], ["run", "pipelines/demo.toml"]);
    // The query stages of the demo and a query run by hand name the library's manifest.
    let hash = sha256_hex(&std::fs::read(lib.join("manifest.json")).unwrap());
    let (code, out, err) =
        demo.sh("stancelib query run --lib out/demo --speed 2 --out q/runs.parquet");
    assert_eq!(code, 0, "{out}{err}");
    for f in [
        lib.join("queries/runs.parquet"),
        lib.join("queries/jump_map/jump_map.parquet"),
        demo.dir.path().join("q/runs.parquet"),
    ] {
        let meta = kv(&f);
        assert_eq!(
            meta.get("stancelib.library_manifest_sha256"),
            Some(&hash),
            "{}",
            f.display()
        );
        assert_eq!(meta["stancelib.tool_version"], env!("CARGO_PKG_VERSION"));
    }
    // The library's own tables keep only deterministic provenance.
    let meta = kv(&lib.join("stances.parquet"));
    assert!(meta.contains_key("stancelib.options"), "{meta:?}");
    assert!(
        !meta.values().any(|v| v.contains(date)),
        "the date leaked into the tables' metadata"
    );
}

// See: issue 17 item 5 — `pyarrow.parquet.read_table(...).schema.metadata` showed no
// `stancelib.*` keys.
#[test]
fn pyarrow_schema_metadata_shows_the_stancelib_keys() {
    let has = Command::new("python3")
        .args(["-c", "import pyarrow"])
        .output()
        .is_ok_and(|o| o.status.success());
    if !has {
        // .ci/run installs pyarrow: there, its absence is a failure.
        crate::util::skip_or_fail(
            "pyarrow_schema_metadata_shows_the_stancelib_keys",
            "no pyarrow",
        );
        return;
    }
    let demo = Demo::build();
    let script = "import sys, pyarrow.parquet as pq\n\
        for f in sys.argv[1:]:\n\
        \x20   m = pq.read_table(f).schema.metadata or {}\n\
        \x20   keys = sorted(k.decode() for k in m if k.startswith(b'stancelib.'))\n\
        \x20   print(f.rsplit('/', 1)[-1], ' '.join(keys))\n";
    let lib = demo.lib();
    let o = Command::new("python3")
        .args(["-c", script])
        .arg(lib.join("stances.parquet"))
        .arg(lib.join("queries/runs.parquet"))
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let text = String::from_utf8_lossy(&o.stdout);
    let lines: Vec<&str> = text.lines().collect();
    assert!(
        lines[0].contains("stancelib.schema_version") && lines[0].contains("stancelib.options"),
        "{text}"
    );
    assert!(
        lines[1].contains("stancelib.library_manifest_sha256"),
        "{text}"
    );
}

// See: issue 17 item 5 — `stancelib info LIB`.
#[test]
fn info_summarises_the_library_as_text_and_json() {
    let demo = Demo::library();
    let lib = demo.lib();
    let (code, text, err) = demo.sh("stancelib info out/demo");
    assert_eq!(code, 0, "{err}");
    for needle in [
        "clips",
        "stances by label",
        "failures by stage",
        "per-character limits",
        env!("CARGO_PKG_VERSION"),
    ] {
        assert!(text.contains(needle), "no '{needle}' in\n{text}");
    }
    let (code, json, err) = demo.sh("stancelib info out/demo --json");
    assert_eq!(code, 0, "{err}");
    let v: serde_json::Value = serde_json::from_str(json.trim()).expect("one JSON object");
    // Against the tables, counted here independently.
    let stances =
        stancelib::library::codec::table::read_parquet(&lib.join("stances.parquet")).unwrap();
    let labels = stances.column("label").unwrap().str().unwrap().clone();
    let mut by_label: BTreeMap<String, u64> = BTreeMap::new();
    for l in labels.iter().flatten() {
        *by_label.entry(l.to_string()).or_default() += 1;
    }
    let got: BTreeMap<String, u64> = serde_json::from_value(v["stances_by_label"].clone()).unwrap();
    assert_eq!(got, by_label);
    let m = manifest(&lib);
    assert_eq!(v["clips_by_status"]["ok"], m["counts"]["ok"]);
    assert_eq!(v["limits"], m["limits"]);
    assert_eq!(v["schema_version"], m["schema_version"]);
    assert_eq!(
        v["manifest_sha256"],
        sha256_hex(&std::fs::read(lib.join("manifest.json")).unwrap())
    );
    let starts: u64 = v["boundary_start"]
        .as_object()
        .unwrap()
        .values()
        .map(|n| n.as_u64().unwrap())
        .sum();
    assert_eq!(starts, stances.height() as u64);
    // Not a library: exit 2, the file named.
    let (code, _, err) = demo.sh("stancelib info fixtures");
    assert_eq!(code, 2);
    assert!(err.contains("manifest.json"), "{err}");
}

// See: issue 17 item 6 — `--speed -3` was parsed as a flag.
#[test]
fn negative_numbers_parse_as_values() {
    let demo = Demo::library();
    let (code, _, err) = demo.sh("stancelib query run --lib out/demo --speed -3 --out q.parquet");
    assert_eq!(code, 2);
    // The value reached the speed check, not clap's "unexpected argument".
    assert!(!err.contains("unexpected argument"), "{err}");
    assert!(err.contains("--speed") && err.contains("-3"), "{err}");
    let (code, out, err) =
        demo.sh("stancelib query jump --lib out/demo --height 0.9 --distance -0.5 --out j.parquet");
    assert_eq!(code, 0, "{out}{err}");
}

// See: issue 17 item 6 — `--help` did not say which limits a command uses or its defaults.
#[test]
fn help_shows_defaults_units_and_limits() {
    let demo = Demo::empty();
    for (cmd, needles) in [
        (
            "stancelib map jumps --help",
            &[
                "[default: 0.6:1.6:0.02]",
                "m/s",
                "MAX_GRID_CELLS",
                "1000000",
            ][..],
        ),
        (
            "stancelib query run --help",
            &["MAX_RUN_ROWS", "MAX_AXIS_VALUES", "m/s"][..],
        ),
        (
            "stancelib build --help",
            &["MAX_BVH_BYTES", "[default: 0]"][..],
        ),
        ("stancelib twopac --help", &["MAX_PHASES"][..]),
    ] {
        let (code, out, err) = demo.sh(cmd);
        assert_eq!(code, 0, "{err}");
        for n in needles {
            assert!(out.contains(n), "`{cmd}` lacks '{n}':\n{out}");
        }
    }
}

// See: issue 17 item 6 — `--quiet` and `--json` summaries.
#[test]
fn quiet_prints_nothing_and_json_prints_one_summary_object() {
    let demo = Demo::empty();
    let clip = "fixtures/bvh/run_120hz_m_yup.bvh";
    let (code, out, err) = demo.sh(&format!("stancelib build {clip} --out a --quiet"));
    assert_eq!(code, 0, "{err}");
    assert_eq!(out, "", "--quiet printed on stdout");
    let (code, out, err) = demo.sh(&format!("stancelib build {clip} --out b --json"));
    assert_eq!(code, 0, "{err}");
    let v: serde_json::Value = serde_json::from_str(out.trim()).expect("one JSON object");
    let stances =
        stancelib::library::codec::table::parquet_rows(&demo.dir.path().join("b/stances.parquet"))
            .unwrap();
    assert_eq!(v["command"], "build");
    assert_eq!((v["clips"].as_u64(), v["ok"].as_u64()), (Some(1), Some(1)));
    assert_eq!(v["stances_rebuilt"].as_u64(), Some(stances as u64));
    assert_eq!(v["clips_reused"].as_u64(), Some(0));
}

// See: issue 17 item 7 — layout 4 renamed the columns; a library of an older layout must be
// refused with a message to rebuild, and never reused column by column.
#[test]
fn a_library_of_an_older_table_layout_is_refused_and_not_reused() {
    let demo = Demo::empty();
    let clip = "fixtures/bvh/run_120hz_m_yup.bvh";
    let (code, _, err) = demo.sh(&format!("stancelib build {clip} --out lib --quiet"));
    assert_eq!(code, 0, "{err}");
    let mpath = demo.dir.path().join("lib/manifest.json");
    let mut m: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&mpath).unwrap()).unwrap();
    m["schema"] = "stancelib.library/3".into();
    std::fs::write(&mpath, serde_json::to_string_pretty(&m).unwrap()).unwrap();
    let (code, _, err) =
        demo.sh("stancelib query run --lib lib --speed 3 --out runs.parquet --quiet");
    assert_eq!(code, 2, "{err}");
    assert!(
        err.contains("manifest.json") && err.contains("table layout 3") && err.contains("rebuild"),
        "{err}"
    );
    assert!(!demo.dir.path().join("runs.parquet").exists());
    let (code, out, err) = demo.sh(&format!(
        "stancelib build {clip} --out lib --incremental --force --json"
    ));
    assert_eq!(code, 0, "{err}");
    let v: serde_json::Value = serde_json::from_str(out.trim()).expect("one JSON object");
    assert_eq!(v["clips_reused"].as_u64(), Some(0), "{v}");
    let again: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&mpath).unwrap()).unwrap();
    let want = format!(
        "stancelib.library/{}",
        stancelib::library::codec::schema::SCHEMA_VERSION
    );
    assert_eq!(again["schema"], want.as_str());
}

/// Width and height of a PNG from its IHDR chunk.
fn png_size(path: &Path) -> (u32, u32) {
    let b = std::fs::read(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    assert_eq!(
        &b[..8],
        b"\x89PNG\r\n\x1a\n",
        "{} is not a PNG",
        path.display()
    );
    let be = |i: usize| u32::from_be_bytes([b[i], b[i + 1], b[i + 2], b[i + 3]]);
    (be(16), be(20))
}

// See: issue 17 item 4 — no plot showed a clip's COM, contacts and flights.
#[test]
fn plot_clip_draws_the_clip_and_refuses_an_unknown_one() {
    let demo = Demo::library();
    let (code, out, err) =
        demo.sh("stancelib plot clip --lib out/demo --clip jump_120hz_cmu_yup --out p/clip.png");
    assert_eq!(code, 0, "{out}{err}");
    assert!(out.contains("flights"), "{out}");
    assert_eq!(png_size(&demo.dir.path().join("p/clip.png")), (1300, 1000));
    let (code, _, err) =
        demo.sh("stancelib plot clip --lib out/demo --clip no_such_clip --out p/none.png");
    assert_eq!(code, 2);
    assert!(
        err.contains("no_such_clip") && err.contains("jump_100hz_m_zup"),
        "{err}"
    );
    assert!(!demo.dir.path().join("p/none.png").exists());
}

// See: issue 17 item 4 — "feasible at 5 m/s" returned nothing and no plot showed why.
#[test]
fn query_run_png_draws_table_1_beside_the_table() {
    let demo = Demo::library();
    let (code, out, err) = demo.sh(
        "stancelib query run --lib out/demo --speeds 0:6:1 --out q/runs.parquet --png q/runs.png",
    );
    assert_eq!(code, 0, "{out}{err}");
    // Four panels since issue 37 (times, peak force, friction, extension), under the
    // legend row of issue 38.
    assert_eq!(
        png_size(&demo.dir.path().join("q/runs.png")),
        stancelib::plot::runs::RUNS_PLOT_PX
    );
    assert!(demo.dir.path().join("q/runs.parquet").is_file());
}

// See: issue 17 item 4 — `equilibrium … --png`: the feasible region with the contacts.
#[test]
fn equilibrium_png_draws_the_region_slice() {
    use polars::prelude::{Column, DataFrame, ParquetWriter};
    let demo = Demo::empty();
    let p = demo.dir.path().join("p.parquet");
    let mut df = DataFrame::new_infer_height(vec![
        Column::new("x_m".into(), [0.0, 0.05, 2.0]),
        Column::new("y_m".into(), [0.0, 0.0, 2.0]),
        Column::new("z_m".into(), [0.9, 0.9, 0.9]),
    ])
    .unwrap();
    ParquetWriter::new(std::fs::File::create(&p).unwrap())
        .finish(&mut df)
        .unwrap();
    let (code, out, err) = demo.sh(
        "stancelib equilibrium --contacts fixtures/twopac/r2_contacts.json --points p.parquet \
         --out r.parquet --png r.png",
    );
    assert_eq!(code, 0, "{out}{err}");
    assert_eq!(png_size(&demo.dir.path().join("r.png")), (900, 820));
    assert!(demo.dir.path().join("r.parquet").is_file());
}
