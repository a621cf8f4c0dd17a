//! Streaming BVH parser: `parse_file(path)` opens the file and calls `parse_reader`.

use std::collections::HashMap;
use std::io::Read;
use std::path::Path;

use super::{Bvh, Channel, Hierarchy, JointDef, Motion};
use crate::error::{echo, Error, Result, MAX_ECHO_CHARS};

/// Smallest accepted frame time, s (100 kHz): anything shorter is a corrupt header.
pub const MIN_FRAME_TIME_S: f64 = 1e-5;
/// Largest accepted frame time, s (0.1 Hz).
pub const MAX_FRAME_TIME_S: f64 = 10.0;
/// Longest accepted line, bytes (line break excluded): 8 MiB. A MOTION row of a 300-joint
/// skeleton is under 20 KB; the bound keeps the reader's memory bounded on a file with no
/// line breaks (binary data, `/dev/zero`), which is refused at the line where it is met.
pub const MAX_LINE_BYTES: usize = 8 << 20;
/// Size of the reader's buffer, bytes.
const READ_CHUNK_BYTES: usize = 1 << 16;

/// Parse a BVH file from disk. Errors name the file and the line.
///
/// # Errors
/// I/O failures and every malformation listed in [`parse_reader`].
pub fn parse_file(path: &Path) -> Result<Bvh> {
    let f =
        std::fs::File::open(path).map_err(|e| Error::io(path, format!("cannot open: {e}"), e))?;
    parse_reader(f).map_err(|e| e.with_path(path))
}

/// Parse BVH text from any reader, streaming the MOTION section row by row.
///
/// Accepts LF, CRLF, CR-only (old Mac) and mixed line endings, tabs, a UTF-8 BOM,
/// scientific notation, `End Site`/`End site`, and a `Frames:` count that disagrees with the
/// data (a warning). Joints may nest to any depth (the parser keeps its own stack).
/// Raw input echoed in a message is escaped and cut (see [`crate::error::echo`]).
///
/// # Errors
/// `ErrorKind::Bvh` with the 1-based line for: an empty file, a line longer than
/// [`MAX_LINE_BYTES`], a read error (with the OS reason), unbalanced braces, missing or
/// repeated sections, a missing root name, `End` without `Site`, bad OFFSET or CHANNELS
/// lines, a duplicate joint name (with the line of the first), a non-positive or non-finite
/// frame time, a data row with the wrong number of values, a non-numeric or non-finite
/// value, zero data rows, and truncation (end of file inside the header, or a partial last
/// row).
pub fn parse_reader<R: Read>(reader: R) -> Result<Bvh> {
    let mut lines = LineReader::new(reader);
    let mut header = HeaderParser::default();
    loop {
        if !lines.next()? {
            if lines.line == 0 {
                return Err(Error::bvh(1, "empty file"));
            }
            return Err(Error::bvh(
                lines.line,
                if header.seen_hierarchy {
                    "truncated: end of file inside the header"
                } else {
                    "truncated: end of file before HIERARCHY"
                },
            ));
        }
        let text = String::from_utf8_lossy(&lines.buf);
        let text = if lines.line == 1 {
            text.trim_start_matches('\u{feff}')
        } else {
            &text
        };
        if header.line(text, lines.line)? {
            break;
        }
    }
    let hierarchy = header.finish(lines.line)?;
    let (frames_header, frame_time_s) = read_motion_header(&mut lines)?;
    let n_channels = hierarchy.n_channels();
    let hint = frames_header.map_or(0, |h| usize::try_from(h).unwrap_or(usize::MAX));
    let values = read_rows(&mut lines, n_channels, hint)?;
    let motion = Motion {
        frames_header,
        frame_time_s,
        n_channels,
        values,
    };
    let mut warnings = Vec::new();
    if let Some(h) = frames_header {
        if h != motion.n_frames() as u64 {
            warnings.push(format!(
                "header says Frames: {h} but the data has {} rows (the data rows are used)",
                motion.n_frames()
            ));
        }
    }
    Ok(Bvh {
        hierarchy,
        motion,
        warnings,
    })
}

/// Reads raw lines (bytes, line break stripped) and counts them. A line ends at LF, CRLF,
/// CR…CRLF (one break, as a CRLF file converted twice) or a lone CR (CR-only files, where
/// each further CR is an empty line).
struct LineReader<R> {
    inner: R,
    chunk: Box<[u8]>,
    pos: usize,
    end: usize,
    eof: bool,
    /// The current line, without its break.
    buf: Vec<u8>,
    /// 1-based number of the line in `buf` (0 before the first).
    line: usize,
    /// Empty lines still to return (the further CRs of a CR-only file).
    pending_empty: usize,
}

impl<R: Read> LineReader<R> {
    fn new(inner: R) -> Self {
        LineReader {
            inner,
            chunk: vec![0; READ_CHUNK_BYTES].into_boxed_slice(),
            pos: 0,
            end: 0,
            eof: false,
            buf: Vec::with_capacity(4096),
            line: 0,
            pending_empty: 0,
        }
    }

    /// Refill the buffer when it is used up; false at end of file.
    fn fill(&mut self) -> Result<bool> {
        while self.pos == self.end {
            if self.eof {
                return Ok(false);
            }
            match self.inner.read(&mut self.chunk) {
                Ok(0) => self.eof = true,
                Ok(n) => (self.pos, self.end) = (0, n),
                Err(e) if e.kind() == std::io::ErrorKind::Interrupted => {}
                Err(e) => return Err(Error::bvh(self.line + 1, format!("read error: {e}"))),
            }
        }
        Ok(true)
    }

    /// Read the next line into `buf`; false at end of file.
    fn next(&mut self) -> Result<bool> {
        self.buf.clear();
        if self.pending_empty > 0 {
            self.pending_empty -= 1;
            self.line += 1;
            return Ok(true);
        }
        let mut started = false;
        loop {
            if !self.fill()? {
                if started {
                    self.line += 1;
                }
                return Ok(started);
            }
            started = true;
            let avail = &self.chunk[self.pos..self.end];
            let brk = avail.iter().position(|&b| b == b'\n' || b == b'\r');
            let take = brk.unwrap_or(avail.len());
            if self.buf.len() + take > MAX_LINE_BYTES {
                return Err(Error::bvh(
                    self.line + 1,
                    format!(
                        "line longer than {MAX_LINE_BYTES} bytes without a line break \
                         (not a BVH text file?)"
                    ),
                ));
            }
            self.buf.extend_from_slice(&avail[..take]);
            self.pos += take;
            if let Some(i) = brk {
                let cr = avail[i] == b'\r';
                self.pos += 1;
                self.line += 1;
                if cr {
                    self.after_cr()?;
                }
                return Ok(true);
            }
        }
    }

    /// The next line as a slice and its 1-based number; `None` at end of file. A line that
    /// lies whole in the buffer, ended by LF, CRLF or a CR before other text, is returned
    /// in place (no copy); any other goes through [`LineReader::next`] into `buf`.
    fn next_slice(&mut self) -> Result<Option<(&[u8], usize)>> {
        if self.pending_empty == 0 && self.pos < self.end {
            let avail = &self.chunk[self.pos..self.end];
            if let Some(i) = avail.iter().position(|&b| b == b'\n' || b == b'\r') {
                let brk = match (avail[i], avail.get(i + 1)) {
                    (b'\n', _) => Some(1),
                    (b'\r', Some(b'\n')) => Some(2),
                    (b'\r', Some(b)) if *b != b'\r' => Some(1),
                    _ => None, // CR at the buffer's end, or CR CR: the general path
                };
                if let Some(k) = brk {
                    let start = self.pos;
                    self.pos += i + k;
                    self.line += 1;
                    return Ok(Some((&self.chunk[start..start + i], self.line)));
                }
            }
        }
        Ok(self.next()?.then_some((&self.buf[..], self.line)))
    }

    /// After a CR: further CRs then LF make one break with it; otherwise each further CR
    /// is an empty line.
    fn after_cr(&mut self) -> Result<()> {
        let mut extra = 0;
        while self.fill()? {
            match self.chunk[self.pos] {
                b'\r' => extra += 1,
                b'\n' => {
                    self.pos += 1;
                    return Ok(());
                }
                _ => break,
            }
            self.pos += 1;
        }
        self.pending_empty = extra;
        Ok(())
    }
}

/// What an opening brace opens.
#[derive(Clone, Copy)]
enum Block {
    Joint(usize),
    EndSite(usize),
}

#[derive(Default)]
struct HeaderParser {
    seen_hierarchy: bool,
    joints: Vec<JointDef>,
    /// Joint name → index, for the duplicate check (O(1) per joint).
    index: HashMap<String, usize>,
    has_offset: Vec<bool>,
    stack: Vec<Block>,
    pending: Option<Block>,
    root_closed: bool,
    n_channels: usize,
    end_offset_seen: bool,
}

fn split_token(s: &str) -> (&str, &str) {
    let s = s.trim_start();
    match s.find(|c: char| c.is_whitespace()) {
        Some(i) => (&s[..i], &s[i..]),
        None => (s, ""),
    }
}

fn parse_num(tok: &str, line: usize, what: &str) -> Result<f64> {
    match fast_float2::parse::<f64, _>(tok) {
        Ok(v) if v.is_finite() => Ok(v),
        Ok(_) => Err(Error::bvh(
            line,
            format!("{what}: non-finite value '{}'", echo(tok)),
        )),
        Err(_) => Err(Error::bvh(
            line,
            format!("{what}: '{}' is not a number", echo(tok)),
        )),
    }
}

impl HeaderParser {
    /// Consume one header line; true when the `MOTION` keyword was reached.
    fn line(&mut self, text: &str, line: usize) -> Result<bool> {
        let mut rest = text.trim();
        while !rest.is_empty() {
            let (tok, after) = split_token(rest);
            rest = after.trim_start();
            match tok {
                "HIERARCHY" => {
                    if self.seen_hierarchy {
                        return Err(Error::bvh(line, "repeated HIERARCHY"));
                    }
                    self.seen_hierarchy = true;
                }
                "ROOT" | "JOINT" => {
                    self.joint(tok, rest, line)?;
                    rest = "";
                    if text.trim_end().ends_with('{') {
                        self.open(line)?;
                    }
                }
                "End" => {
                    let (site, after) = split_token(rest);
                    if !site.eq_ignore_ascii_case("site") {
                        return Err(Error::bvh(line, "'End' must be followed by 'Site'"));
                    }
                    let Some(Block::Joint(j)) = self.stack.last().copied() else {
                        return Err(Error::bvh(line, "End Site outside a joint"));
                    };
                    if self.joints[j].end_site.is_some() {
                        return Err(Error::bvh(line, "second End Site in one joint"));
                    }
                    self.pending = Some(Block::EndSite(j));
                    rest = after.trim_start();
                }
                "{" => self.open(line)?,
                "}" => self.close(line)?,
                "OFFSET" => {
                    self.offset(rest, line)?;
                    rest = "";
                }
                "CHANNELS" => {
                    self.channels(rest, line)?;
                    rest = "";
                }
                "MOTION" => {
                    if !self.stack.is_empty() || self.pending.is_some() {
                        return Err(Error::bvh(
                            line,
                            "MOTION inside an open joint block (unbalanced braces)",
                        ));
                    }
                    return Ok(true);
                }
                other => {
                    return Err(Error::bvh(
                        line,
                        format!("unexpected '{}' in the HIERARCHY section", echo(other)),
                    ))
                }
            }
        }
        Ok(false)
    }

    fn joint(&mut self, kw: &str, rest: &str, line: usize) -> Result<()> {
        if !self.seen_hierarchy {
            return Err(Error::bvh(line, format!("{kw} before HIERARCHY")));
        }
        if self.pending.is_some() {
            return Err(Error::bvh(line, "expected '{'"));
        }
        let name = rest.trim().trim_end_matches('{').trim();
        if name.is_empty() {
            return Err(Error::bvh(line, format!("{kw} without a name")));
        }
        let parent = match (kw, self.stack.last()) {
            ("ROOT", None) if self.joints.is_empty() => None,
            ("ROOT", _) => {
                return Err(Error::bvh(
                    line,
                    "second ROOT (only one skeleton per file is supported)",
                ))
            }
            ("JOINT", Some(Block::Joint(p))) => Some(*p),
            ("JOINT", Some(Block::EndSite(_))) => {
                return Err(Error::bvh(line, "JOINT inside an End Site"))
            }
            _ => return Err(Error::bvh(line, "JOINT outside a ROOT block")),
        };
        if let Some(&prev) = self.index.get(name) {
            return Err(Error::bvh(
                line,
                format!(
                    "duplicate joint name '{}' (first at line {})",
                    echo(name),
                    self.joints[prev].line
                ),
            ));
        }
        self.index.insert(name.to_string(), self.joints.len());
        self.joints.push(JointDef {
            name: name.to_string(),
            parent,
            offset: [0.0; 3],
            channels: Vec::new(),
            first_channel: self.n_channels,
            end_site: None,
            line,
        });
        self.has_offset.push(false);
        self.pending = Some(Block::Joint(self.joints.len() - 1));
        Ok(())
    }

    fn open(&mut self, line: usize) -> Result<()> {
        let b = self
            .pending
            .take()
            .ok_or_else(|| Error::bvh(line, "'{' without ROOT, JOINT or End Site"))?;
        if let Block::EndSite(_) = b {
            self.end_offset_seen = false;
        }
        self.stack.push(b);
        Ok(())
    }

    fn close(&mut self, line: usize) -> Result<()> {
        if self.pending.is_some() {
            return Err(Error::bvh(line, "expected '{' before '}'"));
        }
        match self.stack.pop() {
            None => Err(Error::bvh(line, "unbalanced '}'")),
            Some(Block::Joint(j)) => {
                if !self.has_offset[j] {
                    return Err(Error::bvh(
                        line,
                        format!("joint '{}' has no OFFSET", echo(&self.joints[j].name)),
                    ));
                }
                if self.stack.is_empty() {
                    self.root_closed = true;
                }
                Ok(())
            }
            Some(Block::EndSite(j)) => {
                if !self.end_offset_seen {
                    return Err(Error::bvh(
                        line,
                        format!("End Site of '{}' has no OFFSET", echo(&self.joints[j].name)),
                    ));
                }
                Ok(())
            }
        }
    }

    fn offset(&mut self, rest: &str, line: usize) -> Result<()> {
        let toks: Vec<&str> = rest.split_whitespace().collect();
        if toks.len() != 3 {
            return Err(Error::bvh(
                line,
                format!("OFFSET needs 3 numbers, found {}", toks.len()),
            ));
        }
        let mut v = [0.0; 3];
        for (k, t) in toks.iter().enumerate() {
            v[k] = parse_num(t, line, "OFFSET")?;
        }
        match self.stack.last().copied() {
            Some(Block::Joint(j)) if self.pending.is_none() => {
                if self.has_offset[j] {
                    return Err(Error::bvh(line, "second OFFSET in one joint"));
                }
                self.joints[j].offset = v;
                self.has_offset[j] = true;
            }
            Some(Block::EndSite(j)) if self.pending.is_none() => {
                self.joints[j].end_site = Some(v);
                self.end_offset_seen = true;
            }
            _ => return Err(Error::bvh(line, "OFFSET outside a joint block")),
        }
        Ok(())
    }

    fn channels(&mut self, rest: &str, line: usize) -> Result<()> {
        let Some(Block::Joint(j)) = self.stack.last().copied() else {
            return Err(Error::bvh(line, "CHANNELS outside a joint block"));
        };
        if !self.joints[j].channels.is_empty() {
            return Err(Error::bvh(line, "second CHANNELS in one joint"));
        }
        if j + 1 != self.joints.len() {
            return Err(Error::bvh(
                line,
                "CHANNELS after a child joint (channel order would be ambiguous)",
            ));
        }
        let mut toks = rest.split_whitespace();
        let n_tok = toks
            .next()
            .ok_or_else(|| Error::bvh(line, "CHANNELS without a count"))?;
        let n: usize = n_tok.parse().map_err(|_| {
            Error::bvh(
                line,
                format!("CHANNELS count '{}' is not a whole number", echo(n_tok)),
            )
        })?;
        let names: Vec<&str> = toks.collect();
        if names.len() != n {
            return Err(Error::bvh(
                line,
                format!("CHANNELS declares {n} channels but lists {}", names.len()),
            ));
        }
        let mut chans = Vec::with_capacity(n);
        for name in names {
            let c = Channel::from_name(name)
                .ok_or_else(|| Error::bvh(line, format!("unknown channel '{}'", echo(name))))?;
            if chans.contains(&c) {
                return Err(Error::bvh(
                    line,
                    format!("channel '{}' listed twice", echo(name)),
                ));
            }
            chans.push(c);
        }
        self.joints[j].channels = chans;
        self.joints[j].first_channel = self.n_channels;
        self.n_channels += n;
        Ok(())
    }

    fn finish(self, line: usize) -> Result<Hierarchy> {
        if !self.seen_hierarchy {
            return Err(Error::bvh(line, "no HIERARCHY section"));
        }
        if self.joints.is_empty() || !self.root_closed {
            return Err(Error::bvh(line, "no complete ROOT block before MOTION"));
        }
        Ok(Hierarchy {
            joints: self.joints,
        })
    }
}

/// Parse `Frames:` (optional, advisory) and `Frame Time:`.
fn read_motion_header<R: Read>(lines: &mut LineReader<R>) -> Result<(Option<u64>, f64)> {
    let mut frames = None;
    loop {
        if !lines.next()? {
            return Err(Error::bvh(
                lines.line,
                "truncated: end of file before 'Frame Time:'",
            ));
        }
        let text = String::from_utf8_lossy(&lines.buf);
        let t = text.trim();
        if t.is_empty() {
            continue;
        }
        let lower = t.to_ascii_lowercase();
        if let Some(v) = lower.strip_prefix("frame time") {
            let v = v.trim_start().strip_prefix(':').unwrap_or(v).trim();
            let dt = parse_num(v, lines.line, "Frame Time")?;
            if dt <= 0.0 {
                return Err(Error::bvh(
                    lines.line,
                    format!("Frame Time must be positive, found {}", echo(v)),
                ));
            }
            if !(MIN_FRAME_TIME_S..=MAX_FRAME_TIME_S).contains(&dt) {
                return Err(Error::bvh(
                    lines.line,
                    format!("Frame Time {} s is outside 1e-5 to 10 s per frame", echo(v)),
                ));
            }
            return Ok((frames, dt));
        } else if let Some(v) = lower.strip_prefix("frames") {
            let v = v.trim_start().strip_prefix(':').unwrap_or(v).trim();
            let n: u64 = v.parse().map_err(|_| {
                Error::bvh(
                    lines.line,
                    format!("Frames: '{}' is not a whole number", echo(v)),
                )
            })?;
            frames = Some(n);
        } else {
            return Err(Error::bvh(
                lines.line,
                format!("expected 'Frames:' or 'Frame Time:', found '{}'", echo(t)),
            ));
        }
    }
}

/// Most values reserved up front from the `Frames:` header (2²² values, 32 MiB of address
/// space, not touched until filled): a header that lies costs no more than this.
const MAX_RESERVED_VALUES: usize = 1 << 22;

/// Read every data row; values are appended row-major. `frames_hint` (the `Frames:` header,
/// 0 without one) sizes the first allocation.
fn read_rows<R: Read>(lines: &mut LineReader<R>, n: usize, frames_hint: usize) -> Result<Vec<f64>> {
    let mut values = Vec::with_capacity(frames_hint.saturating_mul(n).min(MAX_RESERVED_VALUES));
    let mut short: Option<(usize, usize)> = None;
    while let Some((row, line)) = lines.next_slice()? {
        let start = values.len();
        let count = parse_row(row, &mut values, line)?;
        if count == 0 {
            continue;
        }
        if let Some((l, c)) = short {
            return Err(Error::bvh(l, format!("expected {n} values, found {c}")));
        }
        if count != n {
            values.truncate(start);
            if count > n {
                return Err(Error::bvh(
                    line,
                    format!("expected {n} values, found {count}"),
                ));
            }
            short = Some((line, count));
        }
    }
    if let Some((l, c)) = short {
        return Err(Error::bvh(
            l,
            format!("truncated: partial last row ({c} of {n} values)"),
        ));
    }
    if n == 0 {
        return Err(Error::bvh(lines.line, "the skeleton has no channels"));
    }
    if values.is_empty() {
        return Err(Error::bvh(lines.line, "no data rows (zero frames)"));
    }
    Ok(values)
}

/// [`echo`] of raw bytes, converting only the prefix that can be shown.
fn echo_bytes(raw: &[u8]) -> String {
    // 4 bytes per character at most: this prefix holds more than MAX_ECHO_CHARS of them.
    echo(&String::from_utf8_lossy(
        &raw[..raw.len().min(4 * MAX_ECHO_CHARS + 4)],
    ))
}

/// Split one row on ASCII whitespace and parse every token; returns the token count.
/// Each number is scanned once: `parse_partial` reads it and says where it ends, which
/// must be whitespace or the end of the row.
fn parse_row(buf: &[u8], out: &mut Vec<f64>, line: usize) -> Result<usize> {
    let mut count = 0;
    let mut i = 0;
    let len = buf.len();
    loop {
        while i < len && buf[i].is_ascii_whitespace() {
            i += 1;
        }
        if i == len {
            break;
        }
        let rest = &buf[i..];
        match fast_float2::parse_partial::<f64, _>(rest) {
            Ok((v, n)) if rest.get(n).is_none_or(u8::is_ascii_whitespace) => {
                if !v.is_finite() {
                    return Err(Error::bvh(
                        line,
                        format!(
                            "value {}: non-finite '{}'",
                            count + 1,
                            echo_bytes(&rest[..n])
                        ),
                    ));
                }
                out.push(v);
                i += n;
            }
            _ => {
                let end = rest
                    .iter()
                    .position(u8::is_ascii_whitespace)
                    .unwrap_or(rest.len());
                return Err(Error::bvh(
                    line,
                    format!(
                        "value {}: '{}' is not a number",
                        count + 1,
                        echo_bytes(&rest[..end])
                    ),
                ));
            }
        }
        count += 1;
    }
    Ok(count)
}

#[cfg(test)]
mod tests {
    use super::*;

    const SIMPLE: &str = "HIERARCHY\nROOT Hips\n{\n\tOFFSET 0 0 0\n\tCHANNELS 6 Xposition Yposition Zposition Zrotation Xrotation Yrotation\n\tJOINT mixamorig:Left Leg\n\t{\n\t\tOFFSET 1 -2 3e-1\n\t\tCHANNELS 3 Zrotation Xrotation Yrotation\n\t\tEnd site\n\t\t{\n\t\t\tOFFSET 0 -1 0\n\t\t}\n\t}\n}\nMOTION\nFrames:\t2\nFrame Time: .01\n1 2 3 4 5 6 7 8 9\n-1 -2 -3 -4 -5 -6 -7 -8 9e0\n\n";

    fn err_line(text: &str) -> (usize, String) {
        match parse_reader(text.as_bytes()).unwrap_err().kind {
            crate::error::ErrorKind::Bvh { line, msg, .. } => (line, msg),
            k => panic!("unexpected {k:?}"),
        }
    }

    #[test]
    fn parses_names_channels_end_sites_and_values() {
        let b = parse_reader(SIMPLE.replace('\n', "\r\n").as_bytes()).unwrap();
        assert_eq!(b.hierarchy.joints[1].name, "mixamorig:Left Leg");
        assert_eq!(b.hierarchy.joints[1].parent, Some(0));
        assert_eq!(b.hierarchy.joints[1].offset, [1.0, -2.0, 0.3]);
        assert_eq!(b.hierarchy.joints[1].end_site, Some([0.0, -1.0, 0.0]));
        assert_eq!(b.hierarchy.joints[1].first_channel, 6);
        assert_eq!(b.motion.n_frames(), 2);
        assert_eq!(b.motion.frame_time_s, 0.01);
        assert_eq!(b.motion.row(1)[8], 9.0);
        assert!(b.warnings.is_empty());
    }

    #[test]
    fn header_count_is_advisory() {
        let b = parse_reader(SIMPLE.replace("Frames:\t2", "Frames: 3").as_bytes()).unwrap();
        assert_eq!(b.motion.n_frames(), 2);
        assert_eq!(b.warnings.len(), 1);
        let b = parse_reader(
            SIMPLE
                .replace("Frames:\t2", "Frames: 99999999999999")
                .as_bytes(),
        )
        .unwrap();
        assert_eq!(b.motion.n_frames(), 2);
    }

    #[test]
    fn bom_is_ignored() {
        let t = format!("\u{feff}{SIMPLE}");
        assert!(parse_reader(t.as_bytes()).is_ok());
    }

    #[test]
    fn errors_name_the_line() {
        assert_eq!(err_line(&SIMPLE.replace("-8 9e0", "-8")).0, 20);
        assert!(err_line(&SIMPLE.replace("-8 9e0", "-8"))
            .1
            .contains("truncated"));
        assert_eq!(err_line(&SIMPLE.replace("7 8 9\n", "7 x 9\n")).0, 19);
        assert!(err_line(&SIMPLE.replace("7 8 9\n", "7 nan 9\n"))
            .1
            .contains("non-finite"));
        assert!(err_line(&SIMPLE.replace("7 8 9\n", "7 inf 9\n"))
            .1
            .contains("non-finite"));
        assert_eq!(err_line(&SIMPLE.replace("7 8 9\n", "7 8 9 10\n")).0, 19);
        assert!(err_line(&SIMPLE.replace(".01", "0")).1.contains("positive"));
        assert!(err_line(&SIMPLE.replace(".01", "-0.01"))
            .1
            .contains("positive"));
        assert!(err_line(&SIMPLE.replace(".01", "1e-300"))
            .1
            .contains("outside"));
        assert!(err_line(&SIMPLE.replace(".01", "3600"))
            .1
            .contains("outside"));
        assert!(err_line(&SIMPLE.replace("End site", "End"))
            .1
            .contains("Site"));
        assert!(err_line(&SIMPLE.replace("ROOT Hips", "ROOT"))
            .1
            .contains("name"));
        assert!(err_line(&SIMPLE.replace("mixamorig:Left Leg", "Hips"))
            .1
            .contains("duplicate"));
        assert!(err_line(&SIMPLE.replace("CHANNELS 3", "CHANNELS 4"))
            .1
            .contains("declares 4"));
        assert!(err_line(&format!("HIERARCHY\n{SIMPLE}"))
            .1
            .contains("repeated"));
        let (line, msg) = err_line(&SIMPLE[..SIMPLE.find("MOTION").unwrap() - 2]);
        assert!(msg.contains("truncated"), "{msg} at {line}");
        assert!(err_line(&SIMPLE[..SIMPLE.find("1 2 3").unwrap()])
            .1
            .contains("zero frames"));
        assert!(err_line(&SIMPLE.replace("MOTION", "}\nMOTION"))
            .1
            .contains("unbalanced"));
    }

    #[test]
    fn short_row_in_the_middle_is_a_count_error() {
        let t = SIMPLE.replace("1 2 3 4 5 6 7 8 9", "1 2 3 4 5 6 7 8");
        let (line, msg) = err_line(&t);
        assert_eq!(line, 19);
        assert!(msg.contains("expected 9 values, found 8"), "{msg}");
    }
}
