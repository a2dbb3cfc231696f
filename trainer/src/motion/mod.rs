//! Motion capture in, gesture segments and their kinematic parameters out.
//!
//! | module | owns |
//! |---|---|
//! | [`bvh`] | BVH reading/writing; [`Skeleton`], [`Motion`], [`BvhError`] (file:line messages) |
//! | [`fk`] | forward kinematics (per-joint rotation order), [`Positions`], the [`FkPlan`] fast path |
//!
//! ## Contract
//!
//! Nothing in this tree panics on any input file: a BVH file that cannot be used gives a
//! [`BvhError`] naming the file and line; a motion is valid once built ([`Motion`] checks its
//! invariants at its only two gates, [`parse_bvh`] and [`Motion::new`]), and everything after
//! that gate returns results or typed errors. Everything is `f64` and single-threaded;
//! allocation is proportional to the take's size.

pub mod bvh;
pub mod fk;

pub use bvh::{
    parse_bvh, read_bvh, write_bvh, write_bvh_file, BvhError, BvhErrorKind, Channel, Joint, Motion,
    MotionError, Skeleton,
};
pub use fk::{FkError, FkPlan, Positions, Target};
