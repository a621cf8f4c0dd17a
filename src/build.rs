//! Build script: the digest of the source this binary is built from.
//!
//! `STANCELIB_SOURCE_DIGEST` is the SHA-256 of every file under `src/` plus `Cargo.toml`
//! and `Cargo.lock` (relative paths sorted, each as `path NUL length NUL bytes`). A
//! library's manifest records it (`source_digest`), and `build --incremental` reuses rows
//! only from a library written by the same source: the options and the clip's bytes alone
//! did not say that the code computing the rows was the same (a library built before a
//! change of the COM kept its old rows under `--incremental`). The tool version did not
//! either: it changes only at a release.

use sha2::{Digest, Sha256};
use std::path::{Path, PathBuf};

fn main() {
    let root = PathBuf::from(std::env::var_os("CARGO_MANIFEST_DIR").unwrap_or_default());
    let mut files = Vec::new();
    collect(&root, &root.join("src"), &mut files);
    for f in ["Cargo.toml", "Cargo.lock"] {
        if root.join(f).is_file() {
            files.push(PathBuf::from(f));
        }
    }
    files.sort();
    let mut h = Sha256::new();
    for rel in &files {
        let bytes = std::fs::read(root.join(rel)).unwrap_or_default();
        h.update(rel.to_string_lossy().replace('\\', "/").as_bytes());
        h.update([0]);
        h.update(bytes.len().to_string().as_bytes());
        h.update([0]);
        h.update(&bytes);
    }
    let digest: String = h.finalize().iter().map(|b| format!("{b:02x}")).collect();
    println!("cargo:rustc-env=STANCELIB_SOURCE_DIGEST={digest}");
    println!("cargo:rerun-if-changed=src");
    println!("cargo:rerun-if-changed=Cargo.toml");
    println!("cargo:rerun-if-changed=Cargo.lock");
}

/// Every file under `dir`, as paths relative to `root`.
fn collect(root: &Path, dir: &Path, out: &mut Vec<PathBuf>) {
    let Ok(entries) = std::fs::read_dir(dir) else {
        return;
    };
    for e in entries.flatten() {
        let p = e.path();
        if p.is_dir() {
            collect(root, &p, out);
        } else if let Ok(rel) = p.strip_prefix(root) {
            out.push(rel.to_path_buf());
        }
    }
}
