//! The character as a URDF: the blob's skeleton at its rest frame, every blob channel a
//! movable joint named as the JointState messages name it, so `robot_state_publisher` turns
//! the messages into the skeleton's TF frames (docs/ros2.md, "The URDF").
//!
//! **Frames.** One link per BVH joint, named as the joint; a `base_link` above the root(s).
//! BVH is Y up with the character facing +Z and its left at +X; ROS (REP 103) is Z up, X
//! forward, Y left: the fixed joint from `base_link` turns one into the other (a cyclic
//! permutation of the axes, a proper rotation). Lengths are BVH units taken as centimetres
//! (the shared data's), so they are scaled by [`SCALE`] to metres, as the VMC output does.
//!
//! **How a BVH joint becomes URDF joints.** A BVH joint's local transform is its offset (its
//! position channels at their rest values) followed by its rotation channels in file order,
//! `R = R_c1 R_c2 R_c3`. URDF gives each joint one axis, so a BVH joint becomes a short chain
//! of URDF joints with small links between them (`<channel>_link`), the last child link being
//! the BVH joint's own:
//!
//! - full-skeleton blob (channels in `channel` mode): one `continuous` joint per rotation
//!   channel, in the channel order, about that axis. Exact: the chain's product is `R`.
//! - Euler channels of a rig (`mode = "euler"`, order `o`): the chain is measured from the
//!   `relative_to` ancestor, so the fixed origin undoes the rest rotations of the joints above
//!   in that chain, then `R_o0 R_o1 R_o2` with a joint for each axis a channel drives and the
//!   rest angle fixed for the others. Exact (what the simulator's BVH shows).
//! - one twist channel on a joint: origin `L_rest R_a(-twist_rest)`, then the joint about `a`,
//!   so a value `v` gives `L_rest R_a(v - twist_rest)`, the simulator's rule. Exact.
//! - several twist channels on one joint (a pan/tilt head): a serial gimbal in rig order,
//!   each twist measured with the earlier ones at zero; this is how such a head is built, but
//!   the simulator applies each twist to the rotation the previous one left, so the two
//!   differ slightly away from the rest pose ([`Robot::approximate`] names these joints).
//! - body channels (a rig's `body` keys: head pan, tilt, roll; arm raise and swing; elbow
//!   flex): each measure the angle of one revolute joint of a fixed chain at the neck, the
//!   shoulder or the elbow, built on the body frame of the rest frame (`body.rs` gives the
//!   chains). Exact for the measures; an upper arm's twist about itself, which no measure
//!   reads, is the chain's rather than the simulator's least turn.
//! - joints no channel drives: one fixed joint with the rest frame's rotation.
//!
//! A negated axis (`-Y`) becomes the URDF axis `0 -1 0`, so positions are the channel values
//! as the messages carry them. A channel whose calibration spans a full turn is `continuous`;
//! others are `revolute` with the calibration's limits and slew rate as `velocity`.
//!
//! Visuals: a sphere per joint and a cylinder per bone (to each child and end site), so RViz
//! and Foxglove draw the skeleton. Nothing here panics on a validated blob; a channel layout
//! a URDF cannot show (a joint driven in two modes, two channels on one axis, a channel-mode
//! channel the joint lacks, a body measure whose part the skeleton lacks or across a joint
//! another channel turns) is a [`Ros2Error::Urdf`] naming the channel.

use std::fmt::Write as _;

use gesture_runtime::blob::{Blob, DriveMode};
use gesture_runtime::rig::ChannelCal;
use gesture_runtime::rotation::{
    axis_rotation, euler_angles, identity, mat_mul, mat_vec, transpose, twist_deg, Mat3,
};
use gesture_trainer::motion::fk::local_transform;
use gesture_trainer::rig::PoseSkeleton;

mod body;
mod chain;

use super::error::Ros2Error;
use chain::Elem;

/// Metres per BVH unit (BVH units taken as centimetres).
pub const SCALE: f64 = 0.01;

/// The rotation from BVH axes (Y up, facing +Z, left +X) to ROS axes (Z up, X forward, Y
/// left): `ros = M bvh`.
const BVH_TO_ROS: Mat3 = [[0.0, 0.0, 1.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]];

/// A movable joint's motion.
#[derive(Clone, Debug, PartialEq)]
pub enum Motion {
    /// Fixed.
    Fixed,
    /// About `axis` (a unit vector of the joint's frame), following blob channel `channel`;
    /// `limits` (lower, upper in rad, velocity in rad/s) unless it turns freely.
    Turn {
        /// Axis.
        axis: [f64; 3],
        /// Blob channel.
        channel: usize,
        /// Limits, `None` for a continuous joint.
        limits: Option<(f64, f64, f64)>,
    },
}

/// One URDF joint.
#[derive(Clone, Debug, PartialEq)]
pub struct Joint {
    /// Name (a blob channel's for a movable joint).
    pub name: String,
    /// Parent link.
    pub parent: String,
    /// Child link.
    pub child: String,
    /// Origin translation (m) in the parent link's frame.
    pub xyz: [f64; 3],
    /// Origin rotation.
    pub rot: Mat3,
    /// Motion.
    pub motion: Motion,
}

/// A link's visual: a sphere at its origin and a cylinder to each child and end site.
#[derive(Clone, Debug, PartialEq)]
pub struct Link {
    /// Name.
    pub name: String,
    /// Bone vectors (m) from the link's origin, in its frame.
    pub bones: Vec<[f64; 3]>,
    /// A BVH joint's link (drawn as a sphere), not one between the URDF joints of one.
    pub joint: bool,
}

/// The character as URDF joints and links (see the module docs).
#[derive(Clone, Debug, PartialEq)]
pub struct Robot {
    /// The robot's name.
    pub name: String,
    /// Links, parents before children.
    pub links: Vec<Link>,
    /// Joints, parents before children.
    pub joints: Vec<Joint>,
    /// BVH joints whose URDF chain only approximates the simulator's (several twists).
    pub approximate: Vec<String>,
}

fn signed_axis(index: usize, negated: bool) -> [f64; 3] {
    let mut a = [0.0; 3];
    a[index.min(2)] = if negated { -1.0 } else { 1.0 };
    a
}

fn limits(cal: Option<&ChannelCal>) -> Option<(f64, f64, f64)> {
    let c = cal?;
    if c.max_deg - c.min_deg >= 360.0 {
        return None;
    }
    Some((
        (c.min_deg as f64).to_radians(),
        (c.max_deg as f64).to_radians(),
        (c.max_slew_deg_per_s as f64).to_radians(),
    ))
}

impl Robot {
    /// The robot of `blob` (which needs its skeleton section), with servo calibrations
    /// `cals` (one per channel; the blob's or a rig file's) for the joint limits.
    pub fn from_blob(blob: &Blob<'_>, cals: &[ChannelCal]) -> Result<Self, Ros2Error> {
        let err = |s: String| Ros2Error::Urdf(s);
        let view = blob.skeleton().ok_or_else(|| {
            err("the blob has no skeleton section (it was packed with --no-skeleton)".into())
        })?;
        let ps = PoseSkeleton::from_blob(&view).map_err(|e| err(e.to_string()))?;
        let sk = ps.skeleton();
        let rest = ps.rest();
        let starts = sk.channel_starts();
        let names: Vec<&str> = blob.channel_names().collect();
        let drives: Vec<_> = (0..view.drives()).filter_map(|c| view.drive(c)).collect();
        if drives.len() != names.len() {
            return Err(err(format!(
                "the skeleton section drives {} channels, the blob has {}",
                drives.len(),
                names.len()
            )));
        }
        let values = |j: usize| {
            let n = sk.joints[j].channels.len();
            &rest[starts[j]..starts[j] + n]
        };
        let local = |j: usize| local_transform(&sk.joints[j], values(j));
        let mut robot = Robot {
            name: format!("gesture_{}", blob.rig_name()),
            links: vec![Link {
                name: "base_link".into(),
                bones: Vec::new(),
                joint: false,
            }],
            joints: Vec::new(),
            approximate: Vec::new(),
        };
        for (j, joint) in sk.joints.iter().enumerate() {
            let mine: Vec<usize> = (0..drives.len())
                .filter(|&c| drives[c].joint as usize == j)
                .collect();
            let angle: Vec<usize> = mine
                .iter()
                .copied()
                .filter(|&c| drives[c].mode != DriveMode::Channel)
                .collect();
            let (l_rest, t_rest) = local(j);
            let mut elems = Vec::new();
            let body_channels = mine
                .iter()
                .filter(|&&c| matches!(drives[c].mode, DriveMode::Body(_)))
                .count();
            if body_channels > 0 {
                if body_channels != mine.len() {
                    return Err(err(format!(
                        "joint {:?} is driven both by body measures and by other channels ({})",
                        joint.name,
                        mine.iter()
                            .map(|&c| names[c])
                            .collect::<Vec<_>>()
                            .join(", ")
                    )));
                }
                elems = body::chain(&ps, &drives, &names, j, &mine).map_err(err)?;
            } else if !angle.is_empty() {
                if angle.len() != mine.len() {
                    return Err(err(format!(
                        "joint {:?} is driven both by its own channels and by angles ({}); \
                         a URDF cannot show both",
                        joint.name,
                        mine.iter()
                            .map(|&c| names[c])
                            .collect::<Vec<_>>()
                            .join(", ")
                    )));
                }
                let top = drives[angle[0]].chain_top as usize;
                if angle.iter().any(|&c| drives[c].chain_top as usize != top) {
                    return Err(err(format!(
                        "joint {:?}: its channels are measured against different ancestors",
                        joint.name
                    )));
                }
                // The chain from `top` down to the joint, as PoseSkeleton builds it.
                let mut chain = vec![j];
                let mut cur = j;
                while cur != top {
                    match sk.joints[cur].parent {
                        Some(p) => {
                            chain.push(p);
                            cur = p;
                        }
                        None => {
                            chain = vec![j];
                            break;
                        }
                    }
                }
                chain.reverse();
                let above = chain[..chain.len() - 1]
                    .iter()
                    .fold(identity(), |acc, &k| mat_mul(&acc, &local(k).0));
                let r_rest = mat_mul(&above, &l_rest);
                let orders: Vec<Option<[usize; 3]>> = angle
                    .iter()
                    .map(|&c| match drives[c].mode {
                        DriveMode::Euler(o) => Some(o.map(|x| x as usize)),
                        _ => None,
                    })
                    .collect();
                if orders.iter().all(Option::is_some) {
                    let order = orders[0].unwrap_or([0, 1, 2]);
                    if orders.iter().any(|o| *o != Some(order)) {
                        return Err(err(format!(
                            "joint {:?}: Euler channels with different orders",
                            joint.name
                        )));
                    }
                    let a_rest = euler_angles(&r_rest, order);
                    elems.push(Elem::Fixed(transpose(&above)));
                    for (k, &ax) in order.iter().enumerate() {
                        let on: Vec<usize> = angle
                            .iter()
                            .copied()
                            .filter(|&c| drives[c].axis as usize == ax)
                            .collect();
                        match on.as_slice() {
                            [] => elems.push(Elem::Fixed(axis_rotation(ax, a_rest[k]))),
                            [c] => elems.push(Elem::Turn {
                                axis: signed_axis(ax, drives[*c].negated),
                                channel: *c,
                            }),
                            _ => {
                                return Err(err(format!(
                                    "channels {} drive one axis of joint {:?}",
                                    on.iter().map(|&c| names[c]).collect::<Vec<_>>().join(", "),
                                    joint.name
                                )))
                            }
                        }
                    }
                } else if orders.iter().all(Option::is_none) {
                    elems.push(Elem::Fixed(l_rest));
                    let mut r = r_rest;
                    for &c in &angle {
                        let ax = drives[c].axis as usize;
                        let old = twist_deg(&r, ax);
                        let undo = axis_rotation(ax, -old);
                        r = mat_mul(&r, &undo);
                        elems.push(Elem::Fixed(undo));
                        elems.push(Elem::Turn {
                            axis: signed_axis(ax, drives[c].negated),
                            channel: c,
                        });
                    }
                    if angle.len() > 1 {
                        robot.approximate.push(joint.name.clone());
                    }
                } else {
                    return Err(err(format!(
                        "joint {:?} mixes twist and Euler channels ({})",
                        joint.name,
                        angle
                            .iter()
                            .map(|&c| names[c])
                            .collect::<Vec<_>>()
                            .join(", ")
                    )));
                }
            } else {
                let mut used = vec![false; mine.len()];
                for (k, ch) in joint.channels.iter().enumerate() {
                    if !ch.is_rotation() {
                        continue;
                    }
                    let on: Vec<usize> = (0..mine.len())
                        .filter(|&i| drives[mine[i]].axis as usize == ch.axis())
                        .collect();
                    match on.as_slice() {
                        [] => elems.push(Elem::Fixed(axis_rotation(ch.axis(), values(j)[k]))),
                        [i] => {
                            used[*i] = true;
                            elems.push(Elem::Turn {
                                axis: signed_axis(ch.axis(), drives[mine[*i]].negated),
                                channel: mine[*i],
                            });
                        }
                        _ => {
                            return Err(err(format!(
                                "channels {} drive one rotation channel of joint {:?}",
                                on.iter()
                                    .map(|&i| names[mine[i]])
                                    .collect::<Vec<_>>()
                                    .join(", "),
                                joint.name
                            )))
                        }
                    }
                }
                if let Some(i) = used.iter().position(|u| !u) {
                    return Err(err(format!(
                        "channel {} follows a rotation channel joint {:?} does not have",
                        names[mine[i]], joint.name
                    )));
                }
            }
            robot.push_joint(j, &ps, t_rest, elems, &names, cals)?;
        }
        let mut seen = std::collections::HashSet::new();
        for n in robot
            .links
            .iter()
            .map(|l| ("link", &l.name))
            .chain(robot.joints.iter().map(|j| ("joint", &j.name)))
        {
            if !seen.insert(n) {
                return Err(err(format!(
                    "two {}s would be named {:?} (rename the BVH joint or the rig channel)",
                    n.0, n.1
                )));
            }
        }
        Ok(robot)
    }

    /// Appends the URDF chain of BVH joint `j` (see the module docs).
    fn push_joint(
        &mut self,
        j: usize,
        ps: &PoseSkeleton,
        t_rest: [f64; 3],
        elems: Vec<Elem>,
        names: &[&str],
        cals: &[ChannelCal],
    ) -> Result<(), Ros2Error> {
        let sk = ps.skeleton();
        let joint = &sk.joints[j];
        let (mut parent, mut rot, mut xyz) = match joint.parent {
            Some(p) => (
                sk.joints[p].name.clone(),
                identity(),
                t_rest.map(|v| v * SCALE),
            ),
            None => (
                "base_link".to_string(),
                BVH_TO_ROS,
                mat_vec(&BVH_TO_ROS, &t_rest).map(|v| v * SCALE),
            ),
        };
        let turns = elems
            .iter()
            .filter(|e| matches!(e, Elem::Turn { .. }))
            .count();
        let mut done = 0;
        for e in elems {
            match e {
                Elem::Fixed(m) => rot = mat_mul(&rot, &m),
                Elem::Turn { axis, channel } => {
                    done += 1;
                    let name = names[channel].to_string();
                    let child = if done == turns {
                        joint.name.clone()
                    } else {
                        format!("{name}_link")
                    };
                    if done < turns {
                        self.links.push(Link {
                            name: child.clone(),
                            bones: Vec::new(),
                            joint: false,
                        });
                    }
                    self.joints.push(Joint {
                        name,
                        parent: std::mem::replace(&mut parent, child.clone()),
                        child,
                        xyz,
                        rot,
                        motion: Motion::Turn {
                            axis,
                            channel,
                            limits: limits(cals.get(channel)),
                        },
                    });
                    xyz = [0.0; 3];
                    rot = identity();
                }
            }
        }
        let is_identity = rot
            .iter()
            .flatten()
            .zip(identity::<f64>().iter().flatten())
            .all(|(a, b)| (a - b).abs() < 1e-12);
        if turns == 0 || !is_identity {
            // The last turn's link gets the rest of the rotation through a fixed joint.
            let from = if turns == 0 {
                parent
            } else {
                let last = self.joints.last_mut().map(|l| {
                    let link = format!("{}_link", l.name);
                    l.child = link.clone();
                    link
                });
                let link = last.unwrap_or_default();
                self.links.push(Link {
                    name: link.clone(),
                    bones: Vec::new(),
                    joint: false,
                });
                link
            };
            self.joints.push(Joint {
                name: format!("{}_rest", joint.name),
                parent: from,
                child: joint.name.clone(),
                xyz,
                rot,
                motion: Motion::Fixed,
            });
        }
        let mut bones: Vec<[f64; 3]> = sk
            .joints
            .iter()
            .enumerate()
            .filter(|(_, c)| c.parent == Some(j))
            .map(|(c, child)| {
                let s = sk.channel_starts()[c];
                local_transform(child, &ps.rest()[s..s + child.channels.len()])
                    .1
                    .map(|v| v * SCALE)
            })
            .collect();
        bones.extend(joint.end_site.map(|e| e.map(|v| v * SCALE)));
        self.links.push(Link {
            name: joint.name.clone(),
            bones,
            joint: true,
        });
        Ok(())
    }

    /// `; approximate at ...` for joints whose chain is a serial gimbal, else empty.
    pub fn note(&self) -> String {
        if self.approximate.is_empty() {
            String::new()
        } else {
            format!(
                "; a serial gimbal, close to the simulator's motion, at {}",
                self.approximate.join(", ")
            )
        }
    }

    /// The movable joints' names, in blob channel order (the JointState's names).
    pub fn movable(&self) -> Vec<&str> {
        let mut m: Vec<(usize, &str)> = self
            .joints
            .iter()
            .filter_map(|j| match j.motion {
                Motion::Turn { channel, .. } => Some((channel, j.name.as_str())),
                Motion::Fixed => None,
            })
            .collect();
        m.sort_unstable();
        m.into_iter().map(|(_, n)| n).collect()
    }

    /// Forward kinematics: every link's origin in `base_link` (m) with the channels at
    /// `angles_deg` (degrees, blob order), as `robot_state_publisher` would compute them.
    pub fn link_positions(&self, angles_deg: &[f32]) -> Vec<(String, [f64; 3])> {
        self.link_frames(angles_deg)
            .into_iter()
            .map(|(name, _, t)| (name, t))
            .collect()
    }

    /// Forward kinematics: every link's frame in `base_link`, as (name, rotation, origin in
    /// m), with the channels at `angles_deg` (degrees, blob order).
    pub fn link_frames(&self, angles_deg: &[f32]) -> Vec<(String, Mat3, [f64; 3])> {
        let mut frames: std::collections::HashMap<&str, (Mat3, [f64; 3])> =
            std::collections::HashMap::new();
        frames.insert("base_link", (identity(), [0.0; 3]));
        let mut out = vec![("base_link".to_string(), identity(), [0.0; 3])];
        for j in &self.joints {
            let (pr, pt) = frames
                .get(j.parent.as_str())
                .copied()
                .unwrap_or((identity(), [0.0; 3]));
            let mut r = mat_mul(&pr, &j.rot);
            let d = mat_vec(&pr, &j.xyz);
            let t = [pt[0] + d[0], pt[1] + d[1], pt[2] + d[2]];
            if let Motion::Turn { axis, channel, .. } = j.motion {
                let a = angles_deg.get(channel).copied().unwrap_or(0.0) as f64;
                r = mat_mul(&r, &rotation_about(axis, a));
            }
            frames.insert(j.child.as_str(), (r, t));
            out.push((j.child.clone(), r, t));
        }
        out
    }

    /// The URDF text.
    pub fn to_xml(&self) -> String {
        let mut s = String::new();
        let _ = writeln!(s, "<?xml version=\"1.0\"?>");
        let _ = writeln!(
            s,
            // No "--" inside an XML comment.
            "<!-- Written by gesture-sim: the character's skeleton at its rest frame; the \
             movable joints are named as the run's sensor_msgs/JointState messages name them \
             (docs/ros2.md). -->"
        );
        let _ = writeln!(s, "<robot name=\"{}\">", esc(&self.name));
        let _ = writeln!(
            s,
            "  <material name=\"bone\"><color rgba=\"0.8 0.8 0.85 1\"/></material>"
        );
        for l in &self.links {
            let _ = writeln!(s, "  <link name=\"{}\">", esc(&l.name));
            if l.joint {
                let _ = writeln!(
                    s,
                    "    <visual><geometry><sphere radius=\"0.02\"/></geometry><material name=\"bone\"/></visual>"
                );
            }
            for b in &l.bones {
                let len = (b[0] * b[0] + b[1] * b[1] + b[2] * b[2]).sqrt();
                if len < 1e-6 {
                    continue;
                }
                let rpy = rpy(&z_to(b, len));
                let _ = writeln!(
                    s,
                    "    <visual><origin xyz=\"{} {} {}\" rpy=\"{} {} {}\"/><geometry><cylinder radius=\"0.012\" length=\"{}\"/></geometry><material name=\"bone\"/></visual>",
                    num(b[0] / 2.0), num(b[1] / 2.0), num(b[2] / 2.0), num(rpy[0]), num(rpy[1]), num(rpy[2]), num(len)
                );
            }
            let _ = writeln!(s, "  </link>");
        }
        for j in &self.joints {
            let kind = match j.motion {
                Motion::Fixed => "fixed",
                Motion::Turn { limits: None, .. } => "continuous",
                Motion::Turn { .. } => "revolute",
            };
            let rpy = rpy(&j.rot);
            let _ = writeln!(s, "  <joint name=\"{}\" type=\"{kind}\">", esc(&j.name));
            let _ = writeln!(s, "    <parent link=\"{}\"/>", esc(&j.parent));
            let _ = writeln!(s, "    <child link=\"{}\"/>", esc(&j.child));
            let _ = writeln!(
                s,
                "    <origin xyz=\"{} {} {}\" rpy=\"{} {} {}\"/>",
                num(j.xyz[0]),
                num(j.xyz[1]),
                num(j.xyz[2]),
                num(rpy[0]),
                num(rpy[1]),
                num(rpy[2])
            );
            if let Motion::Turn { axis, limits, .. } = &j.motion {
                let _ = writeln!(
                    s,
                    "    <axis xyz=\"{} {} {}\"/>",
                    num(axis[0]),
                    num(axis[1]),
                    num(axis[2])
                );
                if let Some((lo, hi, v)) = limits {
                    let _ = writeln!(
                        s,
                        "    <limit lower=\"{}\" upper=\"{}\" effort=\"0\" velocity=\"{}\"/>",
                        num(*lo),
                        num(*hi),
                        num(*v)
                    );
                }
            }
            let _ = writeln!(s, "  </joint>");
        }
        let _ = writeln!(s, "</robot>");
        s
    }
}

/// Rotation by `deg` about the unit vector `axis` (Rodrigues).
fn rotation_about(axis: [f64; 3], deg: f64) -> Mat3 {
    let (s, c) = deg.to_radians().sin_cos();
    let [x, y, z] = axis;
    let t = 1.0 - c;
    [
        [t * x * x + c, t * x * y - s * z, t * x * z + s * y],
        [t * x * y + s * z, t * y * y + c, t * y * z - s * x],
        [t * x * z - s * y, t * y * z + s * x, t * z * z + c],
    ]
}

/// A rotation taking +Z to the direction of `b` (length `len`).
fn z_to(b: &[f64; 3], len: f64) -> Mat3 {
    let d = b.map(|v| v / len);
    // Axis z x d, angle acos(z . d).
    let (ax, ay) = (-d[1], d[0]);
    let n = (ax * ax + ay * ay).sqrt();
    if n < 1e-12 {
        return if d[2] > 0.0 {
            identity()
        } else {
            axis_rotation(0, 180.0)
        };
    }
    rotation_about(
        [ax / n, ay / n, 0.0],
        d[2].clamp(-1.0, 1.0).acos().to_degrees(),
    )
}

/// URDF `rpy` (radians) of `m`: `m = Rz(yaw) Ry(pitch) Rx(roll)`.
fn rpy(m: &Mat3) -> [f64; 3] {
    let [yaw, pitch, roll] = euler_angles(m, [2, 1, 0]);
    [roll.to_radians(), pitch.to_radians(), yaw.to_radians()]
}

/// A number for the XML: shortest round-trip form, `-0` written as `0`.
fn num(v: f64) -> String {
    if v == 0.0 || !v.is_finite() {
        "0".into()
    } else {
        format!("{v}")
    }
}

/// XML attribute escaping.
fn esc(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
        .replace('"', "&quot;")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rotations_about_unit_axes_match_the_runtimes() {
        for ax in 0..3 {
            let a = rotation_about(signed_axis(ax, false), 37.0);
            let b = axis_rotation(ax, 37.0);
            let n = rotation_about(signed_axis(ax, true), -37.0);
            for r in 0..3 {
                for c in 0..3 {
                    assert!((a[r][c] - b[r][c]).abs() < 1e-12);
                    assert!((n[r][c] - b[r][c]).abs() < 1e-12);
                }
            }
        }
    }

    #[test]
    fn cylinders_point_along_their_bones() {
        for b in [
            [0.0f64, 0.0, 2.0],
            [0.0, 0.0, -1.0],
            [1.0, 2.0, -3.0],
            [0.0, 5.0, 0.0],
        ] {
            let len: f64 = (b[0] * b[0] + b[1] * b[1] + b[2] * b[2]).sqrt();
            let z = mat_vec(&z_to(&b, len), &[0.0, 0.0, len]);
            for k in 0..3 {
                assert!((z[k] - b[k]).abs() < 1e-9, "{b:?} -> {z:?}");
            }
        }
    }

    #[test]
    fn rpy_rebuilds_the_matrix() {
        let m = mat_mul(
            &axis_rotation(2, 30.0),
            &mat_mul(&axis_rotation(1, -20.0), &axis_rotation(0, 70.0)),
        );
        let [r, p, y] = rpy(&m);
        let back = mat_mul(
            &axis_rotation(2, y.to_degrees()),
            &mat_mul(
                &axis_rotation(1, p.to_degrees()),
                &axis_rotation(0, r.to_degrees()),
            ),
        );
        for i in 0..3 {
            for k in 0..3 {
                assert!((m[i][k] - back[i][k]).abs() < 1e-12);
            }
        }
        assert_eq!(esc("a<b&\"c\""), "a&lt;b&amp;&quot;c&quot;");
    }
}
