//! Avatars over the VMC protocol: the played poses as OSC over UDP, for VSeeFace, VNyan,
//! Warudo, VirtualMotionCapture, Blender's VMC4B or Unreal's VRM4U.
//!
//! **What is sent.** One OSC bundle per animation tick (encoded with `rosc`):
//! `/VMC/Ext/Root/Pos` ("root", position 0, identity rotation), then for each humanoid bone the
//! skeleton maps to, `/VMC/Ext/Bone/Pos` (the Unity `HumanBodyBones` name, the bone's local
//! position in metres and its local rotation as a unit quaternion x, y, z, w), then
//! `/VMC/Ext/OK 1` and `/VMC/Ext/T` (seconds since the start).
//!
//! **Frames.** BVH is right-handed with Y up and lengths in skeleton units (centimetres on the
//! shared data); Unity is left-handed with Y up and metres. A position `(x, y, z)` goes out as
//! `(-x, y, z) * scale` (`scale` 0.01 by default) and a rotation quaternion `(x, y, z, w)` as
//! `(x, -y, -z, w)`: the same mirror through the YZ plane applied to both.
//!
//! **Bones.** Library joints map to humanoid bones by name aliases
//! ([`gesture_trainer::motion::humanoid`], shared with the rig's body channels: the first alias
//! the skeleton has wins; names compare without case, punctuation or a `prefix:`), which cover
//! the ZeroEGGS skeletons (75 and 9 joints), the Bandai-Namco, CMU and ReActIdle skeletons and
//! the synthetic character; a bone-map file
//! (`Humanoid = "joint"` lines, TOML) overrides or adds any. A joint that maps to no bone is not
//! lost: its rotation is folded into the nearest mapped descendant, so a bone's rotation is the
//! product of the local rotations from just below its mapped ancestor down to its own joint
//! (a root above `Hips` folds into `Hips`). Rotations are relative to the BVH's rest pose, which
//! receivers take as the avatar's T-pose: the ZeroEGGS and Bandai rest poses are T-poses.

use std::collections::BTreeMap;
use std::net::{SocketAddr, ToSocketAddrs, UdpSocket};
use std::path::Path;

use rosc::{OscBundle, OscMessage, OscPacket, OscTime, OscType};

use gesture_runtime::rotation::{normalize, quat_mul, quaternion, Mat3, Quat};
use gesture_trainer::motion::fk::local_transform;
use gesture_trainer::motion::humanoid::find_bones;
use gesture_trainer::rig::PoseSkeleton;

/// Humanoid bones and the joint names that map to them (the trainer's, shared with the rig's
/// body channels).
pub use gesture_trainer::motion::humanoid::BONE_ALIASES;

/// Why VMC output could not start.
#[derive(Debug, thiserror::Error)]
pub enum VmcError {
    /// The address does not resolve.
    #[error("--vmc {addr}: {reason}")]
    Address {
        /// What was given.
        addr: String,
        /// Why it is unusable.
        reason: String,
    },
    /// The bone-map file is unreadable or names a joint the skeleton lacks.
    #[error("{}: {reason}", path.display())]
    BoneMap {
        /// The file.
        path: std::path::PathBuf,
        /// What is wrong.
        reason: String,
    },
    /// No joint maps to a humanoid bone.
    #[error("no joint of the blob's skeleton maps to a humanoid bone (joints: {joints}); give a --bone-map file")]
    NoBones {
        /// The skeleton's joints.
        joints: String,
    },
    /// The blob has no skeleton section.
    #[error("--vmc needs the blob's skeleton section (it was packed with --no-skeleton)")]
    NoSkeleton,
    /// Sending failed.
    #[error("--vmc: sending: {0}")]
    Send(#[from] std::io::Error),
}

/// Humanoid bone -> joint, for one skeleton.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct BoneMap {
    /// `(humanoid bone, joint index)`, in [`BONE_ALIASES`] order (overrides' extra bones last).
    pub bones: Vec<(String, usize)>,
}

impl BoneMap {
    /// The map for `sk` from the aliases and the optional `file` (overrides).
    pub fn new(sk: &PoseSkeleton, file: Option<&Path>) -> Result<Self, VmcError> {
        let skeleton = sk.skeleton();
        let mut map: BTreeMap<String, usize> = BTreeMap::new();
        for (bone, j) in find_bones(skeleton) {
            map.insert(bone.to_string(), j);
        }
        if let Some(path) = file {
            let bad = |reason: String| VmcError::BoneMap {
                path: path.to_path_buf(),
                reason,
            };
            let text = std::fs::read_to_string(path).map_err(|e| bad(e.to_string()))?;
            let table: BTreeMap<String, String> =
                toml::from_str(&text).map_err(|e| bad(e.message().to_string()))?;
            for (bone, joint) in table {
                let j = skeleton
                    .find_ignore_case(&joint)
                    .ok_or_else(|| bad(format!("{bone}: no joint named {joint:?}")))?;
                map.insert(bone, j);
            }
        }
        if map.is_empty() {
            return Err(VmcError::NoBones {
                joints: skeleton.joint_names().collect::<Vec<_>>().join(", "),
            });
        }
        let order = |b: &str| BONE_ALIASES.iter().position(|(n, _)| *n == b);
        let mut bones: Vec<(String, usize)> = map.into_iter().collect();
        bones.sort_by_key(|(b, _)| (order(b).unwrap_or(usize::MAX), b.clone()));
        Ok(Self { bones })
    }
}

/// The rotation of `m` as a unit quaternion `[w, x, y, z]` with `w >= 0` (identity when `m`
/// is not finite).
fn unit_quat(m: &Mat3) -> Quat {
    let q = normalize(quaternion(m));
    if !q.iter().all(|v| v.is_finite()) {
        return [1.0, 0.0, 0.0, 0.0];
    }
    if q[0] < 0.0 {
        q.map(|v| -v)
    } else {
        q
    }
}

/// The VMC stream of one skeleton (see the module docs).
pub struct VmcStream {
    sk: PoseSkeleton,
    map: BoneMap,
    /// For each mapped bone: the joints whose local rotations it carries, from the top down.
    chains: Vec<Vec<usize>>,
    starts: Vec<usize>,
    /// Metres per skeleton unit.
    pub scale: f64,
}

impl VmcStream {
    /// A stream for `sk` with bones `map`.
    pub fn new(sk: PoseSkeleton, map: BoneMap) -> Self {
        let skeleton = sk.skeleton();
        let mapped: Vec<usize> = map.bones.iter().map(|b| b.1).collect();
        let chains = mapped
            .iter()
            .map(|&j| {
                let mut chain = vec![j];
                let mut p = skeleton.joints[j].parent;
                while let Some(a) = p {
                    if mapped.contains(&a) {
                        break;
                    }
                    chain.push(a);
                    p = skeleton.joints[a].parent;
                }
                chain.reverse();
                chain
            })
            .collect();
        let starts = skeleton.channel_starts();
        Self {
            sk,
            map,
            chains,
            starts,
            scale: 0.01,
        }
    }

    /// The bones sent, in order.
    pub fn bones(&self) -> impl Iterator<Item = &str> {
        self.map.bones.iter().map(|b| b.0.as_str())
    }

    /// The bundle for `pose` (rig channel values) at `t` seconds.
    pub fn packet(&self, t: f64, pose: &[f32]) -> OscPacket {
        let values = self.sk.frame(pose);
        let skeleton = self.sk.skeleton();
        let local = |j: usize| {
            let joint = &skeleton.joints[j];
            let s = self.starts[j];
            let n = joint.channels.len();
            local_transform(joint, values.get(s..s + n).unwrap_or(&[]))
        };
        let f = |v: f64| OscType::Float(if v.is_finite() { v as f32 } else { 0.0 });
        let mut content = vec![OscPacket::Message(OscMessage {
            addr: "/VMC/Ext/Root/Pos".into(),
            args: vec![
                OscType::String("root".into()),
                f(0.0),
                f(0.0),
                f(0.0),
                f(0.0),
                f(0.0),
                f(0.0),
                f(1.0),
            ],
        })];
        for ((bone, j), chain) in self.map.bones.iter().zip(&self.chains) {
            let mut q: Quat = [1.0, 0.0, 0.0, 0.0];
            for &c in chain {
                q = quat_mul(&q, &unit_quat(&local(c).0));
            }
            let q = unit_quat(&gesture_runtime::rotation::quat_matrix(&q));
            let p = local(*j).1;
            content.push(OscPacket::Message(OscMessage {
                addr: "/VMC/Ext/Bone/Pos".into(),
                args: vec![
                    OscType::String(bone.clone()),
                    f(-p[0] * self.scale),
                    f(p[1] * self.scale),
                    f(p[2] * self.scale),
                    f(q[1]),
                    f(-q[2]),
                    f(-q[3]),
                    f(q[0]),
                ],
            }));
        }
        content.push(OscPacket::Message(OscMessage {
            addr: "/VMC/Ext/OK".into(),
            args: vec![OscType::Int(1)],
        }));
        content.push(OscPacket::Message(OscMessage {
            addr: "/VMC/Ext/T".into(),
            args: vec![f(t)],
        }));
        OscPacket::Bundle(OscBundle {
            timetag: OscTime {
                seconds: 0,
                fractional: 1,
            },
            content,
        })
    }
}

/// A UDP sender of a [`VmcStream`].
pub struct VmcSender {
    socket: UdpSocket,
    target: SocketAddr,
    /// The stream.
    pub stream: VmcStream,
    /// Bundles sent.
    pub sent: usize,
}

impl VmcSender {
    /// A sender to `addr` (`HOST:PORT`).
    pub fn new(addr: &str, stream: VmcStream) -> Result<Self, VmcError> {
        let bad = |reason: String| VmcError::Address {
            addr: addr.to_string(),
            reason,
        };
        let target = addr
            .to_socket_addrs()
            .map_err(|e| bad(e.to_string()))?
            .next()
            .ok_or_else(|| bad("resolves to no address".into()))?;
        let bind: SocketAddr = if target.is_ipv4() {
            ([0, 0, 0, 0], 0).into()
        } else {
            ([0u16; 8], 0).into()
        };
        let socket = UdpSocket::bind(bind).map_err(|e| bad(e.to_string()))?;
        Ok(Self {
            socket,
            target,
            stream,
            sent: 0,
        })
    }

    /// Sends the bundle of `pose` at `t` seconds.
    pub fn send(&mut self, t: f64, pose: &[f32]) -> Result<(), VmcError> {
        let bytes = rosc::encoder::encode(&self.stream.packet(t, pose))
            .map_err(|e| std::io::Error::other(e.to_string()))?;
        match self.socket.send_to(&bytes, self.target) {
            Ok(_) => {}
            // Nobody listening yet (ICMP port unreachable on a connected path): keep going,
            // as VMC senders do.
            Err(e) if e.kind() == std::io::ErrorKind::ConnectionRefused => {}
            Err(e) => return Err(e.into()),
        }
        self.sent += 1;
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn matrices_become_unit_quaternions_with_nonnegative_w() {
        let h = std::f64::consts::FRAC_1_SQRT_2;
        // A quarter turn about Z.
        let q = unit_quat(&[[0.0, -1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]]);
        for (a, b) in q.iter().zip([h, 0.0, 0.0, h]) {
            assert!((a - b).abs() < 1e-12, "{q:?}");
        }
        assert_eq!(unit_quat(&[[f64::NAN; 3]; 3]), [1.0, 0.0, 0.0, 0.0]);
    }
}
