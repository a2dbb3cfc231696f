//! Gesture motion with known segments: an upper-body skeleton whose arms make strokes and holds
//! shaped by the planted style state.
//!
//! The dominant (right) arm makes strokes from pose to pose with a minimum-jerk time profile
//! (Flash & Hogan), so speed falls to zero between strokes as in human gesture phases. Strokes
//! alternate out to an extended pose and back to a home pose, both drawn around the state's
//! mean arm elevation, forward swing and elbow flexion (`reach` apart, plus `spread` noise);
//! a stroke's duration is drawn around the state's stroke time, and its path bows sideways by
//! the state's bow (the path's curvature). After a stroke the hand may hold, with a faint tremor.
//! The other arm mirrors the strokes in two-handed states and otherwise drifts near rest on
//! the same timing. Spine, neck and head sway a little. Units: centimetres, Y up, facing +Z.
//!
//! Angles are semantic and mapped to BVH channels per side: left arm `Z = elevation`,
//! `Y = -swing`, forearm `Y = -flexion`; the right arm mirrors the signs. Elevation -90 hangs
//! the arm down, 0 holds it out sideways, 90 raises it. The upper arms use channel order
//! `Yrotation Zrotation Xrotation` (`R = Ry Rz Rx`): the arm is elevated in the frontal plane
//! first and then swung forward about the vertical, so the hand's height depends on the
//! elevation alone (with Z outermost, a forward-swung arm would barely rise). Every other joint
//! uses `Zrotation Yrotation Xrotation`.

use rand::Rng;
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, StandardNormal};
use serde::Serialize;

use super::styles::{StateTrack, Style};

/// Frames per second of the synthetic motion.
pub const FPS: f64 = 30.0;

/// One joint of the synthetic skeleton.
#[derive(Clone, Copy, Debug)]
pub struct JointSpec {
    /// Name (common BVH naming, so effector lookup finds the hands).
    pub name: &'static str,
    /// Parent index.
    pub parent: Option<usize>,
    /// Offset from the parent (cm).
    pub offset: [f64; 3],
    /// End site offset, if the joint is a leaf.
    pub end_site: Option<[f64; 3]>,
}

/// The upper-body skeleton. The root has 6 channels (Xposition Yposition Zposition Zrotation
/// Yrotation Xrotation); every other joint has 3 (see the module docs for their order).
pub const SKELETON: [JointSpec; 13] = [
    JointSpec {
        name: "Hips",
        parent: None,
        offset: [0.0, 0.0, 0.0],
        end_site: None,
    },
    JointSpec {
        name: "Spine",
        parent: Some(0),
        offset: [0.0, 12.0, 0.0],
        end_site: None,
    },
    JointSpec {
        name: "Chest",
        parent: Some(1),
        offset: [0.0, 22.0, 0.0],
        end_site: None,
    },
    JointSpec {
        name: "Neck",
        parent: Some(2),
        offset: [0.0, 22.0, 0.0],
        end_site: None,
    },
    JointSpec {
        name: "Head",
        parent: Some(3),
        offset: [0.0, 10.0, 0.0],
        end_site: Some([0.0, 16.0, 0.0]),
    },
    JointSpec {
        name: "LeftShoulder",
        parent: Some(2),
        offset: [4.0, 19.0, 0.0],
        end_site: None,
    },
    JointSpec {
        name: "LeftArm",
        parent: Some(5),
        offset: [14.0, 0.0, 0.0],
        end_site: None,
    },
    JointSpec {
        name: "LeftForeArm",
        parent: Some(6),
        offset: [28.0, 0.0, 0.0],
        end_site: None,
    },
    JointSpec {
        name: "LeftHand",
        parent: Some(7),
        offset: [25.0, 0.0, 0.0],
        end_site: Some([9.0, 0.0, 0.0]),
    },
    JointSpec {
        name: "RightShoulder",
        parent: Some(2),
        offset: [-4.0, 19.0, 0.0],
        end_site: None,
    },
    JointSpec {
        name: "RightArm",
        parent: Some(9),
        offset: [-14.0, 0.0, 0.0],
        end_site: None,
    },
    JointSpec {
        name: "RightForeArm",
        parent: Some(10),
        offset: [-28.0, 0.0, 0.0],
        end_site: None,
    },
    JointSpec {
        name: "RightHand",
        parent: Some(11),
        offset: [-25.0, 0.0, 0.0],
        end_site: Some([-9.0, 0.0, 0.0]),
    },
];

/// Whether joint `j` is an upper arm (channel order Y Z X).
pub fn is_upper_arm(j: usize) -> bool {
    SKELETON[j].name.ends_with("Arm") && !SKELETON[j].name.ends_with("ForeArm")
}

/// Channels per frame: 6 for the root, 3 for each other joint.
pub const CHANNELS: usize = 6 + 3 * (SKELETON.len() - 1);

/// Height of the hips above the floor (cm).
pub const HIP_HEIGHT: f64 = 100.0;

/// Gesture phase of a planted segment.
#[derive(Clone, Copy, Debug, Serialize, PartialEq, Eq)]
#[serde(rename_all = "snake_case")]
pub enum Phase {
    /// The hand moves to a new pose.
    Stroke,
    /// The hand stays (with tremor).
    Hold,
}

/// One planted gesture segment.
#[derive(Clone, Debug, Serialize)]
pub struct Segment {
    /// Start (s).
    pub start_s: f64,
    /// End (s).
    pub end_s: f64,
    /// Planted state.
    pub state: usize,
    /// Stroke or hold.
    pub phase: Phase,
}

/// Arm pose in semantic angles (degrees).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
struct ArmPose {
    elevation: f64,
    swing: f64,
    flexion: f64,
}

impl ArmPose {
    const REST: Self = Self {
        elevation: -78.0,
        swing: 6.0,
        flexion: 15.0,
    };
    fn lerp(a: &Self, b: &Self, s: f64) -> Self {
        Self {
            elevation: a.elevation + (b.elevation - a.elevation) * s,
            swing: a.swing + (b.swing - a.swing) * s,
            flexion: a.flexion + (b.flexion - a.flexion) * s,
        }
    }
    fn clamp(self) -> Self {
        Self {
            elevation: self.elevation.clamp(-88.0, 75.0),
            swing: self.swing.clamp(-5.0, 85.0),
            flexion: self.flexion.clamp(2.0, 135.0),
        }
    }
}

/// A stroke or hold of both arms over `[start, end)`.
#[derive(Clone, Copy, Debug)]
struct Move {
    start: f64,
    end: f64,
    from: [ArmPose; 2],
    to: [ArmPose; 2],
    /// Sideways bow (degrees, signed) at mid-stroke, per arm.
    bow: [f64; 2],
}

fn gauss(rng: &mut ChaCha8Rng) -> f64 {
    StandardNormal.sample(rng)
}

/// Minimum-jerk position profile on [0, 1].
fn min_jerk(t: f64) -> f64 {
    let t = t.clamp(0.0, 1.0);
    t * t * t * (10.0 - 15.0 * t + 6.0 * t * t)
}

/// Plans the gesture segments of a take and renders the BVH channel values
/// (`frames x CHANNELS`, row-major). Returns `(segments, frames, data)`.
pub fn generate(
    rng: &mut ChaCha8Rng,
    track: &StateTrack,
    styles: &[Style],
    duration_s: f64,
) -> (Vec<Segment>, usize, Vec<f64>) {
    let mut moves: Vec<Move> = Vec::new();
    let mut segments = Vec::new();
    let mut pose = [ArmPose::REST, ArmPose::REST];
    let mut t = 0.0;
    let mut out = true;
    while t < duration_s {
        let state = track.at(t);
        let s = &styles[state];
        let dur = (s.stroke_s * (0.1 * gauss(rng)).exp()).clamp(0.2, 2.5);
        let end = (t + dur).min(duration_s);
        // Out: higher, further forward, straighter; back: the opposite.
        let dir = if out { 1.0 } else { -1.0 };
        out = !out;
        let right = ArmPose {
            elevation: s.elevation + dir * 0.5 * s.reach + s.spread * gauss(rng),
            swing: s.swing + dir * s.reach + s.spread * gauss(rng),
            flexion: s.flexion - dir * s.reach + s.spread * gauss(rng),
        }
        .clamp();
        let left = if s.two_handed {
            ArmPose {
                elevation: right.elevation + 4.0 * gauss(rng),
                swing: right.swing * 0.9 + 3.0 * gauss(rng),
                flexion: right.flexion + 4.0 * gauss(rng),
            }
            .clamp()
        } else {
            ArmPose {
                elevation: ArmPose::REST.elevation + 2.0 * gauss(rng),
                swing: ArmPose::REST.swing + 2.0 * gauss(rng),
                flexion: ArmPose::REST.flexion + 3.0 * gauss(rng),
            }
            .clamp()
        };
        let sign = if rng.random_bool(0.5) { 1.0 } else { -1.0 };
        let bow = s.bow * sign * (0.25 * gauss(rng)).exp();
        let to = [left, right];
        moves.push(Move {
            start: t,
            end,
            from: pose,
            to,
            bow: [if s.two_handed { bow } else { 0.0 }, bow],
        });
        segments.push(Segment {
            start_s: t,
            end_s: end,
            state,
            phase: Phase::Stroke,
        });
        pose = to;
        t = end;
        if t < duration_s && rng.random_bool(s.hold_prob) {
            let hold = (s.hold_s * (0.15 * gauss(rng)).exp()).clamp(0.15, 2.0);
            let end = (t + hold).min(duration_s);
            moves.push(Move {
                start: t,
                end,
                from: pose,
                to: pose,
                bow: [0.0, 0.0],
            });
            segments.push(Segment {
                start_s: t,
                end_s: end,
                state,
                phase: Phase::Hold,
            });
            t = end;
        }
    }

    let frames = (duration_s * FPS).round() as usize;
    let mut data = vec![0.0f64; frames * CHANNELS];
    // Slow tremor and sway: smoothed random walks (per arm 3 angles, plus spine/head).
    let mut tremor = [0.0f64; 9];
    let mut tremor_v = [0.0f64; 9];
    let mut m = 0usize;
    for f in 0..frames {
        let time = f as f64 / FPS;
        while m + 1 < moves.len() && time >= moves[m].end {
            m += 1;
        }
        for k in 0..9 {
            tremor_v[k] = 0.9 * tremor_v[k] + 0.08 * gauss(rng);
            tremor[k] = 0.95 * tremor[k] + tremor_v[k];
        }
        let row = &mut data[f * CHANNELS..(f + 1) * CHANNELS];
        row[1] = HIP_HEIGHT;
        // Spine, chest, neck, head: gentle sway (Z, Y, X rotations).
        row[6] = 0.6 * tremor[6];
        row[9 + 2] = 0.5 * tremor[7];
        row[15 + 2] = 1.2 * tremor[8];
        let Some(mv) = moves.get(m) else { continue };
        let len = (mv.end - mv.start).max(1e-6);
        let tau = ((time - mv.start) / len).clamp(0.0, 1.0);
        let s = min_jerk(tau);
        let bump = (std::f64::consts::PI * tau).sin();
        for (arm, side) in [(0usize, 1.0f64), (1, -1.0)] {
            let mut p = ArmPose::lerp(&mv.from[arm], &mv.to[arm], s);
            // Bow perpendicular to the stroke in the (elevation, swing) plane.
            let de = mv.to[arm].elevation - mv.from[arm].elevation;
            let ds = mv.to[arm].swing - mv.from[arm].swing;
            let norm = (de * de + ds * ds).sqrt();
            if norm > 1e-6 {
                p.elevation += mv.bow[arm] * bump * (-ds / norm);
                p.swing += mv.bow[arm] * bump * (de / norm);
            } else {
                p.elevation += mv.bow[arm] * bump;
            }
            p.elevation += 0.4 * tremor[3 * arm];
            p.swing += 0.4 * tremor[3 * arm + 1];
            p.flexion += 0.5 * tremor[3 * arm + 2];
            // Channel layout: root 0..6, then joint j (1-based) at 6 + 3 (j - 1); upper arm
            // channels are Y, Z, X, forearm channels Z, Y, X.
            let (arm_j, fore_j) = if arm == 0 { (6, 7) } else { (10, 11) };
            let a = 6 + 3 * (arm_j - 1);
            let fa = 6 + 3 * (fore_j - 1);
            row[a] = -side * p.swing;
            row[a + 1] = side * p.elevation;
            row[fa + 1] = -side * p.flexion;
        }
    }
    (segments, frames, data)
}
