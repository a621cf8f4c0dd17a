//! Pure numerical helpers shared by the stages: Savitzky–Golay differentiation,
//! order statistics, small polynomial least-squares fits and branch-free sin/cos.

pub mod constants;
pub mod polyfit;
pub mod savgol;
pub mod spline;
pub mod stats;
pub mod svd;
pub mod trig;
pub mod v3;
