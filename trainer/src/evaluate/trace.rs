//! A motion as shown, ready to measure ([`Trace`]): per frame, the world positions of the
//! hands, their anchor and the feet, and the joint rotation channels; and its segment entries
//! ([`Entry`], [`entries_from_frames`]). Built from any BVH motion by forward kinematics.

use serde::Serialize;

use crate::motion::fk::{FkError, FkPlan, Target, Vec3};
use crate::motion::{EffectorSpec, Motion, Skeleton};

/// A segment entry: at frame `frame`, segment `segment` started; `cut` unless it went on from
/// its recorded predecessor.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
pub struct Entry {
    /// First frame of the segment in the trace.
    pub frame: usize,
    /// Library segment.
    pub segment: usize,
    /// Whether the entry was a cut (including a segment re-entered from its own end).
    pub cut: bool,
}

/// A motion as shown, ready to measure (see the module docs).
#[derive(Clone, Debug, Default)]
pub struct Trace {
    /// Frames per second.
    pub fps: f64,
    /// Per frame, the hands' world positions.
    pub hands: Vec<Vec<Vec3>>,
    /// Per frame, the world position of the hands' nearest common ancestor joint
    /// ([`anchor_joint`]); empty when unknown.
    pub anchor: Vec<Vec3>,
    /// Per frame, the foot and toe joints' world positions (empty rows: no feet).
    pub feet: Vec<Vec<Vec3>>,
    /// Per frame, every joint rotation channel (degrees).
    pub rotations: Vec<Vec<f64>>,
    /// Segment entries in frame order (the first one at frame 0).
    pub entries: Vec<Entry>,
}

/// The foot and toe joints of a skeleton: every joint whose name contains "foot", "toe" or
/// "ankle" (ignoring case).
pub fn feet(skeleton: &Skeleton) -> Vec<usize> {
    skeleton
        .joints
        .iter()
        .enumerate()
        .filter(|(_, j)| {
            let n = j.name.to_ascii_lowercase();
            n.contains("foot") || n.contains("toe") || n.contains("ankle")
        })
        .map(|(i, _)| i)
        .collect()
}

/// The segment entries of a playback given, per frame, the library segment and frame shown:
/// a new entry where the segment changes or a segment starts over at frame 0. An entry is a
/// cut unless it moves on from the last frame of a segment into its recorded successor
/// (`continues(s)`: segment `s + 1` continues `s`; `len(s)`: frames of `s`).
pub fn entries_from_frames(
    shown: &[(usize, usize)],
    continues: impl Fn(usize) -> bool,
    len: impl Fn(usize) -> usize,
) -> Vec<Entry> {
    let mut out = Vec::new();
    for (t, &(seg, frame)) in shown.iter().enumerate() {
        let Some(&(ps, pf)) = t.checked_sub(1).and_then(|p| shown.get(p)) else {
            out.push(Entry {
                frame: 0,
                segment: seg,
                cut: false,
            });
            continue;
        };
        // A segment entered again shows its first frame after a later one; one frame back to
        // the first is a rest played to and fro (`Player::turn`), not an entry.
        if seg != ps || (frame == 0 && pf >= 2) {
            let on = seg == ps + 1 && continues(ps) && pf + 1 >= len(ps) && frame == 0;
            out.push(Entry {
                frame: t,
                segment: seg,
                cut: !on,
            });
        }
    }
    out
}

/// The nearest common ancestor joint of `targets`: the deepest joint that is a proper
/// ancestor of every target joint (an end site's own joint counts as its ancestor). `None`
/// for fewer than two targets or targets in different trees.
pub fn anchor_joint(skeleton: &Skeleton, targets: &[Target]) -> Option<usize> {
    if targets.len() < 2 {
        return None;
    }
    let chain = |t: &Target| -> Vec<usize> {
        let mut out = Vec::new();
        let mut cur = match *t {
            Target::Joint(j) => skeleton.joints.get(j).and_then(|x| x.parent),
            Target::EndSite(j) => Some(j),
        };
        while let Some(j) = cur {
            // Bounded even if a hand-built skeleton had a cycle.
            if j >= skeleton.joints.len() || out.len() > skeleton.joints.len() {
                break;
            }
            out.push(j);
            cur = skeleton.joints[j].parent;
        }
        out
    };
    let chains: Vec<Vec<usize>> = targets.iter().map(chain).collect();
    chains[0]
        .iter()
        .copied()
        .find(|j| chains[1..].iter().all(|c| c.contains(j)))
}

impl Trace {
    /// The trace of `motion` (hands found by `hands`, their anchor by
    /// [`anchor_joint`], feet by [`feet`]) with `entries`.
    pub fn from_motion(
        motion: &Motion,
        hands: &EffectorSpec,
        entries: Vec<Entry>,
    ) -> Result<Self, String> {
        let sk = motion.skeleton();
        let eff = hands
            .resolve(sk, motion.source())
            .map_err(|e| e.to_string())?;
        let fk = |targets: &[Target]| -> Result<Vec<Vec<Vec3>>, FkError> {
            if targets.is_empty() {
                return Ok(vec![Vec::new(); motion.frames()]);
            }
            let p = FkPlan::new(sk, targets)?.positions(motion)?;
            Ok((0..p.frames()).map(|f| p.frame(f).to_vec()).collect())
        };
        let foot_targets: Vec<Target> = feet(sk).into_iter().map(Target::Joint).collect();
        // The anchor rides along with the hands' FK as one more target.
        let anchor = anchor_joint(sk, &eff.targets);
        let mut hand_targets = eff.targets.clone();
        hand_targets.extend(anchor.map(Target::Joint));
        let mut hands = fk(&hand_targets).map_err(|e| e.to_string())?;
        let anchor: Vec<Vec3> = match anchor {
            Some(_) => hands.iter_mut().filter_map(|row| row.pop()).collect(),
            None => Vec::new(),
        };
        let rot: Vec<usize> = {
            let mut v = Vec::new();
            let mut k = 0;
            for j in &sk.joints {
                for c in &j.channels {
                    if c.is_rotation() {
                        v.push(k);
                    }
                    k += 1;
                }
            }
            v
        };
        Ok(Self {
            fps: motion.fps(),
            hands,
            anchor,
            feet: fk(&foot_targets).map_err(|e| e.to_string())?,
            rotations: (0..motion.frames())
                .map(|f| {
                    let row = motion.frame(f).unwrap_or(&[]);
                    rot.iter()
                        .map(|&k| row.get(k).copied().unwrap_or(0.0))
                        .collect()
                })
                .collect(),
            entries,
        })
    }

    /// Frames in the trace.
    pub fn frames(&self) -> usize {
        self.hands.len()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn entries_come_from_segment_changes_and_restarts() {
        // Segment 0 (3 frames) runs on into its successor 1; 1 is cut into 5; 5 restarts from
        // its last frame, then plays back to its first and turns (a rest played to and fro:
        // no entry).
        let shown = [
            (0, 0),
            (0, 1),
            (0, 2),
            (1, 0),
            (1, 1),
            (5, 0),
            (5, 1),
            (5, 2),
            (5, 0),
            (5, 1),
            (5, 2),
            (5, 1),
            (5, 0),
            (5, 1),
        ];
        let e = entries_from_frames(&shown, |s| s == 0, |_| 3);
        let got: Vec<(usize, usize, bool)> =
            e.iter().map(|e| (e.frame, e.segment, e.cut)).collect();
        assert_eq!(
            got,
            [(0, 0, false), (3, 1, false), (5, 5, true), (8, 5, true)]
        );
        // Entering the successor from the middle of a segment is a cut.
        let shown = [(0, 0), (1, 0)];
        assert!(entries_from_frames(&shown, |_| true, |_| 3)[1].cut);
    }

    #[test]
    fn the_anchor_is_the_nearest_common_ancestor() {
        use crate::motion::Joint;
        let names = [
            ("Hips", None),
            ("Spine", Some(0)),
            ("Chest", Some(1)),
            ("LeftArm", Some(2)),
            ("LeftHand", Some(3)),
            ("RightArm", Some(2)),
            ("RightHand", Some(5)),
            ("Neck", Some(2)),
            ("Head", Some(7)),
            ("Prop", None),
        ];
        let sk = Skeleton {
            joints: names
                .iter()
                .map(|&(n, parent)| Joint {
                    name: n.into(),
                    parent,
                    offset: [0.0; 3],
                    channels: vec![],
                    end_site: None,
                })
                .collect(),
        };
        let j = Target::Joint;
        assert_eq!(anchor_joint(&sk, &[j(4), j(6)]), Some(2));
        assert_eq!(anchor_joint(&sk, &[j(4), j(6), j(8)]), Some(2));
        assert_eq!(anchor_joint(&sk, &[j(4), j(3)]), Some(2));
        assert_eq!(anchor_joint(&sk, &[Target::EndSite(4), j(4)]), Some(3));
        assert_eq!(anchor_joint(&sk, &[Target::EndSite(4), j(6)]), Some(2));
        assert_eq!(anchor_joint(&sk, &[j(4)]), None);
        assert_eq!(anchor_joint(&sk, &[j(4), j(9)]), None);
    }
}
