//! Property tests: no input file makes the reader or the ingest panic.

use proptest::prelude::*;
use stancelib::ingest::{ingest, IngestOptions};

fn base() -> Vec<u8> {
    std::fs::read(
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("fixtures/bvh/run_30hz_in_yup.bvh"),
    )
    .unwrap()
}

/// Replacement tokens that stress numeric edge cases.
const TOKENS: [&str; 12] = [
    "0",
    "-0",
    "1e308",
    "-1e308",
    "1e-320",
    "nan",
    "inf",
    "99999999999999999999",
    "{",
    "}",
    "JOINT x",
    "End Site",
];

proptest! {
    #![proptest_config(ProptestConfig { cases: 256, ..ProptestConfig::default() })]

    #[test]
    fn byte_mutations_never_panic(edits in proptest::collection::vec((any::<usize>(), any::<u8>()), 1..8)) {
        let mut b = base();
        for (pos, byte) in edits {
            let n = b.len();
            b[pos % n] = byte;
        }
        if let Ok(bvh) = stancelib::bvh::parse_reader(&b[..]) {
            let _ = ingest(&bvh, &IngestOptions::default());
        }
    }

    #[test]
    fn token_replacements_never_panic(edits in proptest::collection::vec((any::<usize>(), 0..TOKENS.len()), 1..6)) {
        let text = String::from_utf8(base()).unwrap();
        let mut toks: Vec<String> = text.split(' ').map(String::from).collect();
        for (pos, t) in edits {
            let n = toks.len();
            toks[pos % n] = TOKENS[t].to_string();
        }
        let b = toks.join(" ");
        if let Ok(bvh) = stancelib::bvh::parse_reader(b.as_bytes()) {
            let _ = ingest(&bvh, &IngestOptions::default());
        }
    }

    #[test]
    fn any_frame_time_and_offset_scale_is_handled(dt_exp in -320.0f64..300.0, scale_exp in -300.0f64..300.0) {
        let text = String::from_utf8(base()).unwrap();
        let dt = 10f64.powf(dt_exp);
        let mut out = String::new();
        for line in text.lines() {
            if line.starts_with("Frame Time") {
                out.push_str(&format!("Frame Time: {dt:e}\n"));
            } else if let Some(rest) = line.trim_start().strip_prefix("OFFSET") {
                let v: Vec<String> = rest.split_whitespace().map(|x| format!("{:e}", x.parse::<f64>().unwrap() * 10f64.powf(scale_exp))).collect();
                out.push_str(&format!("OFFSET {}\n", v.join(" ")));
            } else {
                out.push_str(line);
                out.push('\n');
            }
        }
        if let Ok(bvh) = stancelib::bvh::parse_reader(out.as_bytes()) {
            let _ = ingest(&bvh, &IngestOptions::default());
        }
    }
}
