//! Rig files: which output channel follows which joint rotation, with servo calibration
//! (docs/method.md, "The runtime").
//!
//! - `spec`: the rig's types ([`Rig`], [`RigChannel`], [`Axis`], [`AngleMode`]), its
//!   errors, and the full-skeleton default rig for BVH output ([`Rig::full_skeleton`]);
//! - `file`: the TOML rig format ([`Rig::parse`], [`Rig::load`]);
//! - `body`: the body measures ([`BodyMeasure`], [`Body`]): channels defined on the humanoid
//!   body, computed from world-space bone directions, with their inverse;
//! - `bind`: binding to a BVH skeleton by body measures or joint-name aliases ([`Rig::bind`] ->
//!   [`BoundRig`]), the extraction of one angle per channel from a motion frame
//!   ([`BoundRig::channel_values`]) and what each channel drives in the blob's skeleton
//!   section ([`BoundRig::drives`]);
//! - `pose`: the inverse, rig poses back on the library's skeleton from a blob's skeleton
//!   section ([`PoseSkeleton`]): what the simulator writes as BVH and what the motion
//!   evaluation measures.
//!
//! The rotation math (Euler decompositions, twist, quaternions) is the runtime's
//! ([`gesture_runtime::rotation`]), shared with the simulator that puts poses back on the
//! skeleton.
//!
//! ## Format
//!
//! ```toml
//! name = "puppet-8ch"
//! period_us = 20000                 # PWM period (us)
//!
//! [[channel]]
//! name = "left_shoulder_raise"
//! body = "left_arm_raise"           # a body measure (below): fits any humanoid skeleton
//! neutral_deg = -70.0               # calibration: see gesture_runtime::rig::ChannelCal
//! min_deg = -90.0
//! max_deg = 90.0
//! direction = 1
//! pulse_neutral_us = 800
//! us_per_deg = 10.0
//! max_slew_deg_per_s = 250.0
//!
//! [[channel]]
//! name = "head_pan"
//! # Or a joint rotation. Aliases, tried in order; the first joint found in the skeleton (ignoring case) wins.
//! # A table form overrides the axis for skeletons whose joint frames differ, and may apply
//! # only when the skeleton also has some joint (to tell apart skeletons with the same name).
//! joint = [{ name = "Head", axis = "X", when_skeleton_has = "joint_Root" }, "Head", "head"]
//! axis = "Y"                        # X, Y or Z of the reference frame; "-Y" flips the sign
//! mode = "twist"                    # optional: "twist" (default), "euler" or "channel"
//! # order = "ZYX"                   # with mode = "euler": the decomposition order
//! relative_to = ["Spine3", "Chest"] # optional: measure against this ancestor, not the parent
//! # body = "head_pan"               # optional: read this body measure where no alias applies
//! neutral_deg = 0.0
//! min_deg = -60.0
//! max_deg = 60.0
//! direction = 1
//! pulse_neutral_us = 1500
//! us_per_deg = 10.0
//! max_slew_deg_per_s = 300.0
//! ```
//!
//! A channel has a `body`, a `joint` list, or both. With `joint`, `axis` is required and
//! `mode`, `order`, `relative_to` may follow; without it they are errors (a body measure needs
//! no axis). Rig files written before `body` existed parse and bind as they did.
//! Unknown keys are errors (a typo in `max_slew_deg_per_s` must not silently mean "default").
//! Every error names the file and, where it has one, the line.
//!
//! ## Body channels (the `body` key)
//!
//! A body measure is an angle of the **humanoid body**, computed from world-space bone
//! directions, so one rig file fits every humanoid skeleton whatever its joints' frames
//! (ZeroEGGS' world-aligned frames, Bandai Namco's bone-along-X frames) and names:
//!
//! - **Parts** are found by common humanoid naming ([`crate::motion::humanoid`], the table the
//!   simulator's VMC output uses): head, upper arm, forearm, hand. A bone ends at the next
//!   part's joint, or at its own `End Site` when the skeleton has no next part (ReActIdle's
//!   wrists are the forearms' end sites). The **chest** is the nearest common ancestor of the
//!   head and the upper arms.
//! - **The body frame** (left, up, forward) comes from the skeleton's geometry in the rest
//!   frame (the library's first frame, which the blob stores): left from the right upper arm
//!   to the left one (else the upper legs), up from the hips to the middle of the shoulders
//!   made perpendicular to left, forward = left x up. It is stored in the chest's frame and
//!   turns with the chest, so leaning the whole torso moves no channel.
//! - `left_arm_raise`, `left_arm_swing` (and `right_...`): with the upper arm's unit direction
//!   `(l, u, f)` in the body frame and `out = l` on the left, `-l` on the right, raise =
//!   `atan2(u, out)` (0 straight out to the side, -90 hanging, 90 straight up) and swing =
//!   `asin(f)` (positive forward). The arm's twist about itself does not count.
//! - `left_elbow_flex`, `right_elbow_flex`: the angle between the upper arm and the forearm
//!   (0 straight, 90 a right angle), in `[0, 180]`.
//! - `head_pan`, `head_tilt`, `head_roll`: the head's rotation relative to the chest, in body
//!   axes, as Euler angles `R = R_up(pan) R_left(tilt) R_forward(roll)`: pan positive to the
//!   character's left, tilt positive nodding down, roll positive toward the right shoulder.
//!   The head is neutral (0, 0, 0) when every joint from the chest down to it has no rotation,
//!   the convention of the BVH rest pose; the whole neck counts.
//!
//! A channel whose part the skeleton lacks (the 9-joint ZeroEGGS take has no head) holds its
//! neutral on every frame, and [`BoundRig::describe`] (what `pack` prints) says so. Where a
//! channel also has `joint` aliases, the first alias that applies wins and the body measure is
//! the fallback: a per-skeleton override.
//!
//! ## The angle of a channel (the convention)
//!
//! A channel's value comes from the joint's rotation relative to a reference frame: its
//! parent's by default (the joint's **local** rotation, built from its rotation channels in its
//! own order, as [`crate::motion::fk`] does), or, with `relative_to`, the first listed joint
//! that is an ancestor of it (the product of the local rotations along the chain, so a head
//! channel can follow the whole neck). The angle is measured about one axis of that frame:
//!
//! - `mode = "twist"` (default): the **twist** angle of a swing-twist decomposition about the
//!   axis. With the rotation as a unit quaternion `(w, v)`, `w >= 0`, it is
//!   `2 atan2(v . axis, w)`, in `[-180, 180]` degrees. It does not depend on the joint's
//!   channel order, has no gimbal lock, and is exact for a pure rotation about the axis (30 deg
//!   about Y gives 30 for Y and 0 for X and Z) and, more usefully, for any composition of two
//!   rotations about perpendicular axes in either order (`Ry(s) Rz(e)` gives `s` for Y and `e`
//!   for Z): a two-servo gimbal reads back its own two angles. With all three axes moving it is
//!   a projection: the part of the rotation about that axis. Right for hinges (elbows) and
//!   small rotations (head), even past 90 degrees.
//! - `mode = "euler"` with `order = "ZYX"` (any permutation of XYZ): the angle for the axis in
//!   the decomposition `R = R_Z(a) R_Y(b) R_X(c)` (rotations acting on column vectors, the
//!   BVH channel convention), the first and last angles in `[-180, 180]`, the middle one in
//!   `[-90, 90]`; at gimbal lock the last angle is 0. Right for a two-servo shoulder: with the
//!   bone axis last (X for arms along X at rest) the first two angles fix the bone's direction
//!   whatever the twist about the bone, which a real upper arm has plenty of and a two-servo
//!   shoulder cannot show. (Twist would mix that rotation into the raise angle: on ZeroEGGS it
//!   made the right shoulder raise swing across +-180 degrees.) Choose the order so the lock
//!   (middle angle +-90) is a rare pose: with `ZYX` it is an arm pointing straight forward or
//!   back, not hanging down as with `YZX`. Exact for a pure rotation about the first or last
//!   axis, and about the middle axis up to 90 degrees.
//! - `mode = "channel"`: the joint's own BVH rotation channel about that axis, wrapped to
//!   `[-180, 180]` (0 if the joint has no such channel). This is the raw Euler angle, used by
//!   the full-skeleton rig so BVH output can reproduce the joints exactly.
//!
//! A leading `-` on the axis negates the value, so one calibration can serve skeletons whose
//! frames point the other way.
//!
//! ## Invariants
//!
//! A [`Rig`] from [`Rig::parse`] or [`Rig::full_skeleton`] has 1..=[`MAX_CHANNELS`](gesture_runtime::rig::MAX_CHANNELS) channels
//! with distinct names, at least one joint alias or a body measure each, calibrations that pass
//! [`ChannelCal::validate`](gesture_runtime::rig::ChannelCal::validate) and a period that passes
//! [`gesture_runtime::rig::validate_period`], so a runtime `ServoRig` built from it cannot
//! refuse it. A [`BoundRig`] holds joint indices valid for the skeleton it was bound to;
//! [`BoundRig::channel_values`] gives `None` rather than panicking for another skeleton or a
//! frame out of range, and finite values for a valid [`Motion`](crate::motion::Motion).

mod bind;
mod body;
mod file;
mod pose;
mod spec;

pub use bind::{BoundChannel, BoundRig};
pub use body::{
    axis_angle, shortest_rotation, Arm, Body, BodyMeasure, BodyPart, Effector, HEAD_ORDER,
};
pub use pose::PoseSkeleton;
pub use spec::{parse_order, AngleMode, Axis, JointAlias, Rig, RigChannel, RigError, WIDE_CAL};

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn order_parsing() {
        assert_eq!(parse_order("ZYX"), Some([2, 1, 0]));
        assert_eq!(parse_order("yzx"), Some([1, 2, 0]));
        assert_eq!(parse_order("ZZX"), None);
        assert_eq!(parse_order("ZY"), None);
        assert_eq!(parse_order("ZYXW"), None);
    }

    #[test]
    fn axis_parsing() {
        assert_eq!(
            Axis::parse("y"),
            Some(Axis {
                index: 1,
                negated: false
            })
        );
        assert_eq!(
            Axis::parse(" +Z "),
            Some(Axis {
                index: 2,
                negated: false
            })
        );
        assert_eq!(
            Axis::parse("-X"),
            Some(Axis {
                index: 0,
                negated: true
            })
        );
        assert_eq!(Axis::parse("W"), None);
        assert_eq!(Axis::parse("--X"), None);
    }
}
