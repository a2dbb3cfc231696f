//! Corpus ingestion: finding speech+motion takes, loading them, and aligning the runtime's
//! prosody steps with the kinematic parameters of the motion.

pub mod discover;
