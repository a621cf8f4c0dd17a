//! Malformed inputs (`fixtures/bvh/bad`): a clear error naming the file and the line, never
//! a panic; a batch with bad files still processes the good ones and exits with 1; a
//! large valid stream loads.

use std::io::Read;
use std::path::{Path, PathBuf};

use stancelib::ErrorKind;

fn bad(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("fixtures/bvh/bad")
        .join(name)
}

/// (file, expected line, words the message must contain). Test cases as data.
const CASES: [(&str, usize, &str); 15] = [
    ("truncated_last_row.bvh", 21, "truncated"),
    ("truncated_header.bvh", 9, "truncated"),
    ("missing_motion.bvh", 15, "truncated"),
    ("wrong_channel_count.bvh", 20, "expected 9 values, found 10"),
    ("non_numeric.bvh", 19, "not a number"),
    ("nan_value.bvh", 19, "non-finite"),
    ("inf_value.bvh", 19, "non-finite"),
    ("zero_frame_time.bvh", 18, "positive"),
    ("negative_frame_time.bvh", 18, "positive"),
    ("zero_frames.bvh", 18, "zero frames"),
    ("duplicate_joint.bvh", 6, "duplicate joint name"),
    ("unbalanced_braces.bvh", 15, "unbalanced"),
    ("channels_count_mismatch.bvh", 9, "declares 4"),
    ("end_without_site.bvh", 10, "Site"),
    ("not_bvh.bvh", 1, "unexpected"),
];

#[test]
fn each_bad_file_names_file_line_and_reason() {
    for (file, line, words) in CASES {
        let err = stancelib::bvh::parse_file(&bad(file)).expect_err(file);
        let ErrorKind::Bvh { path, line: l, msg } = &err.kind else {
            panic!("{file}: {err:?}")
        };
        assert_eq!(path.as_deref(), Some(bad(file).as_path()), "{file}");
        assert_eq!(*l, line, "{file}: {msg}");
        assert!(msg.contains(words), "{file}: '{msg}' lacks '{words}'");
        let shown = err.to_string();
        assert!(
            shown.contains(file) && shown.contains(&format!("line {line}")),
            "{shown}"
        );
    }
}

#[test]
fn every_prefix_of_a_real_file_errors_or_parses_without_panic() {
    // Truncation anywhere (header, motion header, mid-row) must be an error, not a panic.
    let text = std::fs::read(
        Path::new(env!("CARGO_MANIFEST_DIR")).join("fixtures/bvh/run_30hz_in_yup.bvh"),
    )
    .unwrap();
    let motion_at = text.windows(6).position(|w| w == b"MOTION").unwrap();
    for cut in (0..text.len()).step_by(97) {
        let r = stancelib::bvh::parse_reader(&text[..cut]);
        if cut < motion_at {
            assert!(r.is_err(), "prefix of {cut} bytes parsed");
        }
    }
}

/// A generated BVH stream of `rows` copies of a fixture's rows, never held in memory.
struct Stream {
    header: Vec<u8>,
    rows: Vec<Vec<u8>>,
    left: usize,
    cur: Vec<u8>,
    pos: usize,
}

impl Read for Stream {
    fn read(&mut self, buf: &mut [u8]) -> std::io::Result<usize> {
        if self.pos == self.cur.len() {
            if !self.header.is_empty() {
                self.cur = std::mem::take(&mut self.header);
            } else if self.left > 0 {
                self.left -= 1;
                self.cur = self.rows[self.left % self.rows.len()].clone();
            } else {
                return Ok(0);
            }
            self.pos = 0;
        }
        let n = buf.len().min(self.cur.len() - self.pos);
        buf[..n].copy_from_slice(&self.cur[self.pos..self.pos + n]);
        self.pos += n;
        Ok(n)
    }
}

#[test]
fn a_300_mb_stream_with_an_inflated_header_count_loads() {
    let text = std::fs::read_to_string(
        Path::new(env!("CARGO_MANIFEST_DIR")).join("fixtures/bvh/run_120hz_m_yup.bvh"),
    )
    .unwrap();
    let (head, body) = text.split_at(text.find("Frames:").unwrap());
    let rows: Vec<Vec<u8>> = body
        .lines()
        .skip(2)
        .map(|l| format!("{l}\n").into_bytes())
        .collect();
    let row_bytes = rows.iter().map(Vec::len).sum::<usize>() / rows.len();
    let n = 300_000_000 / row_bytes;
    // `Frames:` claims 10^15 rows: the reader must not reserve memory from it.
    let header =
        format!("{head}Frames: 1000000000000000\nFrame Time: 0.008333333333333333\n").into_bytes();
    let bvh = stancelib::bvh::parse_reader(Stream {
        header,
        rows,
        left: n,
        cur: Vec::new(),
        pos: 0,
    })
    .unwrap();
    assert_eq!(bvh.motion.n_frames(), n);
    assert_eq!(
        bvh.warnings.len(),
        1,
        "the advisory count mismatch is a warning"
    );
    println!("streamed {} rows ({} MB)", n, n * row_bytes / 1_000_000);
}
