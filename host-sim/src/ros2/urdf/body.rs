//! Body channels (a rig's `body` keys) as URDF joints. Every body measure is the angle of a
//! revolute joint in a fixed chain, so a URDF shows each exactly (the definitions are the
//! trainer's, `gesture_trainer::rig::Body`; the body frame `C` is the chest's rotation times
//! [`Body::axes`] of the rest frame, columns left, up, forward):
//!
//! - **head** (pan, tilt, roll: Euler `YXZ` of the head relative to the chest in body axes):
//!   at the neck, the origin turns the parent link's frame to the body frame; then pan about
//!   up, tilt about left, roll about forward, in that order; then the turn back from the body
//!   frame, so the head's rotation is `R_chest A E(pan, tilt, roll) Aᵀ`, the simulator's.
//! - **upper arm** (raise = atan2(up, outward), swing = asin(forward) of its direction `b`):
//!   at the shoulder, the origin turns to the body frame; then raise about `±forward` and
//!   swing about `∓up` of the raised frame (upper sign for the left arm, lower for the right),
//!   so the arm's direction is `Rz(±raise) Ry(∓swing) [±1, 0, 0] = [±cos w cos r, cos w sin r,
//!   sin w]`, the measured direction for any (raise, swing); then a fixed turn that points the
//!   bone straight out at zero (the least turn from its rest direction). The arm's twist
//!   about itself is the chain's, not the simulator's least turn (no measure reads it).
//! - **elbow** (flex = the angle between upper arm and forearm): at the elbow, a joint about a
//!   hinge fixed in the upper arm's link, perpendicular to the upper arm: `u × f` of the rest
//!   frame's upper arm `u` and forearm `f`, so it bends the way the rest pose bends; for a
//!   straight arm at rest, `u × forward`, so it bends forward (the simulator's hinge at the
//!   rest pose). Then a fixed turn that straightens the forearm at zero, so flex 0 is
//!   straight and the angle between the bones is the flex for 0 to 180 degrees.
//!
//! Every position is the measure itself, the commanded angle as the JointState carries it:
//! a joint's zero is the measure's zero (arm straight out sideways, elbow straight, head as
//! the chest), as it is for the rig's other modes. A measure no channel reads keeps its rest
//! value as a fixed rotation, as the simulator keeps it. The chain is exact only if nothing
//! between the reference (the chest; the upper arm for an elbow) and the moved joint, or
//! between the moved joint and the point its bone ends at, turns: a channel on such a joint is
//! refused, with its name.

use gesture_runtime::blob::{Drive, DriveMode};
use gesture_runtime::rotation::{axis_rotation, euler_angles, mat_mul, mat_vec, transpose};
use gesture_trainer::motion::fk::{world_transforms, Vec3};
use gesture_trainer::motion::Skeleton;
use gesture_trainer::rig::{
    axis_angle, shortest_rotation, Body, BodyMeasure, BodyPart, Effector, PoseSkeleton, HEAD_ORDER,
};

use super::chain::Elem;

/// The chain of BVH joint `j`, which the body channels `mine` (indices into `drives` and
/// `names`, the blob's channels) move; see the module docs.
pub fn chain(
    ps: &PoseSkeleton,
    drives: &[Drive],
    names: &[&str],
    j: usize,
    mine: &[usize],
) -> Result<Vec<Elem>, String> {
    let sk = ps.skeleton();
    let body = ps.body();
    let axes = ps.body_axes().ok_or_else(|| {
        format!(
            "channel `{}` is a body measure, but the skeleton gives no body frame (no \
             left-right line through two upper arms or upper legs, or no hips)",
            names[mine[0]]
        )
    })?;
    // Which measure each channel reads, by measure index.
    let mut want = [None::<usize>; 9];
    let mut part = None;
    for &c in mine {
        let m = match drives[c].mode {
            DriveMode::Body(k) => BodyMeasure::from_index(k),
            _ => None,
        }
        .ok_or_else(|| format!("channel `{}` is not a body measure", names[c]))?;
        if body.joint(m) != Some(j) {
            let why = body
                .missing(m)
                .unwrap_or_else(|| "its bone is another joint".into());
            return Err(format!("channel `{}` reads {m}: {why}", names[c]));
        }
        if part.is_some_and(|p| p != m.part()) {
            return Err(format!(
                "joint {:?} is moved by body measures of different parts",
                sk.joints[j].name
            ));
        }
        part = Some(m.part());
        let slot = &mut want[usize::from(m.index())];
        if let Some(other) = slot.replace(c) {
            return Err(format!(
                "channels `{}` and `{}` both read {m}",
                names[other], names[c]
            ));
        }
    }
    let world = world_transforms(sk, ps.rest());
    let chest = body.chest.ok_or("no chest")?;
    let parent = sk.joints[j].parent.ok_or("the moved joint is the root")?;
    let rp = world[parent].rotation;
    let frame = mat_mul(&world[chest].rotation, &axes);
    let point = |e: Effector| Body::point(sk, &world, e).ok_or("a point of the arm is missing");
    let driven = |c: usize| drives[c].joint as usize;
    let still = |top: usize, bottom: usize| -> Result<(), String> {
        let moving = between(sk, top, bottom);
        match (0..drives.len()).find(|&c| moving.contains(&driven(c))) {
            Some(c) => Err(format!(
                "channel `{}` moves joint {:?}, between {:?} and {:?}, which the body \
                 measures at {:?} take as rigid",
                names[c],
                sk.joints[driven(c)].name,
                sk.joints[top].name,
                sk.joints[bottom].name,
                sk.joints[j].name
            )),
            None => Ok(()),
        }
    };
    let end = |e: Effector| match e {
        Effector::Joint(k) => k,
        Effector::EndSite(k) => k,
    };
    let turn = |slot: usize, axis: Vec3, rest_rad: f64| match want[slot] {
        Some(channel) => Elem::Turn { axis, channel },
        None => Elem::Fixed(axis_angle(axis, rest_rad)),
    };
    let mut elems = Vec::new();
    match part {
        None => return Err("no body channel".into()),
        Some(BodyPart::Head) => {
            still(chest, j)?;
            let rest = mat_mul(&transpose(&frame), &mat_mul(&world[j].rotation, &axes));
            let a = euler_angles(&rest, HEAD_ORDER);
            elems.push(Elem::Fixed(mat_mul(&transpose(&rp), &frame)));
            for (k, &ax) in HEAD_ORDER.iter().enumerate() {
                elems.push(match want[k] {
                    Some(channel) => Elem::Turn {
                        axis: unit_axis(ax),
                        channel,
                    },
                    None => Elem::Fixed(axis_rotation(ax, a[k])),
                });
            }
            elems.push(Elem::Fixed(transpose(&axes)));
        }
        Some(BodyPart::UpperArm(s)) => {
            let arm = body.arms[s].ok_or("no arm")?;
            still(chest, j)?;
            still(j, end(arm.elbow))?;
            let d = unit(sub(point(arm.elbow)?, point(Effector::Joint(j))?))
                .ok_or("the upper arm has no length")?;
            let b = mat_vec(&transpose(&frame), &d);
            let sign = if s == 0 { 1.0 } else { -1.0 };
            let raise = b[1].atan2(sign * b[0]);
            let swing = b[2].clamp(-1.0, 1.0).asin();
            let slot = 3 + 2 * s;
            elems.push(Elem::Fixed(mat_mul(&transpose(&rp), &frame)));
            elems.push(turn(slot, [0.0, 0.0, sign], raise));
            elems.push(turn(slot + 1, [0.0, -sign, 0.0], swing));
            let in_body = mat_mul(&transpose(&frame), &world[j].rotation);
            elems.push(Elem::Fixed(mat_mul(
                &shortest_rotation(b, [sign, 0.0, 0.0]),
                &in_body,
            )));
        }
        Some(BodyPart::Elbow(s)) => {
            let arm = body.arms[s].ok_or("no arm")?;
            let wrist = arm.wrist.ok_or("no wrist")?;
            still(arm.upper, j)?;
            still(j, end(wrist))?;
            let elbow = point(arm.elbow)?;
            let u = unit(sub(elbow, point(Effector::Joint(arm.upper))?))
                .ok_or("the upper arm has no length")?;
            let f = unit(sub(point(wrist)?, elbow)).ok_or("the forearm has no length")?;
            let to_parent = |v: Vec3| mat_vec(&transpose(&rp), &v);
            let (u, f) = (to_parent(u), to_parent(f));
            let column = |k: usize| to_parent([frame[0][k], frame[1][k], frame[2][k]]);
            let cross_u = |v: Vec3| {
                let c = cross(u, v);
                (dot(c, c).sqrt() > 1e-6).then(|| unit(c)).flatten()
            };
            let hinge = cross_u(f)
                .or_else(|| cross_u(column(2)))
                .or_else(|| cross_u(column(1)))
                .ok_or("no hinge for the elbow")?;
            elems.push(Elem::Turn {
                axis: hinge,
                channel: want[7 + s].ok_or("no flex channel")?,
            });
            let local = mat_mul(&transpose(&rp), &world[j].rotation);
            elems.push(Elem::Fixed(mat_mul(&shortest_rotation(f, u), &local)));
        }
    }
    Ok(elems)
}

/// The joints strictly between `top` and `bottom` (below `top`, above `bottom`); empty if
/// `top` is not above `bottom`.
fn between(sk: &Skeleton, top: usize, bottom: usize) -> Vec<usize> {
    let mut out = Vec::new();
    let mut cur = sk.joints.get(bottom).and_then(|x| x.parent);
    while let Some(p) = cur {
        if p == top || out.len() > sk.joints.len() {
            return out;
        }
        out.push(p);
        cur = sk.joints[p].parent;
    }
    Vec::new()
}

/// Unit vector along axis `k` (0 = X).
fn unit_axis(k: usize) -> Vec3 {
    let mut a = [0.0; 3];
    a[k.min(2)] = 1.0;
    a
}

fn sub(a: Vec3, b: Vec3) -> Vec3 {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
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

/// `a` scaled to length 1; `None` if it is (nearly) zero.
fn unit(a: Vec3) -> Option<Vec3> {
    let n = dot(a, a).sqrt();
    (n > 1e-9 && n.is_finite()).then(|| a.map(|v| v / n))
}
