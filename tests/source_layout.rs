//! The rooms of `src/` (issue 41): no import circle between files or between top-level
//! modules, no file over 800 lines but the flat registries, and no `anyhow` in the build
//! engine. Read from the source text: the `use` lines and every `crate::…`/`super::…` path
//! outside comments, up to a file's `#[cfg(test)]` (test code may reach anywhere); test
//! modules (`tests.rs`, `tests/`, `testkit.rs`) are left out.
//!
//! The same check by hand: `cargo test --test integration source_layout`.

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

use crate::util::root;

/// Lines a file of `src/` may have at most.
const MAX_LINES: usize = 800;

/// Flat registries, longer than [`MAX_LINES`] by nature: one entry per option or column.
const REGISTRIES: [&str; 2] = ["cli/args.rs", "library/codec/schema.rs"];

/// The folder of the build engine: typed errors only.
const ENGINE: &str = "pipeline/engine";

type Module = Vec<String>;

/// Every `.rs` file of `src/` (but `main.rs`) by its module path.
fn modules(src: &Path) -> BTreeMap<Module, PathBuf> {
    fn walk(dir: &Path, out: &mut Vec<PathBuf>) {
        for e in std::fs::read_dir(dir).unwrap() {
            let p = e.unwrap().path();
            if p.is_dir() {
                walk(&p, out);
            } else if p.extension().is_some_and(|x| x == "rs") {
                out.push(p);
            }
        }
    }
    let mut files = Vec::new();
    walk(src, &mut files);
    let mut out = BTreeMap::new();
    for p in files {
        let rel = p.strip_prefix(src).unwrap().with_extension("");
        let mut m: Module = rel
            .components()
            .map(|c| c.as_os_str().to_string_lossy().into_owned())
            .collect();
        if m.last().is_some_and(|l| l == "mod") {
            m.pop();
        }
        if m == ["main"] {
            continue;
        }
        if m == ["lib"] {
            m.clear();
        }
        out.insert(m, p);
    }
    out
}

fn is_test_file(rel: &str) -> bool {
    rel.ends_with("/tests.rs") || rel.contains("/tests/") || rel.ends_with("testkit.rs")
}

/// The code of a file up to its first `#[cfg(test)]`, comments removed.
fn code_of(text: &str) -> String {
    let mut out = String::new();
    for line in text.lines() {
        if line.trim_start().starts_with("#[cfg(test)]") {
            break;
        }
        out.push_str(line.split("//").next().unwrap_or(""));
        out.push('\n');
    }
    out
}

/// The paths of a `use` tree (`a::{b, c::{d, e}}` → `a::b`, `a::c::d`, `a::c::e`).
fn expand_use(tree: &str, prefix: &[String], out: &mut Vec<Vec<String>>) {
    let tree = tree.trim();
    if let (Some(open), true) = (tree.find('{'), tree.ends_with('}')) {
        let mut pre = prefix.to_vec();
        pre.extend(
            tree[..open]
                .split("::")
                .map(str::trim)
                .filter(|s| !s.is_empty())
                .map(String::from),
        );
        let inner = &tree[open + 1..tree.len() - 1];
        let (mut depth, mut start) = (0, 0);
        for (i, ch) in inner.char_indices() {
            match ch {
                '{' => depth += 1,
                '}' => depth -= 1,
                ',' if depth == 0 => {
                    expand_use(&inner[start..i], &pre, out);
                    start = i + 1;
                }
                _ => {}
            }
        }
        expand_use(&inner[start..], &pre, out);
        return;
    }
    let tree = tree.split(" as ").next().unwrap_or("").trim();
    if tree.is_empty() {
        return;
    }
    let mut p = prefix.to_vec();
    p.extend(tree.split("::").map(|s| s.trim().to_string()));
    out.push(p);
}

/// The `crate`/`super`/`self` paths a file's code names.
fn paths_of(code: &str) -> Vec<Vec<String>> {
    let mut out = Vec::new();
    // `use` statements (trees included).
    let mut rest = code;
    while let Some(i) = rest.find("use ") {
        let before = rest[..i].chars().last();
        let after = &rest[i + 4..];
        rest = after;
        if before.is_some_and(|c| c.is_alphanumeric() || c == '_') {
            continue;
        }
        let Some(end) = after.find(';') else { break };
        let tree = after[..end].trim();
        if ["crate", "super", "self"]
            .iter()
            .any(|k| tree.starts_with(k))
        {
            expand_use(tree, &[], &mut out);
        }
    }
    // Paths written in place (`crate::a::b(…)`, `super::x::Y`).
    let bytes = code.as_bytes();
    for key in ["crate::", "super::"] {
        let mut from = 0;
        while let Some(i) = code[from..].find(key) {
            let at = from + i;
            from = at + key.len();
            if at > 0 && (bytes[at - 1].is_ascii_alphanumeric() || bytes[at - 1] == b'_') {
                continue;
            }
            let end = code[at..]
                .find(|c: char| !(c.is_alphanumeric() || c == '_' || c == ':'))
                .map_or(code.len(), |e| at + e);
            let segs: Vec<String> = code[at..end]
                .split("::")
                .filter(|s| !s.is_empty())
                .map(String::from)
                .collect();
            out.push(segs);
        }
    }
    out
}

/// The module a path names, as the longest prefix that is a file of `src/`.
fn resolve(from: &Module, path: &[String], mods: &BTreeMap<Module, PathBuf>) -> Option<Module> {
    let (mut base, mut rest): (Module, &[String]) = match path.first().map(String::as_str) {
        Some("crate") => (Vec::new(), &path[1..]),
        Some("super") | Some("self") => (from.clone(), path),
        _ => return None,
    };
    while let Some(head) = rest.first() {
        match head.as_str() {
            "super" => {
                base.pop();
            }
            "self" => {}
            _ => break,
        }
        rest = &rest[1..];
    }
    base.extend(rest.iter().cloned());
    (0..=base.len())
        .rev()
        .map(|k| base[..k].to_vec())
        .find(|m| mods.contains_key(m))
}

/// File-level import edges of `src/` (test files and test code left out).
fn edges(
    src: &Path,
) -> (
    BTreeMap<Module, PathBuf>,
    BTreeMap<Module, BTreeSet<Module>>,
) {
    let mods = modules(src);
    let rel = |p: &Path| p.strip_prefix(src).unwrap().display().to_string();
    let mut out: BTreeMap<Module, BTreeSet<Module>> = BTreeMap::new();
    for (m, p) in &mods {
        if is_test_file(&rel(p)) {
            continue;
        }
        let code = code_of(&std::fs::read_to_string(p).unwrap());
        for path in paths_of(&code) {
            if let Some(to) = resolve(m, &path, &mods) {
                if &to != m && !is_test_file(&rel(&mods[&to])) {
                    out.entry(m.clone()).or_default().insert(to);
                }
            }
        }
    }
    (mods, out)
}

/// The strongly connected components with more than one node (Tarjan).
fn circles<N: Ord + Clone>(graph: &BTreeMap<N, BTreeSet<N>>) -> Vec<Vec<N>> {
    struct T<'a, N: Ord> {
        g: &'a BTreeMap<N, BTreeSet<N>>,
        index: BTreeMap<N, usize>,
        low: BTreeMap<N, usize>,
        stack: Vec<N>,
        on: BTreeSet<N>,
        out: Vec<Vec<N>>,
    }
    fn visit<N: Ord + Clone>(t: &mut T<'_, N>, v: &N) {
        let i = t.index.len();
        t.index.insert(v.clone(), i);
        t.low.insert(v.clone(), i);
        t.stack.push(v.clone());
        t.on.insert(v.clone());
        for w in t.g.get(v).into_iter().flatten() {
            if !t.index.contains_key(w) {
                visit(t, w);
                let l = t.low[v].min(t.low[w]);
                t.low.insert(v.clone(), l);
            } else if t.on.contains(w) {
                let l = t.low[v].min(t.index[w]);
                t.low.insert(v.clone(), l);
            }
        }
        if t.low[v] == t.index[v] {
            let mut comp = Vec::new();
            while let Some(w) = t.stack.pop() {
                t.on.remove(&w);
                let done = &w == v;
                comp.push(w);
                if done {
                    break;
                }
            }
            if comp.len() > 1 {
                comp.sort();
                t.out.push(comp);
            }
        }
    }
    let mut t = T {
        g: graph,
        index: BTreeMap::new(),
        low: BTreeMap::new(),
        stack: Vec::new(),
        on: BTreeSet::new(),
        out: Vec::new(),
    };
    let nodes: Vec<N> = graph
        .iter()
        .flat_map(|(a, bs)| std::iter::once(a.clone()).chain(bs.iter().cloned()))
        .collect();
    for n in nodes {
        if !t.index.contains_key(&n) {
            visit(&mut t, &n);
        }
    }
    t.out
}

#[test]
fn no_import_circle_between_files_or_top_level_modules() {
    let (_, g) = edges(&root().join("src"));
    let files: Vec<Vec<String>> = circles(&g)
        .into_iter()
        .map(|c| c.iter().map(|m| m.join("::")).collect())
        .collect();
    assert!(files.is_empty(), "import circles between files: {files:?}");
    let mut top: BTreeMap<String, BTreeSet<String>> = BTreeMap::new();
    for (a, bs) in &g {
        for b in bs {
            if let (Some(x), Some(y)) = (a.first(), b.first()) {
                if x != y {
                    top.entry(x.clone()).or_default().insert(y.clone());
                }
            }
        }
    }
    let tops = circles(&top);
    assert!(
        tops.is_empty(),
        "import circles between top-level modules: {tops:?}"
    );
}

// The checker itself: a circle made of `use` trees and in-place paths is found.
#[test]
fn the_circle_check_finds_a_planted_circle() {
    let dir = tempfile::tempdir().unwrap();
    let src = dir.path();
    std::fs::create_dir_all(src.join("a")).unwrap();
    std::fs::write(src.join("lib.rs"), "pub mod a;\npub mod b;\n").unwrap();
    std::fs::write(src.join("a/mod.rs"), "pub mod x;\npub mod y;\n").unwrap();
    std::fs::write(src.join("a/x.rs"), "use super::{y::{Y}};\n").unwrap();
    std::fs::write(src.join("a/y.rs"), "fn f() { crate::b::g(); }\n").unwrap();
    std::fs::write(
        src.join("b.rs"),
        "// use crate::a::y;\npub fn g() { let _ = crate::a::x::X; }\n",
    )
    .unwrap();
    let (_, g) = edges(src);
    let c = circles(&g);
    assert_eq!(c.len(), 1, "{c:?}");
    assert_eq!(c[0].len(), 3, "{c:?}");
}

#[test]
fn no_file_over_800_lines_but_the_registries() {
    let src = root().join("src");
    let mut long = Vec::new();
    for p in modules(&src).values() {
        let rel = p.strip_prefix(&src).unwrap().display().to_string();
        let n = std::fs::read_to_string(p).unwrap().lines().count();
        if n > MAX_LINES && !REGISTRIES.contains(&rel.as_str()) {
            long.push(format!("{rel}: {n} lines"));
        }
    }
    assert!(long.is_empty(), "files over {MAX_LINES} lines: {long:?}");
}

#[test]
fn the_build_engine_has_no_anyhow() {
    let engine = root().join("src").join(ENGINE);
    let hits: Vec<String> = modules(&root().join("src"))
        .values()
        .filter(|p| p.starts_with(&engine))
        .filter(|p| std::fs::read_to_string(p).unwrap().contains("anyhow"))
        .map(|p| p.display().to_string())
        .collect();
    assert!(hits.is_empty(), "anyhow in the build engine: {hits:?}");
}
