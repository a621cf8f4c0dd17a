//! Stances: segmentation of a clip's contacts into stances, the heading frame and the six
//! stance parameters, the Stage A force model and the precomputed constraint coefficients
//! of each stance (one `stances.parquet` row each).
//!
//! Data flow: `ingest::ClipFrames` → [`segment`] → per stance: heading and touchdown state
//! ([`params`]) → `force_model::fit_stage_a` → `constraints::precompute` → [`Stance`];
//! [`assemble_clip`] runs it for every stance of one clip.
//!
//! # References
//! spec stance-model §1–§5, §7.2, §8.1–§8.2, §11.

pub mod assemble;
pub mod ids;
pub mod limits;
pub mod params;
pub mod segment;

pub use assemble::{assemble_clip, StanceOptions};

use crate::constraints::Coefficients;
use crate::force_model::{ForceModel, ForceModelKind};
use params::{Heading, StanceParams};
use segment::Boundary;

/// The fit of a flight next to a stance (`flight_before`, `flight_after`).
#[derive(Debug, Clone, PartialEq)]
pub struct FlightRef {
    /// First no-contact frame (file row).
    pub first_frame: i64,
    /// Last no-contact frame (file row).
    pub last_frame: i64,
    /// Interior frames of the fit.
    pub n_int: i64,
    /// Free-curvature fit (`n_int ≥ 4`).
    pub free: bool,
    /// Fitted or fixed vertical curvature, or `ā_z` without a fit, m/s².
    pub a_z: f64,
    /// The edge parabola's velocity at this stance's touchdown (before) or liftoff (after),
    /// world m/s (curvature −g; the flight's own fit when that has none); `None` when
    /// neither exists.
    pub vel: Option<[f64; 3]>,
}

/// One stance: everything a `stances.parquet` row holds.
#[derive(Debug, Clone, PartialEq)]
pub struct Stance {
    /// `<clip>:<label>:<first frame>`.
    pub stance_id: String,
    /// Clip name.
    pub clip: String,
    /// Character id.
    pub character_id: String,
    /// `L`, `R`, `LR`, `LR+LH`, …
    pub label: String,
    /// Supporting effectors, sorted.
    pub effectors: Vec<String>,
    /// First stance frame (file row).
    pub first_frame: i64,
    /// Last stance frame (file row).
    pub last_frame: i64,
    /// Touchdown in clip time, s.
    pub td_clip_s: f64,
    /// Liftoff in clip time, s.
    pub lo_clip_s: f64,
    /// Ground time Δt, s.
    pub dt_s: f64,
    /// Start boundary.
    pub boundary_start: Boundary,
    /// End boundary.
    pub boundary_end: Boundary,
    /// SG COM speed below `v_quiet` at a clip-edge end.
    pub rest_at_edge: bool,
    /// Adjacent flight before, when `boundary_start` is a flight.
    pub flight_before: Option<FlightRef>,
    /// Adjacent flight after, when `boundary_end` is a flight.
    pub flight_after: Option<FlightRef>,
    /// Heading frame.
    pub heading: Heading,
    /// Contact height `z_c`, m.
    pub z_c: f64,
    /// Model-consistent parameters.
    pub params: StanceParams,
    /// The same from the measured liftoff state (`ze`, `ve`, `vp`, `x` used).
    pub measured: StanceParams,
    /// Body mass, kg.
    pub mass_kg: f64,
    /// The force model (stance axes).
    pub model: ForceModel,
    /// Contact point `(cp_h, cp_p)`, m.
    pub cp: [f64; 2],
    /// Precomputed constraint coefficients and extremes.
    pub coef: Coefficients,
    /// Which force model was fitted.
    pub force_model: ForceModelKind,
    /// `q_h`, `q_p` of the ratio model (power basis in τ, unit-free); empty for Fourier.
    pub ratio: [Vec<f64>; 2],
    /// Advisory messages.
    pub warnings: Vec<String>,
}
