//! The training data of the inference layer: per take, its steps' prosody features with the
//! kinematic targets of the motion segments they fall in ([`Sequence`], [`sequences`]),
//! standardized per take or pooled ([`take_levels`], [`pooled_levels`]), and split over time
//! for cross-validation ([`cv_split`]). Pure functions of the corpus.

use std::collections::HashMap;

use gesture_runtime::inference::StepFeatures;

use super::gmm::ProsodyPoint;
use super::model::level_of;
use crate::corpus::Corpus;
use crate::motion::Normalization;

/// One training or test sequence: a take's steps (optionally a time span of it).
#[derive(Clone, Debug, Default)]
pub struct Sequence {
    /// The take's file stem.
    pub stem: String,
    /// Normalized prosody features per step (from the runtime).
    pub features: Vec<StepFeatures>,
    /// Log kinematic target per step, standardized by its take's level (see `level`), not yet
    /// by the model's normalization.
    pub y_raw: Vec<[f64; 6]>,
    /// Step start and end times (s).
    pub times: Vec<(f64, f64)>,
    /// Start and end times (s) of the take's motion segments (for purging held-out data,
    /// see [`super::select`]).
    pub segments: Vec<(f64, f64)>,
    /// The take's level: the mean and spread of its segments' log kinematic parameters (in
    /// the span used for training), which `y_raw` is standardized by
    /// ([`super::model::InferenceModel::take_level`]).
    pub level: Normalization,
}

impl Sequence {
    /// Number of steps.
    pub fn len(&self) -> usize {
        self.features.len()
    }
    /// Whether empty.
    pub fn is_empty(&self) -> bool {
        self.features.is_empty()
    }

    /// The steps in `range` (same take, same segments).
    pub fn slice(&self, range: std::ops::Range<usize>) -> Sequence {
        Sequence {
            stem: self.stem.clone(),
            features: self.features[range.clone()].to_vec(),
            y_raw: self.y_raw[range.clone()].to_vec(),
            times: self.times[range].to_vec(),
            segments: self.segments.clone(),
            level: self.level,
        }
    }
}

/// Whether the span `a..b` overlaps `lo..hi` (false when either bound is NaN).
fn overlaps(a: f64, b: f64, lo: f64, hi: f64) -> bool {
    a < hi && b > lo
}

/// The segments of a take inside `span` (by midpoint): `(start_s, end_s, raw vector)`.
fn take_segments(
    t: &crate::corpus::LoadedTake,
    inside: impl Fn(f64, f64) -> bool,
) -> Vec<(f64, f64, [f64; 6])> {
    let dt = t.motion.frame_time;
    t.motion
        .segments
        .iter()
        .zip(&t.motion.y_raw)
        .map(|(g, y)| (g.start_frame as f64 * dt, g.end_frame as f64 * dt, *y))
        .filter(|&(g0, g1, _)| inside(g0, g1))
        .collect()
}

fn in_span(span: Option<(f64, f64)>) -> impl Fn(f64, f64) -> bool {
    move |a: f64, b: f64| span.is_none_or(|(s0, s1)| (0.5 * (a + b)) >= s0 && (0.5 * (a + b)) < s1)
}

/// Each take's level ([`super::model::InferenceModel::take_level`]) from its segments inside
/// `span`; a take with too few takes the level of all of them together.
pub fn take_levels(corpus: &Corpus, span: Option<(f64, f64)>) -> HashMap<String, Normalization> {
    let inside = in_span(span);
    let per_take: Vec<(String, Vec<[f64; 6]>)> = corpus
        .takes
        .iter()
        .map(|t| {
            let raw = take_segments(t, &inside).into_iter().map(|g| g.2).collect();
            (t.stem.clone(), raw)
        })
        .collect();
    let all: Vec<[f64; 6]> = per_take
        .iter()
        .flat_map(|(_, r)| r.iter().copied())
        .collect();
    let pooled = level_of(&all, Normalization::identity());
    per_take
        .into_iter()
        .map(|(stem, raw)| (stem, level_of(&raw, pooled)))
        .collect()
}

/// Every take's level as one: the level of all takes' segments inside `span` together (each
/// take standardized alike, so the corpus normalization alone puts them in the model's
/// terms, as before takes had levels of their own; `eval-inference --take-level pooled`).
pub fn pooled_levels(corpus: &Corpus, span: Option<(f64, f64)>) -> HashMap<String, Normalization> {
    let inside = in_span(span);
    let all: Vec<[f64; 6]> = corpus
        .takes
        .iter()
        .flat_map(|t| take_segments(t, &inside).into_iter().map(|g| g.2))
        .collect();
    let pooled = level_of(&all, Normalization::identity());
    corpus
        .takes
        .iter()
        .map(|t| (t.stem.clone(), pooled))
        .collect()
}

/// The sequences of a corpus, keeping steps whose midpoint lies in `span` (seconds), and the
/// log kinematic vectors of the segments inside the span (for the normalization), each take
/// standardized by its level ([`take_levels`] over the same span).
pub fn sequences(corpus: &Corpus, span: Option<(f64, f64)>) -> (Vec<Sequence>, Vec<[f64; 6]>) {
    sequences_with_levels(corpus, span, &take_levels(corpus, span))
}

/// [`sequences`] with given take levels: a take named in `levels` is standardized by that
/// level (a test span of a training take, by the training span's), any other by its own
/// segments inside `span`.
pub fn sequences_with_levels(
    corpus: &Corpus,
    span: Option<(f64, f64)>,
    levels: &HashMap<String, Normalization>,
) -> (Vec<Sequence>, Vec<[f64; 6]>) {
    let own = if corpus.takes.iter().all(|t| levels.contains_key(&t.stem)) {
        HashMap::new()
    } else {
        take_levels(corpus, span)
    };
    let inside = in_span(span);
    let mut seqs = Vec::new();
    let mut segs = Vec::new();
    for t in &corpus.takes {
        let level = levels
            .get(&t.stem)
            .or_else(|| own.get(&t.stem))
            .copied()
            .unwrap_or_else(Normalization::identity);
        let mut s = Sequence {
            stem: t.stem.clone(),
            level,
            ..Sequence::default()
        };
        for a in &t.aligned {
            let (t0, t1) = (a.step.start_s(), a.step.end_s());
            if inside(t0, t1) {
                s.features.push(a.features);
                s.y_raw.push(level.apply(&a.y_raw));
                s.times.push((t0, t1));
            }
        }
        let dt = t.motion.frame_time;
        for g in &t.motion.segments {
            s.segments
                .push((g.start_frame as f64 * dt, g.end_frame as f64 * dt));
        }
        segs.extend(take_segments(t, &inside).iter().map(|g| level.apply(&g.2)));
        if !s.is_empty() {
            seqs.push(s);
        }
    }
    (seqs, segs)
}

/// One fold of a cross-validation over time ([`cv_split`]).
#[derive(Clone, Debug, Default)]
pub struct CvSplit {
    /// Training sequences: every step of the takes not held out, and the steps of the held-out
    /// takes before and after the held-out span (separate sequences), less the steps that
    /// share a motion segment with it.
    pub train: Vec<Sequence>,
    /// Log kinematic vectors of the training segments (for the normalization).
    pub segments: Vec<[f64; 6]>,
    /// The held-out steps.
    pub test: Vec<Sequence>,
}

/// Fold `fold` of `folds` over time: each take whose stem `held` accepts has the span
/// `[fold, fold + 1) / folds` of its motion held out (steps by their midpoint); training
/// keeps the rest of the corpus, less every step and segment that overlaps a motion segment
/// reaching into the held-out span (purged, as model selection's folds are: a segment spans
/// several steps, so its neighbours would carry the held-out motion into training).
pub fn cv_split(
    corpus: &Corpus,
    fold: usize,
    folds: usize,
    held: impl Fn(&str) -> bool,
) -> CvSplit {
    cv_split_levels(corpus, fold, folds, held, true)
}

/// [`cv_split`], with `own_levels` false every take standardized by the level of all training
/// segments together ([`pooled_levels`]) instead of its own.
pub fn cv_split_levels(
    corpus: &Corpus,
    fold: usize,
    folds: usize,
    held: impl Fn(&str) -> bool,
    own_levels: bool,
) -> CvSplit {
    let mut out = CvSplit::default();
    let folds = folds.max(1);
    // Each take is standardized by the level of its training segments (the held-out span's
    // own kinematics are not looked at); a take with too few, by all training segments'.
    let mut parts = Vec::with_capacity(corpus.takes.len());
    for t in &corpus.takes {
        let segs = take_segments(t, |_, _| true);
        let (lo, hi, plo, phi) = if held(&t.stem) {
            let len = t.motion_s();
            // The last span takes whatever lies past the motion's end too (audio a little
            // longer than the motion), so every step is held out once.
            let hi = if fold + 1 >= folds {
                f64::INFINITY
            } else {
                len * (fold + 1) as f64 / folds as f64
            };
            let lo = len * fold as f64 / folds as f64;
            let (mut plo, mut phi) = (lo, hi);
            for &(g0, g1, _) in &segs {
                if overlaps(g0, g1, lo, hi) {
                    plo = plo.min(g0);
                    phi = phi.max(g1);
                }
            }
            (lo, hi, plo, phi)
        } else {
            (f64::NAN, f64::NAN, f64::NAN, f64::NAN)
        };
        parts.push((t, segs, lo, hi, plo, phi));
    }
    // The segments left for training, as raw vectors.
    let trained = |segs: &[(f64, f64, [f64; 6])], plo: f64, phi: f64| -> Vec<[f64; 6]> {
        segs.iter()
            .filter(|g| !overlaps(g.0, g.1, plo, phi))
            .map(|g| g.2)
            .collect()
    };
    let all: Vec<[f64; 6]> = parts
        .iter()
        .flat_map(|(_, segs, _, _, plo, phi)| trained(segs, *plo, *phi))
        .collect();
    let pooled = level_of(&all, Normalization::identity());
    for (t, segs, lo, hi, plo, phi) in parts {
        let train_segs = trained(&segs, plo, phi);
        let level = if own_levels {
            level_of(&train_segs, pooled)
        } else {
            pooled
        };
        let is_held = |a: f64, b: f64| {
            let mid = 0.5 * (a + b);
            mid >= lo && mid < hi
        };
        let times: Vec<(f64, f64)> = segs.iter().map(|g| (g.0, g.1)).collect();
        let empty = || Sequence {
            stem: t.stem.clone(),
            segments: times.clone(),
            level,
            ..Sequence::default()
        };
        let (mut before, mut after, mut test) = (empty(), empty(), empty());
        for a in &t.aligned {
            let (t0, t1) = (a.step.start_s(), a.step.end_s());
            let into = if is_held(t0, t1) {
                &mut test
            } else if overlaps(t0, t1, plo, phi) {
                continue;
            } else if t0 >= phi {
                &mut after
            } else {
                &mut before
            };
            into.features.push(a.features);
            into.y_raw.push(level.apply(&a.y_raw));
            into.times.push((t0, t1));
        }
        out.segments
            .extend(train_segs.iter().map(|y| level.apply(y)));
        out.train
            .extend([before, after].into_iter().filter(|s| !s.is_empty()));
        if !test.is_empty() {
            out.test.push(test);
        }
    }
    out
}

/// The mixture's view of a step.
pub fn prosody_point(f: &StepFeatures) -> ProsodyPoint {
    ProsodyPoint {
        f0: f.f0.map(|v| v as f64),
        obs: [f.obs[0] as f64, f.obs[1] as f64],
    }
}
