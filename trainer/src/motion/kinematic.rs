//! The six kinematic parameters of a segment, y = (T, D, V, A, C, H), and their corpus
//! normalization (the paper's W and B; docs/method.md, "Data and time steps").
//!
//! [`crate::motion::analyze`] measures them in *body units* ([`super::body`]: limb lengths,
//! height above the shoulder, derivatives over 1/30 s); [`segment_kinematics`] below is the
//! same definitions in skeleton units, kept for callers that want physical values.
//!
//! Owns the definitions below; [`Kinematics`] holds the physical values, [`Kinematics::log`]
//! the log-scale vector `y_raw`, [`Normalization`] the fitted affine map to `y`.
//!
//! ## Definitions
//!
//! Over the frames `f` of a segment and the effectors `e` (positions from FK, skeleton units;
//! velocity `v` and acceleration `a` by central differences over the *whole take*, so frames at
//! a segment boundary use their true neighbours; one-sided at the take's ends):
//!
//! - **T**, temporal extent: `frames * frame_time` (s). Segments tile the take, so the T's
//!   add up to its duration.
//! - **D**, spatial extent: path length, **mean over effectors** of
//!   `sum_f |p(f+1) - p(f)|` (each segment owns the steps that start in it, so the D's add up
//!   to the take's path). The mean, not the sum, keeps D comparable between a two-handed
//!   character and an eight-tentacle one, and consistent with V.
//! - **V**, mean speed: mean over frames and effectors of `|v|` (units/s).
//! - **A**, mean acceleration magnitude: mean of `|a|` (units/s^2).
//! - **C**, mean curvature: mean of `|v x a| / max(|v|, v_floor)^3` (1/units). For
//!   `|v| >= v_floor` this is the exact curvature of the path (`1/r` on a circle of radius
//!   `r`); below the floor the denominator is frozen so the nearly still frames of a hold do
//!   not explode (a path's direction is meaningless when it barely moves). `v_floor` is
//!   [`KinematicParams::curvature_speed_floor`] (default 0.1) times the median effector speed
//!   of the take, which keeps it unit-free.
//! - **H**, mean effector height: mean of `p_up - floor`, clamped at 0, with `up` =
//!   [`KinematicParams::up_axis`] (default Y, right for both real skeletons). The floor is by
//!   default the lowest point any joint or end site reaches in the take
//!   ([`HeightReference::LowestPoint`]), i.e. the ground for a standing capture (toes),
//!   whatever the rig's origin: the ZeroEGGS root sits at hip height, the Bandai root on the
//!   ground. [`HeightReference::Floor`] gives a fixed floor height instead.
//!
//! ## Log scale
//!
//! `y_raw[k] = ln(value[k] + eps[k])`. All six values are >= 0 by construction; `eps`
//! ([`KinematicParams::eps`], default `1e-3` in each dimension's unit: s, units, units/s,
//! units/s^2, 1/units, units) only keeps a perfectly still or straight segment finite. It is far
//! below any real motion in cm or m (10 um or 1 mm of path), so it only matters at zero.
//!
//! ## Normalization
//!
//! [`Normalization::fit`] takes the per-dimension mean and population standard deviation of a
//! corpus of `y_raw`, so `apply(y) = (y - mean) / scale` has zero mean and unit spread on that
//! corpus: `W = diag(1/scale)`, `B = -mean/scale`. A dimension with no spread (e.g. every
//! segment exactly the same length) gets `scale = 1` rather than a division by zero.
//!
//! ## Invariants
//!
//! Never panics. Outputs are finite for finite positions of any realistic magnitude (sums of
//! squares overflow only beyond ~1e150 units).

use serde::{Deserialize, Serialize};

use super::fk::{Positions, Vec3};
use super::segment::{quantile, velocities, Segment};

/// Names of the six dimensions, in vector order.
pub const NAMES: [&str; 6] = ["T", "D", "V", "A", "C", "H"];

/// The six kinematic parameters of one segment, in physical units (not yet log-scaled).
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Kinematics {
    /// T: duration (s).
    pub t: f64,
    /// D: mean effector path length (units).
    pub d: f64,
    /// V: mean effector speed (units/s).
    pub v: f64,
    /// A: mean acceleration magnitude (units/s^2).
    pub a: f64,
    /// C: mean curvature (1/units).
    pub c: f64,
    /// H: mean effector height above the floor (units).
    pub h: f64,
}

impl Kinematics {
    /// `[T, D, V, A, C, H]`.
    pub fn to_array(&self) -> [f64; 6] {
        [self.t, self.d, self.v, self.a, self.c, self.h]
    }

    /// From `[T, D, V, A, C, H]`.
    pub fn from_array(x: [f64; 6]) -> Kinematics {
        let [t, d, v, a, c, h] = x;
        Kinematics { t, d, v, a, c, h }
    }

    /// `y_raw = ln(value + eps)` per dimension (values below 0 count as 0).
    pub fn log(&self, eps: &[f64; 6]) -> [f64; 6] {
        let x = self.to_array();
        std::array::from_fn(|k| (x[k].max(0.0) + eps[k]).ln())
    }
}

/// Where height is measured from.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum HeightReference {
    /// The lowest point any joint or end site reaches in the take.
    LowestPoint,
    /// A fixed floor height along the up axis (units).
    Floor(f64),
}

/// Settings for the kinematic parameters. See the module docs for the defaults.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct KinematicParams {
    /// Vertical axis: 0 = X, 1 = Y (default), 2 = Z.
    pub up_axis: usize,
    /// Where H is measured from.
    pub height_reference: HeightReference,
    /// Curvature speed floor as a fraction of the take's median effector speed.
    pub curvature_speed_floor: f64,
    /// Added before the logarithm, per dimension (T, D, V, A, C, H).
    pub eps: [f64; 6],
}

impl Default for KinematicParams {
    fn default() -> Self {
        KinematicParams {
            up_axis: 1,
            height_reference: HeightReference::LowestPoint,
            curvature_speed_floor: 0.1,
            eps: [1e-3; 6],
        }
    }
}

/// A kinematic parameter setting is out of range.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum KinematicParamError {
    /// The up axis is not 0, 1 or 2.
    #[error("up axis must be 0 (X), 1 (Y) or 2 (Z), got {0}")]
    UpAxis(usize),
    /// A value must be finite and > 0 (eps) or >= 0 (speed floor).
    #[error("kinematic parameter `{0}` must be a finite number {1}")]
    Range(&'static str, &'static str),
}

impl KinematicParams {
    /// Checks every field's range.
    pub fn validate(&self) -> Result<(), KinematicParamError> {
        if self.up_axis > 2 {
            return Err(KinematicParamError::UpAxis(self.up_axis));
        }
        let f = self.curvature_speed_floor;
        if !(f.is_finite() && f >= 0.0) {
            return Err(KinematicParamError::Range("curvature_speed_floor", ">= 0"));
        }
        if !self.eps.iter().all(|e| e.is_finite() && *e > 0.0) {
            return Err(KinematicParamError::Range("eps", "> 0"));
        }
        if let HeightReference::Floor(h) = self.height_reference {
            if !h.is_finite() {
                return Err(KinematicParamError::Range(
                    "height_reference",
                    "(floor height)",
                ));
            }
        }
        Ok(())
    }
}

fn sub(a: Vec3, b: Vec3) -> Vec3 {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

fn norm(a: Vec3) -> f64 {
    (a[0] * a[0] + a[1] * a[1] + a[2] * a[2]).sqrt()
}

fn cross(a: Vec3, b: Vec3) -> Vec3 {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

/// Acceleration of every point by central second differences (frames x points); the first
/// and last frame copy their neighbour's value, takes under 3 frames have zero acceleration.
pub fn accelerations(positions: &Positions, frame_time: f64) -> Vec<Vec3> {
    let (n, k) = (positions.frames(), positions.points());
    let mut out = vec![[0.0; 3]; n * k];
    if n < 3 {
        return out;
    }
    let dt2 = frame_time * frame_time;
    for f in 1..n - 1 {
        for e in 0..k {
            let (a, b, c) = (
                positions.get(f - 1, e),
                positions.get(f, e),
                positions.get(f + 1, e),
            );
            out[f * k + e] = std::array::from_fn(|i| (a[i] - 2.0 * b[i] + c[i]) / dt2);
        }
    }
    for e in 0..k {
        out[e] = out[k + e];
        out[(n - 1) * k + e] = out[(n - 2) * k + e];
    }
    out
}

/// Kinematic parameters of each segment.
///
/// `positions` are the effectors (frames x effectors) of the whole take, `floor` the height
/// (along `params.up_axis`) that H is measured from. Segments outside the take are clipped to
/// it (an empty one gives all zeros).
pub fn segment_kinematics(
    positions: &Positions,
    frame_time: f64,
    segments: &[Segment],
    floor: f64,
    params: &KinematicParams,
) -> Result<Vec<Kinematics>, KinematicParamError> {
    params.validate()?;
    let (n, k) = (positions.frames(), positions.points());
    let vel = velocities(positions, frame_time);
    let acc = accelerations(positions, frame_time);
    let speeds: Vec<f64> = vel.iter().map(|&v| norm(v)).collect();
    let v_floor = params.curvature_speed_floor * quantile(&speeds, 0.5);
    let up = params.up_axis;
    Ok(segments
        .iter()
        .map(|seg| {
            let (s, e) = (seg.start_frame.min(n), seg.end_frame.min(n));
            let frames = e.saturating_sub(s);
            let samples = (frames * k) as f64;
            if frames == 0 || k == 0 {
                return Kinematics {
                    t: frames as f64 * frame_time,
                    ..Kinematics::default()
                };
            }
            let (mut path, mut speed, mut accel, mut curv, mut height) = (0.0, 0.0, 0.0, 0.0, 0.0);
            for f in s..e {
                let next = (f + 1).min(n - 1);
                for j in 0..k {
                    let i = f * k + j;
                    let p = positions.get(f, j);
                    path += norm(sub(positions.get(next, j), p));
                    speed += speeds[i];
                    accel += norm(acc[i]);
                    let denom = speeds[i].max(v_floor).powi(3);
                    if denom > 0.0 {
                        curv += norm(cross(vel[i], acc[i])) / denom;
                    }
                    height += (p[up] - floor).max(0.0);
                }
            }
            Kinematics {
                t: frames as f64 * frame_time,
                d: path / k as f64,
                v: speed / samples,
                a: accel / samples,
                c: curv / samples,
                h: height / samples,
            }
        })
        .collect())
}

/// Why a normalization could not be fitted.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum NormalizationError {
    /// No vectors to fit on.
    #[error("cannot fit the kinematic normalization on an empty corpus: analyze some takes first")]
    Empty,
    /// A vector has a NaN or infinite entry.
    #[error("kinematic vector {index} has a non-finite value in dimension {dim}")]
    NonFinite {
        /// Index of the vector in the corpus.
        index: usize,
        /// The dimension's name (T, D, V, A, C or H).
        dim: &'static str,
    },
}

/// Per-dimension affine normalization `z = (y - mean) / scale` (the paper's W and B).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Normalization {
    /// Corpus mean of each dimension.
    pub mean: [f64; 6],
    /// Corpus standard deviation of each dimension (1 where it is zero).
    pub scale: [f64; 6],
}

impl Default for Normalization {
    fn default() -> Self {
        Normalization::identity()
    }
}

impl Normalization {
    /// The map that changes nothing.
    pub fn identity() -> Normalization {
        Normalization {
            mean: [0.0; 6],
            scale: [1.0; 6],
        }
    }

    /// Fits mean and population standard deviation per dimension on `corpus`.
    pub fn fit(corpus: &[[f64; 6]]) -> Result<Normalization, NormalizationError> {
        if corpus.is_empty() {
            return Err(NormalizationError::Empty);
        }
        for (index, y) in corpus.iter().enumerate() {
            if let Some(d) = y.iter().position(|v| !v.is_finite()) {
                return Err(NormalizationError::NonFinite {
                    index,
                    dim: NAMES[d],
                });
            }
        }
        let n = corpus.len() as f64;
        let mean: [f64; 6] = std::array::from_fn(|d| corpus.iter().map(|y| y[d]).sum::<f64>() / n);
        let scale = std::array::from_fn(|d| {
            let var = corpus.iter().map(|y| (y[d] - mean[d]).powi(2)).sum::<f64>() / n;
            let sd = var.sqrt();
            // Relative test: spread that is only rounding noise counts as none.
            if sd > 1e-12 * mean[d].abs().max(1.0) {
                sd
            } else {
                1.0
            }
        });
        Ok(Normalization { mean, scale })
    }

    /// The map that applies `self`, then `next`, as one normalization.
    pub fn then(&self, next: &Normalization) -> Normalization {
        Normalization {
            mean: std::array::from_fn(|d| self.mean[d] + self.scale[d] * next.mean[d]),
            scale: std::array::from_fn(|d| self.scale[d] * next.scale[d]),
        }
    }

    /// `(y - mean) / scale`.
    pub fn apply(&self, y: &[f64; 6]) -> [f64; 6] {
        std::array::from_fn(|d| (y[d] - self.mean[d]) / self.scale[d])
    }

    /// The inverse of [`Normalization::apply`].
    pub fn invert(&self, z: &[f64; 6]) -> [f64; 6] {
        std::array::from_fn(|d| z[d] * self.scale[d] + self.mean[d])
    }

    /// The paper's form `z = W y + B`: the diagonal of W and the vector B.
    pub fn weights(&self) -> ([f64; 6], [f64; 6]) {
        (
            std::array::from_fn(|d| 1.0 / self.scale[d]),
            std::array::from_fn(|d| -self.mean[d] / self.scale[d]),
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::motion::segment::Phase;

    fn whole(n: usize) -> Vec<Segment> {
        vec![Segment {
            start_frame: 0,
            end_frame: n,
            phase: Phase::Moving,
        }]
    }

    fn rel(a: f64, b: f64) -> f64 {
        (a - b).abs() / b.abs()
    }

    #[test]
    fn circle_matches_analytic_values() {
        // Radius r, angular speed w, t seconds, horizontal circle at height h0 above floor 0.
        let (r, w, h0, fps, t) = (20.0, 3.0, 100.0, 30.0, 4.0);
        let n = (t * fps) as usize;
        let dt = 1.0 / fps;
        let track: Vec<Vec3> = (0..n)
            .map(|f| {
                let th = w * f as f64 * dt;
                [r * th.cos(), h0, r * th.sin()]
            })
            .collect();
        let pos = Positions::from_tracks(&[track]).unwrap();
        let k = segment_kinematics(&pos, dt, &whole(n), 0.0, &KinematicParams::default()).unwrap();
        let k = k[0];
        // Tolerances: central differences at w*dt = 0.1 rad are off by (w dt)^2/6 ~ 0.2% (V),
        // (w dt)^2/12 (A) and (w dt)^2/4 ~ 0.25% (C); one-sided end frames add ~1/n.
        assert!(rel(k.t, t) < 1e-12);
        // n frames span n - 1 steps: D = r w (t - dt) (the step after the last frame belongs
        // to the next segment, and there is none).
        assert!(rel(k.d, r * w * (t - dt)) < 3e-3, "D {}", k.d);
        assert!(rel(k.v, r * w) < 3e-3, "V {}", k.v);
        assert!(rel(k.a, r * w * w) < 3e-3, "A {}", k.a);
        assert!(rel(k.c, 1.0 / r) < 3e-3, "C {}", k.c);
        assert!(rel(k.h, h0) < 1e-12);
    }

    #[test]
    fn straight_line_has_no_acceleration_or_curvature() {
        let n = 90;
        let dt = 1.0 / 30.0;
        let track: Vec<Vec3> = (0..n)
            .map(|f| {
                let s = 50.0 * f as f64 * dt;
                [s * 0.6, 10.0 + s * 0.8, 0.0]
            })
            .collect();
        let pos = Positions::from_tracks(&[track]).unwrap();
        let k = segment_kinematics(&pos, dt, &whole(n), 0.0, &KinematicParams::default()).unwrap();
        assert!(rel(k[0].v, 50.0) < 1e-9);
        assert!(k[0].a < 1e-9, "A {}", k[0].a);
        assert!(k[0].c < 1e-12, "C {}", k[0].c);
        let y = k[0].log(&[1e-3; 6]);
        assert!(y.iter().all(|v| v.is_finite()));
        assert!((y[3] - 1e-3f64.ln()).abs() < 1e-6);
    }

    #[test]
    fn still_point_is_finite() {
        let pos = Positions::from_tracks(&[vec![[1.0, 2.0, 3.0]; 10]]).unwrap();
        let k =
            segment_kinematics(&pos, 0.1, &whole(10), 0.0, &KinematicParams::default()).unwrap();
        assert_eq!(k[0].d, 0.0);
        assert_eq!(k[0].c, 0.0);
        assert!(k[0].log(&[1e-3; 6]).iter().all(|v| v.is_finite()));
    }

    #[test]
    fn normalization_gives_zero_mean_unit_spread() {
        let mut x = 99u64;
        let corpus: Vec<[f64; 6]> = (0..500)
            .map(|i| {
                x = x
                    .wrapping_mul(6364136223846793005)
                    .wrapping_add(1442695040888963407);
                let u = (x >> 11) as f64 / (1u64 << 53) as f64;
                [
                    u * 3.0 - 1.0,
                    i as f64,
                    -5.0 * u,
                    7.0,
                    u * u,
                    1e-3 * u + 4.0,
                ]
            })
            .collect();
        let n = Normalization::fit(&corpus).unwrap();
        let z: Vec<[f64; 6]> = corpus.iter().map(|y| n.apply(y)).collect();
        for d in 0..6 {
            let m = z.iter().map(|v| v[d]).sum::<f64>() / z.len() as f64;
            let var = z.iter().map(|v| (v[d] - m).powi(2)).sum::<f64>() / z.len() as f64;
            assert!(m.abs() < 1e-9, "dim {d} mean {m}");
            if d == 3 {
                assert_eq!(n.scale[3], 1.0); // constant dimension
                assert!(var < 1e-20);
            } else {
                assert!((var - 1.0).abs() < 1e-9, "dim {d} var {var}");
            }
        }
        let back = n.invert(&n.apply(&corpus[7]));
        assert!((0..6).all(|d| (back[d] - corpus[7][d]).abs() < 1e-9));
        let (w, b) = n.weights();
        let z0 = n.apply(&corpus[0]);
        assert!((0..6).all(|d| (w[d] * corpus[0][d] + b[d] - z0[d]).abs() < 1e-9));
        assert_eq!(Normalization::fit(&[]), Err(NormalizationError::Empty));
        assert!(Normalization::fit(&[[f64::NAN; 6]]).is_err());
    }
}
