//! Planted feet: a library with legs plays its lower body in one standing pose.
//!
//! A blob's frames drop the root's translation (the character stays where it is), so legs
//! played as captured slide their feet over the floor, and cuts between segments move them
//! from one stance to another. Gesture controllers animate the upper body; so here the lower
//! body is held and the upper body keeps exactly what it did:
//!
//! - the **pelvis** is the deepest joint above both the hands and the feet (`Hips`);
//! - the **legs** (the pelvis's child subtrees without a hand) and the joints above the
//!   pelvis take the values of one reference frame: the frame whose leg and pelvis channels
//!   are closest to their per-channel median over the library (a typical stance);
//! - the pelvis's rotation takes the reference's, and what it did is moved into the pelvis's
//!   other children (the spine): `local' = R_ref^-1 R(t) local(t)` with `R` the pelvis's
//!   world rotation, so every joint from the spine up has the same world rotation as in the
//!   capture.
//!
//! The feet then do not move at all. Skeletons without foot joints (an upper-body capture)
//! are left as they are. Pure function of the motion; no panics (a frame that cannot be
//! rebuilt is kept).

use gesture_runtime::rotation::{euler_angles, mat_mul, transpose, Mat3};

use crate::evaluate::trace::feet;
use crate::motion::fk::local_transform;
use crate::motion::{Motion, Skeleton};

/// How the lower body was held, for the pack report.
#[derive(Clone, Debug, PartialEq)]
pub struct Planted {
    /// The pelvis's name.
    pub pelvis: String,
    /// Joints held (legs, the pelvis and the joints above it).
    pub held_joints: usize,
    /// The joints that took over the pelvis's rotation.
    pub upper: Vec<String>,
}

/// Ancestors of `j`, nearest first.
fn ancestors(sk: &Skeleton, j: usize) -> Vec<usize> {
    let mut out = Vec::new();
    let mut cur = sk.joints.get(j).and_then(|x| x.parent);
    while let Some(p) = cur {
        if out.len() > sk.joints.len() {
            break;
        }
        out.push(p);
        cur = sk.joints[p].parent;
    }
    out
}

fn is_below(sk: &Skeleton, j: usize, top: usize) -> bool {
    j == top || ancestors(sk, j).contains(&top)
}

/// The pelvis, the held joints and the upper-body children of the pelvis for `sk` with hand
/// joints `hands`; `None` without feet or hands below a common joint.
pub fn lower_body(sk: &Skeleton, hands: &[usize]) -> Option<(usize, Vec<usize>, Vec<usize>)> {
    let feet = feet(sk);
    if feet.is_empty() || hands.is_empty() {
        return None;
    }
    // The deepest joint above every hand and foot.
    let mut chain: Vec<usize> = std::iter::once(hands[0])
        .chain(ancestors(sk, hands[0]))
        .collect();
    chain.retain(|&a| hands.iter().chain(&feet).all(|&x| is_below(sk, x, a)));
    let pelvis = *chain.first()?;
    let children: Vec<usize> = (0..sk.joints.len())
        .filter(|&j| sk.joints[j].parent == Some(pelvis))
        .collect();
    let (upper, legs): (Vec<usize>, Vec<usize>) = children
        .into_iter()
        .partition(|&c| hands.iter().any(|&h| is_below(sk, h, c)));
    if legs.is_empty() || upper.is_empty() {
        return None;
    }
    let mut held: Vec<usize> = (0..sk.joints.len())
        .filter(|&j| legs.iter().any(|&l| is_below(sk, j, l)))
        .collect();
    held.push(pelvis);
    held.extend(ancestors(sk, pelvis));
    held.sort_unstable();
    Some((pelvis, held, upper))
}

/// The rotation channels of joint `j` as (index in the frame, axis) in channel order.
fn rotation_channels(sk: &Skeleton, starts: &[usize], j: usize) -> Vec<(usize, usize)> {
    sk.joints[j]
        .channels
        .iter()
        .enumerate()
        .filter(|(_, c)| c.is_rotation())
        .map(|(k, c)| (starts[j] + k, c.axis()))
        .collect()
}

/// Writes rotation `m` into joint `j`'s rotation channels of `row`, decomposed in the joint's
/// channel order (joints with fewer than three rotation channels are left alone).
fn set_rotation(sk: &Skeleton, starts: &[usize], row: &mut [f64], j: usize, m: &Mat3) {
    let rot = rotation_channels(sk, starts, j);
    if rot.len() != 3 {
        return;
    }
    let order = [rot[0].1, rot[1].1, rot[2].1];
    let a = euler_angles(m, order);
    if a.iter().all(|v| v.is_finite()) {
        for (k, &(i, _)) in rot.iter().enumerate() {
            row[i] = a[k];
        }
    }
}

/// World rotation of `j` in `row` (the product of the local rotations from the root).
fn world_rotation(sk: &Skeleton, starts: &[usize], row: &[f64], j: usize) -> Mat3 {
    let mut chain = ancestors(sk, j);
    chain.reverse();
    chain.push(j);
    chain
        .iter()
        .fold(gesture_runtime::rotation::identity(), |acc, &k| {
            let joint = &sk.joints[k];
            let values = &row[starts[k]..starts[k] + joint.channels.len()];
            mat_mul(&acc, &local_transform(joint, values).0)
        })
}

/// The takes with their lower bodies held (see the module docs); `None` (and the takes
/// untouched) when the skeleton has no feet. All takes must share the first one's skeleton.
pub fn plant_feet(takes: &mut [Motion], hands: &[usize]) -> Option<Planted> {
    let sk = takes.first()?.skeleton().clone();
    let (pelvis, held, upper) = lower_body(&sk, hands)?;
    let starts = sk.channel_starts();
    let held_channels: Vec<usize> = held
        .iter()
        .flat_map(|&j| starts[j]..starts[j] + sk.joints[j].channels.len())
        .collect();
    // The reference: the frame closest to the per-channel median of the held channels.
    let rows: Vec<&[f64]> = takes
        .iter()
        .flat_map(|m| (0..m.frames()).filter_map(move |f| m.frame(f)))
        .collect();
    let median: Vec<f64> = held_channels
        .iter()
        .map(|&i| {
            let mut v: Vec<f64> = rows.iter().map(|r| r[i]).collect();
            v.sort_by(f64::total_cmp);
            v[v.len() / 2]
        })
        .collect();
    let reference: Vec<f64> = rows
        .iter()
        .min_by(|a, b| {
            let d = |r: &&[f64]| {
                held_channels
                    .iter()
                    .zip(&median)
                    .map(|(&i, m)| (r[i] - m).powi(2))
                    .sum::<f64>()
            };
            d(a).total_cmp(&d(b))
        })?
        .to_vec();
    let r_ref = world_rotation(&sk, &starts, &reference, pelvis);
    let r_ref_inv = transpose(&r_ref);
    for m in takes.iter_mut() {
        let (skeleton, frame_time, frames, mut data) = m.clone().into_parts();
        let n = skeleton.channel_count();
        for f in 0..frames {
            let row = &mut data[f * n..(f + 1) * n];
            let r_now = world_rotation(&skeleton, &starts, row, pelvis);
            let carry = mat_mul(&r_ref_inv, &r_now);
            for &u in &upper {
                let joint = &skeleton.joints[u];
                let local =
                    local_transform(joint, &row[starts[u]..starts[u] + joint.channels.len()]).0;
                set_rotation(&skeleton, &starts, row, u, &mat_mul(&carry, &local));
            }
            for &i in &held_channels {
                row[i] = reference[i];
            }
        }
        let source = m.source().to_string();
        if let Ok(planted) = Motion::new(skeleton, frame_time, frames, data) {
            *m = planted.with_source(source);
        }
    }
    Some(Planted {
        pelvis: sk.joints[pelvis].name.clone(),
        held_joints: held.len(),
        upper: upper.iter().map(|&u| sk.joints[u].name.clone()).collect(),
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::motion::fk::{FkPlan, Target};
    use crate::motion::parse_bvh;

    /// Hips (6 channels) with a spine and a hand above, two legs with feet below.
    const BVH: &str = "HIERARCHY
ROOT Hips
{
  OFFSET 0 100 0
  CHANNELS 6 Xposition Yposition Zposition Zrotation Yrotation Xrotation
  JOINT Spine
  {
    OFFSET 0 10 0
    CHANNELS 3 Zrotation Yrotation Xrotation
    JOINT LeftHand
    {
      OFFSET 20 30 0
      CHANNELS 3 Zrotation Yrotation Xrotation
      End Site
      {
        OFFSET 5 0 0
      }
    }
    JOINT RightHand
    {
      OFFSET -20 30 0
      CHANNELS 3 Zrotation Yrotation Xrotation
      End Site
      {
        OFFSET -5 0 0
      }
    }
  }
  JOINT LeftUpLeg
  {
    OFFSET 10 0 0
    CHANNELS 3 Zrotation Yrotation Xrotation
    JOINT LeftFoot
    {
      OFFSET 0 -90 0
      CHANNELS 3 Zrotation Yrotation Xrotation
      End Site
      {
        OFFSET 0 0 10
      }
    }
  }
  JOINT RightUpLeg
  {
    OFFSET -10 0 0
    CHANNELS 3 Zrotation Yrotation Xrotation
    JOINT RightFoot
    {
      OFFSET 0 -90 0
      CHANNELS 3 Zrotation Yrotation Xrotation
      End Site
      {
        OFFSET 0 0 10
      }
    }
  }
}
MOTION
";

    fn take() -> Motion {
        let mut text = BVH.to_string();
        text.push_str("Frames: 40\nFrame Time: 0.0333333\n");
        for f in 0..40 {
            let t = f as f64 * 0.2;
            // Hips sway (yaw and roll), spine bends, a hand waves, legs swing.
            let hips = [
                t.sin() * 15.0,
                (t * 0.7).sin() * 20.0,
                (t * 1.3).sin() * 5.0,
            ];
            let spine = [(t * 0.5).sin() * 10.0, 0.0, (t * 0.9).cos() * 8.0];
            let hand = [t.cos() * 40.0, 0.0, 0.0];
            let leg = [(t * 1.1).sin() * 12.0, 0.0, (t * 0.6).sin() * 9.0];
            let row: Vec<f64> = [0.0, 100.0, 0.0]
                .into_iter()
                .chain(hips)
                .chain(spine)
                .chain(hand)
                .chain(hand)
                .chain(leg)
                .chain([0.0; 3])
                .chain(leg)
                .chain([0.0; 3])
                .collect();
            let line: Vec<String> = row.iter().map(|v| format!("{v:.6}")).collect();
            text.push_str(&line.join(" "));
            text.push('\n');
        }
        parse_bvh(&text, "planted.bvh").unwrap()
    }

    fn world(m: &Motion, targets: &[Target]) -> Vec<Vec<[f64; 3]>> {
        let p = FkPlan::new(m.skeleton(), targets)
            .unwrap()
            .positions(m)
            .unwrap();
        (0..p.frames()).map(|f| p.frame(f).to_vec()).collect()
    }

    #[test]
    fn the_feet_stop_and_the_upper_body_keeps_its_world_rotations() {
        let before = take();
        let sk = before.skeleton().clone();
        let find = |n: &str| sk.find_ignore_case(n).unwrap();
        let hands = [find("LeftHand"), find("RightHand")];
        let mut takes = vec![before.clone()];
        let p = plant_feet(&mut takes, &hands).unwrap();
        assert_eq!(p.pelvis, "Hips");
        assert_eq!(p.upper, ["Spine"]);
        // Hips, two legs with a foot each.
        assert_eq!(p.held_joints, 5);
        let after = &takes[0];
        let feet = [
            Target::EndSite(find("LeftFoot")),
            Target::EndSite(find("RightFoot")),
        ];
        let fw = world(after, &feet);
        assert!(fw.windows(2).all(|w| w[0] == w[1]), "the feet moved");
        let fb = world(&before, &feet);
        assert!(
            fb.windows(2).any(|w| w[0] != w[1]),
            "the capture's feet move"
        );
        // The hands' rotations relative to the pelvis change, but relative to the world they
        // are the capture's: world positions of the hands relative to the spine base equal.
        let starts = sk.channel_starts();
        for f in 0..40 {
            let (rb, ra) = (before.frame(f).unwrap(), after.frame(f).unwrap());
            for j in [find("Spine"), find("LeftHand")] {
                let wb = world_rotation(&sk, &starts, rb, j);
                let wa = world_rotation(&sk, &starts, ra, j);
                for r in 0..3 {
                    for c in 0..3 {
                        assert!((wb[r][c] - wa[r][c]).abs() < 1e-9, "frame {f} joint {j}");
                    }
                }
            }
        }
    }

    #[test]
    fn an_upper_body_capture_is_left_alone() {
        // The same skeleton without foot joints (legs end in "shins"): nothing to plant.
        let text = BVH
            .replace("LeftFoot", "LeftShin")
            .replace("RightFoot", "RightShin");
        let row = vec!["0"; 27].join(" ");
        let m = parse_bvh(
            &format!("{text}Frames: 1\nFrame Time: 0.0333333\n{row}\n"),
            "x.bvh",
        )
        .unwrap();
        let hands = [m.skeleton().find_ignore_case("LeftHand").unwrap()];
        let mut one = vec![m.clone()];
        assert_eq!(plant_feet(&mut one, &hands), None);
        assert_eq!(one[0], m);
    }
}
