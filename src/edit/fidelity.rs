//! Does an edited motion keep its recording's posture and smoothness (issue 37 item 5)? The
//! trunk lean and the knee flexion of every written frame against the range the source
//! recorded, a knee held straight through a flight where the source bends it, and root
//! accelerations above 5 g that the source does not have.
//!
//! # Model
//! ```text
//! per frame, from FK of the written (or the source) pose, Z up:
//!   trunk lean     λ = atan2((C − M)·f, (C − M)·z)          deg, forward +
//!                  M = (H_L + H_R)/2 (mid-hip), C: neck base (CERV; the trunk segment of
//!                  the COM model), l = horizontal unit of H_L − H_R, f = l × z
//!   knee flexion   κ = 180° − ∠(H, K, A)                     deg, 0 = straight
//!   root accel.    a_i = |r_{i+1} − 2 r_i + r_{i−1}| / Δt²   m/s² (0 on the first and last frame)
//! recorded: the source frames from the first to the last clip time the edit's poses are
//!   taken from (each frame's source time: FramePose::source_time_s)
//! checks:
//!   lean    λ_min − tol_λ ≤ λ ≤ λ_max + tol_λ
//!   knees   κ_min − tol_κ ≤ κ ≤ κ_max + tol_κ          (both legs pooled)
//!   flight  a leg with κ < κ_lock on every frame of a whole flight (between two stances)
//!           whose source poses bend it (κ ≥ κ_lock on some frame) is locked
//!   spike   a_i > a_max on a frame whose source time has no source frame above a_max
//!           within one frame (the capture's own jitter stays where it was)
//! ```
//!
//! # Frames and units
//! Positions in metres (internal frame, Z up), angles in degrees, accelerations in m/s².
//!
//! # Examples
//! ```
//! use stancelib::edit::fidelity::{knee_flexion_deg, trunk_lean_deg};
//! // Hips 0.2 m apart along y (left +y), neck base 0.5 m up and 0.1 m forward (+x).
//! let (hl, hr) = ([0.0, 0.1, 1.0], [0.0, -0.1, 1.0]);
//! let lean = trunk_lean_deg(hl, hr, [0.1, 0.0, 1.5], [0.0, 0.0, 1.0]);
//! assert!((lean - 0.2f64.atan().to_degrees()).abs() < 1e-12);
//! // A straight leg has no flexion, a right angle at the knee 90°.
//! assert!(knee_flexion_deg([0.0, 0.0, 1.0], [0.0, 0.0, 0.5], [0.0, 0.0, 0.0]).abs() < 1e-9);
//! assert!((knee_flexion_deg([0.0, 0.0, 1.0], [0.0, 0.0, 0.5], [0.5, 0.0, 0.5]) - 90.0).abs() < 1e-9);
//! ```

use super::path::Phase;
use super::pose::FramePose;
use crate::bvh::Motion;
use crate::ingest::body::BodyModel;
use crate::math::v3::{cross, dot, norm, sub, V3};
use crate::skeleton::fk::FkWorkspace;

/// Standard gravity, m/s² (the unit of the spike threshold).
pub const G_MPS2: f64 = 9.81;
/// How far an edited trunk may lean beyond the recorded range, degrees. The ten runs of
/// CMU subject 9 (3.45–3.65 m/s, `bvh-bulk/cmu/09_*`) reach a largest lean of 15.7–20.2°:
/// one runner at one speed varies by 4.5° between trials; a speed change of a few tenths
/// of the recorded one may add a few degrees, not the 20° the posture solver used to add.
pub const DEFAULT_LEAN_TOL_DEG: f64 = 5.0;
/// How far an edited knee may flex beyond the recorded range, degrees. Swing flexion grows
/// with speed: the same runner (Hamner) peaks at 89° at 2 m/s and 103° at 3 m/s, and the
/// ten CMU subject-9 runs at one speed peak at 111.9–124.7°.
pub const DEFAULT_KNEE_TOL_DEG: f64 = 10.0;
/// A knee flexed less than this is locked (within 10° of 180°), degrees; the edit's
/// straightest leg (`DEFAULT_MAX_REACH` 0.999) measures 2.6–5.1°.
pub const DEFAULT_KNEE_LOCK_DEG: f64 = 10.0;
/// A root acceleration above this between consecutive frames is a spike, m/s² (5 g).
pub const DEFAULT_SPIKE_MPS2: f64 = 5.0 * G_MPS2;

/// The bounds of the checks.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FidelityOptions {
    /// [`DEFAULT_LEAN_TOL_DEG`].
    pub lean_tol_deg: f64,
    /// [`DEFAULT_KNEE_TOL_DEG`].
    pub knee_tol_deg: f64,
    /// [`DEFAULT_KNEE_LOCK_DEG`].
    pub knee_lock_deg: f64,
    /// [`DEFAULT_SPIKE_MPS2`].
    pub spike_mps2: f64,
    /// Whether a knee straighter than recorded fails (a run), or only one more bent (a
    /// jump: higher than recorded it must extend further at liftoff, which the flight check
    /// watches after).
    pub knee_extension: bool,
    /// Whether a root acceleration spike fails (a jump), or is only reported (a run: see
    /// [`FidelityOptions::run`]).
    pub spikes: bool,
}

impl FidelityOptions {
    /// The checks of `edit run`: lean and knee within the recorded range both ways; spikes
    /// reported. A run's root inherits the capture's jitter, time-warped: the CMU run's own
    /// second differences reach 10.8 g, and its edits at 4–5 m/s reach 9.6–13.4 g on
    /// frames where the recording's are under 5 g, at liftoffs where the piecewise-linear
    /// time warp changes rate (a known miss: `docs/edited-motion.md`).
    pub fn run() -> FidelityOptions {
        FidelityOptions {
            knee_extension: true,
            spikes: false,
            ..FidelityOptions::default()
        }
    }

    /// The checks of `edit jump`: lean, knee flexion, bent knees in flight and no spike.
    pub fn jump() -> FidelityOptions {
        FidelityOptions {
            knee_extension: false,
            spikes: true,
            ..FidelityOptions::default()
        }
    }
}

impl Default for FidelityOptions {
    fn default() -> Self {
        FidelityOptions {
            lean_tol_deg: DEFAULT_LEAN_TOL_DEG,
            knee_tol_deg: DEFAULT_KNEE_TOL_DEG,
            knee_lock_deg: DEFAULT_KNEE_LOCK_DEG,
            spike_mps2: DEFAULT_SPIKE_MPS2,
            knee_extension: true,
            spikes: true,
        }
    }
}

/// What one frame measures.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Gauge {
    /// Trunk lean, deg (forward +).
    pub lean_deg: f64,
    /// Knee flexion, left and right, deg (0 = straight).
    pub knee_deg: [f64; 2],
    /// Root acceleration, m/s² (0 on the first and last frame).
    pub root_accel_mps2: f64,
    /// Acceleration of the root relative to the pose's COM, m/s² (0 on the first and last
    /// frame): the pose's own motion, without the COM's.
    pub root_rel_accel_mps2: f64,
}

/// One flight of the edit: its frames and each leg's largest knee flexion, edited and in
/// the source poses of those frames.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FlightKnees {
    /// First frame and number of frames.
    pub frames: (usize, usize),
    /// Largest edited flexion per leg, deg.
    pub edited_max_deg: [f64; 2],
    /// Largest source flexion per leg at the frames' source times, deg.
    pub source_max_deg: [f64; 2],
    /// Frames with the knee locked, per leg.
    pub locked_frames: [usize; 2],
}

/// The checks of one edit.
#[derive(Debug, Clone, PartialEq)]
pub struct Fidelity {
    /// Per written frame.
    pub frames: Vec<Gauge>,
    /// Lean range, recorded and edited, deg.
    pub lean_recorded_deg: [f64; 2],
    /// See `lean_recorded_deg`.
    pub lean_edited_deg: [f64; 2],
    /// Knee flexion range (both legs), recorded and edited, deg.
    pub knee_recorded_deg: [f64; 2],
    /// The reference's swing knees were folded by the run speed law (`super::swing`): the
    /// "recorded" ranges are the recording's with that fold, and the texts say so.
    pub swing_folded: bool,
    /// See `knee_recorded_deg`.
    pub knee_edited_deg: [f64; 2],
    /// Frames whose lean or knee is outside the recorded range plus its tolerance.
    pub lean_outside: usize,
    /// See `lean_outside`.
    pub knee_outside: usize,
    /// Every flight of the edit.
    pub flights: Vec<FlightKnees>,
    /// Largest root acceleration, edited and over the recorded frames, m/s².
    pub root_accel_max_mps2: f64,
    /// See `root_accel_max_mps2`.
    pub source_root_accel_max_mps2: f64,
    /// Frames with a root acceleration spike the source does not have.
    pub spikes: Vec<usize>,
    /// The bounds checked.
    pub options: FidelityOptions,
}

/// Trunk lean λ (deg, forward +) of a pose: hips `hl`, `hr`, neck base `cerv`, unit `up`
/// (any frame, one unit).
pub fn trunk_lean_deg(hl: V3, hr: V3, cerv: V3, up: V3) -> f64 {
    let d = sub(hl, hr);
    let lat = sub(d, up.map(|u| u * dot(d, up)));
    let trunk = sub(cerv, std::array::from_fn(|i| 0.5 * (hl[i] + hr[i])));
    let fwd = cross(lat, up);
    let n = norm(fwd);
    let f = if n > 0.0 { dot(trunk, fwd) / n } else { 0.0 };
    f.atan2(dot(trunk, up)).to_degrees()
}

/// Knee flexion κ = 180° − ∠(hip, knee, ankle), deg ([`crate::math::v3::flexion_deg`]).
pub use crate::math::v3::flexion_deg as knee_flexion_deg;

/// Every frame of `motion` measured with `body` (rows in `body`'s channel layout).
pub fn gauge(body: &BodyModel, motion: &Motion) -> Vec<Gauge> {
    let sk = &body.skeleton;
    let lm = &body.landmarks;
    let root = (0..sk.n_joints())
        .find(|&j| sk.parents[j].is_none())
        .unwrap_or(0);
    let mut ws = FkWorkspace::new(sk);
    let (mut file, mut pts) = (vec![[0.0; 3]; sk.n_points()], vec![[0.0; 3]; sk.n_points()]);
    let n = motion.n_frames();
    let mut roots = Vec::with_capacity(n);
    let mut out = Vec::with_capacity(n);
    for f in 0..n {
        body.points(&mut ws, motion.row(f), &mut file, &mut pts);
        let legs = [&lm.left, &lm.right];
        out.push(Gauge {
            lean_deg: trunk_lean_deg(
                pts[lm.left.hip],
                pts[lm.right.hip],
                pts[lm.cerv],
                [0.0, 0.0, 1.0],
            ),
            knee_deg: legs.map(|l| knee_flexion_deg(pts[l.hip], pts[l.knee], pts[l.ankle])),
            root_accel_mps2: 0.0,
            root_rel_accel_mps2: 0.0,
        });
        let c = body.com(&pts);
        roots.push((
            pts[root],
            std::array::from_fn::<f64, 3, _>(|k| pts[root][k] - c[k]),
        ));
    }
    let dt2 = motion.frame_time_s * motion.frame_time_s;
    let second = |p: &dyn Fn(usize) -> V3, i: usize| -> f64 {
        let (a, b, c) = (p(i - 1), p(i), p(i + 1));
        norm(std::array::from_fn(|k| c[k] - 2.0 * b[k] + a[k])) / dt2
    };
    for (i, g) in out.iter_mut().enumerate().take(n.saturating_sub(1)).skip(1) {
        g.root_accel_mps2 = second(&|j| roots[j].0, i);
        g.root_rel_accel_mps2 = second(&|j| roots[j].1, i);
    }
    out
}

/// The knee flexion range (both legs, deg) of the source `motion` between clip times `t0`
/// and `t1` (s; the frames nearest them, past the lead-in rows), `[+∞, −∞]` when empty.
pub fn recorded_knee_range(body: &BodyModel, motion: &Motion, t0: f64, t1: f64) -> [f64; 2] {
    let g = gauge(body, motion);
    let last = g.len().saturating_sub(1);
    let frame = |t: f64| {
        ((t / motion.frame_time_s).round().max(0.0) as usize).clamp(body.leadin.min(last), last)
    };
    let span = if g.is_empty() || t0 > t1 {
        &g[..0]
    } else {
        &g[frame(t0)..=frame(t1)]
    };
    span.iter()
        .flat_map(|g| g.knee_deg)
        .fold([f64::INFINITY, f64::NEG_INFINITY], |[lo, hi], k| {
            [lo.min(k), hi.max(k)]
        })
}

/// The checks of an edit: its written `motion` and `frames` against the source `reference`
/// motion (both in `body`'s layout; the source's first `body.leadin` frames are not poses).
pub fn check(
    body: &BodyModel,
    reference: &Motion,
    motion: &Motion,
    frames: &[FramePose],
    options: FidelityOptions,
) -> Fidelity {
    let edited = gauge(body, motion);
    let source = gauge(body, reference);
    let dt_src = reference.frame_time_s;
    let last = source.len().saturating_sub(1);
    let src_frame =
        |t: f64| ((t / dt_src).round().max(0.0) as usize).clamp(body.leadin.min(last), last);
    let (t0, t1) = frames
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), f| {
            (a.min(f.source_time_s), b.max(f.source_time_s))
        });
    let recorded = if t0 <= t1 {
        &source[src_frame(t0)..=src_frame(t1)]
    } else {
        &source[..0]
    };
    let range = |g: &[Gauge], v: &dyn Fn(&Gauge) -> [f64; 2]| {
        g.iter()
            .flat_map(v)
            .fold([f64::INFINITY, f64::NEG_INFINITY], |[lo, hi], x| {
                [lo.min(x), hi.max(x)]
            })
    };
    let lean = |g: &Gauge| [g.lean_deg; 2];
    let knee = |g: &Gauge| g.knee_deg;
    let (lean_rec, knee_rec) = (range(recorded, &lean), range(recorded, &knee));
    let outside =
        |v: f64, r: [f64; 2], tol: f64, low: bool| (low && v < r[0] - tol) || v > r[1] + tol;
    let lean_outside = edited
        .iter()
        .filter(|g| outside(g.lean_deg, lean_rec, options.lean_tol_deg, true))
        .count();
    let knee_outside = edited
        .iter()
        .filter(|g| {
            g.knee_deg
                .iter()
                .any(|&k| outside(k, knee_rec, options.knee_tol_deg, options.knee_extension))
        })
        .count();
    let spike_at_source = |i: usize| {
        let (lo, hi) = source_window(frames, i, dt_src);
        (lo..=hi.min(last)).any(|k| source[k].root_accel_mps2 > options.spike_mps2)
    };
    let spikes = (0..edited.len())
        .filter(|&i| {
            let g = &edited[i];
            g.root_accel_mps2 > options.spike_mps2 && g.root_rel_accel_mps2 > options.spike_mps2
        })
        .filter(|&i| i >= frames.len() || !spike_at_source(i))
        .collect();
    let flights = flight_spans(frames)
        .into_iter()
        .map(|(first, n)| {
            let span = first..first + n;
            let max = |v: &mut dyn Iterator<Item = [f64; 2]>| {
                v.fold([f64::NEG_INFINITY; 2], |m, k| {
                    [m[0].max(k[0]), m[1].max(k[1])]
                })
            };
            FlightKnees {
                frames: (first, n),
                edited_max_deg: max(&mut span.clone().map(|i| edited[i].knee_deg)),
                source_max_deg: max(&mut span
                    .clone()
                    .map(|i| source[src_frame(frames[i].source_time_s)].knee_deg)),
                locked_frames: [0, 1].map(|s| {
                    span.clone()
                        .filter(|&i| edited[i].knee_deg[s] < options.knee_lock_deg)
                        .count()
                }),
            }
        })
        .collect();
    let accel_max = |g: &[Gauge]| g.iter().map(|g| g.root_accel_mps2).fold(0.0, f64::max);
    Fidelity {
        lean_recorded_deg: lean_rec,
        lean_edited_deg: range(&edited, &lean),
        knee_recorded_deg: knee_rec,
        swing_folded: false,
        knee_edited_deg: range(&edited, &knee),
        lean_outside,
        knee_outside,
        flights,
        root_accel_max_mps2: accel_max(&edited),
        source_root_accel_max_mps2: accel_max(recorded),
        spikes,
        options,
        frames: edited,
    }
}

/// The source frames the second difference at written frame `i` is taken from: from the
/// frame at or before the earliest to the frame at or after the latest source time of
/// frames `i − 1`, `i`, `i + 1` (each within two source frames of frame `i`'s: a flight
/// between two stances switches from one edge's source time to the other's).
fn source_window(frames: &[FramePose], i: usize, dt_src: f64) -> (usize, usize) {
    let t = frames[i].source_time_s;
    let near = |j: usize| {
        frames[j]
            .source_time_s
            .clamp(t - 2.0 * dt_src, t + 2.0 * dt_src)
    };
    let ts = [
        i.checked_sub(1).map(near),
        Some(t),
        frames.get(i + 1).map(|_| near(i + 1)),
    ];
    let (t0, t1) = ts
        .into_iter()
        .flatten()
        .fold((t, t), |(a, b), x| (a.min(x), b.max(x)));
    (
        (t0 / dt_src).floor().max(0.0) as usize,
        (t1 / dt_src).ceil().max(0.0) as usize,
    )
}

/// The whole flights of an edit: runs of consecutive [`Phase::Flight`] frames between the
/// same two stances, as (first frame, number of frames). The half flights before a run's
/// first stance and after its last (the edit starts and ends at an apex) are left out:
/// their legs have just left or are about to meet the floor, straight where the push ends.
fn flight_spans(frames: &[FramePose]) -> Vec<(usize, usize)> {
    let mut out: Vec<(usize, usize)> = Vec::new();
    for (i, f) in frames.iter().enumerate() {
        if !matches!(
            f.phase,
            Phase::Flight {
                before: Some(_),
                after: Some(_)
            }
        ) {
            continue;
        }
        match out.last_mut() {
            Some((first, n)) if *first + *n == i && frames[*first].phase == f.phase => *n += 1,
            _ => out.push((i, 1)),
        }
    }
    out
}

impl FlightKnees {
    /// The legs locked through the whole flight while the source bends them.
    pub fn locked_legs(&self, lock_deg: f64) -> Vec<usize> {
        (0..2)
            .filter(|&s| {
                self.locked_frames[s] == self.frames.1 && self.source_max_deg[s] >= lock_deg
            })
            .collect()
    }
}

impl Fidelity {
    /// One line per failed check (empty when every check holds).
    pub fn failures(&self) -> Vec<String> {
        let o = &self.options;
        let mut out = Vec::new();
        if self.lean_outside > 0 {
            out.push(format!(
                "trunk lean {:.1}…{:.1}° on {} frame(s) outside the recorded {:.1}…{:.1}° ± {}°",
                self.lean_edited_deg[0],
                self.lean_edited_deg[1],
                self.lean_outside,
                self.lean_recorded_deg[0],
                self.lean_recorded_deg[1],
                o.lean_tol_deg
            ));
        }
        if self.knee_outside > 0 {
            let below = if o.knee_extension { "" } else { " (above)" };
            out.push(format!(
                "knee flexion {:.1}…{:.1}° on {} frame(s) outside{below} the {} {:.1}…{:.1}° ± {}°",
                self.knee_edited_deg[0],
                self.knee_edited_deg[1],
                self.knee_outside,
                self.knee_reference_word(),
                self.knee_recorded_deg[0],
                self.knee_recorded_deg[1],
                o.knee_tol_deg
            ));
        }
        for f in &self.flights {
            for s in f.locked_legs(o.knee_lock_deg) {
                out.push(format!(
                    "{} knee locked (under {}° of flexion) through the flight of frames {}–{}, \
                     where the source bends it to {:.1}°",
                    ["left", "right"][s],
                    o.knee_lock_deg,
                    f.frames.0,
                    f.frames.0 + f.frames.1 - 1,
                    f.source_max_deg[s]
                ));
            }
        }
        if o.spikes && !self.spikes.is_empty() {
            let worst = self
                .spikes
                .iter()
                .map(|&i| self.frames[i].root_accel_mps2)
                .fold(0.0, f64::max);
            out.push(format!(
                "root acceleration above {:.1} g on {} frame(s) the source has none (largest {:.1} g, frame {})",
                o.spike_mps2 / G_MPS2,
                self.spikes.len(),
                worst / G_MPS2,
                self.spikes[0]
            ));
        }
        out
    }

    /// What the knee range is measured against: the recording, or the recording with its
    /// swing folded by the speed law.
    fn knee_reference_word(&self) -> &'static str {
        if self.swing_folded {
            "recorded, swing folded by the speed law,"
        } else {
            "recorded"
        }
    }

    /// A one-line summary of the figures.
    pub fn summary(&self) -> String {
        let locked: usize = self
            .flights
            .iter()
            .map(|f| f.locked_legs(self.options.knee_lock_deg).len())
            .sum();
        let flights = if self.flights.is_empty() {
            String::new()
        } else {
            format!(", {locked} knee(s) locked through a flight")
        };
        format!(
            "trunk lean {:.1}…{:.1}° (recorded {:.1}…{:.1}°), knee flexion {:.1}…{:.1}° \
             ({} {:.1}…{:.1}°){flights}, root acceleration ≤ {:.1} g (recorded {:.1} g), \
             {} frame(s) above {:.1} g where the recording is not{}",
            self.lean_edited_deg[0],
            self.lean_edited_deg[1],
            self.lean_recorded_deg[0],
            self.lean_recorded_deg[1],
            self.knee_edited_deg[0],
            self.knee_edited_deg[1],
            self.knee_reference_word(),
            self.knee_recorded_deg[0],
            self.knee_recorded_deg[1],
            self.root_accel_max_mps2 / G_MPS2,
            self.source_root_accel_max_mps2 / G_MPS2,
            self.spikes.len(),
            self.options.spike_mps2 / G_MPS2,
            if self.options.spikes {
                ""
            } else {
                " (reported, not checked for a run: FidelityOptions::run)"
            }
        )
    }
}
