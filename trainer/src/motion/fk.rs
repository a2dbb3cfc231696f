//! Forward kinematics: world positions of joints and end sites, frame by frame.
//!
//! Owns the BVH transform convention and the [`Positions`] container that the segmentation and
//! kinematic-parameter code consume.
//!
//! ## Convention (what BVH tools do)
//!
//! - Rotation channels are in degrees. A joint's local rotation is the product of its axis
//!   rotations **in the order its `CHANNELS` line lists them**, acting on column vectors: for
//!   `Zrotation Yrotation Xrotation` it is `Rz(z) * Ry(y) * Rx(x)`; for
//!   `Zrotation Xrotation Yrotation` it is `Rz(z) * Rx(x) * Ry(y)`. Each joint has its own order.
//! - Translation channels *replace* the matching component of the joint's `OFFSET` (a root's
//!   position channels are its absolute position; the Bandai Namco files repeat every joint's
//!   offset in its translation channels). Components without a channel keep the offset.
//! - `world(j) = world(parent) * [R_local | t_local]`, so the joint sits at
//!   `p_parent + R_parent * t_local` and an end site at `p_j + R_j * end_offset`.
//!
//! ## Choices
//!
//! The runtime's rotation module ([`gesture_runtime::rotation`], `[f64; 3]` and
//! `[[f64; 3]; 3]`) instead of nalgebra: FK needs only 3x3 products and matrix-vector
//! products, the simulator and the rig code use the same functions, and the trainer keeps one
//! heavy dependency fewer.
//!
//! [`FkPlan`] evaluates only the joints a set of targets needs (the targets and their ancestor
//! chains, parents first, as the depth-first joint order guarantees) and skips rotations nobody
//! reads, so tracking two hands in a 75-joint skeleton costs a fraction of full FK.
//!
//! ## Invariants
//!
//! Nothing here panics on a valid [`Motion`] (every `Motion` is valid, see [`super::skeleton`]);
//! target indices are checked once when an [`FkPlan`] is built and the skeleton is checked
//! against the motion's when it is run. Results are finite for finite input.

use super::skeleton::{Joint, Motion, Skeleton};

use gesture_runtime::rotation::{axis_rotation, identity, mat_mul, mat_vec};
pub use gesture_runtime::rotation::{Mat3, Vec3};

fn add(a: Vec3, b: Vec3) -> Vec3 {
    [a[0] + b[0], a[1] + b[1], a[2] + b[2]]
}

/// A joint's local transform from its channel values (`values[k]` belongs to
/// `joint.channels[k]`; missing values count as 0). Returns (rotation, translation).
pub fn local_transform(joint: &Joint, values: &[f64]) -> (Mat3, Vec3) {
    let mut rot: Option<Mat3> = None;
    let mut t = joint.offset;
    for (k, &c) in joint.channels.iter().enumerate() {
        let v = values.get(k).copied().unwrap_or(0.0);
        if c.is_rotation() {
            let r = axis_rotation(c.axis(), v);
            rot = Some(match rot {
                None => r,
                Some(prev) => mat_mul(&prev, &r),
            });
        } else {
            t[c.axis()] = v;
        }
    }
    (rot.unwrap_or_else(identity), t)
}

/// World rotation and position of one joint.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Transform {
    /// Joint frame to world.
    pub rotation: Mat3,
    /// The joint's world position.
    pub position: Vec3,
}

/// World transforms of every joint at frame `f` (`None` if `f` is out of range).
pub fn world_pose(motion: &Motion, f: usize) -> Option<Vec<Transform>> {
    Some(world_transforms(motion.skeleton(), motion.frame(f)?))
}

/// World transforms of every joint of `skeleton` for one frame's channel values `row`
/// (values past the end of `row` count as 0).
pub fn world_transforms(skeleton: &Skeleton, row: &[f64]) -> Vec<Transform> {
    let mut out: Vec<Transform> = Vec::with_capacity(skeleton.joints.len());
    let mut start = 0;
    for joint in &skeleton.joints {
        let n = joint.channels.len();
        let (r, t) = local_transform(joint, row.get(start..start + n).unwrap_or(&[]));
        start += n;
        let parent = joint.parent.and_then(|p| out.get(p)).copied();
        out.push(match parent {
            None => Transform {
                rotation: r,
                position: t,
            },
            Some(p) => Transform {
                rotation: mat_mul(&p.rotation, &r),
                position: add(p.position, mat_vec(&p.rotation, &t)),
            },
        });
    }
    out
}

/// A point whose world position FK can compute.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Target {
    /// The origin of joint `j`.
    Joint(usize),
    /// The end site of joint `j` (the joint must have one).
    EndSite(usize),
}

/// Every joint, then (if asked) every end site, in joint order.
pub fn all_targets(skeleton: &Skeleton, with_end_sites: bool) -> Vec<Target> {
    let mut t: Vec<Target> = (0..skeleton.joints.len()).map(Target::Joint).collect();
    if with_end_sites {
        t.extend(
            skeleton
                .joints
                .iter()
                .enumerate()
                .filter(|(_, j)| j.end_site.is_some())
                .map(|(i, _)| Target::EndSite(i)),
        );
    }
    t
}

/// Why FK could not be set up or run.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum FkError {
    /// A target names a joint index past the end of the skeleton.
    #[error("target joint index {joint} is out of range (the skeleton has {joints} joints)")]
    JointOutOfRange {
        /// The index asked for.
        joint: usize,
        /// Number of joints.
        joints: usize,
    },
    /// An end-site target names a joint without an `End Site`.
    #[error("joint `{joint}` has no End Site")]
    NoEndSite {
        /// The joint's name.
        joint: String,
    },
    /// The plan was built for a different skeleton than the motion's.
    #[error("this FK plan was built for another skeleton than the motion's ({motion})")]
    SkeletonMismatch {
        /// The motion's source name.
        motion: String,
    },
}

/// World positions of some points over all frames (frames x points).
#[derive(Clone, Debug, PartialEq, Default)]
pub struct Positions {
    frames: usize,
    points: usize,
    data: Vec<Vec3>,
}

impl Positions {
    /// Frames x points, row-major. `None` if `data.len()` is not a multiple of `points`
    /// (or `points == 0` with non-empty data).
    pub fn from_frames(points: usize, data: Vec<Vec3>) -> Option<Positions> {
        if points == 0 {
            return data.is_empty().then_some(Positions::default());
        }
        if !data.len().is_multiple_of(points) {
            return None;
        }
        Some(Positions {
            frames: data.len() / points,
            points,
            data,
        })
    }

    /// One track per point, all of the same length; `None` if the lengths differ.
    pub fn from_tracks(tracks: &[Vec<Vec3>]) -> Option<Positions> {
        let frames = tracks.first().map_or(0, Vec::len);
        if tracks.iter().any(|t| t.len() != frames) {
            return None;
        }
        let data = (0..frames)
            .flat_map(|f| tracks.iter().map(move |t| t[f]))
            .collect();
        Some(Positions {
            frames,
            points: tracks.len(),
            data,
        })
    }

    /// Number of frames.
    pub fn frames(&self) -> usize {
        self.frames
    }

    /// Number of points per frame.
    pub fn points(&self) -> usize {
        self.points
    }

    /// Position of point `k` at frame `f`. Panics if out of range, like slice indexing.
    pub fn get(&self, f: usize, k: usize) -> Vec3 {
        assert!(k < self.points, "point {k} out of range");
        self.data[f * self.points + k]
    }

    /// All points of frame `f`. Panics if `f >= frames()`.
    pub fn frame(&self, f: usize) -> &[Vec3] {
        &self.data[f * self.points..(f + 1) * self.points]
    }

    /// The trajectory of point `k`. Panics if `k >= points()`.
    pub fn track(&self, k: usize) -> Vec<Vec3> {
        assert!(k < self.points, "point {k} out of range");
        (0..self.frames).map(|f| self.get(f, k)).collect()
    }

    /// The raw frames x points data.
    pub fn as_slice(&self) -> &[Vec3] {
        &self.data
    }
}

#[derive(Clone, Debug)]
struct Node {
    joint: usize,
    parent_node: Option<usize>,
    channel_start: usize,
    /// Whether any child node or end-site target reads this node's world rotation.
    needs_rotation: bool,
}

/// Precomputed evaluation order for a fixed set of targets (the fast path).
#[derive(Clone, Debug)]
pub struct FkPlan {
    skeleton: Skeleton,
    nodes: Vec<Node>,
    /// (node index, end-site offset if the target is an end site).
    targets: Vec<(usize, Option<Vec3>)>,
}

impl FkPlan {
    /// Plans FK for `targets` on `skeleton`: only the targets' joints and their ancestors are
    /// evaluated.
    pub fn new(skeleton: &Skeleton, targets: &[Target]) -> Result<FkPlan, FkError> {
        let n = skeleton.joints.len();
        let mut needed = vec![false; n];
        for &t in targets {
            let (Target::Joint(j) | Target::EndSite(j)) = t;
            if j >= n {
                return Err(FkError::JointOutOfRange {
                    joint: j,
                    joints: n,
                });
            }
            if let Target::EndSite(_) = t {
                if skeleton.joints[j].end_site.is_none() {
                    return Err(FkError::NoEndSite {
                        joint: skeleton.joints[j].name.clone(),
                    });
                }
            }
            // Walk up the chain; stop at a joint already marked (its chain is marked too).
            let mut cur = Some(j);
            while let Some(c) = cur {
                if needed[c] {
                    break;
                }
                needed[c] = true;
                cur = skeleton.joints[c].parent;
            }
        }
        let starts = skeleton.channel_starts();
        let mut node_of = vec![usize::MAX; n];
        let mut nodes: Vec<Node> = Vec::new();
        // Depth-first order puts parents before children, so one pass suffices.
        for j in (0..n).filter(|&j| needed[j]) {
            let parent_node = skeleton.joints[j].parent.map(|p| node_of[p]);
            if let Some(p) = parent_node {
                nodes[p].needs_rotation = true;
            }
            node_of[j] = nodes.len();
            nodes.push(Node {
                joint: j,
                parent_node,
                channel_start: starts[j],
                needs_rotation: false,
            });
        }
        let targets = targets
            .iter()
            .map(|&t| match t {
                Target::Joint(j) => (node_of[j], None),
                Target::EndSite(j) => {
                    nodes[node_of[j]].needs_rotation = true;
                    (node_of[j], skeleton.joints[j].end_site)
                }
            })
            .collect();
        Ok(FkPlan {
            skeleton: skeleton.clone(),
            nodes,
            targets,
        })
    }

    /// Number of joints this plan evaluates per frame.
    pub fn evaluated_joints(&self) -> usize {
        self.nodes.len()
    }

    /// World positions of the targets (in the order given to [`FkPlan::new`]) for every
    /// frame of `motion`.
    pub fn positions(&self, motion: &Motion) -> Result<Positions, FkError> {
        if motion.skeleton() != &self.skeleton {
            return Err(FkError::SkeletonMismatch {
                motion: motion.source().to_string(),
            });
        }
        let mut rot = vec![identity(); self.nodes.len()];
        let mut pos = vec![[0.0; 3]; self.nodes.len()];
        let mut data = Vec::with_capacity(motion.frames() * self.targets.len());
        for row in motion.frame_rows() {
            for (i, node) in self.nodes.iter().enumerate() {
                let joint = &self.skeleton.joints[node.joint];
                let values = &row[node.channel_start..node.channel_start + joint.channels.len()];
                let (r, t) = local_transform(joint, values);
                match node.parent_node {
                    None => {
                        pos[i] = t;
                        rot[i] = r;
                    }
                    Some(p) => {
                        pos[i] = add(pos[p], mat_vec(&rot[p], &t));
                        if node.needs_rotation {
                            rot[i] = mat_mul(&rot[p], &r);
                        }
                    }
                }
            }
            for &(node, end) in &self.targets {
                data.push(match end {
                    None => pos[node],
                    Some(e) => add(pos[node], mat_vec(&rot[node], &e)),
                });
            }
        }
        Ok(Positions {
            frames: motion.frames(),
            points: self.targets.len(),
            data,
        })
    }
}

/// World positions of every joint (points in joint order) for every frame.
pub fn joint_positions(motion: &Motion) -> Positions {
    target_positions(motion, &all_targets(motion.skeleton(), false))
        .expect("all_targets only names existing joints of this skeleton")
}

/// World positions of `targets` for every frame of `motion`.
pub fn target_positions(motion: &Motion, targets: &[Target]) -> Result<Positions, FkError> {
    FkPlan::new(motion.skeleton(), targets)?.positions(motion)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn close(a: Vec3, b: Vec3, tol: f64) -> bool {
        (0..3).all(|i| (a[i] - b[i]).abs() <= tol)
    }

    #[test]
    fn axis_rotations_are_right_handed() {
        // 90 degrees about Z maps X to Y; about X maps Y to Z; about Y maps Z to X.
        assert!(close(
            mat_vec(&axis_rotation(2, 90.0), &[1.0, 0.0, 0.0]),
            [0.0, 1.0, 0.0],
            1e-15
        ));
        assert!(close(
            mat_vec(&axis_rotation(0, 90.0), &[0.0, 1.0, 0.0]),
            [0.0, 0.0, 1.0],
            1e-15
        ));
        assert!(close(
            mat_vec(&axis_rotation(1, 90.0), &[0.0, 0.0, 1.0]),
            [1.0, 0.0, 0.0],
            1e-15
        ));
    }
}
