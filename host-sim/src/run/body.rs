//! The skeleton drawn as a body: limbs as shaded capsules with thickness by what they are, a
//! head, a floor and the body's shadow on it. One model for every picture of a run: the
//! previews draw it here (`Painter`: palette-index pixels with a depth buffer) and
//! `viewer.html` draws the same shapes on a canvas from [`BodyModel`]'s numbers.
//!
//! **Thickness by name.** A bone belongs to the joint it leaves (the upper arm is the bone
//! from `LeftArm` to `LeftForeArm`), and its radius is a fraction of the body's height `H`,
//! chosen by that joint's name: the torso (spine, chest, back, hips) 0.075 H, thighs 0.055 H,
//! shins 0.042 H, upper arms 0.034 H, forearms 0.028 H, hands and fingers 0.02 H, the neck
//! 0.035 H (human proportions, rounded). The head is a ball of 0.064 H half-way along the head
//! bone (at the neck's end when there is no head joint); each hand gets a ball of 0.03 H.
//! `H` comes from the arms, which every gesture skeleton has: shoulder to wrist is a third of
//! the height (0.332 H); without hands, the rest pose's height.
//!
//! **Facing.** The character's left is the horizontal direction from its right arm to its
//! left arm in the first frame, its front that direction turned by 90 degrees about the up
//! axis, so the front view shows the face whatever way the capture faced. The floor is the
//! lowest point over the frames (legs), or where the feet would be (an upper body: 0.5 H
//! under the lowest joint).
//!
//! Nothing here panics: non-finite points are skipped, pixels are clipped to the box.

use gesture_trainer::motion::effectors::{find_hand, Side};
use gesture_trainer::motion::fk::{Target, Vec3};
use gesture_trainer::motion::Skeleton;

use super::canvas::Canvas;

/// First palette index of the body's shading ramp (dark to light).
pub(super) const SHADE0: u8 = 80;
/// Shades in the ramp.
pub(super) const SHADES: usize = 32;
/// The floor disk.
pub(super) const FLOOR: u8 = 11;
/// The shadow on it.
pub(super) const SHADOW: u8 = 12;

/// The body colours: the floor, the shadow, and the shading ramp (clay, dark to light).
pub(super) fn palette_into(p: &mut [u8]) {
    p[3 * FLOOR as usize..3 * FLOOR as usize + 3].copy_from_slice(&[214, 210, 200]);
    p[3 * SHADOW as usize..3 * SHADOW as usize + 3].copy_from_slice(&[168, 163, 154]);
    let stops: [[f64; 3]; 3] = [
        [52.0, 40.0, 44.0],
        [176.0, 118.0, 96.0],
        [252.0, 222.0, 196.0],
    ];
    for i in 0..SHADES {
        let t = i as f64 / (SHADES - 1) as f64 * 2.0;
        let k = (t.floor() as usize).min(1);
        let f = t - k as f64;
        let at = 3 * (SHADE0 as usize + i);
        for ch in 0..3 {
            p[at + ch] = (stops[k][ch] + f * (stops[k + 1][ch] - stops[k][ch])).round() as u8;
        }
    }
}

/// A limb: the capsule between two points (indices into the frame's points).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Limb {
    /// From.
    pub a: usize,
    /// To.
    pub b: usize,
    /// Radius (skeleton units).
    pub radius: f64,
}

/// A ball at `a + t (b - a)`: the head, a hand.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Ball {
    /// From.
    pub a: usize,
    /// To.
    pub b: usize,
    /// Where between them.
    pub t: f64,
    /// Radius (skeleton units).
    pub radius: f64,
}

/// How a skeleton is drawn (see the module docs).
#[derive(Clone, Debug, PartialEq)]
pub struct BodyModel {
    /// Limbs.
    pub limbs: Vec<Limb>,
    /// The head (first, when there is one) and the hands.
    pub balls: Vec<Ball>,
    /// Body height `H` (skeleton units).
    pub height: f64,
    /// Floor height (up axis Y).
    pub floor: f64,
    /// The character's left, horizontal unit vector.
    pub left: Vec3,
    /// The character's front, horizontal unit vector.
    pub front: Vec3,
}

/// Radius of the bone leaving joint `name`, in body heights.
fn radius_of(name: &str) -> f64 {
    let n = name.to_ascii_lowercase();
    let has = |keys: &[&str]| keys.iter().any(|k| n.contains(k));
    if has(&[
        "thumb", "index", "finger", "hand", "wrist", "middle", "ring", "pinky",
    ]) {
        0.02
    } else if has(&["forearm", "lowerarm", "lower_arm", "elbow"]) {
        0.028
    } else if has(&["shoulder", "clavicle", "collar"]) {
        0.036
    } else if has(&["arm"]) {
        0.034
    } else if has(&["toe", "foot", "ankle"]) {
        0.026
    } else if has(&["upleg", "thigh", "upperleg", "upper_leg", "hipjoint"]) {
        0.055
    } else if has(&["leg", "shin", "knee", "calf"]) {
        0.042
    } else if has(&["neck"]) {
        0.035
    } else if has(&["head", "face", "skull"]) {
        0.05
    } else if has(&[
        "spine", "back", "chest", "torso", "hip", "pelvis", "abdomen", "root",
    ]) {
        0.075
    } else {
        0.03
    }
}

fn sub(a: Vec3, b: Vec3) -> Vec3 {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

fn norm(a: Vec3) -> f64 {
    (a[0] * a[0] + a[1] * a[1] + a[2] * a[2]).sqrt()
}

impl BodyModel {
    /// The model of `skeleton` whose points are `targets` (joints and end sites), from the
    /// points of every frame (`frames`; the first gives the facing).
    pub fn new(skeleton: &Skeleton, targets: &[Target], frames: &[&[Vec3]]) -> Option<Self> {
        let first = frames.first()?;
        let index = |t: Target| targets.iter().position(|&x| x == t);
        let point = |t: Target| index(t).and_then(|k| first.get(k).copied());
        let hands = [Side::Left, Side::Right].map(|s| find_hand(skeleton, s));
        // Shoulder to wrist: the hand's parent (forearm) and grandparent (upper arm).
        let arm = |h: usize| -> Option<(f64, Vec3)> {
            let fore = skeleton.joints[h].parent?;
            let upper = skeleton.joints[fore].parent?;
            let (ph, pf, pu) = (
                point(Target::Joint(h))?,
                point(Target::Joint(fore))?,
                point(Target::Joint(upper))?,
            );
            Some((norm(sub(ph, pf)) + norm(sub(pf, pu)), pu))
        };
        let arms = [hands[0].and_then(arm), hands[1].and_then(arm)];
        let all = first.iter().filter(|p| p.iter().all(|c| c.is_finite()));
        let (lo, hi) = all.fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), p| {
            (lo.min(p[1]), hi.max(p[1]))
        });
        let height = match arms {
            [Some((l, _)), Some((r, _))] if l + r > 0.0 => 0.5 * (l + r) / 0.332,
            [Some((l, _)), None] | [None, Some((l, _))] if l > 0.0 => l / 0.332,
            _ => hi - lo,
        };
        if !(height.is_finite() && height > 0.0) {
            return None;
        }
        let (left, front) = match arms {
            [Some((_, l)), Some((_, r))] => {
                let d = [l[0] - r[0], 0.0, l[2] - r[2]];
                let n = norm(d);
                if n > 1e-9 {
                    let left = [d[0] / n, 0.0, d[2] / n];
                    // left x up.
                    (left, [-left[2], 0.0, left[0]])
                } else {
                    ([1.0, 0.0, 0.0], [0.0, 0.0, 1.0])
                }
            }
            _ => ([1.0, 0.0, 0.0], [0.0, 0.0, 1.0]),
        };
        let lowest = frames
            .iter()
            .flat_map(|f| f.iter())
            .map(|p| p[1])
            .filter(|v| v.is_finite())
            .fold(f64::INFINITY, f64::min);
        // Under the feet; an upper body stands on its lowest point like a bust on a plinth.
        let floor = lowest;
        let mut limbs = Vec::new();
        for (j, joint) in skeleton.joints.iter().enumerate() {
            if let Some(p) = joint.parent {
                if let (Some(a), Some(b)) = (index(Target::Joint(p)), index(Target::Joint(j))) {
                    let r = radius_of(&skeleton.joints[p].name);
                    limbs.push(Limb {
                        a,
                        b,
                        radius: r * height,
                    });
                }
            }
            if let (Some(a), Some(b)) = (index(Target::Joint(j)), index(Target::EndSite(j))) {
                limbs.push(Limb {
                    a,
                    b,
                    radius: radius_of(&joint.name) * height,
                });
            }
        }
        let mut balls = Vec::new();
        let head = skeleton
            .joints
            .iter()
            .position(|j| j.name.eq_ignore_ascii_case("head"))
            .or_else(|| {
                skeleton
                    .joints
                    .iter()
                    .position(|j| j.name.to_ascii_lowercase().contains("head"))
            });
        let neck = || {
            skeleton
                .joints
                .iter()
                .rposition(|j| j.name.to_ascii_lowercase().contains("neck"))
        };
        let ball = |j: usize, t: f64, r: f64| {
            let a = index(Target::Joint(j))?;
            let b = index(Target::EndSite(j))
                .or_else(|| {
                    skeleton
                        .children(j)
                        .next()
                        .and_then(|c| index(Target::Joint(c)))
                })
                .unwrap_or(a);
            Some(Ball {
                a,
                b,
                t,
                radius: r * height,
            })
        };
        if let Some(b) = head.or_else(neck).and_then(|j| {
            let mut b = ball(j, 0.5, 0.064)?;
            if head.is_none() || b.a == b.b {
                // No head joint, or nothing above it: the head sits on the neck's end.
                b.t = 1.0;
            }
            Some(b)
        }) {
            balls.push(b);
        }
        for h in hands.into_iter().flatten() {
            balls.extend(ball(h, 0.0, 0.03));
        }
        Some(Self {
            limbs,
            balls,
            height,
            floor,
            left,
            front,
        })
    }
}

/// Which side the camera looks from.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Camera {
    /// The character's front.
    Front,
    /// The character's left (it faces to the right of the picture).
    Left,
}

/// An orthographic camera a little above the character (looking down by `PITCH`).
#[derive(Clone, Copy, Debug)]
pub(super) struct View {
    right: Vec3,
    toward: Vec3,
}

/// How far the cameras look down (rad): enough to see the floor and the shadow.
pub(super) const PITCH: f64 = 0.22;

impl View {
    pub(super) fn new(body: &BodyModel, camera: Camera) -> Self {
        match camera {
            Camera::Front => Self {
                right: body.left,
                toward: body.front,
            },
            Camera::Left => Self {
                right: body.front,
                toward: body.left,
            },
        }
    }

    /// World point -> (right, up, toward the camera), skeleton units.
    pub(super) fn project(&self, p: Vec3) -> Vec3 {
        let dot = |a: Vec3, b: Vec3| a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
        let (u, y, d) = (dot(p, self.right), p[1], dot(p, self.toward));
        let (s, c) = PITCH.sin_cos();
        [u, y * c - d * s, d * c + y * s]
    }
}

/// Draws bodies into a box of a canvas, nearest surface wins (a depth buffer per box).
pub(super) struct Painter<'a> {
    cv: &'a mut Canvas,
    x: i64,
    y: i64,
    w: i64,
    h: i64,
    depth: Vec<f32>,
}

/// Light from the upper left, in front (screen right, up, toward the viewer; unit length).
const LIGHT: [f64; 3] = [-0.45, 0.6, 0.66];

impl<'a> Painter<'a> {
    pub(super) fn new(cv: &'a mut Canvas, (x, y, w, h): (i64, i64, i64, i64)) -> Self {
        let n = (w.max(0) * h.max(0)) as usize;
        Self {
            cv,
            x,
            y,
            w,
            h,
            depth: vec![f32::NEG_INFINITY; n],
        }
    }

    /// Pixel rows and columns of the box that a disc of radius `r` around the segment a-b
    /// may touch.
    fn bounds(&self, a: (f64, f64), b: (f64, f64), r: f64) -> Option<(i64, i64, i64, i64)> {
        let x0 = (a.0.min(b.0) - r).floor().max(self.x as f64);
        let x1 = (a.0.max(b.0) + r).ceil().min((self.x + self.w) as f64);
        let y0 = (a.1.min(b.1) - r).floor().max(self.y as f64);
        let y1 = (a.1.max(b.1) + r).ceil().min((self.y + self.h) as f64);
        (x0.is_finite() && y0.is_finite() && x0 < x1 && y0 < y1)
            .then_some((x0 as i64, y0 as i64, x1 as i64, y1 as i64))
    }

    /// A flat ellipse (the floor disk), centre and radii in pixels.
    pub(super) fn ellipse(&mut self, c: (f64, f64), rx: f64, ry: f64, colour: u8) {
        let Some((x0, y0, x1, y1)) = self.bounds(c, c, rx.max(ry)) else {
            return;
        };
        for py in y0..y1 {
            for px in x0..x1 {
                let (dx, dy) = ((px as f64 + 0.5 - c.0) / rx, (py as f64 + 0.5 - c.1) / ry);
                if dx * dx + dy * dy <= 1.0 {
                    self.cv.px[py as usize * self.cv.w + px as usize] = colour;
                }
            }
        }
    }

    /// A flat capsule (a shadow), screen pixels, no depth.
    pub(super) fn flat_capsule(&mut self, a: (f64, f64), b: (f64, f64), r: f64, colour: u8) {
        let Some((x0, y0, x1, y1)) = self.bounds(a, b, r) else {
            return;
        };
        for py in y0..y1 {
            for px in x0..x1 {
                let (d, _) = distance((px as f64 + 0.5, py as f64 + 0.5), a, b);
                if d <= r {
                    self.cv.px[py as usize * self.cv.w + px as usize] = colour;
                }
            }
        }
    }

    /// A shaded capsule between screen points `a` and `b` (x, y in pixels, depth in pixels
    /// toward the viewer) of radius `r` pixels; a ball when `a == b`.
    pub(super) fn capsule(&mut self, a: Vec3, b: Vec3, r: f64) {
        let r = r.max(0.8);
        let Some((x0, y0, x1, y1)) = self.bounds((a[0], a[1]), (b[0], b[1]), r) else {
            return;
        };
        for py in y0..y1 {
            for px in x0..x1 {
                let p = (px as f64 + 0.5, py as f64 + 0.5);
                let (d, t) = distance(p, (a[0], a[1]), (b[0], b[1]));
                if d > r {
                    continue;
                }
                let c = (a[0] + t * (b[0] - a[0]), a[1] + t * (b[1] - a[1]));
                let nz = (1.0 - (d / r) * (d / r)).max(0.0).sqrt();
                let z = (a[2] + t * (b[2] - a[2]) + nz * r) as f32;
                let k = ((py - self.y) * self.w + (px - self.x)) as usize;
                // Nearest wins (a NaN depth never does).
                if z.partial_cmp(&self.depth[k]) != Some(std::cmp::Ordering::Greater) {
                    continue;
                }
                self.depth[k] = z;
                let (nx, ny) = ((p.0 - c.0) / r, -(p.1 - c.1) / r);
                let lit = (nx * LIGHT[0] + ny * LIGHT[1] + nz * LIGHT[2]).max(0.0);
                // A dark rim keeps a limb readable over the body behind it.
                let shade = if r - d < 0.9 { 0.0 } else { 0.18 + 0.82 * lit };
                let i = (shade * (SHADES - 1) as f64).round() as u8;
                self.cv.px[py as usize * self.cv.w + px as usize] =
                    SHADE0 + i.min(SHADES as u8 - 1);
            }
        }
    }
}

/// Distance from `p` to the segment a-b, and the parameter of the nearest point.
fn distance(p: (f64, f64), a: (f64, f64), b: (f64, f64)) -> (f64, f64) {
    let (dx, dy) = (b.0 - a.0, b.1 - a.1);
    let len2 = dx * dx + dy * dy;
    let t = if len2 > 1e-12 {
        (((p.0 - a.0) * dx + (p.1 - a.1) * dy) / len2).clamp(0.0, 1.0)
    } else {
        0.0
    };
    let (cx, cy) = (a.0 + t * dx, a.1 + t * dy);
    (((p.0 - cx).powi(2) + (p.1 - cy).powi(2)).sqrt(), t)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn limbs_are_thicker_at_the_torso_than_at_the_hands() {
        assert!(radius_of("Spine1") > radius_of("LeftUpLeg"));
        assert!(radius_of("LeftUpLeg") > radius_of("LeftLeg"));
        assert!(radius_of("LeftArm") > radius_of("LeftForeArm"));
        assert!(radius_of("LeftForeArm") > radius_of("LeftHand"));
        assert_eq!(radius_of("LeftShoulder"), radius_of("RightShoulder"));
    }

    #[test]
    fn a_ball_is_lit_from_the_upper_left() {
        let mut cv = Canvas::new(40, 40, 0);
        Painter::new(&mut cv, (0, 0, 40, 40)).capsule([20.0, 20.0, 0.0], [20.0, 20.0, 0.0], 15.0);
        let at = |x: usize, y: usize| cv.px[y * 40 + x];
        assert!(at(14, 14) > at(26, 26), "{} {}", at(14, 14), at(26, 26));
        assert_eq!(at(1, 1), 0);
        assert_eq!(at(20, 5), SHADE0, "the rim is dark");
    }
}
