//! Clip names: the file stem, with the shortest distinguishing parent path on collisions.
//!
//! # Model
//! ```text
//! inputs sorted by path; clip = stem; when several inputs share a stem, each gets
//! <last k parent folders>/<stem> with the smallest k that makes all of them distinct
//! ```
//!
//! # References
//! spec com-from-bvh §1.1.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

fn stem(p: &Path) -> String {
    p.file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_default()
}

fn with_parents(p: &Path, k: usize) -> String {
    let parents: Vec<String> = p
        .parent()
        .map(|d| {
            d.components()
                .map(|c| c.as_os_str().to_string_lossy().into_owned())
                .collect()
        })
        .unwrap_or_default();
    let start = parents.len().saturating_sub(k);
    let mut parts: Vec<String> = parents[start..].to_vec();
    parts.push(stem(p));
    parts.join("/")
}

/// Clip names for `paths` (any order); returned in the same order as `paths`.
pub fn clip_names(paths: &[PathBuf]) -> Vec<String> {
    let mut by_stem: BTreeMap<String, Vec<usize>> = BTreeMap::new();
    for (i, p) in paths.iter().enumerate() {
        by_stem.entry(stem(p)).or_default().push(i);
    }
    let mut out = vec![String::new(); paths.len()];
    for (s, idx) in by_stem {
        if idx.len() == 1 {
            out[idx[0]] = s;
            continue;
        }
        let depth = idx
            .iter()
            .map(|&i| paths[i].components().count())
            .max()
            .unwrap_or(1);
        for k in 1..=depth {
            let names: Vec<String> = idx.iter().map(|&i| with_parents(&paths[i], k)).collect();
            let mut uniq = names.clone();
            uniq.sort();
            uniq.dedup();
            if uniq.len() == names.len() || k == depth {
                for (j, &i) in idx.iter().enumerate() {
                    out[i] = names[j].clone();
                }
                break;
            }
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn collisions_get_the_shortest_distinguishing_parent() {
        let p: Vec<PathBuf> = [
            "d/run/cmu_09_01_run_mb.bvh",
            "d/odd/cmu_09_01_run_mb.bvh",
            "d/walk/w.bvh",
            "a/x/s.bvh",
            "b/x/s.bvh",
        ]
        .iter()
        .map(PathBuf::from)
        .collect();
        assert_eq!(
            clip_names(&p),
            vec![
                "run/cmu_09_01_run_mb",
                "odd/cmu_09_01_run_mb",
                "w",
                "a/x/s",
                "b/x/s"
            ]
        );
    }
}
