//! Edited motion out: a scaled run or jump as a full-body pose per frame, with the support
//! feet planted, ready to write as BVH (the paper's "motion of a more complex character",
//! Pollard and Behmaram-Mosavat, §5).
//!
//! # Model
//! ```text
//! query (β, times, contact point per stance) → plan (requests, chain)   [plan]
//!   → COM path: stances in closed form, ballistic flights, C¹ at the apexes   [path]
//!   → per output frame: time-warped reference pose, new heading, feet by two-bone IK,
//!     root so that COM(pose) = planned COM (iterated below the tolerance)     [pose]
//! ```
//! Choices where the method is silent, in short:
//! - A run cycle is made exactly periodic so that any number of cycles chain with
//!   continuous COM position and velocity: the first stance is the run policy's own
//!   request, the second runs from its end apex back to its start apex ([`plan`]).
//! - Where a request asks a stance for a speed change its scaled recorded impulse does not
//!   carry (the periodic second stance), the difference is a constant friction-ratio offset
//!   (the body leans), not a rescaling of the whole horizontal force ([`lean`]; a departure
//!   from the paper: its `β_h = Δv/J_h` is ill-conditioned for a running stance).
//! - A run cycle's recorded height change is split between its start and its end: the
//!   periodic cycle sits half of it higher ([`plan::run_requests`]), instead of the second
//!   stance taking all of it.
//! - Each planned stance carries its recording's COM detail, the part of the recorded path
//!   its force model does not carry, time-warped ([`detail`]; displacement mapping):
//!   where it joins a planned flight it starts at 0 or ends at the model's height, with
//!   zero velocity and acceleration (corrected within 0.2 s of the edge); a run's travel
//!   offsets are balanced over its stances, a jump's kept, and its first touchdown and
//!   last liftoff, which join no flight, keep the recording's. The flights stay the
//!   query's parabolas, shifted by a constant. With it and the height split, a
//!   recorded-speed edit of the CMU run follows its recording's root within 1.6 cm
//!   (3.0 cm with the model's path), the shared recorded jumps within 0.96, 1.42 and
//!   1.98 cm. The force checks judge the scaled model.
//! - The reference is the source stance's own frames; stance time is warped linearly
//!   between touchdown and liftoff, flight time linearly on each side of the apex, and
//!   a flight blends the pose after one stance into the pose before the next (quaternion
//!   slerp, smoothstep weight), so a run cycle can repeat.
//! - A support foot follows the reference foot's motion about the source contact point,
//!   moved to the planned contact point and turned by the heading change; its orientation
//!   (the toe's pitch, level when the reference's is) is the reference's, turned.
//! - The capture's foot slide is not reproduced: between the first and the last frame where
//!   the ankle or toe tip rests (within [`FOOT_REST_BAND_M`] of its lowest height in the
//!   stance), its horizontal motion is removed from the planted foot, so the heel holds
//!   while the foot lands and the toe tip while it rolls off (the CMU run's markers slid
//!   1–2.6 cm while resting; the edits slid 17 mm with them). A point that leaves the
//!   band and rests again more than [`FOOT_STEP_M`] away has stepped: that move is kept.
//! - A foot whose ankle is beyond the leg's reach turns about its toe tip (heel up, at most
//!   [`DEFAULT_MAX_TOE_PIVOT_DEG`]) instead of leaving the floor: a jump higher than
//!   recorded plans the COM farther from the contact point than the recorded push reaches
//!   with the foot flat (1.10 m against 0.97 m at 1.2 × the apex; the jump query allows
//!   1.05 × the stance's own extension), and without the pivot the feet left the floor
//!   4.7 frames early. The toe keeps the reference toe's path, so contacts begin and end
//!   on the plan.
//! - A support foot still beyond reach on its upright toe (a CMU run at 1.1 × its speed
//!   plans the COM 1.127 m from the contact at liftoff, 3 % beyond the recorded 1.094 m) is
//!   reached by posture, not by the leg alone ([`posture`]): the pelvis (pitch, roll, yaw,
//!   at most [`DEFAULT_MAX_PELVIS_TURN_DEG`]) turns under a trunk (and swinging legs, by
//!   how little their feet are held) that keeps its recorded orientation, by the smallest damped least-squares change that brings the stance hip
//!   within reach of the foot once the root has put the COM back on the plan (Jacobian of
//!   the leg's shortfall by finite differences of FK, foot IK and COM), and the solved
//!   changes are ramped in and out over [`DEFAULT_POSTURE_RAMP_S`]. Without it the left
//!   push-off ended 2.0 frames early and 10 frames were reported; with it 0.91 frames and
//!   none. A run's pelvis turns too where a support knee would straighten more than
//!   `pose::reach::POSTURE_KNEE_SLACK_DEG` beyond the toe pivot's bound (below).
//! - Where a written run's support leg does not follow the plan (a push-off farther behind
//!   the body than the leg reaches, a landing straighter than the recorded knee), its
//!   contact point moves along the heading by the least step (an eighth of its bound) that
//!   lets it, at most a tenth of a leg ([`footing`], a departure from the paper's
//!   angular-impulse contact point: the edit prints the shift and the change of the
//!   stance's angular impulse).
//! - The edit keeps its source's posture (issue 37 item 5, [`fidelity`]): a run's knee
//!   straightens no further than the source's least flexion less [`RUN_KNEE_SLACK_DEG`]
//!   (the heel rises instead), a jump's knee shares the end of its push with the heel
//!   ([`DEFAULT_SOFT_REACH`]), swinging feet rise with a body that flies higher than
//!   recorded ([`DEFAULT_SWING_HOLD_S`]), and a swinging ankle stays within the reference
//!   knee's flexion less [`RUN_KNEE_SLACK_DEG`] of its hip (`pose::reach::swing_reach`: a
//!   run faster than recorded lifts the foot with the body instead of locking the knee).
//!   Every written motion is checked against its source: trunk lean, knee flexion, knees
//!   locked through a flight, root spikes.
//! - A run's swing knee folds with speed ([`swing`], a departure from the paper's replayed
//!   swing): `k (Fr_target − Fr_source)` degrees more at each swing's peak, `Fr = v/√(g L)`,
//!   `k` measured on five runners of the shared data (leaving one out: 22–27°).
//! - The root carries the COM exactly: the COM is affine in the root translation, so one
//!   root shift corrects it, and root shift and leg IK alternate until the COM error is
//!   below [`DEFAULT_COM_TOL_M`]; frames that do not get there are reported.
//!
//! # Frames and units
//! Metres, seconds, internal Z-up frame for the plan; the written motion uses the source
//! file's axes, unit and channel layout (times √L and lengths L for a new character).
//!
//! # References
//! Pollard and Behmaram-Mosavat, *Force-Based Motion Editing for Locomotion Tasks*, §5
//! (editing the full body from the COM), §6.8 (run at speed v), §6.9 (jumps), §9 (new
//! characters); the closed forms of the force model (`force_model::model`).

pub mod detail;
pub mod fidelity;
pub mod footing;
pub mod lean;
pub mod path;
pub mod plan;
pub mod pose;
pub mod posture;
pub mod rotation;
pub mod select;
pub mod swing;

/// COM tolerance of a written frame, m (the issue's 1 mm): a frame whose pose COM is
/// farther from the plan is reported as not converged.
pub const DEFAULT_COM_TOL_M: f64 = 1e-3;
/// Where the root/IK iteration stops, m: far below [`DEFAULT_COM_TOL_M`], because what is
/// measured from the written COM is its curvature. A COM error `e` over a flight of
/// duration `T` moves the fitted vertical acceleration by about `8e/T²`: stopping at 1 mm
/// put a re-ingested 0.11 s running flight 0.9 m/s² from −g (the plan's own flight is
/// ballistic to 1e-12); at 10 µm it is 0.01 m/s². Costs about four more iterations on the
/// frames with a leg pulled towards a target (a free frame converges in one root shift).
pub const DEFAULT_COM_SOLVE_TOL_M: f64 = 1e-5;
/// Most root/IK iterations per frame (the error shrinks by the legs' mass share, about
/// 0.3, per iteration: 16 take a 1 m error below 10 µm).
pub const DEFAULT_MAX_ITERATIONS: usize = 16;
/// Longest reach of a leg as a fraction of thigh plus shank (a straight knee has no
/// bending direction; 0.999 leaves 2.6° of flexion).
pub const DEFAULT_MAX_REACH: f64 = 0.999;
/// Most extra plantarflexion of a foot turned about its toe tip to reach its target, degrees.
/// When a planned COM is farther from the contact point than the leg reaches with the
/// reference's foot pitch (a jump higher than recorded, the end of a push-off), the foot
/// turns about its toe tip (the heel rises) until the ankle is within reach, so the toe
/// stays on the floor where the reference's is; 50° is about the ankle's range of
/// plantarflexion beyond standing.
pub const DEFAULT_MAX_TOE_PIVOT_DEG: f64 = 50.0;
/// Largest turn of the pelvis (root) about each of its axes to let a support leg reach,
/// degrees ([`posture`]): a foot still out of reach on its upright toe (the end of a push
/// faster than recorded) is reached by moving the stance hip relative to the COM instead
/// of leaving the floor. 10° of rotation, hip hike or pitch is within a runner's own
/// cycle-to-cycle pelvis motion. The trunk keeps its orientation (its lean is the
/// recording's; issue 37).
pub const DEFAULT_MAX_PELVIS_TURN_DEG: f64 = 10.0;
/// Ramp of a solved posture change in and out, s ([`posture::envelope`]): the change grows
/// from zero over this time before the frames that need it and decays over it after, so
/// that a lean of 10° turns at most a few degrees per frame at 120 Hz.
pub const DEFAULT_POSTURE_RAMP_S: f64 = 0.1;
/// Where a leg starts to share its extension with the foot, as a fraction of thigh plus
/// shank ([`pose`]'s toe pivot): a support ankle asked farther from the hip than this (or
/// than the reference leg's own extension, if longer) is reached partly by the knee and
/// partly by the heel rising about the toe tip, the knee's share approaching the reach
/// [`DEFAULT_MAX_REACH`] smoothly (`tanh`) instead of snapping straight in one frame.
/// Without it a jump 1.1 × higher than recorded straightened the knee from 27° to locked in
/// one 120 Hz frame at the end of its push and the root accelerated at 17 g there (the
/// recording: under 5 g). 0.95 leaves 36° of knee flexion where the sharing begins, about
/// what a vertical push has left a tenth of a second before liftoff.
pub const DEFAULT_SOFT_REACH: f64 = 0.95;
/// Least knee flexion the reach of [`pose`] gives a leg, degrees (0: the knee straightens
/// up to [`DEFAULT_MAX_REACH`]); beyond it the heel rises about the toe tip instead
/// ([`DEFAULT_MAX_TOE_PIVOT_DEG`]), and only a foot still out of reach on its toe
/// straightens the knee further. `edit jump` keeps 0 (a jump higher than recorded pushes
/// further than the recorded push); `edit run` sets it per edit to the source's least
/// knee flexion over the cycle less [`RUN_KNEE_SLACK_DEG`] (issue 37: the fixture run
/// edited to 5 m/s landed with its knee at 5° where the recording bends it 32.5° or more).
pub const DEFAULT_MIN_KNEE_FLEXION_DEG: f64 = 0.0;
/// How far a run edit's knee may straighten beyond the source's least flexion over the
/// cycle, degrees ([`DEFAULT_MIN_KNEE_FLEXION_DEG`]): half the tolerance of the posture
/// check (`fidelity::DEFAULT_KNEE_TOL_DEG`), the other half left to the frames where the
/// foot is out of reach even on its toe.
pub const RUN_KNEE_SLACK_DEG: f64 = 5.0;
/// How long before its touchdown and after its liftoff a swinging foot is held on its
/// planted path, s ([`pose`]): between, it follows the body (the reference pose placed by
/// the planned COM), so a flight higher than recorded keeps the recorded bent knees instead
/// of stretching the legs to feet held at the recorded height above the floor (a jump
/// 1.2 × higher than recorded held both knees locked through its whole flight). The hold
/// fades in and out with a smoothstep over this time, so the foot leaves and meets the floor
/// on the plan; 0.1 s is about the time a running foot takes to rise or sink through its
/// last 5 cm.
pub const DEFAULT_SWING_HOLD_S: f64 = 0.1;
/// [`DEFAULT_SWING_HOLD_S`] for `edit jump`, s. A push higher than recorded ends with the
/// knee nearly straight, where a small lift of the foot folds the knee fast: held 0.1 s,
/// the fixture jump 1.2 × higher folded its knees from 6° to 70° in 0.1 s of flight and
/// its root accelerated 5.5 g where the recording's does not (the target: none above
/// 5 g). Chosen over a lower soft reach (0.9 also removed it) because it leaves the push
/// as it was; on the real CMU jumps that did not set it (`01_01`, `13_32` at 1.1 ×) it
/// keeps 0 frames above 5 g, and the fixture reaches 1.4 m without a spike (1.35 m with
/// 0.1 s). A running flight (about 0.1 s) keeps [`DEFAULT_SWING_HOLD_S`].
pub const DEFAULT_JUMP_SWING_HOLD_S: f64 = 0.2;
/// Resting band of a planted foot point, m: from the first to the last frame of a stance
/// where the ankle or the toe tip is within this of its lowest height in the stance, its
/// horizontal motion is the capture's slide and is removed from the planted foot
/// (`pose::Reference::foot_drift`). Twice the 5 mm resting band of the round-trip check:
/// output frames fall between source frames, and a toe that rests twice (flat, then again
/// at toe-off, as the CMU run's does) must be held across the rise between.
pub const FOOT_REST_BAND_M: f64 = 0.01;
/// A planted foot point that leaves its resting band and comes back to it farther than
/// this (horizontally, m) has stepped inside its stance: the move is the recording's, not
/// the capture's slide, and is kept (`pose::Reference::foot_drift`). The slides and toe
/// rolls between two rests of one stance measure 0.1–3.4 cm on the shared CMU run and
/// jumps; the vertical jump's left foot shuffles 15 cm (ankle) and 17 cm (toe tip), lifted
/// 5 cm, inside a landing stance the contacts do not split, and a forward jump's foot
/// steps 37 cm (its ankle up 9.6 cm) inside `cmu_01_01_forward_jumps_mb:LR:1003`.
pub const FOOT_STEP_M: f64 = 0.05;
/// Recording written before a jump's first touchdown, s (at most; less where the clip
/// begins sooner). A jump's liftoff starts from rest: the library cuts it where a quiet
/// period of at least `T_QUIET_S` (0.3 s) ends (`stances::segment`), and its fitted
/// distance depends on how it begins. Written from its first touchdown, the CMU forward
/// jump's rebuilt liftoff began at the clip's edge and its model distance came out 1.8 cm
/// shorter than the recording's, although it travelled the same 0.681 m; with the
/// recording's rest before it, the rebuilt stance begins where its source did. The
/// quiet period plus the SG filter's half window (0.05 s) on each side of its edges, and
/// some margin: 0.5 s.
pub const LEAD_IN_S: f64 = 0.5;
/// Default number of steady run cycles.
pub const DEFAULT_CYCLES: usize = 4;
/// Most run cycles of one edit (each a second or so of motion: a cap on the output).
pub const MAX_CYCLES: usize = 1_000;
/// Most output frames × skeleton joints of one edit (count), checked once the plan is
/// placed, before any frame is posed. Posing holds about 100 bytes and the BVH takes
/// about 28 bytes per frame and joint (measured: 100 cycles of the 21-joint fixture run
/// at 1000 Hz, 73,292 frames, 179 MB peak, a 42 MB file), so the limit means at most
/// about 500 MB and a 140 MB file; 1000 cycles at the default rate of a 120 Hz clip
/// stay within it (88,000 frames × 31 joints), at 1000 Hz they do not (an 871 MB BVH
/// and 2.6 GB once).
pub const MAX_EDIT_FRAME_JOINTS: usize = 5_000_000;
/// Highest output frame rate, Hz (as `synth::MAX_FRAME_RATE_HZ`).
pub const MAX_FPS: f64 = 1000.0;
/// Lowest output frame rate, Hz.
pub const MIN_FPS: f64 = 10.0;

/// Knobs of the pose stage.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct EditOptions {
    /// [`DEFAULT_COM_TOL_M`].
    pub com_tol_m: f64,
    /// [`DEFAULT_COM_SOLVE_TOL_M`].
    pub com_solve_tol_m: f64,
    /// [`DEFAULT_MAX_ITERATIONS`].
    pub max_iterations: usize,
    /// [`DEFAULT_MAX_REACH`].
    pub max_reach: f64,
    /// [`DEFAULT_MAX_TOE_PIVOT_DEG`].
    pub max_toe_pivot_deg: f64,
    /// [`DEFAULT_MAX_PELVIS_TURN_DEG`].
    pub max_pelvis_turn_deg: f64,
    /// [`DEFAULT_POSTURE_RAMP_S`].
    pub posture_ramp_s: f64,
    /// [`DEFAULT_SOFT_REACH`].
    pub soft_reach: f64,
    /// [`DEFAULT_SWING_HOLD_S`].
    pub swing_hold_s: f64,
    /// [`DEFAULT_MIN_KNEE_FLEXION_DEG`].
    pub min_knee_flexion_deg: f64,
}

impl Default for EditOptions {
    fn default() -> Self {
        EditOptions {
            com_tol_m: DEFAULT_COM_TOL_M,
            com_solve_tol_m: DEFAULT_COM_SOLVE_TOL_M,
            max_iterations: DEFAULT_MAX_ITERATIONS,
            max_reach: DEFAULT_MAX_REACH,
            max_toe_pivot_deg: DEFAULT_MAX_TOE_PIVOT_DEG,
            max_pelvis_turn_deg: DEFAULT_MAX_PELVIS_TURN_DEG,
            posture_ramp_s: DEFAULT_POSTURE_RAMP_S,
            soft_reach: DEFAULT_SOFT_REACH,
            swing_hold_s: DEFAULT_SWING_HOLD_S,
            min_knee_flexion_deg: DEFAULT_MIN_KNEE_FLEXION_DEG,
        }
    }
}
