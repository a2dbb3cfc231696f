//! The gesture library: motion segments with their kinematic vectors, recorded order, exit
//! points and the pose features the transition costs need (docs/method.md, control layer).
//!
//! A library comes from any BVH files (the training takes or another character): each take is
//! segmented like the corpus ([`crate::motion::analyze`]) and each segment gets its normalized
//! kinematic vector `y_a` (with the *model's* normalization, so it is comparable with the state
//! Gaussians). Segments of one take keep their recorded order (`prev`/`next`), which the
//! successor cost D_sp uses; clips without neighbours fall back to junction distances.
//!
//! Exit points: a segment can be left at its last frame or at `interruptions` frames spaced
//! uniformly inside it (3 in the paper); segments shorter than `2 * (interruptions + 1)` frames
//! get fewer.

use std::path::PathBuf;

use crate::motion::{
    analyze, read_bvh, EffectorSpec, Motion, Normalization, SegmentParams, TakeAnalysis,
};

/// One library segment.
#[derive(Clone, Debug)]
pub struct LibSegment {
    /// Index of its take in [`Library::takes`].
    pub take: usize,
    /// First frame in the take.
    pub start: usize,
    /// One past the last frame.
    pub end: usize,
    /// Normalized kinematic vector.
    pub y: [f64; 6],
    /// Previous segment of the same take.
    pub prev: Option<usize>,
    /// Next segment of the same take.
    pub next: Option<usize>,
}

impl LibSegment {
    /// Frames in the segment.
    pub fn len(&self) -> usize {
        self.end - self.start
    }
    /// Whether it has no frames.
    pub fn is_empty(&self) -> bool {
        self.end <= self.start
    }
}

/// A place where the controller decides: segment `segment` at its frame `frame` (relative to
/// the segment's start). `end` marks the last frame; others are interruption frames.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ExitPoint {
    /// Segment index.
    pub segment: usize,
    /// Frame offset within the segment.
    pub frame: usize,
    /// Whether this is the segment's end.
    pub end: bool,
}

/// One library take.
#[derive(Clone, Debug)]
pub struct LibTake {
    /// Source file.
    pub source: PathBuf,
    /// The motion.
    pub motion: Motion,
    /// Its analysis (effector positions, segments).
    pub analysis: TakeAnalysis,
}

/// A gesture library.
#[derive(Clone, Debug)]
pub struct Library {
    /// The takes.
    pub takes: Vec<LibTake>,
    /// All segments, take by take in recorded order.
    pub segments: Vec<LibSegment>,
    /// Exit points, grouped by segment in frame order (the end exit last).
    pub exits: Vec<ExitPoint>,
    /// For each segment, the index of its first exit point.
    pub first_exit: Vec<usize>,
    /// Frames per second (all takes share it).
    pub fps: f64,
}

/// Why a library could not be built.
#[derive(Debug, thiserror::Error)]
pub enum LibraryError {
    /// A BVH file failed.
    #[error(transparent)]
    Bvh(#[from] crate::motion::BvhError),
    /// Analysis failed.
    #[error("{0}")]
    Analysis(String),
    /// Frame rates differ between takes.
    #[error("{path}: {fps:.3} fps, but the library's first take has {first:.3} fps: resample to one rate")]
    FrameRate {
        /// The file.
        path: String,
        /// Its rate.
        fps: f64,
        /// The first take's rate.
        first: f64,
    },
    /// No segments at all.
    #[error("the library has no motion segments")]
    Empty,
}

impl Library {
    /// Builds a library from BVH files, with `interruptions` interruption frames per segment.
    pub fn from_files(
        files: &[PathBuf],
        norm: &Normalization,
        effectors: &EffectorSpec,
        segment: &SegmentParams,
        interruptions: usize,
    ) -> Result<Library, LibraryError> {
        let mut takes = Vec::new();
        for f in files {
            let motion = read_bvh(f)?;
            let analysis = analyze(&motion, effectors, segment)
                .map_err(|e| LibraryError::Analysis(format!("{}: {e}", f.display())))?;
            takes.push(LibTake {
                source: f.clone(),
                motion,
                analysis,
            });
        }
        Self::from_takes(takes, norm, interruptions)
    }

    /// Builds a library from analysed takes.
    pub fn from_takes(
        takes: Vec<LibTake>,
        norm: &Normalization,
        interruptions: usize,
    ) -> Result<Library, LibraryError> {
        let fps = takes
            .first()
            .map(|t| t.motion.fps())
            .ok_or(LibraryError::Empty)?;
        let mut segments = Vec::new();
        for (ti, t) in takes.iter().enumerate() {
            if (t.motion.fps() - fps).abs() > 1e-3 * fps {
                return Err(LibraryError::FrameRate {
                    path: t.source.display().to_string(),
                    fps: t.motion.fps(),
                    first: fps,
                });
            }
            let base = segments.len();
            let n = t.analysis.segments.len();
            for (k, (g, y)) in t
                .analysis
                .segments
                .iter()
                .zip(&t.analysis.y_raw)
                .enumerate()
            {
                segments.push(LibSegment {
                    take: ti,
                    start: g.start_frame,
                    end: g.end_frame,
                    y: norm.apply(y),
                    prev: (k > 0).then(|| base + k - 1),
                    next: (k + 1 < n).then(|| base + k + 1),
                });
            }
        }
        if segments.is_empty() {
            return Err(LibraryError::Empty);
        }
        let mut exits = Vec::new();
        let mut first_exit = Vec::with_capacity(segments.len());
        for (i, s) in segments.iter().enumerate() {
            first_exit.push(exits.len());
            let len = s.len();
            let r = if len >= 2 * (interruptions + 1) {
                interruptions
            } else {
                0
            };
            for k in 1..=r {
                let f = len * k / (r + 1);
                if f > 0 && f < len - 1 {
                    exits.push(ExitPoint {
                        segment: i,
                        frame: f,
                        end: false,
                    });
                }
            }
            exits.push(ExitPoint {
                segment: i,
                frame: len.saturating_sub(1),
                end: true,
            });
        }
        Ok(Library {
            takes,
            segments,
            exits,
            first_exit,
            fps,
        })
    }

    /// The exit point after `e` in the same segment (None for an end exit).
    pub fn next_exit(&self, e: usize) -> Option<usize> {
        (!self.exits[e].end).then_some(e + 1)
    }

    /// Effector positions of segment `a` at its frame `f` (clamped into the segment).
    pub fn pose(&self, a: usize, f: usize) -> &[[f64; 3]] {
        let s = &self.segments[a];
        let t = &self.takes[s.take];
        let frame = (s.start + f.min(s.len().saturating_sub(1)))
            .min(t.analysis.positions.frames().saturating_sub(1));
        t.analysis.positions.frame(frame)
    }

    /// Effector velocities (units/s) of segment `a` at its frame `f` (central differences
    /// within the take).
    pub fn velocity(&self, a: usize, f: usize) -> Vec<[f64; 3]> {
        let s = &self.segments[a];
        let t = &self.takes[s.take];
        let n = t.analysis.positions.frames();
        let fr = (s.start + f).min(n.saturating_sub(1));
        let (lo, hi) = (fr.saturating_sub(1), (fr + 1).min(n.saturating_sub(1)));
        let dt = (hi - lo).max(1) as f64 / self.fps;
        let (pa, pb) = (
            t.analysis.positions.frame(lo),
            t.analysis.positions.frame(hi),
        );
        pa.iter()
            .zip(pb)
            .map(|(a, b)| [(b[0] - a[0]) / dt, (b[1] - a[1]) / dt, (b[2] - a[2]) / dt])
            .collect()
    }
}
