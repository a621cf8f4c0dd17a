//! One clip from parsed BVH to per-frame COM, contacts and per-clip diagnostics.
//!
//! # Model
//! ```text
//! Bvh → Skeleton → landmarks → lead-in                                  (ingest)
//!     → points::clip_points: FK (file frame) → unit, up axis → points (m, Z up)
//!     → points::toe_tips → COM (de Leva) → SG velocity/acceleration      (clip::run)
//!     → contacts::tracks (local floor) → contacts::detect (timeline)
//!     → contacts::runs_and_flights: contact runs (§8), cross-check, flights (§7.7)
//! ```
//! `clip` is that sequence of stage calls; `points` holds the FK, unit, up-axis and toe-tip
//! steps that [`body::BodyModel`] shares. Pure: no I/O. The batch layer (`library`, `cli`)
//! reads files and writes tables.
//!
//! # References
//! spec com-from-bvh §1–§8.

pub mod body;
mod clip;
pub mod knee_branch;
pub mod masses;
pub mod plates;
mod points;
pub mod reach;

use std::collections::BTreeMap;

use crate::bvh::Bvh;
use crate::contacts::flight::Flight;
use crate::contacts::ContactOptions;
use crate::error::Result;
use crate::skeleton::com::Sex;
use crate::skeleton::landmarks::{self, Mapping};
use crate::skeleton::units::UpAxis;
use crate::skeleton::{fk, leadin, Skeleton};

pub use crate::contacts::ContactRun;

/// Default body mass, kg (spec com-from-bvh §5).
pub const DEFAULT_MASS_KG: f64 = 70.0;

/// Largest clip ingested, in point samples: points (joints and End Sites) × frames
/// (2²⁶ = 67,108,864). Forward kinematics holds every point of every frame at once, 24
/// bytes each (three f64), so this bounds that array to 1.5 GiB per clip. Ordinary clips
/// stay far below: CMU clips (38 points, 120 Hz) take about 20 bytes of file per point
/// sample, so a clip of the largest file read (`MAX_BVH_BYTES`, 1 GiB) is about 55 million.
/// Joints without channels cost a few bytes of file each but 24 bytes per frame, so a
/// small file can ask for gigabytes (100,000 `CHANNELS 0` joints × 2,500 frames: 6 GB);
/// such a clip is an error of its own, checked before the skeleton is used.
pub const MAX_POINT_SAMPLES: usize = 1 << 26;

/// Options of the ingest stage.
#[derive(serde::Serialize, Debug, Clone, PartialEq)]
pub struct IngestOptions {
    /// Body mass, kg (scales forces downstream; does not move the COM).
    pub mass_kg: f64,
    /// de Leva column.
    pub sex: Sex,
    /// Unit override, metres per file unit.
    pub unit_m: Option<f64>,
    /// Up-axis override.
    pub up_axis: Option<UpAxis>,
    /// Landmark overrides (`AJC_L` → joint name, …).
    pub landmarks: BTreeMap<String, String>,
    /// Contact thresholds.
    pub contacts: ContactOptions,
    /// Keep every joint's world position (for `joints.parquet`).
    pub joints: bool,
    /// Character id from the body file (`id`); derived from the skeleton when `None`.
    pub character_id: Option<String>,
    /// Whether `mass_kg` was given (`--mass`, a body or pipeline `mass_kg`); the default
    /// mass is a warning on every clip that no masses row names.
    pub mass_given: bool,
    /// Per-clip masses (`--masses`, pipeline `masses`), first over `mass_kg`.
    #[serde(serialize_with = "masses::serialize_rows")]
    pub masses: Option<std::sync::Arc<masses::MassTable>>,
}

/// Where a clip's body mass came from (`clips.parquet` `mass_source`).
pub const MASS_SOURCE_DEFAULT: &str = "default";
/// `--mass` or a body or pipeline file's `mass_kg`.
pub const MASS_SOURCE_GIVEN: &str = "mass_kg";

impl IngestOptions {
    /// The mass, sex and `mass_source` of one clip: the first masses row that matches it
    /// (`table <file>:<line>`), else `mass_kg` (given or the default).
    pub fn body_of(&self, clip: &str) -> (f64, Sex, String) {
        match self
            .masses
            .as_ref()
            .and_then(|t| t.lookup(clip).map(|r| (t, r)))
        {
            Some((t, r)) => (
                r.mass_kg,
                r.sex.unwrap_or(self.sex),
                format!("table {}:{}", t.file, r.line),
            ),
            None if self.mass_given => (self.mass_kg, self.sex, MASS_SOURCE_GIVEN.into()),
            None => (self.mass_kg, self.sex, MASS_SOURCE_DEFAULT.into()),
        }
    }
}

impl Default for IngestOptions {
    fn default() -> Self {
        IngestOptions {
            mass_kg: DEFAULT_MASS_KG,
            sex: Sex::Male,
            unit_m: None,
            up_axis: None,
            landmarks: BTreeMap::new(),
            contacts: ContactOptions::default(),
            joints: false,
            character_id: None,
            mass_given: false,
            masses: None,
        }
    }
}

/// Per-frame outputs of a clip (kept frames only), metres, Z up.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct ClipFrames {
    /// File row index per kept frame.
    pub frame: Vec<i64>,
    /// `frame · dt`, s.
    pub time_s: Vec<f64>,
    /// Whole-body COM, m.
    pub com: Vec<[f64; 3]>,
    /// SG COM velocity, m/s.
    pub com_v: Vec<[f64; 3]>,
    /// SG COM acceleration, m/s².
    pub com_a: Vec<[f64; 3]>,
    /// Local floor height, m.
    pub ground_z: Vec<f64>,
    /// Contact flags per effector (`contacts::EFFECTORS` order).
    pub contact: [Vec<bool>; 4],
    /// Static flags per effector (static mode only).
    pub static_contact: Option<[Vec<bool>; 4]>,
    /// Static surface height per effector and frame (static mode only).
    pub surface_z: Option<[Vec<Option<f64>>; 4]>,
    /// Ankle (feet) or wrist (hands) centre per effector; `None` without that limb.
    pub effector_pos: [Option<Vec<[f64; 3]>>; 4],
    /// Left and right toe tips.
    pub toe: [Vec<[f64; 3]>; 2],
    /// Horizontal facing direction from the hips per frame (unit; stance-model §2).
    pub facing: Vec<[f64; 3]>,
    /// All joint and End Site positions (`--joints`): names and frames × points.
    pub joints: Option<(Vec<String>, Vec<[f64; 3]>)>,
}

/// Per-clip results (the `clips.parquet` fields that come from the motion).
#[derive(Debug, Clone, PartialEq, Default)]
pub struct ClipSummary {
    /// `Frames:` header value.
    pub frames_header: Option<i64>,
    /// Complete data rows.
    pub frames_data: i64,
    /// Kept frames.
    pub frames_kept: i64,
    /// Dropped lead-in rows.
    pub leadin_dropped: Vec<i64>,
    /// Frame time, s.
    pub frame_time_s: f64,
    /// Metres per file unit.
    pub unit_scale: Option<f64>,
    /// Unit name, `estimated` or `override`.
    pub unit: Option<String>,
    /// Up axis used.
    pub up_axis: Option<String>,
    /// Handedness check passed.
    pub handedness_ok: Option<bool>,
    /// Leg length, m.
    pub leg_length_m: Option<f64>,
    /// How far from its COM the body reaches a contact, m ([`reach`]).
    pub reach_m: Option<f64>,
    /// `landmark=joint` pairs.
    pub skeleton: Option<String>,
    /// Toe-tip rules, left and right.
    pub toe_tip_rule: [Option<String>; 2],
    /// Flights (no-contact runs not at a clip edge).
    pub flights: Vec<Flight>,
    /// Median `a_z` over airborne intervals, m/s².
    pub flight_az_median: Option<f64>,
    /// Clip effective time scale.
    pub s_eff: Option<f64>,
    /// Advisory messages.
    pub warnings: Vec<String>,
    /// Where the body mass came from: `table <file>:<line>`, `mass_kg` (given) or `default`.
    pub mass_source: String,
    /// Character id (stance-model §11): the body file's `id`, else `sk-` + 12 hex digits.
    pub character_id: Option<String>,
}

/// What ingesting a clip gives.
// Returned once per clip and destructured at once: boxing the large variant buys nothing.
#[allow(clippy::large_enum_variant)]
#[derive(Debug, Clone, PartialEq)]
pub enum ClipOutcome {
    /// A body with enough frames.
    Body {
        /// Per-clip fields.
        summary: ClipSummary,
        /// Per-frame table.
        frames: ClipFrames,
        /// Contact runs.
        contacts: Vec<ContactRun>,
    },
    /// Not a body, or too short: not a failure.
    Skipped {
        /// Per-clip fields known so far.
        summary: ClipSummary,
        /// Why.
        reason: String,
    },
}

/// Refuses a clip whose forward kinematics would hold more than [`MAX_POINT_SAMPLES`]
/// point samples (`n_points` × `n_frames`).
///
/// # Errors
/// [`crate::ErrorKind::Cap`] naming both counts and the cap.
pub fn check_point_samples(n_points: usize, n_frames: usize) -> Result<()> {
    let samples = n_points as f64 * n_frames as f64;
    if samples > MAX_POINT_SAMPLES as f64 {
        return Err(crate::error::Error::cap(
            format!("{n_points} points (joints and End Sites) × {n_frames} frames"),
            "point samples (24 bytes each)",
            samples,
            MAX_POINT_SAMPLES,
            "MAX_POINT_SAMPLES",
        ));
    }
    Ok(())
}

/// Ingest one parsed clip.
///
/// # Errors
/// More point samples than [`MAX_POINT_SAMPLES`] (`ErrorKind::Cap`, checked before the
/// skeleton is used); a segment far longer than the skeleton's others
/// (`ErrorKind::Skeleton`, [`crate::skeleton::plausibility`]: before forward kinematics);
/// a partial landmark mapping (spec com-from-bvh §1.1), a `[landmarks]` override that
/// names no joint (`ErrorKind::Skeleton`); a frame time so short that the smoothing window
/// exceeds `MAX_SAVGOL_WINDOW` (`ErrorKind::Smoothing`, checked before any per-frame
/// work); offsets and angles so large that a leg length, a position, the COM or its
/// derivatives overflow f64 (`ErrorKind::NonFinite`, naming the first bad frame and joint).
pub fn ingest(bvh: &Bvh, opts: &IngestOptions) -> Result<ClipOutcome> {
    let m = &bvh.motion;
    let mut summary = ClipSummary {
        frames_header: m.frames_header.map(|v| v.min(i64::MAX as u64) as i64),
        frames_data: m.n_frames() as i64,
        frame_time_s: m.frame_time_s,
        warnings: bvh.warnings.clone(),
        ..Default::default()
    };
    let skel = Skeleton::from_bvh(bvh);
    check_point_samples(skel.n_points(), m.n_frames())?;
    crate::skeleton::plausibility::check_segments(&skel)?;
    let rest = fk::rest_pose(&skel);
    let lm = match landmarks::map(&skel, &rest, &opts.landmarks)? {
        Mapping::NotABody => {
            let reason =
                "no body landmark found (no sided ankle, knee or hip, no head)".to_string();
            return Ok(ClipOutcome::Skipped { summary, reason });
        }
        Mapping::Found(lm) => lm,
    };
    let skip = leadin::leadin_frames(&skel, m);
    summary.leadin_dropped = (0..skip as i64).collect();
    summary.frames_kept = (m.n_frames() - skip) as i64;
    summary.skeleton = Some(lm.describe(&skel));
    // Refused before any per-frame work when above MAX_SAVGOL_WINDOW.
    let w = crate::math::savgol::window_for_frame_time(m.frame_time_s)?;
    if m.n_frames() - skip < w {
        let reason = format!(
            "too short: {} kept frames, fewer than the SG window of {w}",
            m.n_frames() - skip
        );
        return Ok(ClipOutcome::Skipped { summary, reason });
    }
    let src = points::ClipSource {
        skel: &skel,
        lm: &lm,
        rest_file: &rest,
        bvh,
        skip,
        opts,
    };
    let (frames, contacts) = clip::run(&src, &mut summary)?;
    Ok(ClipOutcome::Body {
        summary,
        frames,
        contacts,
    })
}
