//! Build script: the digest of the source this binary is built from.
//!
//! `STANCELIB_SOURCE_DIGEST` is the SHA-256 of every file under `src/` plus `Cargo.toml`
//! and the `Cargo.lock` that pins the dependencies (this package's, or the nearest one
//! above it in a workspace), relative paths sorted, each as `path NUL length NUL bytes`. A
//! library's manifest records it (`source_digest`), and `build --incremental` and `merge`
//! take rows only from a library written by the same source: the options and the clip's
//! bytes alone did not say that the code computing the rows was the same (a library built
//! before a change of the COM kept its old rows under `--incremental`). The tool version
//! did not either: it changes only at a release.

use sha2::{Digest, Sha256};
use std::path::{Path, PathBuf};

fn main() {
    let root = PathBuf::from(
        std::env::var_os("CARGO_MANIFEST_DIR").expect("cargo sets CARGO_MANIFEST_DIR"),
    );
    let mut files: Vec<(String, PathBuf)> = Vec::new();
    collect(&root, &root.join("src"), &mut files);
    files.push(("Cargo.toml".into(), root.join("Cargo.toml")));
    // The lockfile: this package's, else a workspace's above it. Without one the digest
    // holds the source only (and Cargo is not told to watch a file that does not exist,
    // which would rerun this script on every build).
    if let Some(lock) = root
        .ancestors()
        .map(|d| d.join("Cargo.lock"))
        .find(|p| p.is_file())
    {
        files.push(("Cargo.lock".into(), lock));
    }
    files.sort();
    let mut h = Sha256::new();
    for (rel, path) in &files {
        let bytes =
            std::fs::read(path).unwrap_or_else(|e| panic!("cannot read {}: {e}", path.display()));
        h.update(rel.as_bytes());
        h.update([0]);
        h.update(bytes.len().to_string().as_bytes());
        h.update([0]);
        h.update(&bytes);
        if !rel.starts_with("src/") {
            println!("cargo:rerun-if-changed={}", path.display());
        }
    }
    let digest: String = h.finalize().iter().map(|b| format!("{b:02x}")).collect();
    println!("cargo:rustc-env=STANCELIB_SOURCE_DIGEST={digest}");
    println!("cargo:rerun-if-changed=src");
}

/// Every regular file under `dir` (symbolic links not followed: a link loop cannot recurse),
/// as (path relative to `root` with `/` separators, path).
fn collect(root: &Path, dir: &Path, out: &mut Vec<(String, PathBuf)>) {
    let entries =
        std::fs::read_dir(dir).unwrap_or_else(|e| panic!("cannot list {}: {e}", dir.display()));
    for e in entries {
        let e = e.unwrap_or_else(|e| panic!("cannot list {}: {e}", dir.display()));
        let p = e.path();
        let kind = e
            .file_type()
            .unwrap_or_else(|e| panic!("cannot stat {}: {e}", p.display()));
        if kind.is_dir() {
            collect(root, &p, out);
        } else if kind.is_file() {
            let rel = p.strip_prefix(root).unwrap_or(&p);
            let rel: Vec<String> = rel
                .components()
                .map(|c| c.as_os_str().to_string_lossy().into_owned())
                .collect();
            out.push((rel.join("/"), p));
        }
    }
}
