//! Pure numerical helpers shared by the stages: Savitzky–Golay differentiation,
//! order statistics and small polynomial least-squares fits.

pub mod constants;
pub mod polyfit;
pub mod savgol;
pub mod spline;
pub mod stats;
pub mod svd;
pub mod v3;
