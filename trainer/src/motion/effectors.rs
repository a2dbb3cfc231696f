//! End effectors: which points of the skeleton the segmentation and the kinematic parameters
//! follow.
//!
//! Owns the mapping from a user's wish ([`EffectorSpec`]) to FK targets on a concrete
//! skeleton ([`Effectors`]).
//!
//! - [`EffectorSpec::Hands`] (the default) finds the two hands by name. Names are split into
//!   lower-case words at `_`, `-`, `.`, `:`, spaces, digits-to-letters and camelCase
//!   boundaries (`LeftHand` -> `left hand`, `Hand_L` -> `hand l`, `mixamorig:RightHand` ->
//!   `mixamorig right hand`, `Bip01 L Hand` -> `bip01 l hand`). A joint is a left-hand
//!   candidate when its words contain a left marker (`left`, `l`, `lft`, or a glued `lhand`,
//!   `handl`, ...) and `hand` or `wrist`, and no finger/helper word (`thumb`, `index`,
//!   `middle`, `ring`, `pinky`, `finger`, `end`, `tip`, `ik`, ...). Among candidates a
//!   `hand` joint beats a `wrist` joint, then the one closest to the root wins (the wrist is
//!   the ancestor of the fingers), then file order. The ZeroEGGS skeleton resolves to
//!   `LeftHand`/`RightHand`, the Bandai Namco skeleton to `Hand_L`/`Hand_R`.
//! - [`EffectorSpec::Joints`] lists joint names (any number: eight tentacle tips are fine).
//!   A name matches exactly, else ignoring case. `NAME/end` means the `End Site` of `NAME`
//!   (useful when the tips of a chain are end sites).
//!
//! Errors name what was missing and list the skeleton's joints, e.g.
//! "no left hand found in x.bvh: looked for LeftHand, Hand_L, L_Hand, LeftWrist, l_hand or
//! any name with a left marker and `hand`/`wrist`; joints are: Hips, Spine, ...".
//! Resolution never panics.

use super::fk::Target;
use super::skeleton::Skeleton;

/// Which points to follow.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub enum EffectorSpec {
    /// The left and right hands, found by name (left first).
    #[default]
    Hands,
    /// These joints, by name (`NAME/end` for the end site of `NAME`).
    Joints(Vec<String>),
}

/// Effectors resolved on one skeleton.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Effectors {
    /// Display names (joint names, with `/end` for end sites).
    pub names: Vec<String>,
    /// The FK targets, in the same order.
    pub targets: Vec<Target>,
}

/// Which side a hand is on.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Side {
    /// Left.
    Left,
    /// Right.
    Right,
}

impl std::fmt::Display for Side {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            Side::Left => "left",
            Side::Right => "right",
        })
    }
}

/// Why effectors could not be resolved.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum EffectorError {
    /// No joint looks like the hand on `side`.
    #[error(
        "no {side} hand found in {source_name}: looked for {looked_for} or any name with a \
         {side} marker and `hand`/`wrist`; joints are: {available}; name the effectors \
         explicitly if this rig calls them something else"
    )]
    NoHand {
        /// The side.
        side: Side,
        /// The motion's source name.
        source_name: String,
        /// The usual names tried.
        looked_for: String,
        /// Some joint names of the skeleton.
        available: String,
    },
    /// An explicitly named joint does not exist.
    #[error("joint `{name}` not found in {source_name}; joints are: {available}")]
    UnknownJoint {
        /// The name asked for.
        name: String,
        /// The motion's source name.
        source_name: String,
        /// Some joint names of the skeleton.
        available: String,
    },
    /// `NAME/end` was asked for a joint without an end site.
    #[error("joint `{name}` in {source_name} has no End Site (asked for `{name}/end`)")]
    NoEndSite {
        /// The joint name.
        name: String,
        /// The motion's source name.
        source_name: String,
    },
    /// The explicit list is empty.
    #[error("the effector list is empty: name at least one joint")]
    Empty,
}

const LEFT_NAMES: &str = "LeftHand, Hand_L, L_Hand, LeftWrist, l_hand";
const RIGHT_NAMES: &str = "RightHand, Hand_R, R_Hand, RightWrist, r_hand";
const NOT_A_HAND: &[&str] = &[
    "thumb",
    "index",
    "middle",
    "mid",
    "ring",
    "pinky",
    "pinkie",
    "little",
    "finger",
    "fingers",
    "end",
    "tip",
    "site",
    "nub",
    "ik",
    "pole",
    "target",
    "ctrl",
    "control",
    "null",
    "twist",
    "roll",
    "palm",
    "meta",
    "carpal",
    "metacarpal",
];

/// Lower-case words of a joint name (see the module docs).
fn words(name: &str) -> Vec<String> {
    let mut out: Vec<String> = Vec::new();
    let mut cur = String::new();
    let chars: Vec<char> = name.chars().collect();
    for (i, &c) in chars.iter().enumerate() {
        if !c.is_alphanumeric() {
            if !cur.is_empty() {
                out.push(std::mem::take(&mut cur));
            }
            continue;
        }
        if let Some(&prev) = i.checked_sub(1).and_then(|p| chars.get(p)) {
            let next = chars.get(i + 1).copied();
            let boundary = (prev.is_lowercase() && c.is_uppercase())
                // `LHand`: split before the last capital of a run when a lower-case follows.
                || (prev.is_uppercase() && c.is_uppercase() && next.is_some_and(char::is_lowercase))
                || (prev.is_ascii_digit() && c.is_alphabetic());
            if boundary && !cur.is_empty() {
                out.push(std::mem::take(&mut cur));
            }
        }
        cur.extend(c.to_lowercase());
    }
    if !cur.is_empty() {
        out.push(cur);
    }
    out
}

/// (is a hand/wrist candidate for `side`, is a "hand" rather than a "wrist").
fn classify(name: &str, side: Side) -> Option<bool> {
    let (markers, other): (&[&str], &[&str]) = match side {
        Side::Left => (&["left", "l", "lft", "lf"], &["right", "r", "rt", "rgt"]),
        Side::Right => (&["right", "r", "rt", "rgt"], &["left", "l", "lft", "lf"]),
    };
    let ws = words(name);
    let mut has_side = false;
    let mut has_other_side = false;
    let mut part: Option<bool> = None; // Some(true) = hand, Some(false) = wrist
    for w in &ws {
        let w = w.as_str();
        if NOT_A_HAND.contains(&w) || NOT_A_HAND.iter().any(|f| w.starts_with(f) && f.len() > 3) {
            return None;
        }
        if markers.contains(&w) {
            has_side = true;
            continue;
        }
        if other.contains(&w) {
            has_other_side = true;
            continue;
        }
        for (p, is_hand) in [("hand", true), ("wrist", false)] {
            let glued_side = markers
                .iter()
                .any(|m| w == format!("{m}{p}") || w == format!("{p}{m}"));
            if w == p || glued_side {
                has_side |= glued_side;
                part = Some(part.unwrap_or(false) || is_hand);
            }
        }
    }
    if has_side && !has_other_side {
        part
    } else {
        None
    }
}

/// Index of the joint that is most plausibly the hand on `side`.
pub fn find_hand(skeleton: &Skeleton, side: Side) -> Option<usize> {
    skeleton
        .joints
        .iter()
        .enumerate()
        .filter_map(|(i, j)| classify(&j.name, side).map(|is_hand| (i, is_hand)))
        .min_by_key(|&(i, is_hand)| (!is_hand, skeleton.depth(i), i))
        .map(|(i, _)| i)
}

/// Up to 40 joint names, comma separated, for messages.
fn available(skeleton: &Skeleton) -> String {
    const MAX: usize = 40;
    let mut s = skeleton
        .joint_names()
        .take(MAX)
        .collect::<Vec<_>>()
        .join(", ");
    if skeleton.joints.len() > MAX {
        s.push_str(&format!(", ... ({} joints)", skeleton.joints.len()));
    }
    if s.is_empty() {
        s.push_str("(none)");
    }
    s
}

impl EffectorSpec {
    /// The explicit list `names`.
    pub fn joints<S: Into<String>>(names: impl IntoIterator<Item = S>) -> EffectorSpec {
        EffectorSpec::Joints(names.into_iter().map(Into::into).collect())
    }

    /// Resolves this spec on `skeleton`. `source_name` is used in messages (the file name).
    pub fn resolve(
        &self,
        skeleton: &Skeleton,
        source_name: &str,
    ) -> Result<Effectors, EffectorError> {
        let mut names = Vec::new();
        let mut targets = Vec::new();
        match self {
            EffectorSpec::Hands => {
                for (side, looked_for) in [(Side::Left, LEFT_NAMES), (Side::Right, RIGHT_NAMES)] {
                    let j = find_hand(skeleton, side).ok_or_else(|| EffectorError::NoHand {
                        side,
                        source_name: source_name.to_string(),
                        looked_for: looked_for.to_string(),
                        available: available(skeleton),
                    })?;
                    names.push(skeleton.joints[j].name.clone());
                    targets.push(Target::Joint(j));
                }
            }
            EffectorSpec::Joints(list) => {
                if list.is_empty() {
                    return Err(EffectorError::Empty);
                }
                for name in list {
                    let lookup =
                        |n: &str| skeleton.find(n).or_else(|| skeleton.find_ignore_case(n));
                    let (joint_name, end) = match lookup(name) {
                        Some(_) => (name.as_str(), false),
                        None => match name.strip_suffix("/end") {
                            Some(base) => (base, true),
                            None => (name.as_str(), false),
                        },
                    };
                    let j = lookup(joint_name).ok_or_else(|| EffectorError::UnknownJoint {
                        name: joint_name.to_string(),
                        source_name: source_name.to_string(),
                        available: available(skeleton),
                    })?;
                    if end {
                        if skeleton.joints[j].end_site.is_none() {
                            return Err(EffectorError::NoEndSite {
                                name: skeleton.joints[j].name.clone(),
                                source_name: source_name.to_string(),
                            });
                        }
                        names.push(format!("{}/end", skeleton.joints[j].name));
                        targets.push(Target::EndSite(j));
                    } else {
                        names.push(skeleton.joints[j].name.clone());
                        targets.push(Target::Joint(j));
                    }
                }
            }
        }
        Ok(Effectors { names, targets })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::motion::skeleton::Joint;

    fn skeleton(names: &[(&str, Option<usize>)]) -> Skeleton {
        Skeleton {
            joints: names
                .iter()
                .map(|&(n, parent)| Joint {
                    name: n.to_string(),
                    parent,
                    offset: [0.0; 3],
                    channels: vec![],
                    end_site: None,
                })
                .collect(),
        }
    }

    #[test]
    fn splits_words() {
        assert_eq!(words("LeftHand"), ["left", "hand"]);
        assert_eq!(words("Hand_L"), ["hand", "l"]);
        assert_eq!(words("LHand"), ["l", "hand"]);
        assert_eq!(
            words("mixamorig:RightHandIndex1"),
            ["mixamorig", "right", "hand", "index1"]
        );
        assert_eq!(words("Bip01 L Hand"), ["bip01", "l", "hand"]);
        assert_eq!(words("hand.R"), ["hand", "r"]);
    }

    #[test]
    fn finds_hands_under_common_names() {
        for (l, r) in [
            ("LeftHand", "RightHand"),
            ("Hand_L", "Hand_R"),
            ("L_Hand", "R_Hand"),
            ("LeftWrist", "RightWrist"),
            ("l_hand", "r_hand"),
            ("Bip01 L Hand", "Bip01 R Hand"),
            ("mixamorig:LeftHand", "mixamorig:RightHand"),
            ("hand.L", "hand.R"),
            ("lhand", "rhand"),
        ] {
            let s = skeleton(&[
                ("Hips", None),
                (l, Some(0)),
                (&format!("{l}Thumb1"), Some(1)),
                (r, Some(0)),
                (&format!("{r}Index1"), Some(3)),
            ]);
            let e = EffectorSpec::Hands.resolve(&s, "t.bvh").unwrap();
            assert_eq!(e.names, vec![l.to_string(), r.to_string()], "{l}/{r}");
        }
    }

    #[test]
    fn prefers_hand_over_wrist_and_shallow_over_fingers() {
        let s = skeleton(&[
            ("Hips", None),
            ("LeftWrist", Some(0)),
            ("LeftHand", Some(1)),
            ("LeftHandEnd", Some(2)),
            ("RightWrist", Some(0)),
            ("RightHandThumb", Some(4)),
        ]);
        let e = EffectorSpec::Hands.resolve(&s, "t.bvh").unwrap();
        assert_eq!(e.names, ["LeftHand", "RightWrist"]);
    }

    #[test]
    fn missing_hand_lists_joints() {
        let s = skeleton(&[("Hips", None), ("Spine", Some(0)), ("RightHand", Some(1))]);
        let e = EffectorSpec::Hands.resolve(&s, "x.bvh").unwrap_err();
        let msg = e.to_string();
        assert!(msg.starts_with("no left hand found in x.bvh: looked for LeftHand, Hand_L"));
        assert!(msg.contains("joints are: Hips, Spine, RightHand"), "{msg}");
    }

    #[test]
    fn explicit_names_and_end_sites() {
        let mut s = skeleton(&[("Body", None), ("Tip1", Some(0)), ("tip2", Some(0))]);
        s.joints[2].end_site = Some([1.0, 0.0, 0.0]);
        let spec = EffectorSpec::joints(["Tip1", "TIP2/end"]);
        let e = spec.resolve(&s, "octo.bvh").unwrap();
        assert_eq!(e.targets, vec![Target::Joint(1), Target::EndSite(2)]);
        assert_eq!(e.names, ["Tip1", "tip2/end"]);
        let err = EffectorSpec::joints(["Tip3"])
            .resolve(&s, "octo.bvh")
            .unwrap_err();
        assert_eq!(
            err.to_string(),
            "joint `Tip3` not found in octo.bvh; joints are: Body, Tip1, tip2"
        );
        let err = EffectorSpec::joints(["Tip1/end"]).resolve(&s, "octo.bvh");
        assert!(matches!(err, Err(EffectorError::NoEndSite { .. })));
        assert_eq!(
            EffectorSpec::Joints(vec![]).resolve(&s, "octo.bvh"),
            Err(EffectorError::Empty)
        );
    }
}
