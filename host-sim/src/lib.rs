//! # host-sim
//!
//! The desktop simulator.
