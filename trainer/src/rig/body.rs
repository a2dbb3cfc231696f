//! Body measures: rig channels defined on the humanoid body rather than on one skeleton's
//! joints, computed from world-space bone directions (the convention is in the parent
//! module's docs, "Body channels").
//!
//! [`Body::find`] finds the parts by common humanoid naming ([`crate::motion::humanoid`]): the
//! head, each upper arm, forearm and wrist (the hand joint, or the forearm's `End Site` when
//! the skeleton has no hand), and the **chest**, the nearest common ancestor of the head and
//! the upper arms. [`Body::axes`] takes the body frame (left, up, forward) from the skeleton's
//! own geometry in a rest frame: left from the right shoulder to the left, up from the hips to
//! the middle of the shoulders, forward = left x up. It is stored in the chest's frame, so it
//! turns with the chest and never depends on the joints' frame conventions.
//!
//! Everything is `f64`; nothing panics for any skeleton and frame (a part the skeleton lacks
//! gives `None`, and a channel on it holds its neutral).

use std::fmt;

use gesture_runtime::blob::BODY_MEASURES;
use gesture_runtime::rotation::{euler_angles, euler_matrix, mat_mul, mat_vec, transpose, Mat3};

use crate::motion::fk::{Transform, Vec3};
use crate::motion::humanoid::{find_bone, BONE_ALIASES};
use crate::motion::Skeleton;

/// One body measure (an index into [`BODY_MEASURES`], which also gives its name).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct BodyMeasure(u8);

/// Which body part a measure reads.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum BodyPart {
    /// The head relative to the chest.
    Head,
    /// An upper arm's direction (0 = left, 1 = right).
    UpperArm(usize),
    /// The angle between an upper arm and its forearm (0 = left, 1 = right).
    Elbow(usize),
}

impl BodyMeasure {
    /// The measure called `name` (ignoring ASCII case), e.g. `left_arm_raise`.
    pub fn parse(name: &str) -> Option<BodyMeasure> {
        BODY_MEASURES
            .iter()
            .position(|m| m.eq_ignore_ascii_case(name.trim()))
            .map(|k| BodyMeasure(k as u8))
    }

    /// The measure of blob drive index `k` (`None` past [`BODY_MEASURES`]).
    pub fn from_index(k: u8) -> Option<BodyMeasure> {
        (usize::from(k) < BODY_MEASURES.len()).then_some(BodyMeasure(k))
    }

    /// Its index in [`BODY_MEASURES`] (the blob's drive mode is 8 + this).
    pub fn index(self) -> u8 {
        self.0
    }

    /// Its name.
    pub fn name(self) -> &'static str {
        BODY_MEASURES[usize::from(self.0).min(BODY_MEASURES.len() - 1)]
    }

    /// The part it reads.
    pub fn part(self) -> BodyPart {
        match self.0 {
            0..=2 => BodyPart::Head,
            3 | 4 => BodyPart::UpperArm(0),
            5 | 6 => BodyPart::UpperArm(1),
            7 => BodyPart::Elbow(0),
            _ => BodyPart::Elbow(1),
        }
    }
}

impl fmt::Display for BodyMeasure {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

/// A point a bone ends at: a joint's origin or a joint's `End Site`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Effector {
    /// The origin of this joint.
    Joint(usize),
    /// The end site of this joint.
    EndSite(usize),
}

/// One arm's joints.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Arm {
    /// The upper arm (shoulder joint).
    pub upper: usize,
    /// Where the upper arm ends: the forearm (elbow) joint, or the upper arm's end site.
    pub elbow: Effector,
    /// The forearm joint, if the skeleton has one.
    pub fore: Option<usize>,
    /// Where the forearm ends: the hand joint, or the forearm's end site.
    pub wrist: Option<Effector>,
}

/// A skeleton's humanoid parts (see the module docs).
#[derive(Clone, Debug, PartialEq)]
pub struct Body {
    /// The reference joint: the nearest common ancestor of the head and the upper arms.
    pub chest: Option<usize>,
    /// The head joint.
    pub head: Option<usize>,
    /// Left and right arm.
    pub arms: [Option<Arm>; 2],
    hips: Option<usize>,
    upper_legs: [Option<usize>; 2],
}

fn ancestors_or_self(skeleton: &Skeleton, j: usize) -> Vec<usize> {
    let mut out = vec![j];
    let mut cur = skeleton.joints.get(j).and_then(|x| x.parent);
    while let Some(p) = cur {
        if out.len() > skeleton.joints.len() {
            break;
        }
        out.push(p);
        cur = skeleton.joints[p].parent;
    }
    out
}

fn is_below(skeleton: &Skeleton, j: usize, ancestor: usize) -> bool {
    j != ancestor && ancestors_or_self(skeleton, j).contains(&ancestor)
}

fn has_end_site(skeleton: &Skeleton, j: usize) -> bool {
    skeleton.joints.get(j).is_some_and(|x| x.end_site.is_some())
}

impl Body {
    /// Finds the parts of `skeleton` by name (never fails: missing parts are `None`).
    pub fn find(skeleton: &Skeleton) -> Body {
        let bone = |b: &str| find_bone(skeleton, b);
        let arm = |side: &str| -> Option<Arm> {
            let upper = bone(&format!("{side}UpperArm"))?;
            let fore = bone(&format!("{side}LowerArm")).filter(|&f| is_below(skeleton, f, upper));
            let elbow = match fore {
                Some(f) => Effector::Joint(f),
                None if has_end_site(skeleton, upper) => Effector::EndSite(upper),
                None => return None,
            };
            let wrist = fore.and_then(|f| {
                match bone(&format!("{side}Hand")).filter(|&h| is_below(skeleton, h, f)) {
                    Some(h) => Some(Effector::Joint(h)),
                    None => has_end_site(skeleton, f).then_some(Effector::EndSite(f)),
                }
            });
            Some(Arm {
                upper,
                elbow,
                fore,
                wrist,
            })
        };
        let head = bone("Head");
        let arms = [arm("Left"), arm("Right")];
        let mut tops: Vec<usize> = head.into_iter().collect();
        tops.extend(arms.iter().flatten().map(|a| a.upper));
        let chest = match tops.as_slice() {
            [] => None,
            [one] => ["UpperChest", "Chest", "Spine"]
                .iter()
                .filter_map(|b| bone(b))
                .find(|&c| is_below(skeleton, *one, c)),
            [first, rest @ ..] => {
                // Nearest common ancestor: the first ancestor of `first` above all the others.
                ancestors_or_self(skeleton, *first)
                    .into_iter()
                    .skip(1)
                    .find(|&c| rest.iter().all(|&t| is_below(skeleton, t, c)))
            }
        };
        Body {
            chest,
            head: head.filter(|&h| chest.is_some_and(|c| is_below(skeleton, h, c))),
            arms: arms.map(|a| a.filter(|a| chest.is_some_and(|c| is_below(skeleton, a.upper, c)))),
            hips: bone("Hips").or((!skeleton.joints.is_empty()).then_some(0)),
            upper_legs: [bone("LeftUpperLeg"), bone("RightUpperLeg")],
        }
    }

    /// Why `m` cannot be read on this skeleton (`None` if it can), for messages.
    pub fn missing(&self, m: BodyMeasure) -> Option<String> {
        let names = |bone: &str| {
            BONE_ALIASES
                .iter()
                .find(|(b, _)| *b == bone)
                .map_or(String::new(), |(_, a)| a.join(", "))
        };
        let side = |s: usize| ["Left", "Right"][s.min(1)];
        if self.chest.is_none() {
            return Some(format!(
                "no chest (no common ancestor of a head ({}) and upper arms ({}))",
                names("Head"),
                names("LeftUpperArm")
            ));
        }
        match m.part() {
            BodyPart::Head if self.head.is_none() => {
                Some(format!("no head (looked for {})", names("Head")))
            }
            BodyPart::UpperArm(s) if self.arms[s].is_none() => Some(format!(
                "no {} upper arm (looked for {})",
                side(s).to_ascii_lowercase(),
                names(&format!("{}UpperArm", side(s)))
            )),
            BodyPart::Elbow(s) if self.arms[s].and_then(|a| a.wrist).is_none() => Some(format!(
                "no {} forearm with a hand or an end site (looked for {} and {})",
                side(s).to_ascii_lowercase(),
                names(&format!("{}LowerArm", side(s))),
                names(&format!("{}Hand", side(s)))
            )),
            _ => None,
        }
    }

    /// The moved joint of measure `m` (head, upper arm or forearm), if the skeleton has it.
    pub fn joint(&self, m: BodyMeasure) -> Option<usize> {
        if self.missing(m).is_some() {
            return None;
        }
        match m.part() {
            BodyPart::Head => self.head,
            BodyPart::UpperArm(s) => self.arms[s].map(|a| a.upper),
            BodyPart::Elbow(s) => self.arms[s].and_then(|a| a.fore),
        }
    }

    /// The body frame in the chest's frame (columns: left, up, forward) from the world
    /// transforms of a rest frame; `None` without a chest or a left-right line (two upper arms,
    /// else two upper legs) or if the geometry is degenerate.
    pub fn axes(&self, world: &[Transform]) -> Option<Mat3> {
        let chest = world.get(self.chest?)?;
        let pos = |j: usize| world.get(j).map(|t| t.position);
        let (left, mid) = match self.arms {
            [Some(l), Some(r)] => {
                let (a, b) = (pos(l.upper)?, pos(r.upper)?);
                (sub(a, b), scale(add(a, b), 0.5))
            }
            _ => {
                let (a, b) = (pos(self.upper_legs[0]?)?, pos(self.upper_legs[1]?)?);
                (sub(a, b), pos(self.head.unwrap_or(self.chest?))?)
            }
        };
        let up = sub(mid, pos(self.hips?)?);
        let l = unit(left)?;
        let u = unit(sub(up, scale(l, dot(up, l))))?;
        let f = cross(l, u);
        let world_axes = [[l[0], u[0], f[0]], [l[1], u[1], f[1]], [l[2], u[2], f[2]]];
        Some(mat_mul(&transpose(&chest.rotation), &world_axes))
    }

    /// The world position of an effector.
    pub fn point(skeleton: &Skeleton, world: &[Transform], e: Effector) -> Option<Vec3> {
        match e {
            Effector::Joint(j) => world.get(j).map(|t| t.position),
            Effector::EndSite(j) => {
                let t = world.get(j)?;
                let site = skeleton.joints.get(j)?.end_site?;
                Some(add(t.position, mat_vec(&t.rotation, &site)))
            }
        }
    }

    /// The world body frame (columns left, up, forward) at `world`.
    fn frame(&self, world: &[Transform], axes: &Mat3) -> Option<Mat3> {
        Some(mat_mul(&world.get(self.chest?)?.rotation, axes))
    }

    /// Upper arm `s`'s direction and the forearm's (world, unit), where the skeleton has them.
    fn arm_dirs(
        &self,
        skeleton: &Skeleton,
        world: &[Transform],
        s: usize,
    ) -> Option<(Vec3, Option<Vec3>)> {
        let arm = self.arms.get(s).copied().flatten()?;
        let shoulder = Body::point(skeleton, world, Effector::Joint(arm.upper))?;
        let elbow = Body::point(skeleton, world, arm.elbow)?;
        let upper = unit(sub(elbow, shoulder))?;
        let fore = arm
            .wrist
            .and_then(|w| Body::point(skeleton, world, w))
            .and_then(|w| unit(sub(w, elbow)));
        Some((upper, fore))
    }

    /// The head's rotation relative to the chest in body axes, as Euler `YXZ` angles
    /// (pan about up, tilt about left, roll about forward), degrees.
    fn head_angles(&self, world: &[Transform], axes: &Mat3) -> Option<[f64; 3]> {
        let q = mat_mul(
            &transpose(&world.get(self.chest?)?.rotation),
            &world.get(self.head?)?.rotation,
        );
        let m = mat_mul(&transpose(axes), &mat_mul(&q, axes));
        Some(euler_angles(&m, HEAD_ORDER))
    }

    /// The value of measure `m` (degrees) in the frame whose world transforms are `world`,
    /// with the body frame `axes` (from [`Body::axes`]); `None` if the skeleton lacks the part.
    pub fn measure(
        &self,
        skeleton: &Skeleton,
        world: &[Transform],
        axes: &Mat3,
        m: BodyMeasure,
    ) -> Option<f64> {
        self.missing(m).is_none().then_some(())?;
        match m.part() {
            BodyPart::Head => self.head_angles(world, axes).map(|a| a[usize::from(m.0)]),
            BodyPart::UpperArm(s) => {
                let c = self.frame(world, axes)?;
                let (d, _) = self.arm_dirs(skeleton, world, s)?;
                let [raise, swing] = raise_swing(s, mat_vec(&transpose(&c), &d));
                Some(if m.0 % 2 == 1 { raise } else { swing })
            }
            BodyPart::Elbow(s) => {
                let (u, f) = self.arm_dirs(skeleton, world, s)?;
                Some(dot(u, f?).clamp(-1.0, 1.0).acos().to_degrees())
            }
        }
    }

    /// The world rotation of the head that shows `pan`, `tilt`, `roll` (each `None` keeps the
    /// current value), as (head joint, world rotation).
    pub fn head_target(
        &self,
        world: &[Transform],
        axes: &Mat3,
        want: [Option<f64>; 3],
    ) -> Option<(usize, Mat3)> {
        let now = self.head_angles(world, axes)?;
        let angles = [0, 1, 2].map(|k| want[k].unwrap_or(now[k]));
        let m = euler_matrix(HEAD_ORDER, angles);
        let q = mat_mul(axes, &mat_mul(&m, &transpose(axes)));
        Some((self.head?, mat_mul(&world.get(self.chest?)?.rotation, &q)))
    }

    /// The world rotation of upper arm `s` that points it at `raise`, `swing` (each `None`
    /// keeps the current value), turning it the least, as (upper arm joint, world rotation).
    pub fn upper_arm_target(
        &self,
        skeleton: &Skeleton,
        world: &[Transform],
        axes: &Mat3,
        s: usize,
        want: [Option<f64>; 2],
    ) -> Option<(usize, Mat3)> {
        let c = self.frame(world, axes)?;
        let (d, _) = self.arm_dirs(skeleton, world, s)?;
        let now = raise_swing(s, mat_vec(&transpose(&c), &d));
        let (r, w) = (
            want[0].unwrap_or(now[0]).to_radians(),
            want[1].unwrap_or(now[1]).to_radians(),
        );
        let sign = if s == 0 { 1.0 } else { -1.0 };
        let b = [sign * w.cos() * r.cos(), w.cos() * r.sin(), w.sin()];
        let target = mat_vec(&c, &b);
        let upper = self.arms[s]?.upper;
        Some((
            upper,
            mat_mul(&shortest_rotation(d, target), &world.get(upper)?.rotation),
        ))
    }

    /// The world rotation of forearm `s` that bends the elbow to `flex` degrees about its
    /// current hinge (forward when the arm is straight), as (forearm joint, world rotation).
    pub fn elbow_target(
        &self,
        skeleton: &Skeleton,
        world: &[Transform],
        axes: &Mat3,
        s: usize,
        flex: f64,
    ) -> Option<(usize, Mat3)> {
        let c = self.frame(world, axes)?;
        let (u, f) = self.arm_dirs(skeleton, world, s)?;
        let f = f?;
        let now = dot(u, f).clamp(-1.0, 1.0).acos().to_degrees();
        let column = |k: usize| [c[0][k], c[1][k], c[2][k]];
        let hinge = unit(cross(u, f))
            .or_else(|| unit(cross(u, column(2))))
            .or_else(|| unit(cross(u, column(1))))?;
        let fore = self.arms[s]?.fore?;
        Some((
            fore,
            mat_mul(
                &axis_angle(hinge, (flex - now).to_radians()),
                &world.get(fore)?.rotation,
            ),
        ))
    }
}

/// Pan (about up), tilt (about left), roll (about forward): body axes are (left, up, forward)
/// = (0, 1, 2), so this is the Euler order `YXZ`.
pub const HEAD_ORDER: [usize; 3] = [1, 0, 2];

/// [raise, swing] (degrees) of a unit direction `b` in body axes for side `s` (0 = left):
/// raise = atan2(up, outward), swing = asin(forward).
fn raise_swing(s: usize, b: Vec3) -> [f64; 2] {
    let out = if s == 0 { b[0] } else { -b[0] };
    [
        b[1].atan2(out).to_degrees(),
        b[2].clamp(-1.0, 1.0).asin().to_degrees(),
    ]
}

fn add(a: Vec3, b: Vec3) -> Vec3 {
    [a[0] + b[0], a[1] + b[1], a[2] + b[2]]
}

fn sub(a: Vec3, b: Vec3) -> Vec3 {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

fn scale(a: Vec3, k: f64) -> Vec3 {
    [a[0] * k, a[1] * k, a[2] * k]
}

fn dot(a: Vec3, b: Vec3) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

fn cross(a: Vec3, b: Vec3) -> Vec3 {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

/// `a` scaled to length 1; `None` if it is (nearly) zero or not finite.
fn unit(a: Vec3) -> Option<Vec3> {
    let n = dot(a, a).sqrt();
    (n > 1e-9 && n.is_finite()).then(|| scale(a, 1.0 / n))
}

/// Rotation by `angle` radians about unit axis `n` (Rodrigues).
pub fn axis_angle(n: Vec3, angle: f64) -> Mat3 {
    let (s, c) = angle.sin_cos();
    let t = 1.0 - c;
    let [x, y, z] = n;
    [
        [t * x * x + c, t * x * y - s * z, t * x * z + s * y],
        [t * x * y + s * z, t * y * y + c, t * y * z - s * x],
        [t * x * z - s * y, t * y * z + s * x, t * z * z + c],
    ]
}

/// The smallest rotation taking unit vector `a` to unit vector `b`.
pub fn shortest_rotation(a: Vec3, b: Vec3) -> Mat3 {
    let c = dot(a, b).clamp(-1.0, 1.0);
    match unit(cross(a, b)) {
        Some(n) => axis_angle(n, c.acos()),
        None if c > 0.0 => axis_angle([1.0, 0.0, 0.0], 0.0),
        None => {
            // Opposite: half a turn about any axis perpendicular to `a`.
            let n = unit(cross(a, [1.0, 0.0, 0.0]))
                .or_else(|| unit(cross(a, [0.0, 1.0, 0.0])))
                .unwrap_or([0.0, 0.0, 1.0]);
            axis_angle(n, std::f64::consts::PI)
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn measures_round_trip_their_names_and_parts() {
        for (k, name) in BODY_MEASURES.iter().enumerate() {
            let m = BodyMeasure::parse(name).unwrap();
            assert_eq!((usize::from(m.index()), m.name()), (k, *name));
        }
        assert_eq!(
            BodyMeasure::parse("LEFT_ELBOW_FLEX").map(|m| m.part()),
            Some(BodyPart::Elbow(0))
        );
        assert_eq!(
            BodyMeasure::parse("right_arm_raise").map(|m| m.part()),
            Some(BodyPart::UpperArm(1))
        );
        assert_eq!(BodyMeasure::parse("tail_wag"), None);
        assert_eq!(BodyMeasure::from_index(9), None);
    }

    #[test]
    fn raise_and_swing_follow_the_conventions() {
        let close =
            |a: [f64; 2], b: [f64; 2]| (a[0] - b[0]).abs() < 1e-9 && (a[1] - b[1]).abs() < 1e-9;
        // Left arm straight out (T-pose), hanging, forward-and-out.
        assert!(close(raise_swing(0, [1.0, 0.0, 0.0]), [0.0, 0.0]));
        assert!(close(raise_swing(0, [0.0, -1.0, 0.0]), [-90.0, 0.0]));
        let h = std::f64::consts::FRAC_1_SQRT_2;
        assert!(close(raise_swing(0, [h, 0.0, h]), [0.0, 45.0]));
        // The right arm mirrored.
        assert!(close(raise_swing(1, [-h, h, 0.0]), [45.0, 0.0]));
    }

    #[test]
    fn shortest_rotation_maps_a_to_b() {
        for (a, b) in [
            ([1.0, 0.0, 0.0], [0.0, 1.0, 0.0]),
            ([0.0, 0.0, 1.0], [0.0, 0.0, -1.0]),
            ([0.6, 0.8, 0.0], [0.6, 0.8, 0.0]),
        ] {
            let r = mat_vec(&shortest_rotation(a, b), &a);
            assert!(dot(sub(r, b), sub(r, b)) < 1e-18, "{a:?} -> {b:?}: {r:?}");
        }
    }
}
