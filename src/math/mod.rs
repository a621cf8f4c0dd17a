//! Pure numerical helpers shared by the stages: Savitzky–Golay differentiation,
//! order statistics, small polynomial least-squares fits, branch-free sin/cos, and the
//! stance heading frame.

pub mod constants;
pub mod heading;
pub mod polyfit;
pub mod savgol;
pub mod spline;
pub mod stats;
pub mod svd;
pub mod trig;
pub mod v3;
