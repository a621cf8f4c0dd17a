//! BVH reader and writer: hierarchy and motion, in f64, streaming, with line-numbered
//! errors; [`write_file`] writes what the reader reads (the edited motion of `edit`).
//!
//! # Model
//! ```text
//! HIERARCHY
//! ROOT <name> { OFFSET x y z  CHANNELS n <ch1> … <chn>  JOINT <name> { … } … }
//! MOTION
//! Frames: <F>            advisory: the data rows decide (spec com-from-bvh §1)
//! Frame Time: <dt>       seconds, used as given
//! <rows of Σn floats, joints in file (depth-first) order>
//! ```
//! Joints are stored flat in file order, so `parent[i] < i` (parents before children).
//!
//! # Frames and units
//! Values are in the file's own axes and length unit; rotations in degrees. Mapping to
//! metres and Z up happens later (`skeleton::units`).
//!
//! # References
//! spec `com-from-bvh.md` §1 (structure, advisory frame count), §1.1 (large files stream).
//!
//! # Examples
//! ```
//! let text = "HIERARCHY\nROOT Hips\n{\n OFFSET 0 0 0\n CHANNELS 3 Xposition Yposition Zposition\n End Site\n {\n  OFFSET 0 1 0\n }\n}\nMOTION\nFrames: 2\nFrame Time: 0.01\n0 0 0\n1 2 3\n";
//! let bvh = stancelib::bvh::parse_reader(text.as_bytes()).unwrap();
//! assert_eq!(bvh.motion.n_frames(), 2);
//! assert_eq!(bvh.motion.row(1), &[1.0, 2.0, 3.0]);
//! ```

mod parse;
mod write;

pub use parse::{parse_file, parse_reader, MAX_FRAME_TIME_S, MAX_LINE_BYTES, MIN_FRAME_TIME_S};
pub use write::{hierarchy_text, write_file, write_writer, DEFAULT_SIGNIFICANT_DIGITS};

/// One channel of a joint: a translation or a rotation about a file axis.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Channel {
    /// Translation along file X.
    Xposition,
    /// Translation along file Y.
    Yposition,
    /// Translation along file Z.
    Zposition,
    /// Rotation about file X, degrees.
    Xrotation,
    /// Rotation about file Y, degrees.
    Yrotation,
    /// Rotation about file Z, degrees.
    Zrotation,
}

impl Channel {
    /// Parse a channel name as written in BVH files (case-insensitive).
    pub fn from_name(s: &str) -> Option<Channel> {
        Some(match s.to_ascii_lowercase().as_str() {
            "xposition" => Channel::Xposition,
            "yposition" => Channel::Yposition,
            "zposition" => Channel::Zposition,
            "xrotation" => Channel::Xrotation,
            "yrotation" => Channel::Yrotation,
            "zrotation" => Channel::Zrotation,
            _ => return None,
        })
    }

    /// The file axis (0 = X, 1 = Y, 2 = Z).
    pub fn axis(self) -> usize {
        match self {
            Channel::Xposition | Channel::Xrotation => 0,
            Channel::Yposition | Channel::Yrotation => 1,
            Channel::Zposition | Channel::Zrotation => 2,
        }
    }

    /// True for a rotation channel.
    pub fn is_rotation(self) -> bool {
        matches!(
            self,
            Channel::Xrotation | Channel::Yrotation | Channel::Zrotation
        )
    }
}

/// One joint of the hierarchy, as declared.
#[derive(Debug, Clone, PartialEq)]
pub struct JointDef {
    /// The name as written (rest of the line, trimmed; may contain spaces or `:`).
    pub name: String,
    /// Index of the parent joint (`None` for the root); always less than this joint's index.
    pub parent: Option<usize>,
    /// OFFSET, file units.
    pub offset: [f64; 3],
    /// Channels in the order listed.
    pub channels: Vec<Channel>,
    /// Index of this joint's first channel within a motion row.
    pub first_channel: usize,
    /// End Site OFFSET, when the joint has one.
    pub end_site: Option<[f64; 3]>,
    /// 1-based line of the `ROOT`/`JOINT` keyword.
    pub line: usize,
}

/// The HIERARCHY section: joints in file order (parents before children).
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Hierarchy {
    /// Joints in file (depth-first) order.
    pub joints: Vec<JointDef>,
}

impl Hierarchy {
    /// Total number of channels in a motion row.
    pub fn n_channels(&self) -> usize {
        self.joints.iter().map(|j| j.channels.len()).sum()
    }
}

/// The MOTION section: `n_frames × n_channels` values, row-major.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Motion {
    /// The `Frames:` header value (advisory).
    pub frames_header: Option<u64>,
    /// `Frame Time`, seconds, as given.
    pub frame_time_s: f64,
    /// Channels per row.
    pub n_channels: usize,
    /// Row-major values; length `n_frames · n_channels`.
    pub values: Vec<f64>,
}

impl Motion {
    /// Number of complete data rows.
    pub fn n_frames(&self) -> usize {
        self.values.len().checked_div(self.n_channels).unwrap_or(0)
    }

    /// The values of row `f`.
    pub fn row(&self, f: usize) -> &[f64] {
        &self.values[f * self.n_channels..(f + 1) * self.n_channels]
    }
}

/// A parsed BVH file.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Bvh {
    /// The joint tree.
    pub hierarchy: Hierarchy,
    /// The frames.
    pub motion: Motion,
    /// Advisory problems (for example a `Frames:` count that disagrees with the data).
    pub warnings: Vec<String>,
}

impl Bvh {
    /// The clip of a character `length` times as long: joint offsets, End Sites and every
    /// position channel × `length` (rotations kept), so FK positions scale by `length`.
    pub fn scaled(mut self, length: f64) -> Bvh {
        if length == 1.0 {
            return self;
        }
        let mut position = vec![false; self.motion.n_channels];
        for j in &mut self.hierarchy.joints {
            j.offset = j.offset.map(|v| v * length);
            j.end_site = j.end_site.map(|e| e.map(|v| v * length));
            for (k, c) in j.channels.iter().enumerate() {
                if let Some(p) = position.get_mut(j.first_channel + k) {
                    *p = !c.is_rotation();
                }
            }
        }
        let nc = self.motion.n_channels.max(1);
        for (i, v) in self.motion.values.iter_mut().enumerate() {
            if position[i % nc] {
                *v *= length;
            }
        }
        self
    }
}
