//! Shards of one build: `--shard I/N` keeps the inputs whose content hash falls in the I-th
//! of N partitions, so N machines build disjoint parts of one library that `merge` joins.
//!
//! # Model
//! ```text
//! key(file)   = SHA-256 of its bytes (of its path as given, when it cannot be read)
//! shard(file) = 1 + (first 8 bytes of key, big-endian u64) mod N
//! ```
//! A file's shard depends on its content alone, never on which other files exist or where
//! the job runs; copies of one file land in the same shard. Clip names are decided over all
//! the inputs first (they depend on the other inputs only on stem collisions), then the
//! shard's files are kept, so a shard's rows carry the names a single build gives them.

use std::path::Path;

use sha2::{Digest, Sha256};

use super::inputs::file_sha256;
use crate::error::{Error, Result};

/// Most shards one build may be cut into.
pub const MAX_SHARDS: usize = 10_000;

/// The I-th of N shards (`1 ≤ index ≤ count`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub struct Shard {
    /// Which shard, from 1.
    pub index: usize,
    /// How many shards.
    pub count: usize,
}

impl std::fmt::Display for Shard {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}/{}", self.index, self.count)
    }
}

impl std::str::FromStr for Shard {
    type Err = Error;

    /// Parses `I/N` (`--shard`).
    fn from_str(s: &str) -> Result<Shard> {
        let bad = |why: &str| {
            Error::config(
                None,
                None,
                format!("--shard {s:?}: {why} (expected I/N with 1 ≤ I ≤ N ≤ {MAX_SHARDS})"),
            )
        };
        let (i, n) = s.split_once('/').ok_or_else(|| bad("no '/'"))?;
        let index: usize = i
            .trim()
            .parse()
            .map_err(|_| bad("I is not a whole number"))?;
        let count: usize = n
            .trim()
            .parse()
            .map_err(|_| bad("N is not a whole number"))?;
        if count == 0 || count > MAX_SHARDS {
            return Err(bad("N out of range"));
        }
        if index == 0 || index > count {
            return Err(bad("I out of range"));
        }
        Ok(Shard { index, count })
    }
}

/// The shard (1 ..= `count`) of a content hash or, for an unreadable input, of its path.
pub fn shard_of_key(key: &[u8], count: usize) -> usize {
    let mut first = [0u8; 8];
    first.copy_from_slice(&key[..8]);
    1 + (u64::from_be_bytes(first) % count as u64) as usize
}

/// The shard of the file at `path` among `count` (reads the whole file once).
pub fn shard_of(path: &Path, count: usize) -> usize {
    let key: Vec<u8> = match file_sha256(path) {
        Some(hex) => (0..hex.len() / 2)
            .filter_map(|i| u8::from_str_radix(&hex[2 * i..2 * i + 2], 16).ok())
            .collect(),
        None => Sha256::digest(path.to_string_lossy().as_bytes()).to_vec(),
    };
    shard_of_key(&key, count)
}

/// SHA-256 (hex) of the whole input list (clip names and paths, sorted): equal for the
/// shards of one build, recorded in each shard's manifest and checked by `merge`.
pub fn inputs_fingerprint(named: &[(std::path::PathBuf, String)]) -> String {
    let mut rows: Vec<String> = named
        .iter()
        .map(|(p, c)| format!("{c}\t{}\n", p.display()))
        .collect();
    rows.sort();
    let mut h = Sha256::new();
    for r in rows {
        h.update(r.as_bytes());
    }
    h.finalize().iter().map(|b| format!("{b:02x}")).collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parses_and_refuses() {
        let s: Shard = "3/7".parse().unwrap();
        assert_eq!((s.index, s.count), (3, 7));
        assert_eq!(s.to_string(), "3/7");
        for bad in ["0/3", "4/3", "1/0", "x/3", "3", "1/10001"] {
            let e = bad.parse::<Shard>().unwrap_err().to_string();
            assert!(e.contains("--shard"), "{bad}: {e}");
        }
    }

    #[test]
    fn every_key_has_exactly_one_shard() {
        for b in 0u8..=255 {
            let key = Sha256::digest([b]).to_vec();
            for n in [1, 3, 7] {
                let s = shard_of_key(&key, n);
                assert!((1..=n).contains(&s));
            }
            assert_eq!(shard_of_key(&key, 1), 1);
        }
        // Spread: 256 keys over 7 shards leave none empty.
        let mut seen = [0usize; 7];
        for b in 0u8..=255 {
            seen[shard_of_key(&Sha256::digest([b]), 7) - 1] += 1;
        }
        assert!(seen.iter().all(|&c| c > 10), "{seen:?}");
    }
}
