//! Contact thresholds with documented defaults (spec com-from-bvh §7.1–§7.4; README
//! "Configuration files", `[contacts]`).

/// Foot enter height above the point's floor, m.
pub const DEFAULT_FOOT_H_ON: f64 = 0.04;
/// Foot leave height, m.
pub const DEFAULT_FOOT_H_OFF: f64 = 0.06;
/// Foot enter speed (3-D, unsmoothed), m/s.
pub const DEFAULT_FOOT_V_ON: f64 = 2.0;
/// Foot leave speed, m/s.
pub const DEFAULT_FOOT_V_OFF: f64 = 2.0;
/// Hand enter height, m.
pub const DEFAULT_HAND_H_ON: f64 = 0.05;
/// Hand leave height, m.
pub const DEFAULT_HAND_H_OFF: f64 = 0.08;
/// Hand enter speed, m/s.
pub const DEFAULT_HAND_V_ON: f64 = 0.5;
/// Hand leave speed, m/s.
pub const DEFAULT_HAND_V_OFF: f64 = 0.9;
/// Minimum contact run, s.
pub const DEFAULT_MIN_ON_S: f64 = 0.03;
/// Gaps shorter than this are filled, s.
pub const DEFAULT_MIN_GAP_S: f64 = 0.03;
/// Half-width of the local floor window `T_floor`, s.
pub const DEFAULT_FLOOR_WINDOW_S: f64 = 1.5;
/// Static mode: height above the floor to enter, m.
pub const STATIC_H: f64 = 0.10;
/// Static mode: enter speed, m/s.
pub const STATIC_V_ON: f64 = 0.15;
/// Static mode: leave speed, m/s.
pub const STATIC_V_OFF: f64 = 0.30;
/// Static mode: minimum run, s.
pub const STATIC_MIN_ON_S: f64 = 0.2;
/// Static mode: gaps shorter than this are filled, s (fixed by spec §7.4, not configurable).
pub const STATIC_MIN_GAP_S: f64 = 0.03;

/// Thresholds of one effector kind.
#[derive(serde::Serialize, Debug, Clone, Copy, PartialEq)]
pub struct Thresholds {
    /// Enter when some point is at most this high, m.
    pub h_on: f64,
    /// Leave when every point is above this, m (or too fast).
    pub h_off: f64,
    /// Enter when that point is at most this fast, m/s.
    pub v_on: f64,
    /// Leave when every point is faster than this, m/s (or too high).
    pub v_off: f64,
}

/// Contact detection options.
#[derive(serde::Serialize, Debug, Clone, Copy, PartialEq)]
pub struct ContactOptions {
    /// Foot thresholds.
    pub foot: Thresholds,
    /// Hand thresholds.
    pub hand: Thresholds,
    /// Hands are support effectors.
    pub hands: bool,
    /// Static / elevated contact mode (§7.4).
    pub static_mode: bool,
    /// Minimum contact run, s.
    pub min_on_s: f64,
    /// Gap fill, s.
    pub min_gap_s: f64,
    /// Local floor half-window, s.
    pub floor_window_s: f64,
    /// Physics cross-check: re-detect the support of a non-ballistic no-contact interval
    /// with the speed-led rule ([`crate::contacts::support`]), open the hidden flights of
    /// jogs ([`crate::contacts::hidden_flight`]) and find the landings of feet with an
    /// estimated toe tip from their own motion ([`crate::contacts::landing`]); on by default.
    pub support_check: bool,
}

impl Default for ContactOptions {
    fn default() -> Self {
        ContactOptions {
            foot: Thresholds {
                h_on: DEFAULT_FOOT_H_ON,
                h_off: DEFAULT_FOOT_H_OFF,
                v_on: DEFAULT_FOOT_V_ON,
                v_off: DEFAULT_FOOT_V_OFF,
            },
            hand: Thresholds {
                h_on: DEFAULT_HAND_H_ON,
                h_off: DEFAULT_HAND_H_OFF,
                v_on: DEFAULT_HAND_V_ON,
                v_off: DEFAULT_HAND_V_OFF,
            },
            hands: true,
            static_mode: false,
            min_on_s: DEFAULT_MIN_ON_S,
            min_gap_s: DEFAULT_MIN_GAP_S,
            floor_window_s: DEFAULT_FLOOR_WINDOW_S,
            support_check: true,
        }
    }
}
