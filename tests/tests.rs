//! The one integration-test binary. Table of contents:
//!
//! - `util`: shared helpers (paths to `../shared`, skip messages, temp dirs, running the binary).
mod util;
