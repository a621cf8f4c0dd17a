//! The parse limit shared by the benchmarks: the least work any BVH ingest must do, reading
//! the bytes and turning every MOTION number into an f64.

/// Skip to the line after `Frame Time:`, then split every line on ASCII whitespace and
/// parse each token with `fast_float2`. No validation, no line numbers.
///
/// # Panics
/// On text without a `Frame Time` line or with a token that is not a number (benchmark
/// inputs are valid clips).
pub fn baseline_split_parse(bytes: &[u8]) -> Vec<f64> {
    let text = std::str::from_utf8(bytes).expect("utf-8");
    let at = text.find("Frame Time").expect("Frame Time line");
    let body = &text[at..];
    let body = &body[body.find('\n').expect("newline") + 1..];
    let mut out = Vec::new();
    for line in body.lines() {
        for tok in line.split_ascii_whitespace() {
            out.push(fast_float2::parse::<f64, _>(tok).expect("number"));
        }
    }
    out
}
