//! Evaluations that run what the device runs: the model and library packed into blob bytes,
//! read back and driven through the runtime's device loop.
//!
//! - [`motion`]: motion quality of the online controller on held-out audio against random
//!   selection, the offline DP reference and the motion capture.

pub mod metrics;
pub mod motion;
