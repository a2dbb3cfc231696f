//! What a BVH joint becomes in the URDF: a chain of fixed rotations and turns about an axis,
//! each turn following one blob channel (the parent module lays the chain out as URDF joints
//! and links).

use gesture_runtime::rotation::Mat3;

/// One element of a BVH joint's chain, from its parent link's frame (after the joint's rest
/// offset) to its own link's frame.
pub enum Elem {
    /// A fixed rotation.
    Fixed(Mat3),
    /// A turn about `axis` (a unit vector of the frame reached so far) by the angle of blob
    /// channel `channel`.
    Turn {
        /// The axis.
        axis: [f64; 3],
        /// The blob channel.
        channel: usize,
    },
}
