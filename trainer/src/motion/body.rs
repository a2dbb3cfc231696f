//! Kinematic parameters that mean the same on any skeleton: distances in *limb lengths*,
//! heights relative to the *shoulder*, derivatives over a fixed time (docs/method.md,
//! "Kinematic parameters").
//!
//! Takes of one speaker recorded on different skeletons (another joint layout, another scale,
//! another frame rate) must give comparable `y = (T, D, V, A, C, H)`, or a model trained on
//! both pools two populations. What depends on the skeleton is removed here:
//!
//! - **Limb**: an effector's limb is the chain of the two bones above it, e.g. for a hand the
//!   forearm (elbow to hand) and the upper arm (shoulder to elbow); for an end site, its joint's
//!   bone and the one above. Each limb's length is the median over frames of the two bone
//!   lengths measured by forward kinematics (so position channels on every joint are handled,
//!   and a stretchy rig gets its typical length), and the body's limb length `L` is the mean
//!   over the effectors: one unit per body, so a rig's left/right asymmetry (the ZeroEGGS arms
//!   measure 52.5 and 54.5 cm) does not make one hand's motion count more than the other's.
//!   The hands give `L` = 53.5 cm on both ZeroEGGS skeletons and 46.6 on the Bandai Namco one.
//!   The point two bones up is the effector's *shoulder*.
//! - **D, V, A** are measured in limb lengths (path, per second, per second squared) and **C**
//!   in 1/limb length: positions are divided by `L`.
//! - **H** is the effector's height above its shoulder at the same frame, in limb lengths, plus
//!   one: 0 = arm hanging straight down, 1 = hand at shoulder height, 2 = arm straight up.
//!   Clamped at 0 (a hand cannot be lower than a straight arm allows, up to capture noise).
//!   Standing, sitting or crouching, and where the rig's origin is, no longer matter.
//! - **Derivatives over 1/30 s** whatever the frame rate: with `h = max(1, round(fps / 30))`
//!   frames, `v(f) = (p(f+h) - p(f-h)) / (2 h dt)`, `a(f) = (p(f+h) - 2 p(f) + p(f-h)) /
//!   (h dt)^2` (one-sided at a take's ends), and the path `D` sums `|p(f+h) - p(f)| / h` over
//!   the segment's frames. At 60 fps single-frame differences would amplify capture jitter
//!   that a 30 fps take does not have.
//! - **Curvature floor** fixed at [`CURVATURE_SPEED_FLOOR`] limb lengths per second (not a
//!   fraction of each take's median speed, which would differ between a lively and a calm
//!   take).
//!
//! T stays in seconds. The log scale and the normalization are those of
//! [`super::kinematic`].
//!
//! ## Invariants
//!
//! Never panics. An effector with fewer than two bones above it (e.g. the root) or a limb of
//! zero length is an error naming it ([`BodyError`]), not a silent fallback.

use super::effectors::Effectors;
use super::fk::{self, FkError, Positions, Target, Vec3};
use super::kinematic::Kinematics;
use super::segment::Segment;
use super::skeleton::Motion;

/// Speed (limb lengths per second) below which the curvature's denominator is frozen.
pub const CURVATURE_SPEED_FLOOR: f64 = 0.05;
/// The time base of derivatives (s).
pub const DERIVATIVE_TIME: f64 = 1.0 / 30.0;

/// Why an effector's limb could not be found.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum BodyError {
    /// Fewer than two bones above the effector.
    #[error(
        "effector {0} has fewer than two bones above it, so it has no limb to measure \
         distances by: choose effectors at the end of a limb (hands, feet, tips)"
    )]
    NoLimb(String),
    /// The limb has no length.
    #[error("the limb above effector {0} has zero length in every frame")]
    ZeroLimb(String),
    /// FK failed.
    #[error(transparent)]
    Fk(#[from] FkError),
}

/// The body's limb length and each effector's shoulder track.
#[derive(Clone, Debug, PartialEq)]
pub struct Limbs {
    /// The body's limb length `L` (skeleton units): the mean of the effectors' limbs.
    pub length: f64,
    /// Limb length per effector (skeleton units).
    pub lengths: Vec<f64>,
    /// Shoulder positions, frames x effectors.
    pub shoulders: Positions,
}

fn dist(a: Vec3, b: Vec3) -> f64 {
    ((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2) + (a[2] - b[2]).powi(2)).sqrt()
}

/// The two joints above a target: (elbow, shoulder).
fn chain(motion: &Motion, t: Target) -> Option<(usize, usize)> {
    let joints = &motion.skeleton().joints;
    let elbow = match t {
        Target::Joint(j) => joints.get(j)?.parent?,
        Target::EndSite(j) => j,
    };
    let shoulder = joints.get(elbow)?.parent?;
    Some((elbow, shoulder))
}

/// Resolves every effector's limb on `motion`.
pub fn limbs(motion: &Motion, effectors: &Effectors) -> Result<Limbs, BodyError> {
    let mut chains = Vec::new();
    for (t, name) in effectors.targets.iter().zip(&effectors.names) {
        chains.push(chain(motion, *t).ok_or_else(|| BodyError::NoLimb(name.clone()))?);
    }
    let k = chains.len();
    let mut targets: Vec<Target> = effectors.targets.clone();
    targets.extend(chains.iter().map(|&(e, _)| Target::Joint(e)));
    targets.extend(chains.iter().map(|&(_, s)| Target::Joint(s)));
    let pos = fk::target_positions(motion, &targets)?;
    let n = pos.frames();
    let mut lengths = Vec::with_capacity(k);
    for (e, name) in effectors.names.iter().enumerate() {
        let mut per_frame: Vec<f64> = (0..n)
            .map(|f| {
                let (p, el, sh) = (pos.get(f, e), pos.get(f, k + e), pos.get(f, 2 * k + e));
                dist(p, el) + dist(el, sh)
            })
            .filter(|v| v.is_finite())
            .collect();
        per_frame.sort_by(f64::total_cmp);
        let l = per_frame.get(per_frame.len() / 2).copied().unwrap_or(0.0);
        if l <= 0.0 {
            return Err(BodyError::ZeroLimb(name.clone()));
        }
        lengths.push(l);
    }
    let shoulders: Vec<Vec3> = (0..n)
        .flat_map(|f| (0..k).map(move |e| (f, e)))
        .map(|(f, e)| pos.get(f, 2 * k + e))
        .collect();
    let shoulders = Positions::from_frames(k, shoulders).ok_or(BodyError::NoLimb(
        effectors.names.first().cloned().unwrap_or_default(),
    ))?;
    let length = lengths.iter().sum::<f64>() / k.max(1) as f64;
    Ok(Limbs {
        length,
        lengths,
        shoulders,
    })
}

/// Frames spanned by a derivative at frame rate `1 / frame_time`.
pub fn derivative_lag(frame_time: f64) -> usize {
    if frame_time > 0.0 && frame_time.is_finite() {
        ((DERIVATIVE_TIME / frame_time).round() as usize).max(1)
    } else {
        1
    }
}

fn cross(a: Vec3, b: Vec3) -> Vec3 {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

fn norm(a: Vec3) -> f64 {
    (a[0] * a[0] + a[1] * a[1] + a[2] * a[2]).sqrt()
}

/// Kinematic parameters of each segment in body units (see the module docs). `positions` are
/// the effectors (frames x effectors), `limbs` from [`limbs`], `up` the vertical axis.
pub fn segment_kinematics(
    positions: &Positions,
    limbs: &Limbs,
    frame_time: f64,
    segments: &[Segment],
    up: usize,
) -> Vec<Kinematics> {
    let (n, k) = (positions.frames(), positions.points());
    let h = derivative_lag(frame_time);
    let up = up.min(2);
    // Positions in limb lengths.
    let l = limbs.length;
    let p = |f: usize, e: usize| -> Vec3 {
        let q = positions.get(f, e);
        [q[0] / l, q[1] / l, q[2] / l]
    };
    let velocity = |f: usize, e: usize| -> Vec3 {
        let (a, b) = (f.saturating_sub(h), (f + h).min(n - 1));
        let dt = (b - a).max(1) as f64 * frame_time;
        let (pa, pb) = (p(a, e), p(b, e));
        std::array::from_fn(|i| (pb[i] - pa[i]) / dt)
    };
    let acceleration = |f: usize, e: usize| -> Vec3 {
        if n < 2 * h + 1 {
            return [0.0; 3];
        }
        let c = f.clamp(h, n - 1 - h);
        let (a, b, d) = (p(c - h, e), p(c, e), p(c + h, e));
        let dt2 = (h as f64 * frame_time).powi(2);
        std::array::from_fn(|i| (a[i] - 2.0 * b[i] + d[i]) / dt2)
    };
    segments
        .iter()
        .map(|seg| {
            let (s, e) = (seg.start_frame.min(n), seg.end_frame.min(n));
            let frames = e.saturating_sub(s);
            let t = frames as f64 * frame_time;
            if frames == 0
                || k == 0
                || limbs.shoulders.points() != k
                || l.partial_cmp(&0.0) != Some(std::cmp::Ordering::Greater)
            {
                return Kinematics {
                    t,
                    ..Kinematics::default()
                };
            }
            let samples = (frames * k) as f64;
            let (mut path, mut speed, mut accel, mut curv, mut height) = (0.0, 0.0, 0.0, 0.0, 0.0);
            for f in s..e {
                for j in 0..k {
                    let pf = p(f, j);
                    path += norm(std::array::from_fn(|i| p((f + h).min(n - 1), j)[i] - pf[i]))
                        / h as f64;
                    let v = velocity(f, j);
                    let a = acceleration(f, j);
                    let sp = norm(v);
                    speed += sp;
                    accel += norm(a);
                    curv += norm(cross(v, a)) / sp.max(CURVATURE_SPEED_FLOOR).powi(3);
                    let shoulder = limbs.shoulders.get(f, j)[up] / l;
                    height += (pf[up] - shoulder + 1.0).max(0.0);
                }
            }
            Kinematics {
                t,
                d: path / k as f64,
                v: speed / samples,
                a: accel / samples,
                c: curv / samples,
                h: height / samples,
            }
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::motion::segment::Phase;

    fn limbs_of(lengths: Vec<f64>, shoulder: Vec3, frames: usize) -> Limbs {
        let k = lengths.len();
        Limbs {
            shoulders: Positions::from_frames(k, vec![shoulder; frames * k]).unwrap(),
            length: lengths.iter().sum::<f64>() / k as f64,
            lengths,
        }
    }

    #[test]
    fn circle_in_limb_units_at_any_frame_rate() {
        // A hand circling horizontally (radius r, angular speed w) at shoulder height, limb
        // L: D = r w T / L, V = r w / L, A = r w^2 / L, C = L / r, H = 1; the same at 30,
        // 60 and 120 fps.
        let (r, w, l, t) = (20.0, 3.0, 50.0, 4.0);
        for fps in [30.0, 60.0, 120.0] {
            let n = (t * fps) as usize;
            let dt = 1.0 / fps;
            let track: Vec<Vec3> = (0..n)
                .map(|f| {
                    let th = w * f as f64 * dt;
                    [r * th.cos(), 140.0, r * th.sin()]
                })
                .collect();
            let pos = Positions::from_tracks(&[track]).unwrap();
            let limbs = limbs_of(vec![l], [0.0, 140.0, 0.0], n);
            let seg = [Segment {
                start_frame: 0,
                end_frame: n,
                phase: Phase::Moving,
            }];
            let k = segment_kinematics(&pos, &limbs, dt, &seg, 1)[0];
            let rel = |a: f64, b: f64| (a - b).abs() / b;
            // Differences over 1/30 s at w = 3 rad/s: chord errors (w/30)^2/6 ~ 0.2%; the
            // ends add ~ 2h/n.
            assert!(rel(k.v, r * w / l) < 0.01, "{fps}: V {}", k.v);
            assert!(rel(k.a, r * w * w / l) < 0.02, "{fps}: A {}", k.a);
            assert!(rel(k.c, l / r) < 0.02, "{fps}: C {}", k.c);
            assert!(rel(k.d, r * w * t / l) < 0.02, "{fps}: D {}", k.d);
            assert!((k.h - 1.0).abs() < 1e-12, "{fps}: H {}", k.h);
        }
    }

    #[test]
    fn height_is_zero_hanging_one_at_the_shoulder_two_straight_up() {
        let l = 53.5;
        for (y, want) in [(100.0 - l, 0.0), (100.0, 1.0), (100.0 + l, 2.0)] {
            let pos = Positions::from_tracks(&[vec![[0.0, y, 0.0]; 10]]).unwrap();
            let limbs = limbs_of(vec![l], [0.0, 100.0, 0.0], 10);
            let seg = [Segment {
                start_frame: 0,
                end_frame: 10,
                phase: Phase::Still,
            }];
            let k = segment_kinematics(&pos, &limbs, 1.0 / 30.0, &seg, 1)[0];
            assert!((k.h - want).abs() < 1e-12, "{y}: {}", k.h);
            assert_eq!(k.v, 0.0);
            assert_eq!(k.c, 0.0);
        }
    }

    #[test]
    fn derivative_lag_is_a_thirtieth_of_a_second() {
        assert_eq!(derivative_lag(1.0 / 30.0), 1);
        assert_eq!(derivative_lag(1.0 / 60.0), 2);
        assert_eq!(derivative_lag(1.0 / 120.0), 4);
        assert_eq!(derivative_lag(1.0 / 24.0), 1);
        assert_eq!(derivative_lag(0.0), 1);
    }
}
