//! Seeded generator of small BVH clips with known ground truth: COM, foot contacts and
//! ground-reaction force per unit mass.
//!
//! # Model
//!
//! The COM `c(t)` is integrated in closed form from a piecewise force model (`f = F/m`,
//! `g = 9.81 m/s²`). Every phase edge falls on a frame. Each frame's pose is built (feet,
//! legs by IK, upper body), then the root is placed so that the de Leva (1996, male) COM
//! of the posed skeleton is exactly `c(t)`:
//!
//! ```text
//! c̈(t) = f(t) − g e_z                          flight: f = 0 (exactly ballistic)
//! Run   stance Ts = round(0.25 s·F)/F, flight Tf = 2·round(0.06 s·F)/F, Tc = Ts + Tf
//!   stance, τ ∈ [0, Ts]:  f_z = A sin(πτ/Ts),    A = π g Tc / (2 Ts)   (≈ 22.6 m/s²)
//!                         f_x = −B sin(2πτ/Ts),  B = 4 m/s²  (brake, then push; ∫ = 0)
//!                         f_y = ∓C sin(πτ/Ts),   C = π·0.1 m/s / Ts  (left stance: −)
//!   flight velocity (3.5 m/s + B Ts²/(2π Tc), ±0.1 m/s, ±g Tf/2): mean speed 3.5 m/s
//!   t = 0 is a flight apex, c(0) = (0, 0, 0.88 m); then left stance, flight, right…
//!   The clip ends at the apex or mid-stance nearest the requested duration.
//! Jump  in place: stand 0.3 s (f_z = g), push Tp = 0.6 s, flight Tf = 0.35 s,
//!   landing Tp (the push reversed in time), stand; standing COM 0.97 m
//!   push:     f_z = g/2 + (g/2) cos(πτ/Tp) + b₁ sin(πτ/Tp) + b₂ sin(2πτ/Tp)
//!   landing:  f_z = g/2 − (g/2) cos(πτ/Tp) + b₁ sin(πτ/Tp) − b₂ sin(2πτ/Tp)
//!   b₁ = π (v₀ + g Tp/2) / (2 Tp),  b₂ = 2π g (1/4 − 1/π²) − 2 b₁,  v₀ = g Tf/2
//!   (takeoff at the standing height and speed v₀; b₂ < 0 is the countermovement)
//! COM   c = Σₛ m%ₛ (Pₒ + COM%ₛ (Pₑ − Pₒ)) / Σₛ m%ₛ   (14 segments, spec §5)
//! root  r ← r + (c − COM(pose(r)))   until |c − COM| ≤ 1e-12 m
//! ```
//!
//! Planted feet are flat (ankle 0.08 m above the floor, toe tip on it) at a footprint
//! half-way between the hip at touchdown and at liftoff; `platform_m` lifts the right
//! foot's first running stance onto a step that high. Like a captured foot, a planted foot
//! bears force before its joint centres come to rest: it touches down and lifts off
//! `g = 3 cm` above its footprint (the sole's give) and settles over `T = 50 ms`:
//!
//! ```text
//! height above the footprint, s from the nearer contact edge, u = s/T:
//!   give(s) = g (2u³ − 3u² + 1) − v_e T (u³ − 2u² + u)   (u < 1; else 0)   v_e = 0.6 m/s
//! ```
//!
//! A swing foot stays flat and moves from P₀ to P₁ (the footprints raised by `g`) in time
//! T as `P₀ + (P₁ − P₀)(u − (1 − r) sin(2πu)/(2π)) + v_z s (1 − u) e_z` (`u = s/T`),
//! leaving and arriving at 3 m/s (run: 2.2 m/s of it horizontal), so the contact
//! detector's 2 m/s gate separates it from the floor, and the sub-frame event test (3 cm,
//! spec com-from-bvh §7.3) is met exactly at the force's first and last frame. The
//! legs use two-bone IK (knee towards the root heading). The trunk leans forward (run 8°,
//! jump 4°) with seeded wobbles ≤ 2° per axis on root, spine, neck and head; the arms are
//! rigid (fixed elbow) and swing at the shoulder. A clip never ends on a touchdown frame.
//! The tests check the contact-detector margins from 24 to 1000 Hz; below about 24 Hz
//! (down to the 10 Hz floor) the whole-frame phase lengths leave them unchecked.
//!
//! # Frames and units
//!
//! Truth (`com`, `force_n_per_kg`) is in metres and seconds in the internal Z-up frame
//! (facing +X, left = +Y). The BVH is in file units (`unit_m` metres each), with
//! `file = (x, z, −y)` for Y-up and `file = (x, y, z)` for Z-up; angles in degrees.
//!
//! # References
//!
//! de Leva P. (1996) Adjustments to Zatsiorsky–Seluyanov's segment inertia parameters,
//! J. Biomech. 29(9):1223–1230, Table 4. Spec `com-from-bvh.md` §2, §3, §4.2, §5, §7.
//!
//! # Examples
//!
//! ```
//! use stancelib::synth::{generate, SynthOptions};
//! let clip = generate(&SynthOptions::default());
//! assert_eq!(clip.com.len(), 177); // the apex nearest to 1.5 s at 120 Hz
//! assert!(clip.bvh.starts_with("HIERARCHY"));
//! ```

use nalgebra::{Matrix3, Rotation3, Vector3};
use std::f64::consts::PI;
use std::fmt::Write as _;

type V3 = Vector3<f64>;
type M3 = Matrix3<f64>;

/// Default frame rate, Hz.
pub const DEFAULT_FRAME_RATE_HZ: f64 = 120.0;
/// Default requested duration, s.
pub const DEFAULT_DURATION_S: f64 = 1.5;
/// Default file unit, metres per file unit.
pub const DEFAULT_UNIT_M: f64 = 1.0;
/// Default seed of the upper-body wobble.
pub const DEFAULT_SEED: u64 = 1;
/// Lowest frame rate, Hz; lower or non-finite rates are clamped or defaulted.
pub const MIN_FRAME_RATE_HZ: f64 = 10.0;
/// Highest frame rate, Hz.
pub const MAX_FRAME_RATE_HZ: f64 = 1000.0;
/// Longest duration, s; a clip has at least one frame.
pub const MAX_DURATION_S: f64 = 60.0;
/// Smallest file unit, metres per file unit; smaller units are clamped.
pub const MIN_UNIT_M: f64 = 1e-6;
/// Largest file unit, metres per file unit; larger units are clamped.
pub const MAX_UNIT_M: f64 = 1e6;
/// Gravity of the force model, m/s² (the crate's one [`GRAVITY`](crate::math::constants::GRAVITY)).
pub const GRAVITY_MPS2: f64 = crate::math::constants::GRAVITY;
/// Highest platform under the right foot's first running stance, m.
pub const MAX_PLATFORM_M: f64 = 0.3;

const G: f64 = GRAVITY_MPS2;
const RUN_SPEED: f64 = 3.5; // m/s, mean forward speed
const RUN_STANCE_S: f64 = 0.25;
const RUN_FLIGHT_S: f64 = 0.12;
const RUN_BRAKE: f64 = 4.0; // m/s², B
const RUN_SWAY: f64 = 0.1; // m/s, lateral flight speed
const RUN_APEX_Z: f64 = 0.88; // m, COM height at a flight apex
const JUMP_STAND_S: f64 = 0.3;
const JUMP_PUSH_S: f64 = 0.6;
const JUMP_FLIGHT_S: f64 = 0.35;
const JUMP_STAND_Z: f64 = 0.97; // m, standing COM height
const SWING_END_SPEED: f64 = 3.0; // m/s, swing foot at liftoff and touchdown
const RUN_SWING_END_VX: f64 = 2.2; // m/s, its horizontal part in the run
const ANKLE_Z: f64 = 0.08; // m, ankle above the sole
/// The sole's give, m: a planted foot first and last bears force this far above the
/// height where it rests (heel pad, shoe and the foot rolling flat). The captured feet of
/// the 4 m/s force-plate run are 1.5–2.8 cm above their resting height at the plates'
/// first 20 N (ankle) and 2.8–3.4 cm at the last (toe tip); the event height of the
/// sub-frame contact times ([`crate::contacts::timing::EVENT_H_M`], 3 cm), chosen on
/// those plates, is that foot state, so the generator's feet take it as their give.
const SOLE_GIVE_M: f64 = crate::contacts::timing::EVENT_H_M;
/// Time over which the give settles after touchdown (and builds before liftoff), s: the
/// captured ankle comes to rest about 50 ms after the plates' first 20 N.
const SOLE_GIVE_S: f64 = 0.05;
/// Speed of a planted foot at the contact edge itself, m/s (downward at touchdown, upward
/// at liftoff). The swing meets the give at 3 m/s, so the central-difference speed of the
/// edge frame is about (3 + 0.6)/2 = 1.8 m/s: below the detector's 2 m/s gate, which
/// keeps the edge frame in contact, and below the Hermite's monotone limit 3·give/T.
const SOLE_GIVE_EDGE_MPS: f64 = 0.6;
const HIP_Y: f64 = 0.09; // m, hip joint lateral offset
const THIGH: f64 = 0.42;
const SHANK: f64 = 0.42;
const ROOT_TOL_M: f64 = 1e-12;
const ROOT_MAX_ITER: usize = 100;
const FOOT_PASSES: usize = 4; // footprint refinements (pass 0: reference-pose estimate)
const WOBBLE_MAX_DEG: f64 = 2.0;
/// de Leva (1996) male (mass %, COM % from the origin): head+neck, trunk, upper arm,
/// forearm, hand, thigh, shank, foot.
#[rustfmt::skip]
const DE_LEVA_MALE: [(f64, f64); 8] = [
    (6.94, 50.02), (43.46, 51.38), (2.71, 57.72), (1.62, 45.74),
    (0.61, 79.00), (14.16, 40.95), (4.33, 43.95), (1.37, 44.15),
];

/// Which motion to synthesise.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SynthMotion {
    /// Running along +X: alternating single-foot stances and flights.
    Run,
    /// Countermovement jump in place with one flight.
    Jump,
}

/// Up axis of the written file.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SynthUp {
    /// Y up: `file = (x, z, −y)` of the internal Z-up frame.
    Y,
    /// Z up: file coordinates are the internal ones.
    Z,
}

/// Options of [`generate`]; out-of-range values are clamped, non-finite ones defaulted.
#[derive(Clone, Debug, PartialEq)]
pub struct SynthOptions {
    /// Motion to synthesise (default `Run`).
    pub motion: SynthMotion,
    /// Frame rate, Hz (default [`DEFAULT_FRAME_RATE_HZ`]).
    pub frame_rate_hz: f64,
    /// Requested duration, s (default [`DEFAULT_DURATION_S`]); see the module docs.
    pub duration_s: f64,
    /// Metres per file unit: 1.0, 0.01, 0.0254, 0.056444… (default [`DEFAULT_UNIT_M`]).
    pub unit_m: f64,
    /// Up axis of the file (default `Y`).
    pub up: SynthUp,
    /// Seed of the upper-body wobble (default [`DEFAULT_SEED`]).
    pub seed: u64,
    /// Run only: the right foot's first stance that starts after frame 0 is planted this
    /// high above the floor, as on a step or platform, m (default 0: every footprint on the floor; clamped to
    /// `0..=`[`MAX_PLATFORM_M`]). The COM and the truth are unchanged: the leg reaches down
    /// that much less.
    pub platform_m: f64,
}

impl Default for SynthOptions {
    fn default() -> Self {
        SynthOptions {
            motion: SynthMotion::Run,
            frame_rate_hz: DEFAULT_FRAME_RATE_HZ,
            duration_s: DEFAULT_DURATION_S,
            unit_m: DEFAULT_UNIT_M,
            up: SynthUp::Y,
            seed: DEFAULT_SEED,
            platform_m: 0.0,
        }
    }
}

/// A generated clip and its ground truth, one entry per frame.
#[derive(Clone, Debug, Default)]
pub struct SynthClip {
    /// Full BVH text.
    pub bvh: String,
    /// True whole-body de Leva COM, metres, internal Z-up frame.
    pub com: Vec<[f64; 3]>,
    /// True left-foot contact (foot planted).
    pub contact_left: Vec<bool>,
    /// True right-foot contact (foot planted).
    pub contact_right: Vec<bool>,
    /// Applied ground-reaction force per unit mass, m/s², Z-up: `c̈ + g e_z`.
    pub force_n_per_kg: Vec<[f64; 3]>,
}

/// Generates a clip; pure and deterministic in `opts`, never panics.
pub fn generate(opts: &SynthOptions) -> SynthClip {
    build(opts).0
}

// ---------------------------------------------------------------- skeleton

const N: usize = 21;
const ROOT: usize = usize::MAX;
const HIPS: usize = 0;
const LEGS: [[usize; 4]; 2] = [[1, 2, 3, 4], [5, 6, 7, 8]]; // UpLeg, Leg, Foot, ToeBase
const NECK: usize = 11;
const HEAD: usize = 12;
const ARMS: [[usize; 4]; 2] = [[13, 14, 15, 16], [17, 18, 19, 20]]; // Shoulder…Hand
type Joint = (&'static str, usize, [f64; 3], Option<[f64; 3]>); // name, parent, OFFSET, End

/// A 1.75 m adult in internal metres, in file (depth-first) order, parents first.
#[rustfmt::skip]
const SKELETON: [Joint; N] = [
    ("Hips", ROOT, [0.0, 0.0, 0.0], None),
    ("LeftUpLeg", 0, [0.0, HIP_Y, -0.07], None),
    ("LeftLeg", 1, [0.0, 0.0, -THIGH], None),
    ("LeftFoot", 2, [0.0, 0.0, -SHANK], None),
    ("LeftToeBase", 3, [0.04, 0.0, -0.06], Some([0.15, 0.0, -0.02])),
    ("RightUpLeg", 0, [0.0, -HIP_Y, -0.07], None),
    ("RightLeg", 5, [0.0, 0.0, -THIGH], None),
    ("RightFoot", 6, [0.0, 0.0, -SHANK], None),
    ("RightToeBase", 7, [0.04, 0.0, -0.06], Some([0.15, 0.0, -0.02])),
    ("Spine", 0, [0.0, 0.0, 0.11], None),
    ("Spine1", 9, [0.0, 0.0, 0.20], None),
    ("Neck", 10, [0.0, 0.0, 0.21], None),
    ("Head", 11, [0.0, 0.0, 0.09], Some([0.0, 0.0, 0.15])),
    ("LeftShoulder", 10, [0.0, 0.03, 0.14], None),
    ("LeftArm", 13, [0.0, 0.15, 0.0], None),
    ("LeftForeArm", 14, [0.0, 0.0, -0.28], None),
    ("LeftHand", 15, [0.0, 0.0, -0.27], Some([0.0, 0.0, -0.09])),
    ("RightShoulder", 10, [0.0, -0.03, 0.14], None),
    ("RightArm", 17, [0.0, -0.15, 0.0], None),
    ("RightForeArm", 18, [0.0, 0.0, -0.28], None),
    ("RightHand", 19, [0.0, 0.0, -0.27], Some([0.0, 0.0, -0.09])),
];

/// Joint OFFSETs and End Site offsets (zero where none), internal metres.
fn skeleton_offsets() -> ([V3; N], [V3; N]) {
    let offs = SKELETON.map(|j| V3::from(j.2));
    (offs, SKELETON.map(|j| V3::from(j.3.unwrap_or([0.0; 3]))))
}

/// World positions of the joints and of their End Sites.
struct Kin {
    pos: [V3; N],
    end: [V3; N],
}

/// FK of spec §2: `R_j = R_p · R_local`, `P_j = P_p + R_p · OFFSET_j`, root at `root`.
fn forward(offs: &[V3; N], ends: &[V3; N], root: V3, local: &[M3; N]) -> Kin {
    let (mut rot, mut pos, mut end) = ([M3::identity(); N], [root; N], [V3::zeros(); N]);
    for j in 0..N {
        let p = SKELETON[j].1;
        if p != ROOT {
            pos[j] = pos[p] + rot[p] * offs[j];
            rot[j] = rot[p] * local[j];
        } else {
            rot[j] = local[j];
        }
        end[j] = pos[j] + rot[j] * ends[j];
    }
    Kin { pos, end }
}

/// Whole-body de Leva COM (spec §5) from the landmarks of spec §4.2.
fn de_leva_com(k: &Kin) -> V3 {
    let (p, e, t) = (&k.pos, &k.end, &DE_LEVA_MALE);
    let midh = (p[LEGS[0][0]] + p[LEGS[1][0]]) * 0.5;
    let mut segs = vec![(e[HEAD], p[NECK], t[0]), (p[NECK], midh, t[1])];
    for (a, l) in ARMS.iter().zip(LEGS.iter()) {
        segs.extend([(p[a[1]], p[a[2]], t[2]), (p[a[2]], p[a[3]], t[3])]);
        segs.extend([(p[a[3]], e[a[3]], t[4]), (p[l[0]], p[l[1]], t[5])]);
        segs.extend([(p[l[1]], p[l[2]], t[6]), (p[l[2]], e[l[3]], t[7])]);
    }
    let (mut acc, mut mass) = (V3::zeros(), 0.0);
    for (o, x, (m, pct)) in segs {
        acc += (o + (x - o) * (pct / 100.0)) * m;
        mass += m;
    }
    acc / mass
}

// ---------------------------------------------------------------- force model

/// Force term on one axis: `amp · sin(ωτ)` or `amp · cos(ωτ)`; `ω = 0` is `amp`.
#[derive(Clone, Copy)]
struct Term(usize, f64, f64, bool); // axis, amp (m/s²), ω (rad/s), cos

/// One force phase from frame `k0` with COM state `(c0, v0)`.
struct Phase {
    k0: i64,
    c0: V3,
    v0: V3,
    terms: Vec<Term>,
}

impl Phase {
    /// COM position, velocity and force per unit mass `tau` s into the phase.
    fn eval(&self, tau: f64) -> (V3, V3, V3) {
        let mut p = self.c0 + self.v0 * tau - V3::z() * (0.5 * G * tau * tau);
        let (mut v, mut f) = (self.v0 - V3::z() * (G * tau), V3::zeros());
        for &Term(axis, amp, w, cos) in &self.terms {
            let (s, c) = (w * tau).sin_cos();
            let (fi, vi, pi) = match (w == 0.0, cos) {
                (true, _) => (1.0, tau, 0.5 * tau * tau),
                (false, true) => (c, s / w, (1.0 - c) / (w * w)),
                (false, false) => (s, (1.0 - c) / w, (tau - s / w) / w),
            };
            f[axis] += amp * fi;
            v[axis] += amp * vi;
            p[axis] += amp * pi;
        }
        (p, v, f)
    }
}

/// A foot planted over frames `k_a..=k_b` with its ankle at `ankle`.
#[derive(Clone, Copy)]
struct Stance {
    k_a: i64,
    k_b: i64,
    ankle: V3,
}

/// The plan: force phases, stances per foot, and timing for the arms.
struct Timeline {
    motion: SynthMotion,
    dt: f64,
    phases: Vec<Phase>,
    end: (i64, V3, V3), // frame, COM and velocity at the end of the last phase
    stances: [Vec<Stance>; 2],
    k_ref: i64,  // run: first left touchdown; jump: push start
    period: i64, // run: frames per step; jump: push frames
    k_land: i64, // jump: touchdown
}

impl Timeline {
    fn new(motion: SynthMotion, dt: f64, k0: i64, c0: V3, v0: V3) -> Self {
        let (phases, stances) = (vec![], [vec![], vec![]]);
        let (end, k_ref, period, k_land) = ((k0, c0, v0), 0, 1, 0);
        Timeline {
            motion,
            dt,
            phases,
            end,
            stances,
            k_ref,
            period,
            k_land,
        }
    }

    fn append(&mut self, len: i64, terms: Vec<Term>) {
        let (k0, c0, v0) = self.end;
        let phase = Phase { k0, c0, v0, terms };
        let (c1, v1, _) = phase.eval(len as f64 * self.dt);
        self.end = (k0 + len, c1, v1);
        self.phases.push(phase);
    }

    fn plant(&mut self, side: usize, k_a: i64, k_b: i64) {
        let ankle = V3::zeros();
        self.stances[side].push(Stance { k_a, k_b, ankle });
    }

    /// COM position and force per unit mass at frame `k`.
    fn com(&self, k: i64) -> (V3, V3) {
        let i = self.phases.partition_point(|p| p.k0 <= k).saturating_sub(1);
        let Some(p) = self.phases.get(i) else {
            return (self.end.1, V3::zeros());
        };
        let (c, _, f) = p.eval((k - p.k0) as f64 * self.dt);
        (c, f)
    }

    fn planted(&self, side: usize, k: i64) -> bool {
        self.stances[side].iter().any(|s| s.k_a <= k && k <= s.k_b)
    }

    /// Ankle of one foot at frame `k`: planted (sinking into or rising out of the sole's
    /// give near the contact edges), or on its swing path between the give heights.
    fn ankle(&self, side: usize, k: i64) -> V3 {
        let st = &self.stances[side];
        let Some(i) = st.iter().position(|s| k <= s.k_b) else {
            return st.last().map_or(V3::zeros(), |s| s.ankle);
        };
        if k >= st[i].k_a || i == 0 {
            return st[i].ankle + V3::z() * self.sole_give(&st[i], k);
        }
        let lift = V3::z() * SOLE_GIVE_M;
        let (p0, d) = (st[i - 1].ankle + lift, st[i].ankle - st[i - 1].ankle);
        let s = (k - st[i - 1].k_b) as f64 * self.dt;
        let t = (st[i].k_a - st[i - 1].k_b) as f64 * self.dt;
        let run = self.motion == SynthMotion::Run;
        let vh = if run { RUN_SWING_END_VX } else { 0.0 };
        let (r, u) = ((vh * t / d.norm().max(1e-9)).min(1.9), s / t);
        let vz = (SWING_END_SPEED * SWING_END_SPEED - vh * vh).sqrt();
        let ease = u - (1.0 - r) * (2.0 * PI * u).sin() / (2.0 * PI);
        p0 + d * ease + V3::z() * (vz * s * (1.0 - u))
    }
}

impl Timeline {
    /// Height of a planted foot above its footprint at frame `k` of stance `s`, m: the
    /// sole's give, [`SOLE_GIVE_M`] at the contact edges, settling to 0 over
    /// [`SOLE_GIVE_S`] (at most half the stance) as a cubic Hermite that leaves the edge
    /// at [`SOLE_GIVE_EDGE_MPS`]; an open end (the jump's standing) has none.
    fn sole_give(&self, s: &Stance, k: i64) -> f64 {
        let t = SOLE_GIVE_S.min((s.k_b - s.k_a) as f64 * self.dt / 2.0);
        let settle = |frames: i64| {
            let u = frames as f64 * self.dt / t;
            if !(0.0..1.0).contains(&u) {
                return 0.0;
            }
            let h00 = 2.0 * u * u * u - 3.0 * u * u + 1.0;
            let h10 = u * u * u - 2.0 * u * u + u;
            SOLE_GIVE_M * h00 - SOLE_GIVE_EDGE_MPS * t * h10
        };
        settle(k - s.k_a).max(settle(s.k_b - k))
    }
}

fn run_timeline(dt: f64, n: i64) -> Timeline {
    let ns = ((RUN_STANCE_S / dt).round() as i64).max(2);
    let nf = 2 * ((RUN_FLIGHT_S / dt / 2.0).round() as i64).max(1);
    let (ts, tc) = (ns as f64 * dt, (ns + nf) as f64 * dt);
    let (w1, w2) = (PI / ts, 2.0 * PI / ts);
    let vx = RUN_SPEED + RUN_BRAKE * ts * ts / (2.0 * PI * tc);
    let (c0, v0) = (V3::new(0.0, 0.0, RUN_APEX_Z), V3::new(vx, RUN_SWAY, 0.0));
    let mut tl = Timeline::new(SynthMotion::Run, dt, -2 * (ns + nf), c0, v0);
    tl.append(nf / 2, vec![]);
    (tl.k_ref, tl.period) = (tl.end.0, ns + nf);
    for side in [0, 1].into_iter().cycle() {
        if tl.end.0 > n + 2 * (ns + nf) {
            break;
        }
        let sway = if side == 0 { -1.0 } else { 1.0 } * PI * RUN_SWAY / ts;
        let k_a = tl.end.0;
        let lift = Term(2, PI * G * tc / (2.0 * ts), w1, false);
        let terms = vec![
            lift,
            Term(0, -RUN_BRAKE, w2, false),
            Term(1, sway, w1, false),
        ];
        tl.append(ns, terms);
        tl.plant(side, k_a, k_a + ns);
        tl.append(nf, vec![]);
    }
    let (c, _) = tl.com(0); // shift so that c(0) = (0, 0, apex)
    for p in &mut tl.phases {
        p.c0 -= V3::new(c.x, c.y, 0.0);
    }
    tl
}

fn jump_timeline(dt: f64, n: i64) -> Timeline {
    let frames = |s: f64| ((s / dt).round() as i64).max(2);
    let (n_s, n_p) = (frames(JUMP_STAND_S), frames(JUMP_PUSH_S));
    let n_f = frames(JUMP_FLIGHT_S);
    let (tp, v_to) = (n_p as f64 * dt, G * n_f as f64 * dt / 2.0);
    let b1 = PI * (v_to + G * tp / 2.0) / (2.0 * tp);
    let b2 = 2.0 * PI * G * (0.25 - 1.0 / (PI * PI)) - 2.0 * b1;
    let (w1, w2) = (PI / tp, 2.0 * PI / tp);
    let c0 = V3::new(0.0, 0.0, JUMP_STAND_Z);
    let mut tl = Timeline::new(SynthMotion::Jump, dt, 0, c0, V3::zeros());
    let push = |s: f64| {
        let cos = Term(2, s * G / 2.0, w1, true);
        let sines = [Term(2, b1, w1, false), Term(2, s * b2, w2, false)];
        vec![Term(2, G / 2.0, 0.0, false), cos, sines[0], sines[1]]
    };
    tl.append(n_s, vec![Term(2, G, 0.0, false)]);
    (tl.k_ref, tl.period, tl.k_land) = (n_s, n_p, n_s + n_p + n_f);
    tl.append(n_p, push(1.0));
    tl.append(n_f, vec![]);
    tl.append(n_p, push(-1.0));
    tl.append((n - tl.end.0).max(1), vec![Term(2, G, 0.0, false)]);
    for side in 0..2 {
        tl.plant(side, i64::MIN / 4, n_s + n_p);
        tl.plant(side, tl.k_land, i64::MAX / 4);
    }
    tl
}

/// Puts every footprint half-way between its hip at touchdown and at liftoff (open-ended
/// stances: under the hip at frame 0), re-solving those frames `FOOT_PASSES − 1` times.
fn place_footprints(tl: &mut Timeline, wob: &Wobble, o_ref: V3, platform: f64) {
    let raised = tl.stances[1].iter().position(|s| s.k_a > 0);
    for pass in 0..FOOT_PASSES {
        for (side, lateral) in [(0, HIP_Y), (1, -HIP_Y)] {
            for i in 0..tl.stances[side].len() {
                let s = tl.stances[side][i];
                let open = s.k_b - s.k_a >= 1 << 30;
                let ks = if open { [0, 0] } else { [s.k_a, s.k_b] };
                let hips = ks.map(|k| {
                    let ((c, _), hip) = (tl.com(k), V3::new(0.0, lateral, 0.0));
                    if pass == 0 {
                        return c - o_ref + hip;
                    }
                    let ankles = [tl.ankle(0, k), tl.ankle(1, k)];
                    let (root, local, ..) = solve_root(&upper_pose(tl, wob, k), &ankles, c, c);
                    root + local[HIPS] * hip
                });
                let mid = (hips[0] + hips[1]) * 0.5;
                let raise = if side == 1 && Some(i) == raised && !open {
                    platform
                } else {
                    0.0
                };
                tl.stances[side][i].ankle = V3::new(mid.x, mid.y, ANKLE_Z + raise);
            }
        }
    }
}

// ---------------------------------------------------------------- pose

/// Elementary right-handed rotation about axis `i` (0 = x, 1 = y, 2 = z), degrees.
fn rot(i: usize, deg: f64) -> M3 {
    Rotation3::from_axis_angle(&V3::ith_axis(i), deg.to_radians()).into_inner()
}

fn rot_zyx(z: f64, y: f64, x: f64) -> M3 {
    rot(2, z) * rot(1, y) * rot(0, x)
}

/// Euler angles (degrees) `[z, y, x]` with `R = R_z · R_y · R_x`.
fn zyx_deg(r: &M3) -> [f64; 3] {
    let cb = r[(0, 0)].hypot(r[(1, 0)]);
    let (a, c) = if cb > 1e-12 {
        (r[(1, 0)].atan2(r[(0, 0)]), r[(2, 1)].atan2(r[(2, 2)]))
    } else {
        (0.0, (-r[(1, 2)]).atan2(r[(1, 1)]))
    };
    [a, (-r[(2, 0)]).atan2(cb), c].map(f64::to_degrees)
}

/// Seeded smooth wobbles: 15 sinusoids (amplitude °, frequency Hz, phase rad).
struct Wobble([(f64, f64, f64); 15]);

impl Wobble {
    fn new(seed: u64) -> Self {
        let mut state = seed;
        let mut next = || {
            // splitmix64 → [0, 1)
            state = state.wrapping_add(0x9E37_79B9_7F4A_7C15);
            let mut z = (state ^ (state >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
            z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
            ((z ^ (z >> 31)) >> 11) as f64 / (1u64 << 53) as f64
        };
        let mut one = || {
            let amp = WOBBLE_MAX_DEG * (0.5 + 0.5 * next());
            (amp, 0.5 + next(), 2.0 * PI * next())
        };
        Wobble(std::array::from_fn(|_| one()))
    }

    /// Rotation `R_z(w₀) R_y(pitch + w₁) R_x(w₂)` of wobble set `i` at `t` s.
    fn rot(&self, i: usize, t: f64, pitch: f64) -> M3 {
        let w = |j: usize| {
            let (a, f, p) = self.0[3 * i + j];
            a * (2.0 * PI * f * t + p).sin()
        };
        rot_zyx(w(0), pitch + w(1), w(2))
    }
}

/// Local rotations of everything but the legs at frame `k` (internal frame).
fn upper_pose(tl: &Timeline, wob: &Wobble, k: i64) -> [M3; N] {
    let mut local = [M3::identity(); N];
    let (lean, elbow, arm_l, arm_r) = match tl.motion {
        SynthMotion::Run => {
            let th = 35.0 * (PI * (k - tl.k_ref) as f64 / tl.period as f64).cos();
            (8.0, 80.0, th, -th)
        }
        SynthMotion::Jump => {
            let swing = |k0: i64, s: f64| {
                let u = (k - k0) as f64 / tl.period as f64;
                s * 40.0 * (2.0 * PI * u.clamp(0.0, 1.0)).sin()
            };
            let th = swing(tl.k_ref, 1.0) + swing(tl.k_land, -1.0);
            (4.0, 15.0, th, th)
        }
    };
    let t = k as f64 * tl.dt;
    for (i, j) in [HIPS, 9, 10, NECK, HEAD].into_iter().enumerate() {
        local[j] = wob.rot(i, t, if j == HIPS { lean } else { 0.0 });
    }
    for (a, th, abd) in [(ARMS[0], arm_l, 8.0), (ARMS[1], arm_r, -8.0)] {
        local[a[1]] = rot(1, th) * rot(0, abd);
        local[a[2]] = rot(1, -elbow);
    }
    local
}

/// Two-bone IK: world rotations of thigh and shank putting the ankle at `ankle` with the
/// knee towards `fwd`, and `|ankle − hip| / (THIGH + SHANK)`.
fn leg_ik(hip: V3, ankle: V3, fwd: V3) -> (M3, M3, f64) {
    let (dv, reach) = (ankle - hip, THIGH + SHANK);
    let d_raw = dv.norm();
    let d = d_raw.clamp(1e-6, reach * (1.0 - 1e-12));
    let u = if d_raw > 1e-12 { dv / d_raw } else { -V3::z() };
    let perp = |f: V3| f - u * f.dot(&u);
    let cands = [fwd, V3::x(), V3::z()].map(perp);
    let n = cands.into_iter().find(|n| n.norm() > 1e-6);
    let n = n.unwrap_or(V3::y()).normalize();
    let cos_a = (THIGH * THIGH + d * d - SHANK * SHANK) / (2.0 * THIGH * d);
    let cos_a = cos_a.clamp(-1.0, 1.0);
    let knee = hip + (u * cos_a + n * (1.0 - cos_a * cos_a).sqrt()) * THIGH;
    let axis = n.cross(&u);
    let frame = |down: V3| {
        let z = -down.normalize();
        M3::from_columns(&[axis.cross(&z), axis, z])
    };
    (frame(knee - hip), frame(ankle - knee), d_raw / reach)
}

/// Fills the leg rotations for the root at `root` (flat feet facing +X); returns the
/// largest leg extension ratio.
fn pose_legs(local: &mut [M3; N], offs: &[V3; N], root: V3, ankles: &[V3; 2]) -> f64 {
    let r_root = local[HIPS];
    let heading = r_root * V3::x();
    let fwd = V3::new(heading.x, heading.y, 0.0);
    let mut ratio: f64 = 0.0;
    for (l, ankle) in LEGS.iter().zip(ankles) {
        let (r_thigh, r_shank, q) = leg_ik(root + r_root * offs[l[0]], *ankle, fwd);
        local[l[0]] = r_root.transpose() * r_thigh;
        local[l[1]] = r_thigh.transpose() * r_shank;
        local[l[2]] = r_shank.transpose(); // foot world rotation = I
        local[l[3]] = M3::identity();
        ratio = ratio.max(q);
    }
    ratio
}

/// Fixed point `root ← root + (c − COM(pose(root)))`; returns root, local rotations, leg
/// extension ratio and COM residual (m).
fn solve_root(upper: &[M3; N], ankles: &[V3; 2], c: V3, guess: V3) -> (V3, [M3; N], f64, f64) {
    let (offs, ends) = skeleton_offsets();
    let (mut root, mut it) = (guess, 0);
    loop {
        let mut local = *upper;
        let ratio = pose_legs(&mut local, &offs, root, ankles);
        let err = c - de_leva_com(&forward(&offs, &ends, root, &local));
        it += 1;
        if err.norm() <= ROOT_TOL_M || it >= ROOT_MAX_ITER || !err.norm().is_finite() {
            return (root, local, ratio, err.norm());
        }
        root += err;
    }
}

// ---------------------------------------------------------------- output

/// `F` with `file = F · internal` (before the unit); `F⁻¹ = Fᵀ`.
fn file_from_internal(up: SynthUp) -> M3 {
    match up {
        SynthUp::Y => M3::new(1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, -1.0, 0.0),
        SynthUp::Z => M3::identity(),
    }
}

/// Nine decimals, without `-0.000000000`.
fn num(x: f64) -> String {
    format!("{:.9}", if x.abs() < 5e-10 { 0.0 } else { x })
}

fn triple(v: V3) -> String {
    format!("{} {} {}", num(v.x), num(v.y), num(v.z))
}

fn write_joint(out: &mut String, j: usize, depth: usize, f: &M3, unit: f64) {
    let (ind, (name, _, off, end)) = ("\t".repeat(depth), SKELETON[j]);
    let root = j == HIPS;
    let kind = if root { "ROOT" } else { "JOINT" };
    let off = triple(f * V3::from(off) / unit); // the root's position channels replace it
    let ch = if root { CH_6 } else { CH_3 };
    let _ = writeln!(out, "{ind}{kind} {name}\n{ind}{{\n{ind}\tOFFSET {off}");
    let _ = writeln!(out, "{ind}\tCHANNELS {ch}");
    for c in (0..N).filter(|&c| SKELETON[c].1 == j) {
        write_joint(out, c, depth + 1, f, unit);
    }
    if let Some(e) = end {
        let e = triple(f * V3::from(e) / unit);
        let _ = writeln!(out, "{ind}\tEnd Site\n{ind}\t{{");
        let _ = writeln!(out, "{ind}\t\tOFFSET {e}\n{ind}\t}}");
    }
    let _ = writeln!(out, "{ind}}}");
}

const CH_6: &str = "6 Xposition Yposition Zposition Zrotation Yrotation Xrotation";
const CH_3: &str = "3 Zrotation Yrotation Xrotation";

fn write_row(out: &mut String, root: V3, local: &[M3; N], f: &M3, unit: f64) {
    out.push_str(&triple(f * root / unit));
    for r in local {
        let [z, y, x] = zyx_deg(&(f * r * f.transpose()));
        let _ = write!(out, " {}", triple(V3::new(z, y, x)));
    }
    out.push('\n');
}

/// Frame rate (Hz), requested frame count and unit (m) after clamping.
fn sanitize(opts: &SynthOptions) -> (f64, i64, f64) {
    let or = |x: f64, d: f64| if x.is_finite() { x } else { d };
    let rate = or(opts.frame_rate_hz, DEFAULT_FRAME_RATE_HZ);
    let rate = rate.clamp(MIN_FRAME_RATE_HZ, MAX_FRAME_RATE_HZ);
    let dur = or(opts.duration_s, DEFAULT_DURATION_S).clamp(0.0, MAX_DURATION_S);
    let unit = Some(opts.unit_m).filter(|u| *u > 0.0 && u.is_finite());
    let unit = unit.map_or(DEFAULT_UNIT_M, |u| u.clamp(MIN_UNIT_M, MAX_UNIT_M));
    (rate, ((dur * rate).round() as i64).max(1), unit)
}

/// Frame count: a run ends at the apex or mid-stance nearest `n_req` frames; a clip whose
/// last frame would be a touchdown loses that frame.
fn clip_frames(tl: &Timeline, n_req: i64) -> i64 {
    let mut n = n_req;
    if let (SynthMotion::Run, Some(s)) = (tl.motion, tl.stances[0].get(1)) {
        let (cycle, target) = (tl.period, n_req - 1);
        let j = target / cycle;
        let cands = [j * cycle, j * cycle + (s.k_a + s.k_b) / 2, (j + 1) * cycle];
        let best = cands.into_iter().min_by_key(|c| (c - target).abs());
        n = 1 + best.unwrap_or(0);
    }
    let touchdown = |s: usize| tl.planted(s, n - 1) && !tl.planted(s, n - 2);
    if n >= 2 && (touchdown(0) || touchdown(1)) {
        n -= 1;
    }
    n
}

/// The clip and, for the tests, the largest leg extension ratio and COM residual (m).
fn build(opts: &SynthOptions) -> (SynthClip, [f64; 2]) {
    let (rate, n_req, unit) = sanitize(opts);
    let dt = 1.0 / rate;
    let mut tl = match opts.motion {
        SynthMotion::Run => run_timeline(dt, n_req),
        SynthMotion::Jump => jump_timeline(dt, n_req),
    };
    let n = clip_frames(&tl, n_req);
    let (wob, (offs, ends)) = (Wobble::new(opts.seed), skeleton_offsets());
    let upper0 = upper_pose(&tl, &wob, 0);
    let o_ref = de_leva_com(&forward(&offs, &ends, V3::zeros(), &upper0));
    let platform = if opts.motion == SynthMotion::Run && opts.platform_m.is_finite() {
        opts.platform_m.clamp(0.0, MAX_PLATFORM_M)
    } else {
        0.0
    };
    place_footprints(&mut tl, &wob, o_ref, platform);

    let f = file_from_internal(opts.up);
    let mut clip = SynthClip::default();
    clip.bvh.push_str("HIERARCHY\n");
    write_joint(&mut clip.bvh, HIPS, 0, &f, unit);
    let _ = write!(clip.bvh, "MOTION\nFrames: {n}\nFrame Time: {dt}\n");
    let (mut guess, mut diag) = (tl.com(0).0 - o_ref, [0.0f64; 2]);
    for k in 0..n {
        let ((c, force), ankles) = (tl.com(k), [tl.ankle(0, k), tl.ankle(1, k)]);
        let (root, local, ratio, res) = solve_root(&upper_pose(&tl, &wob, k), &ankles, c, guess);
        (guess, diag) = (root, [diag[0].max(ratio), diag[1].max(res)]);
        write_row(&mut clip.bvh, root, &local, &f, unit);
        clip.com.push(c.into());
        clip.force_n_per_kg.push(force.into());
        clip.contact_left.push(tl.planted(0, k));
        clip.contact_right.push(tl.planted(1, k));
    }
    (clip, diag)
}

#[cfg(test)]
mod tests;
