//! Kinematic samples kept on disk while a library is written: every contact frame's COM in
//! its contact frame goes to one scratch file as it comes (a batch of a build, a slice of
//! a shard's `kinematics_samples.parquet` in a merge), and only an index of runs stays in
//! memory, so the memory a build needs does not grow with the number of samples.
//!
//! # Layout
//! ```text
//! file:   records of RECORD_BYTES: frame (i64), x, y, z (f64, m), little-endian, exact bits
//! index:  per (character, effector): runs (clip, arrival, first record, records)
//! order:  a group is read run by run in (clip, arrival) order: the (clip, frame) order of
//!         the tables (every table added is sorted by SAMPLES_SORT_KEYS, and a clip's rows
//!         come from one batch or one shard, in order)
//! ```
//! The index holds one run per (character, effector, clip) and so grows with the clips,
//! by tens of bytes each, as the manifest's input list does; the samples do not stay.
//! The file lives in the library's temporary folder under a scratch name and is removed
//! when the spill is dropped.

use std::collections::BTreeMap;
use std::fs::File;
use std::io::{BufWriter, Read, Seek, SeekFrom, Write};
use std::path::{Path, PathBuf};
use std::sync::Arc;

use polars::prelude::*;

use crate::error::{Error, Result};
use crate::library::codec::kinematics::Sample;
use crate::library::codec::schema::kinematics as K;

/// Bytes of one spilled sample: the frame and the three coordinates.
pub const RECORD_BYTES: usize = 32;

/// Samples read back at a time from the spill file.
const READ_RECORDS: usize = 8192;

/// One run of a group's samples: consecutive records of one clip.
#[derive(Debug, Clone)]
struct Run {
    clip: Arc<str>,
    arrival: u64,
    first: u64,
    len: u64,
}

/// Kinematic samples spilled to a scratch file (see the module docs).
#[derive(Debug)]
pub struct SampleSpill {
    path: PathBuf,
    out: Option<BufWriter<File>>,
    records: u64,
    arrivals: u64,
    groups: BTreeMap<(String, String), Vec<Run>>,
}

fn io(path: &Path, what: &str, e: impl std::error::Error + Send + Sync + 'static) -> Error {
    Error::io(path, what, e)
}

impl SampleSpill {
    /// Start an empty spill file at `path` (a scratch name in a temporary folder).
    ///
    /// # Errors
    /// The file cannot be created.
    pub fn create(path: &Path) -> Result<SampleSpill> {
        let f = File::create(path).map_err(|e| io(path, "cannot create scratch file", e))?;
        Ok(SampleSpill {
            path: path.to_path_buf(),
            out: Some(BufWriter::new(f)),
            records: 0,
            arrivals: 0,
            groups: BTreeMap::new(),
        })
    }

    /// Samples spilled so far.
    pub fn len(&self) -> u64 {
        self.records
    }

    /// No samples spilled.
    pub fn is_empty(&self) -> bool {
        self.records == 0
    }

    /// Append the rows of a samples table sorted by
    /// [`crate::library::codec::kinematics::SAMPLES_SORT_KEYS`] (rows with a null are skipped).
    ///
    /// # Errors
    /// A column is missing or of another type, or the write fails.
    pub fn add(&mut self, samples: &DataFrame) -> Result<()> {
        let name = crate::library::codec::schema::KINEMATICS_SAMPLES_FILE;
        let bad = |e: PolarsError| Error::io(name, "samples of another schema", e);
        let str_col = |n: &str| -> Result<StringChunked> {
            Ok(samples.column(n).map_err(bad)?.str().map_err(bad)?.clone())
        };
        let f64_col = |n: &str| -> Result<Float64Chunked> {
            Ok(samples.column(n).map_err(bad)?.f64().map_err(bad)?.clone())
        };
        let (ch, eff, clip) = (
            str_col(K::CHARACTER_ID)?,
            str_col(K::EFFECTOR)?,
            str_col(K::CLIP)?,
        );
        let frame = samples
            .column(K::FRAME)
            .map_err(bad)?
            .i64()
            .map_err(bad)?
            .clone();
        let [nx, ny, nz] = K::POINT;
        let (x, y, z) = (f64_col(nx)?, f64_col(ny)?, f64_col(nz)?);
        let Some(out) = self.out.as_mut() else {
            return Err(io(
                &self.path,
                "spill already read",
                std::io::Error::other("sealed"),
            ));
        };
        let mut run: Option<((String, String), Run)> = None;
        let rows = ch.iter().zip(eff.iter()).zip(clip.iter()).zip(frame.iter());
        for (i, (((c, e), k), f)) in rows.enumerate() {
            let (Some(c), Some(e), Some(k), Some(f)) = (c, e, k, f) else {
                continue;
            };
            let (Some(px), Some(py), Some(pz)) = (x.get(i), y.get(i), z.get(i)) else {
                continue;
            };
            let same = run
                .as_ref()
                .is_some_and(|(key, r)| key.0 == c && key.1 == e && &*r.clip == k);
            if !same {
                if let Some((key, r)) = run.take() {
                    self.groups.entry(key).or_default().push(r);
                }
                self.arrivals += 1;
                run = Some((
                    (c.to_string(), e.to_string()),
                    Run {
                        clip: Arc::from(k),
                        arrival: self.arrivals,
                        first: self.records,
                        len: 0,
                    },
                ));
            }
            let mut rec = [0u8; RECORD_BYTES];
            rec[..8].copy_from_slice(&f.to_le_bytes());
            for (a, v) in [px, py, pz].into_iter().enumerate() {
                rec[8 + 8 * a..16 + 8 * a].copy_from_slice(&v.to_le_bytes());
            }
            out.write_all(&rec)
                .map_err(|e| io(&self.path, "cannot write scratch file", e))?;
            self.records += 1;
            if let Some((_, r)) = run.as_mut() {
                r.len += 1;
            }
        }
        if let Some((key, r)) = run.take() {
            self.groups.entry(key).or_default().push(r);
        }
        Ok(())
    }

    /// Stop writing: flush the file and put each group's runs in (clip, arrival) order.
    ///
    /// # Errors
    /// The flush fails.
    pub fn seal(&mut self) -> Result<()> {
        if let Some(mut out) = self.out.take() {
            out.flush()
                .map_err(|e| io(&self.path, "cannot write scratch file", e))?;
        }
        for runs in self.groups.values_mut() {
            runs.sort_by(|a, b| (&a.clip, a.arrival).cmp(&(&b.clip, b.arrival)));
        }
        Ok(())
    }

    /// The (character, effector) groups in key order, with their sample counts.
    pub fn groups(&self) -> Vec<(&(String, String), u64)> {
        self.groups
            .iter()
            .map(|(k, runs)| (k, runs.iter().map(|r| r.len).sum()))
            .collect()
    }

    /// Call `f` on the raw records of `key`'s runs in (clip, frame) order, up to
    /// `READ_RECORDS` at a time, with the run they belong to (after [`SampleSpill::seal`]).
    fn read_records(
        &self,
        key: &(String, String),
        f: &mut dyn FnMut(&Run, &[u8]) -> Result<()>,
    ) -> Result<()> {
        let Some(runs) = self.groups.get(key) else {
            return Ok(());
        };
        let err = |e| io(&self.path, "cannot read scratch file", e);
        let mut file = File::open(&self.path).map_err(|e| io(&self.path, "cannot open", e))?;
        let mut bytes = vec![0u8; READ_RECORDS * RECORD_BYTES];
        let mut at = None;
        for run in runs {
            // Runs of one group mostly follow each other in the file: seek only where not.
            if at != Some(run.first) {
                file.seek(SeekFrom::Start(run.first * RECORD_BYTES as u64))
                    .map_err(err)?;
            }
            at = Some(run.first + run.len);
            let mut left = run.len;
            while left > 0 {
                let n = left.min(READ_RECORDS as u64) as usize;
                let chunk = &mut bytes[..n * RECORD_BYTES];
                file.read_exact(chunk).map_err(err)?;
                f(run, chunk)?;
                left -= n as u64;
            }
        }
        Ok(())
    }

    /// Call `f` on the samples of `key` in (clip, frame) order, up to `READ_RECORDS`
    /// at a time (after [`SampleSpill::seal`]).
    ///
    /// # Errors
    /// The file cannot be read, or `f` fails.
    pub fn read_group(
        &self,
        key: &(String, String),
        f: &mut dyn FnMut(&[Sample]) -> Result<()>,
    ) -> Result<()> {
        let mut buf: Vec<Sample> = Vec::with_capacity(READ_RECORDS);
        self.read_records(key, &mut |run, chunk| {
            buf.clear();
            buf.extend(chunk.chunks_exact(RECORD_BYTES).map(|rec| Sample {
                clip: run.clip.clone(),
                frame: i64::from_le_bytes(word(rec, 0)),
                rc: point(rec),
            }));
            f(&buf)
        })
    }

    /// Call `f` on the points (x, y, z in m) of `key`'s samples in (clip, frame) order, up
    /// to `READ_RECORDS` at a time: [`SampleSpill::read_group`] without the clip and frame,
    /// for the passes that need only the points.
    ///
    /// # Errors
    /// The file cannot be read, or `f` fails.
    pub fn read_points(
        &self,
        key: &(String, String),
        f: &mut dyn FnMut(&[[f64; 3]]) -> Result<()>,
    ) -> Result<()> {
        let mut buf: Vec<[f64; 3]> = Vec::with_capacity(READ_RECORDS);
        self.read_records(key, &mut |_, chunk| {
            buf.clear();
            buf.extend(chunk.chunks_exact(RECORD_BYTES).map(point));
            f(&buf)
        })
    }
}

/// The 8 bytes of word `a` of a record.
fn word(rec: &[u8], a: usize) -> [u8; 8] {
    let mut w = [0u8; 8];
    w.copy_from_slice(&rec[8 * a..8 * a + 8]);
    w
}

/// The point (x, y, z) of a record.
fn point(rec: &[u8]) -> [f64; 3] {
    [1, 2, 3].map(|a| f64::from_le_bytes(word(rec, a)))
}

impl Drop for SampleSpill {
    fn drop(&mut self) {
        self.out = None;
        let _ = std::fs::remove_file(&self.path);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::library::codec::kinematics::points_frame;

    fn sample(clip: &str, frame: i64, v: f64) -> Sample {
        Sample {
            clip: Arc::from(clip),
            frame,
            rc: [v, -v, v * 1e-300],
        }
    }

    /// A samples table of `rows` (sorted by the caller), several groups stacked.
    fn table(rows: &[(&str, &str, Sample)]) -> DataFrame {
        let mut all: Option<DataFrame> = None;
        for (c, e, s) in rows {
            let df =
                points_frame(&(c.to_string(), e.to_string()), std::slice::from_ref(s)).unwrap();
            all = Some(match all {
                None => df,
                Some(a) => a.vstack(&df).unwrap(),
            });
        }
        all.unwrap()
    }

    fn read(spill: &SampleSpill, key: (&str, &str)) -> Vec<(String, i64, [f64; 3])> {
        let mut out = Vec::new();
        spill
            .read_group(&(key.0.into(), key.1.into()), &mut |b| {
                out.extend(b.iter().map(|s| (s.clip.to_string(), s.frame, s.rc)));
                Ok(())
            })
            .unwrap();
        out
    }

    #[test]
    fn a_group_reads_back_in_clip_and_frame_order_with_exact_bits() {
        let d = tempfile::tempdir().unwrap();
        let path = d.path().join("spill");
        let mut spill = SampleSpill::create(&path).unwrap();
        // Shard-like arrival: clip b before clip a, a's rows cut into two slices.
        spill
            .add(&table(&[
                ("c1", "L", sample("b", 1, 0.1)),
                ("c1", "R", sample("b", 1, 0.2)),
            ]))
            .unwrap();
        spill
            .add(&table(&[
                ("c1", "L", sample("a", 7, 0.3)),
                ("c1", "L", sample("a", 9, f64::MIN_POSITIVE)),
            ]))
            .unwrap();
        spill
            .add(&table(&[("c1", "L", sample("a", 11, 1.0 / 3.0))]))
            .unwrap();
        assert_eq!(spill.len(), 5);
        spill.seal().unwrap();
        assert_eq!(
            std::fs::metadata(&path).unwrap().len(),
            5 * RECORD_BYTES as u64,
            "every sample is on disk"
        );
        let groups: Vec<((String, String), u64)> = spill
            .groups()
            .into_iter()
            .map(|(k, n)| (k.clone(), n))
            .collect();
        assert_eq!(
            groups,
            vec![
                (("c1".into(), "L".into()), 4),
                (("c1".into(), "R".into()), 1)
            ]
        );
        let l = read(&spill, ("c1", "L"));
        let want = [
            ("a", 7, 0.3),
            ("a", 9, f64::MIN_POSITIVE),
            ("a", 11, 1.0 / 3.0),
            ("b", 1, 0.1),
        ];
        assert_eq!(l.len(), want.len());
        for (got, (c, f, v)) in l.iter().zip(want) {
            assert_eq!((got.0.as_str(), got.1), (c, f));
            assert_eq!(
                got.2.map(f64::to_bits),
                [v, -v, v * 1e-300].map(f64::to_bits)
            );
        }
        assert_eq!(read(&spill, ("c1", "R")).len(), 1);
        assert!(read(&spill, ("c2", "L")).is_empty());
        drop(spill);
        assert!(!path.exists(), "the scratch file is removed with the spill");
    }

    #[test]
    fn a_group_longer_than_one_read_comes_back_whole() {
        let d = tempfile::tempdir().unwrap();
        let mut spill = SampleSpill::create(&d.path().join("spill")).unwrap();
        let n = READ_RECORDS * 2 + 5;
        let rows: Vec<Sample> = (0..n).map(|i| sample("k", i as i64, i as f64)).collect();
        spill
            .add(&points_frame(&("c".into(), "L".into()), &rows).unwrap())
            .unwrap();
        spill.seal().unwrap();
        let back = read(&spill, ("c", "L"));
        assert_eq!(back.len(), n);
        assert!(back
            .iter()
            .enumerate()
            .all(|(i, r)| r.1 == i as i64 && r.2[0] == i as f64));
        // The points alone, in the same order and chunks of at most READ_RECORDS.
        let mut points: Vec<[f64; 3]> = Vec::new();
        spill
            .read_points(&("c".into(), "L".into()), &mut |b| {
                assert!(b.len() <= READ_RECORDS);
                points.extend_from_slice(b);
                Ok(())
            })
            .unwrap();
        let expected: Vec<[f64; 3]> = back.iter().map(|r| r.2).collect();
        assert!(points == expected);
    }
}
