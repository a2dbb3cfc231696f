//! Corpus ingestion: finding speech+motion takes, loading them, and aligning the runtime's
//! prosody steps with the kinematic parameters of the motion.

pub mod align;
pub mod discover;
pub mod load;
pub mod stats;

pub use align::{align, AlignedStep};
pub use discover::{discover, DiscoverError, Take};
pub use load::{load_corpus, load_take, Corpus, CorpusError, LoadOptions, LoadedTake};
