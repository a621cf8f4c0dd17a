//! BVH writer: a hierarchy and a motion back to text, the reader's inverse.
//!
//! `write_writer` streams to any `Write`; `write_file` writes beside the target under a
//! temporary name and renames it into place, so a failed write leaves no half file and an
//! earlier file survives.

use std::fmt::Write as _;
use std::io::Write;
use std::path::Path;

use super::{Bvh, Hierarchy, Motion};
use crate::error::{Error, Result};

/// Significant digits of every written value: 10 keeps a 1 m offset to 0.1 nm and an angle
/// to 1e-8°, well below anything the ingest resolves, and rows stay about 10 bytes a value.
pub const DEFAULT_SIGNIFICANT_DIGITS: usize = 10;

fn num(s: &mut String, v: f64) {
    // `{:e}` with a fixed mantissa length gives DEFAULT_SIGNIFICANT_DIGITS digits at any
    // magnitude; plain decimals read better where they are exact enough.
    if v == 0.0 {
        s.push('0');
    } else if (1e-4..1e7).contains(&v.abs()) {
        let digits = DEFAULT_SIGNIFICANT_DIGITS as i32 - 1 - v.abs().log10().floor() as i32;
        let _ = write!(s, "{:.*}", digits.max(0) as usize, v);
        if s.contains('.') {
            while s.ends_with('0') {
                s.pop();
            }
            if s.ends_with('.') {
                s.pop();
            }
        }
    } else {
        let _ = write!(s, "{:.*e}", DEFAULT_SIGNIFICANT_DIGITS - 1, v);
    }
}

fn joint(h: &Hierarchy, j: usize, depth: usize, s: &mut String) {
    let jd = &h.joints[j];
    let ind = "\t".repeat(depth);
    let kw = if jd.parent.is_none() { "ROOT" } else { "JOINT" };
    let _ = write!(s, "{ind}{kw} {}\n{ind}{{\n{ind}\tOFFSET", jd.name);
    for v in jd.offset {
        s.push(' ');
        num(s, v);
    }
    s.push('\n');
    if !jd.channels.is_empty() {
        let names: Vec<String> = jd.channels.iter().map(|c| format!("{c:?}")).collect();
        let _ = writeln!(s, "{ind}\tCHANNELS {} {}", names.len(), names.join(" "));
    }
    for c in (j + 1..h.joints.len()).filter(|&c| h.joints[c].parent == Some(j)) {
        joint(h, c, depth + 1, s);
    }
    if let Some(e) = jd.end_site {
        let _ = write!(s, "{ind}\tEnd Site\n{ind}\t{{\n{ind}\t\tOFFSET");
        for v in e {
            s.push(' ');
            num(s, v);
        }
        let _ = writeln!(s, "\n{ind}\t}}");
    }
    let _ = writeln!(s, "{ind}}}");
}

/// The HIERARCHY section as text (joints depth first, tabs, LF).
pub fn hierarchy_text(h: &Hierarchy) -> String {
    let mut s = String::from("HIERARCHY\n");
    for r in (0..h.joints.len()).filter(|&j| h.joints[j].parent.is_none()) {
        joint(h, r, 0, &mut s);
    }
    s
}

/// Writes a hierarchy and a motion as BVH text to `w`.
///
/// # Errors
/// `ErrorKind::Shape` when the motion's channel count is not the hierarchy's; the writer's
/// I/O error (as `ErrorKind::Io` on `<bvh>`).
///
/// # Examples
/// ```
/// let text = "HIERARCHY\nROOT Hips\n{\n OFFSET 0 0 0\n CHANNELS 3 Xposition Yposition Zposition\n End Site\n {\n  OFFSET 0 1 0\n }\n}\nMOTION\nFrames: 2\nFrame Time: 0.01\n0 0 0\n1 2.5 -3\n";
/// let bvh = stancelib::bvh::parse_reader(text.as_bytes()).unwrap();
/// let mut out = Vec::new();
/// stancelib::bvh::write_writer(&mut out, &bvh.hierarchy, &bvh.motion).unwrap();
/// let again = stancelib::bvh::parse_reader(out.as_slice()).unwrap();
/// assert_eq!(again.motion, bvh.motion);
/// ```
pub fn write_writer<W: Write>(mut w: W, h: &Hierarchy, m: &Motion) -> Result<()> {
    if m.n_channels != h.n_channels() {
        return Err(crate::error::ErrorKind::Shape {
            name: "motion channels",
            expected: h.n_channels(),
            found: m.n_channels,
        }
        .into());
    }
    let io = |e: std::io::Error| Error::io(Path::new("<bvh>"), "cannot write", e);
    w.write_all(hierarchy_text(h).as_bytes()).map_err(io)?;
    // The frame time in full (Rust's shortest round-trip form): a clip written here reads
    // back with its source's exact clock, and 10 digits would drift by 3e-13 s a frame.
    let mut s = format!(
        "MOTION\nFrames: {}\nFrame Time: {}\n",
        m.n_frames(),
        m.frame_time_s
    );
    for f in 0..m.n_frames() {
        for (k, &v) in m.row(f).iter().enumerate() {
            if k > 0 {
                s.push(' ');
            }
            num(&mut s, v);
        }
        s.push('\n');
        if s.len() > 1 << 16 {
            w.write_all(s.as_bytes()).map_err(io)?;
            s.clear();
        }
    }
    w.write_all(s.as_bytes()).map_err(io)?;
    w.flush().map_err(io)
}

/// Writes `bvh` to `path` atomically (a temporary name beside it, then a rename).
///
/// # Errors
/// The folder is not writable, or as [`write_writer`]; errors name the file.
pub fn write_file(path: &Path, bvh: &Bvh) -> Result<()> {
    let name = path
        .file_name()
        .and_then(|n| n.to_str())
        .ok_or_else(|| Error::invalid("--out", format!("{}: not a file name", path.display())))?;
    let tmp = path.with_file_name(format!(".{name}.tmp-{}", std::process::id()));
    let result = (|| {
        let f = std::fs::File::create(&tmp).map_err(|e| Error::io(&tmp, "cannot create", e))?;
        write_writer(std::io::BufWriter::new(f), &bvh.hierarchy, &bvh.motion).map_err(
            |e| match e.kind {
                crate::error::ErrorKind::Io { msg, source, .. } => Error {
                    kind: crate::error::ErrorKind::Io {
                        path: path.to_path_buf(),
                        msg,
                        source,
                    },
                },
                _ => e,
            },
        )?;
        std::fs::rename(&tmp, path).map_err(|e| Error::io(path, "cannot rename into place", e))
    })();
    if result.is_err() {
        let _ = std::fs::remove_file(&tmp);
    }
    result
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn numbers_keep_ten_significant_digits() {
        for v in [
            0.0,
            1.0,
            -2.5,
            0.123456789012,
            12345.6789012345,
            1e-9,
            -3.3e12,
            179.99999,
        ] {
            let mut s = String::new();
            num(&mut s, v);
            let back: f64 = s.parse().unwrap();
            // 10 significant digits: relative error ≤ 5e-10.
            assert!((back - v).abs() <= 5e-10 * v.abs(), "{v} → {s}");
        }
    }
}
