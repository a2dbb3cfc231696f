//! Humanoid bones by common naming: which joint of a BVH skeleton is the head, the left upper
//! arm, and so on, named as Unity's `HumanBodyBones` (the names VMC receivers expect). Shared by
//! the rig's body measures ([`crate::rig`]) and the simulator's VMC output, so a skeleton maps
//! the same way everywhere.
//!
//! Names compare after [`normalize`]: a namespace prefix up to the last `:` is dropped
//! (`mixamorig:LeftArm`), then everything but ASCII letters and digits, and case is ignored. So
//! `UpperArm_L` (Bandai Namco), `upper_arm.L` (Blender's Rigify, ReActIdle) and
//! `upperarm_l` are one alias. For each bone the aliases are tried in order and the first one
//! the skeleton has wins (the first such joint in file order). Nothing here allocates more
//! than the names it returns, and nothing panics.

use std::collections::BTreeMap;

use super::Skeleton;

/// Humanoid bones and the joint names that map to them, in order of preference.
pub const BONE_ALIASES: [(&str, &[&str]); 22] = [
    ("Hips", &["Hips", "Pelvis"]),
    ("Spine", &["Spine"]),
    ("Chest", &["Chest", "Spine2", "Spine1"]),
    ("UpperChest", &["UpperChest", "Spine3"]),
    ("Neck", &["Neck"]),
    // ReActIdle's head joint is `face` (neck -> face -> end site).
    ("Head", &["Head", "face"]),
    (
        "LeftShoulder",
        &["LeftShoulder", "Shoulder_L", "LeftCollar"],
    ),
    ("LeftUpperArm", &["LeftUpperArm", "LeftArm", "UpperArm_L"]),
    (
        "LeftLowerArm",
        &["LeftLowerArm", "LeftForeArm", "LowerArm_L", "ForeArm_L"],
    ),
    ("LeftHand", &["LeftHand", "Hand_L", "LeftWrist"]),
    (
        "RightShoulder",
        &["RightShoulder", "Shoulder_R", "RightCollar"],
    ),
    (
        "RightUpperArm",
        &["RightUpperArm", "RightArm", "UpperArm_R"],
    ),
    (
        "RightLowerArm",
        &["RightLowerArm", "RightForeArm", "LowerArm_R", "ForeArm_R"],
    ),
    ("RightHand", &["RightHand", "Hand_R", "RightWrist"]),
    (
        "LeftUpperLeg",
        &["LeftUpperLeg", "LeftUpLeg", "UpperLeg_L", "Thigh_L"],
    ),
    (
        "LeftLowerLeg",
        &["LeftLowerLeg", "LeftLeg", "LowerLeg_L", "Shin_L"],
    ),
    ("LeftFoot", &["LeftFoot", "Foot_L"]),
    ("LeftToes", &["LeftToes", "LeftToeBase", "Toes_L"]),
    (
        "RightUpperLeg",
        &["RightUpperLeg", "RightUpLeg", "UpperLeg_R", "Thigh_R"],
    ),
    (
        "RightLowerLeg",
        &["RightLowerLeg", "RightLeg", "LowerLeg_R", "Shin_R"],
    ),
    ("RightFoot", &["RightFoot", "Foot_R"]),
    ("RightToes", &["RightToes", "RightToeBase", "Toes_R"]),
];

/// A joint name as compared with the aliases: the part after the last `:`, ASCII letters and
/// digits only, lower case.
pub fn normalize(name: &str) -> String {
    let base = name.rsplit(':').next().unwrap_or(name);
    base.chars()
        .filter(char::is_ascii_alphanumeric)
        .map(|c| c.to_ascii_lowercase())
        .collect()
}

/// The joint of `skeleton` that `bone` (a name of [`BONE_ALIASES`]) maps to, if any.
pub fn find_bone(skeleton: &Skeleton, bone: &str) -> Option<usize> {
    let (_, aliases) = BONE_ALIASES.iter().find(|(b, _)| *b == bone)?;
    let names: Vec<String> = skeleton.joints.iter().map(|j| normalize(&j.name)).collect();
    aliases.iter().find_map(|a| {
        let a = normalize(a);
        names.iter().position(|n| *n == a)
    })
}

/// Every humanoid bone `skeleton` has, as bone name -> joint index.
pub fn find_bones(skeleton: &Skeleton) -> BTreeMap<&'static str, usize> {
    BONE_ALIASES
        .iter()
        .filter_map(|&(bone, _)| find_bone(skeleton, bone).map(|j| (bone, j)))
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::motion::Joint;

    fn skeleton(names: &[&str]) -> Skeleton {
        Skeleton {
            joints: names
                .iter()
                .enumerate()
                .map(|(i, n)| Joint {
                    name: n.to_string(),
                    parent: i.checked_sub(1),
                    offset: [0.0; 3],
                    channels: Vec::new(),
                    end_site: None,
                })
                .collect(),
        }
    }

    #[test]
    fn names_normalize_across_conventions() {
        assert_eq!(normalize("mixamorig:LeftArm"), "leftarm");
        assert_eq!(normalize("upper_arm.L"), normalize("UpperArm_L"));
        assert_eq!(normalize("spine.001"), "spine001");
    }

    #[test]
    fn aliases_are_tried_in_order() {
        let sk = skeleton(&["pelvis", "spine", "Spine1", "Spine2", "face", "forearm.R"]);
        let bones = find_bones(&sk);
        assert_eq!(bones["Hips"], 0);
        assert_eq!(bones["Chest"], 3);
        assert_eq!(bones["Head"], 4);
        assert_eq!(bones["RightLowerArm"], 5);
        assert!(!bones.contains_key("LeftHand"));
        assert_eq!(find_bone(&sk, "NoSuchBone"), None);
    }
}
