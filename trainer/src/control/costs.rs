//! Costs of the control layer (docs/method.md, "Control layer"): how well a segment fits each hidden
//! state (`psi`), and how well one segment follows another (successor costs).
//!
//! - `psi_a(i) = E_{y ~ N(mu_i, Sigma_i)} ||y - y_a||`, by Monte Carlo with the same 512
//!   standard-normal draws for every state and segment (common random numbers: differences
//!   between segments are not blurred by sampling noise; deterministic).
//! - Segment distance `D(a, b)`: Euclidean over a signature of each segment, each part scaled
//!   by its spread over the library: log length, the initial pose of the effectors, and the
//!   dynamics (log mean speed and log start-to-end displacement of each effector).
//! - Leaving `a` at its end for `a'`: `D_sp = D(next(a), a') + D(a, prev(a'))`, zero for the
//!   recorded successor. Where `next(a)` or `prev(a')` does not exist (clip ends, libraries
//!   of separate clips), the junction distance: pose plus velocity difference between `a`'s
//!   last frame and `a'`'s first frame.
//! - Leaving `a` at an interruption frame `f`: the junction distance from frame `f` to `a'`'s
//!   first frame plus a fixed interruption penalty.
//! - All of the above is multiplied by `transition_weight` to trade smoothness against fit.
//! - Leaving `a` at its end for any segment but its recorded successor adds
//!   `junction_weight` times the visible jump: the mean effector distance between `a`'s last
//!   frame and `a'`'s first, over the library's spread of start poses. D_sp says how well `a'`
//!   substitutes for the recorded successor, which in a large library implies a small jump; in
//!   a small one (the 50 s ZeroEGGS take has 39 segments) the best substitute can still start
//!   far away, and without this term the policy's cuts jumped as far as random ones (measured
//!   with `gesture-train eval-motion`, see the README).

use nalgebra::DMatrix;
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, StandardNormal};
use rayon::prelude::*;

use super::library::Library;
use crate::inference::gaussian::Gaussian;

/// Tunables.
#[derive(Clone, Copy, Debug)]
pub struct CostParams {
    /// Added to every interruption (in segment-distance units).
    pub interruption_penalty: f64,
    /// Weight of transition costs against `psi`.
    pub transition_weight: f64,
    /// Weight of the pose jump at segment ends (not scaled by `transition_weight`).
    pub junction_weight: f64,
    /// Monte Carlo draws for `psi`.
    pub psi_samples: usize,
}

impl Default for CostParams {
    fn default() -> Self {
        Self {
            interruption_penalty: 1.0,
            transition_weight: 0.05,
            junction_weight: 0.3,
            psi_samples: 512,
        }
    }
}

/// `psi[a][i]` for every segment and state.
pub fn psi(lib: &Library, states: &[Gaussian], samples: usize) -> Vec<Vec<f64>> {
    let ys: Vec<[f64; 6]> = lib.segments.iter().map(|s| s.y).collect();
    psi_of(&ys, states, samples)
}

/// `psi[a][i]` for segments whose kinematic vectors are `ys` (a tone scores the library's
/// segments through its transform, see `super::style`).
pub fn psi_of(ys: &[[f64; 6]], states: &[Gaussian], samples: usize) -> Vec<Vec<f64>> {
    let mut rng = ChaCha8Rng::seed_from_u64(0x5053_4931);
    let z: Vec<[f64; 6]> = (0..samples)
        .map(|_| std::array::from_fn(|_| StandardNormal.sample(&mut rng)))
        .collect();
    // y = mu + L z for each state, drawn once.
    let draws: Vec<Vec<[f64; 6]>> = states
        .iter()
        .map(|g| {
            let l = g
                .cov()
                .clone()
                .cholesky()
                .map(|c| c.l())
                .unwrap_or_else(|| DMatrix::identity(6, 6));
            z.iter()
                .map(|zz| {
                    std::array::from_fn(|r| {
                        g.mean()[r] + (0..6).map(|c| l[(r, c)] * zz[c]).sum::<f64>()
                    })
                })
                .collect()
        })
        .collect();
    ys.par_iter()
        .map(|sy| {
            draws
                .iter()
                .map(|d| {
                    d.iter()
                        .map(|y| (0..6).map(|k| (y[k] - sy[k]).powi(2)).sum::<f64>().sqrt())
                        .sum::<f64>()
                        / d.len().max(1) as f64
                })
                .collect()
        })
        .collect()
}

/// Per-segment signature for [`Signatures::segment_distance`] and the scales of junction
/// distances.
#[derive(Clone, Debug)]
pub struct Signatures {
    sig: Vec<Vec<f64>>,
    pos_scale: f64,
    vel_scale: f64,
}

fn norm3(v: &[f64; 3]) -> f64 {
    (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt()
}

impl Signatures {
    /// Signatures of every library segment, each component divided by its library spread.
    pub fn new(lib: &Library) -> Self {
        let raw: Vec<Vec<f64>> = (0..lib.segments.len())
            .map(|a| {
                let s = &lib.segments[a];
                let first = lib.pose(a, 0);
                let last = lib.pose(a, s.len().saturating_sub(1));
                let mut v = vec![(s.len().max(1) as f64 / lib.fps).ln()];
                for p in first {
                    v.extend_from_slice(p);
                }
                for (k, (p0, p1)) in first.iter().zip(last).enumerate() {
                    let disp = norm3(&[p1[0] - p0[0], p1[1] - p0[1], p1[2] - p0[2]]);
                    // Mean speed over the segment's frames.
                    let mut path = 0.0;
                    for f in 1..s.len() {
                        let (a0, a1) = (lib.pose(a, f - 1)[k], lib.pose(a, f)[k]);
                        path += norm3(&[a1[0] - a0[0], a1[1] - a0[1], a1[2] - a0[2]]);
                    }
                    let speed = path * lib.fps / s.len().max(1) as f64;
                    v.push((speed + 1e-3).ln());
                    v.push((disp + 1e-3).ln());
                }
                v
            })
            .collect();
        let dims = raw.first().map_or(0, |v| v.len());
        let n = raw.len().max(1) as f64;
        let sd: Vec<f64> = (0..dims)
            .map(|d| {
                let m = raw.iter().map(|v| v[d]).sum::<f64>() / n;
                (raw.iter().map(|v| (v[d] - m).powi(2)).sum::<f64>() / n)
                    .sqrt()
                    .max(1e-9)
            })
            .collect();
        let sig = raw
            .iter()
            .map(|v| v.iter().zip(&sd).map(|(x, s)| x / s).collect())
            .collect();
        // Junction scales: typical pose and velocity spreads over all segment starts.
        let starts: Vec<Vec<[f64; 3]>> = (0..lib.segments.len())
            .map(|a| lib.pose(a, 0).to_vec())
            .collect();
        let vels: Vec<Vec<[f64; 3]>> = (0..lib.segments.len())
            .map(|a| lib.velocity(a, 0))
            .collect();
        let spread = |xs: &[Vec<[f64; 3]>]| {
            let n = xs.len().max(1) as f64;
            let k = xs.first().map_or(0, |v| v.len());
            let mut total = 0.0;
            for e in 0..k {
                for c in 0..3 {
                    let m = xs.iter().map(|v| v[e][c]).sum::<f64>() / n;
                    total += xs.iter().map(|v| (v[e][c] - m).powi(2)).sum::<f64>() / n;
                }
            }
            total.sqrt().max(1e-9)
        };
        Self {
            sig,
            pos_scale: spread(&starts),
            vel_scale: spread(&vels),
        }
    }

    /// Perceptual distance between two segments.
    pub fn segment_distance(&self, a: usize, b: usize) -> f64 {
        self.sig[a]
            .iter()
            .zip(&self.sig[b])
            .map(|(x, y)| (x - y).powi(2))
            .sum::<f64>()
            .sqrt()
    }

    /// Mean effector distance from frame `f` of `a` to the first frame of `b`, over the spread
    /// of start poses.
    pub fn pose_jump(&self, lib: &Library, a: usize, f: usize, b: usize) -> f64 {
        let (pa, pb) = (lib.pose(a, f), lib.pose(b, 0));
        let d: f64 = pa
            .iter()
            .zip(pb)
            .map(|(x, y)| (0..3).map(|c| (x[c] - y[c]).powi(2)).sum::<f64>().sqrt())
            .sum();
        d / pa.len().max(1) as f64 / self.pos_scale
    }

    /// Junction distance from frame `f` of `a` to the first frame of `b`.
    pub fn junction(&self, lib: &Library, a: usize, f: usize, b: usize) -> f64 {
        self.junction_at(lib, a, f, b, 0)
    }

    /// Junction distance from frame `f` of `a` to frame `g` of `b`: effector pose difference
    /// over the library's spread of start poses plus half the velocity difference over its
    /// spread of velocities.
    pub fn junction_at(&self, lib: &Library, a: usize, f: usize, b: usize, g: usize) -> f64 {
        let (pa, pb) = (lib.pose(a, f), lib.pose(b, g));
        let (va, vb) = (lib.velocity(a, f), lib.velocity(b, g));
        let dp: f64 = pa
            .iter()
            .zip(pb)
            .map(|(x, y)| (0..3).map(|c| (x[c] - y[c]).powi(2)).sum::<f64>())
            .sum();
        let dv: f64 = va
            .iter()
            .zip(&vb)
            .map(|(x, y)| (0..3).map(|c| (x[c] - y[c]).powi(2)).sum::<f64>())
            .sum();
        dp.sqrt() / self.pos_scale + 0.5 * dv.sqrt() / self.vel_scale
    }
}

/// Successor costs `succ[e][c]` from every exit point to every segment's start.
pub fn successor_costs(lib: &Library, sig: &Signatures, p: &CostParams) -> Vec<Vec<f64>> {
    let n = lib.segments.len();
    lib.exits
        .par_iter()
        .map(|ex| {
            let a = ex.segment;
            (0..n)
                .map(|c| {
                    let raw = if ex.end {
                        match (lib.segments[a].next, lib.segments[c].prev) {
                            (Some(next), Some(prev)) => {
                                sig.segment_distance(next, c) + sig.segment_distance(a, prev)
                            }
                            _ => sig.junction(lib, a, ex.frame, c),
                        }
                    } else {
                        sig.junction(lib, a, ex.frame, c) + p.interruption_penalty
                    };
                    let jump = if ex.end && lib.segments[a].next != Some(c) {
                        p.junction_weight * sig.pose_jump(lib, a, ex.frame, c)
                    } else {
                        0.0
                    };
                    p.transition_weight * raw + jump
                })
                .collect()
        })
        .collect()
}
