//! The body follows the voice (`gesture_runtime::follow`) through the whole controller: in a
//! pause the character moves to the calmest segments even when no successor list holds one,
//! holds the rest (played to and fro, never frozen) until the speech returns, and then cuts
//! into a gesture at once, the gesture shrinking in the silence and growing back with the
//! speech; without it (`VoiceFollow::NONE`) the paper's rule keeps gesturing.

use gesture_runtime::controller::{Controller, ControllerEvent};
use gesture_runtime::follow::{VoiceFollow, EXPRESSION};
use gesture_runtime::inference::{CrfWeights, GmmComponent, I16Table};
use gesture_runtime::player::{LibraryFrames, PlayerCommand};
use gesture_runtime::policy::{PolicyTables, Variety};
use gesture_runtime::prosody::ProsodyConfig;

/// Segments 0 and 1 gesture (energy +1, +0.5); 2 and 3 are calm (-2, -1.5) and listed as no
/// exit's successor.
const LENS: [usize; 4] = [45, 36, 30, 24];
const ENERGY: [f32; 4] = [1.0, 0.5, -2.0, -1.5];

struct Tables {
    exits: Vec<(usize, usize, bool)>,
}

impl Tables {
    fn new() -> Self {
        let mut exits = Vec::new();
        for (c, &len) in LENS.iter().enumerate() {
            exits.push((c, len / 2, false));
            exits.push((c, len - 1, true));
        }
        Self { exits }
    }
}

impl PolicyTables for Tables {
    fn states(&self) -> usize {
        2
    }
    fn exit_count(&self) -> usize {
        self.exits.len()
    }
    fn exit_segment(&self, e: usize) -> usize {
        self.exits[e].0
    }
    fn exit_frame(&self, e: usize) -> usize {
        self.exits[e].1
    }
    fn exit_is_end(&self, e: usize) -> bool {
        self.exits[e].2
    }
    fn first_exit(&self, c: usize) -> usize {
        2 * c
    }
    fn u(&self, c: usize, _s: usize) -> f32 {
        [1.0, 1.2, 1.0, 1.0][c]
    }
    fn u_cont(&self, _e: usize, _s: usize) -> f32 {
        1.1
    }
    fn successor_count(&self, _e: usize) -> usize {
        2
    }
    fn successor(&self, _e: usize, k: usize) -> (usize, f32) {
        [(0, 0.2), (1, 0.1)][k]
    }
    fn energy(&self, c: usize) -> f32 {
        ENERGY[c]
    }
}

/// The frames: segment `c`'s frame `f` holds pose `100 c + f`. With `partly_calm`, the
/// calmest segment (2) is calm only in frames 10-19 and its frames hold poses 150 down to 121,
/// so the one nearest a gesture's pose is known.
struct Lib {
    partly_calm: bool,
}

const LIB: Lib = Lib { partly_calm: false };

impl LibraryFrames for Lib {
    fn channels(&self) -> usize {
        1
    }
    fn fps(&self) -> f32 {
        30.0
    }
    fn segment_count(&self) -> usize {
        4
    }
    fn segment_len(&self, c: usize) -> usize {
        LENS[c]
    }
    fn value(&self, c: usize, f: usize, _ch: usize) -> f32 {
        match c {
            2 if self.partly_calm => 150.0 - f as f32,
            _ => (c * 100 + f) as f32,
        }
    }
    /// The calm segments' frames are calm (as `pack` marks the slowest frames).
    fn is_calm(&self, c: usize, f: usize) -> bool {
        match c {
            2 if self.partly_calm => (10..20).contains(&f),
            _ => ENERGY[c] < 0.0,
        }
    }
    /// The gestures' hands pause every 8 frames (their speed's local minima).
    fn is_beat(&self, _c: usize, f: usize) -> bool {
        f % 8 == 7
    }
}

/// Syllables at 3.5 Hz while `speaking(t)`, silence otherwise (16 kHz).
fn audio(seconds: f32, speaking: impl Fn(f32) -> bool) -> Vec<i16> {
    let n = (seconds * 16000.0) as usize;
    let mut ph = 0.0f32;
    (0..n)
        .map(|i| {
            let t = i as f32 / 16000.0;
            ph += 2.0 * std::f32::consts::PI * 130.0 / 16000.0;
            let env = if speaking(t) {
                (2.0 * std::f32::consts::PI * 3.5 * t).sin().max(0.0)
            } else {
                0.0
            };
            (env * 9000.0 * (ph.sin() + 0.4 * (2.0 * ph).sin())) as i16
        })
        .collect()
}

/// Per tick: the segment and frame shown, whether a decision was made, whether an onset was
/// heard before it.
#[derive(Clone, Copy, Debug, Default)]
struct Tick {
    segment: usize,
    frame: usize,
    pose: f32,
    decided: bool,
    onset: bool,
    /// The expression gain aimed at from this tick on, when the controller changed it.
    gain: Option<f32>,
}

fn run(samples: &[i16], follow: VoiceFollow) -> Vec<Tick> {
    run_with(samples, follow, Variety::NONE)
}

fn run_with(samples: &[i16], follow: VoiceFollow, variety: Variety) -> Vec<Tick> {
    run_lib(samples, follow, variety, &LIB)
}

fn run_lib(
    samples: &[i16],
    follow: VoiceFollow,
    variety: Variety,
    lib: &impl LibraryFrames,
) -> Vec<Tick> {
    let t = Tables::new();
    let mut bytes = Vec::new();
    for v in [0i16, 0, 0, 0] {
        bytes.extend_from_slice(&v.to_le_bytes());
    }
    let crf = CrfWeights::new(
        2,
        2,
        1,
        I16Table::new(&bytes[..4], 1e-3, 2).unwrap(),
        I16Table::new(&bytes, 1e-3, 4).unwrap(),
        I16Table::new(&bytes, 1e-3, 4).unwrap(),
    )
    .unwrap();
    let g = [GmmComponent::default(), GmmComponent::default()];
    let mut c = Controller::new(&ProsodyConfig::DEFAULT, &g, crf, &t, lib).unwrap();
    c.set_variety(variety);
    c.set_follow(follow);
    let mut ticks: Vec<Tick> = Vec::new();
    let mut heard = false;
    let mut gain = None;
    let mut sink = |e: ControllerEvent<'_>| match e {
        ControllerEvent::Play {
            command: PlayerCommand::Gain(g),
            ..
        } => gain = Some(g),
        ControllerEvent::Pose {
            segment,
            frame,
            pose,
            ..
        } => {
            ticks.push(Tick {
                segment,
                frame,
                pose: pose[0],
                decided: false,
                onset: heard,
                gain: gain.take(),
            });
            heard = false;
        }
        ControllerEvent::Decision { .. } => {
            if let Some(t) = ticks.last_mut() {
                t.decided = true;
            }
        }
        ControllerEvent::Onset(_) => heard = true,
        _ => {}
    };
    for ch in samples.chunks(160) {
        c.push(ch, &mut sink);
    }
    ticks
}

const FOLLOW: VoiceFollow = VoiceFollow {
    rest_ms: 500,
    rest_cost: 4.0,
    energy_cost: 1.0,
};

fn rest(c: usize) -> bool {
    ENERGY[c] < 0.0
}

#[test]
fn a_pause_brings_the_calmest_segments_held_to_and_fro_until_the_speech_returns() {
    // Speech 0-3 s, silence 3-7 s, speech 7-9 s.
    let samples = audio(9.0, |t| !(3.0..7.0).contains(&t));
    let ticks = run(&samples, FOLLOW);
    let at = |s: f32| (s * 30.0) as usize;
    // While speaking, gestures only.
    assert!(ticks[..at(3.0)].iter().all(|t| !rest(t.segment)));
    // Within 1.3 s of the silence (0.5 s to rest, at most 0.4 s for the hands to pause, the
    // front-end's latency), a rest segment plays, though no successor list holds one.
    let first_rest = ticks.iter().position(|t| rest(t.segment)).unwrap();
    assert!(
        (at(3.0)..=at(4.3)).contains(&first_rest),
        "rest from tick {first_rest}"
    );
    // The speech returns: the first onset after the silence.
    let back = (at(6.9)..ticks.len()).find(|&i| ticks[i].onset).unwrap();
    assert!(back < at(7.3), "onset heard at tick {back}");
    // The rest holds without a decision until then, the same segment throughout, its frames
    // moving every tick or two (at the rest's pace) and turning back at its end.
    let held = &ticks[first_rest + 1..back];
    assert!(held.iter().all(|t| t.segment == ticks[first_rest].segment));
    assert!(held.iter().all(|t| !t.decided));
    for w in held.windows(3) {
        assert!(
            w[0].pose != w[1].pose || w[1].pose != w[2].pose,
            "frozen at {:?}",
            w
        );
    }
    assert!(held.windows(2).any(|w| w[1].frame < w[0].frame));
    assert!(held.windows(2).any(|w| w[1].frame > w[0].frame));
    // The speech brings a gesture at once: a decision on the onset's tick, the cut not put
    // off (the rest's frames are calm; its first frames show on the next tick).
    assert!(ticks[back].decided || ticks[back + 1].decided);
    assert!(
        !rest(ticks[back + 2].segment),
        "{:?}",
        &ticks[back..back + 3]
    );
}

#[test]
fn a_rest_begins_at_its_calm_frame_nearest_the_pose_and_stays_among_its_calm_frames() {
    // Speech 0-3 s, silence 3-9 s.
    let samples = audio(9.0, |t| t < 3.0);
    let ticks = run_lib(&samples, FOLLOW, Variety::NONE, &Lib { partly_calm: true });
    let first = ticks.iter().position(|t| rest(t.segment)).unwrap();
    assert_eq!(ticks[first].segment, 2);
    // Entered at the calm frame (10-19) whose pose (150 - f) is nearest the pose shown just
    // before the cut.
    let before = ticks[first - 1].pose;
    let nearest = (10..20usize)
        .min_by(|&a, &b| {
            let d = |f: usize| (150.0 - f as f32 - before).abs();
            d(a).total_cmp(&d(b))
        })
        .unwrap();
    assert_eq!(ticks[first].frame, nearest, "pose before the cut {before}");
    // Held to and fro among the calm frames widened to half a second (15 frames): 7-22,
    // never at the segment's restless ends, and never frozen.
    let held = &ticks[first..];
    assert!(held.iter().all(|t| t.segment == 2));
    assert!(
        held.iter().all(|t| (7..=22).contains(&t.frame)),
        "{:?}",
        held.iter().map(|t| t.frame).collect::<Vec<_>>()
    );
    assert!(held.windows(2).any(|w| w[1].frame < w[0].frame));
    assert!(held.windows(2).any(|w| w[1].frame > w[0].frame));
    assert!(held.iter().any(|t| t.frame == 7) && held.iter().any(|t| t.frame == 22));
    for w in held.windows(3) {
        assert!(w[0].pose != w[1].pose || w[1].pose != w[2].pose);
    }
}

#[test]
fn a_rest_held_through_a_long_pause_hands_over_to_the_other_rest() {
    // Speech 0-3 s, silence 3-15 s. A usage window of 20 s: a rest hands over once it has
    // held for 0.14 of it (2.8 s), at its next turn.
    let samples = audio(15.0, |t| t < 3.0);
    let variety = Variety {
        recency_cost: 0.0,
        recency_ms: 0,
        usage_cost: 1.0,
        usage_ms: 20_000,
    };
    let ticks = run_with(&samples, FOLLOW, variety);
    let first_rest = ticks.iter().position(|t| rest(t.segment)).unwrap();
    let resting = &ticks[first_rest..];
    // Only rests from then on, never frozen.
    assert!(resting.iter().all(|t| rest(t.segment)));
    for w in resting.windows(3) {
        assert!(w[0].pose != w[1].pose || w[1].pose != w[2].pose);
    }
    // Each hold lasts at least 2.8 s, and at most that and one more traversal of the longest
    // rest to a turn at the rest's slowest pace (30 frames at half speed: 2 s); a hold hands
    // over to the other rest at one of its ends, with no decision.
    let mut holds = vec![(first_rest, ticks[first_rest].segment)];
    for (i, w) in ticks.windows(2).enumerate().skip(first_rest) {
        if w[1].segment != w[0].segment {
            assert_ne!(holds.last().unwrap().1, w[1].segment);
            // The frame shown last is next to an end (the player has reached it).
            let len = LENS[w[0].segment];
            assert!(w[0].frame <= 1 || w[0].frame + 2 >= len, "{w:?}");
            // Into the other's frame nearest the pose shown (all its frames are calm).
            let c = w[1].segment;
            let d = |f: usize| (LIB.value(c, f, 0) - w[0].pose).abs();
            let nearest = (0..LENS[c]).min_by(|&a, &b| d(a).total_cmp(&d(b))).unwrap();
            assert_eq!(w[1].frame, nearest, "{w:?}");
            assert!(!w[1].decided);
            holds.push((i + 1, w[1].segment));
        }
    }
    assert!(holds.len() >= 3, "{holds:?}");
    for h in holds.windows(2) {
        let held = (h[1].0 - h[0].0) as f32 / 30.0;
        assert!((2.8..=4.9).contains(&held), "held {held} s: {holds:?}");
    }
    // Without variety costs one rest holds the whole silence.
    let ticks = run(&samples, FOLLOW);
    let first_rest = ticks.iter().position(|t| rest(t.segment)).unwrap();
    assert!(ticks[first_rest..]
        .iter()
        .all(|t| t.segment == ticks[first_rest].segment));
}

#[test]
fn without_following_the_voice_a_pause_plays_gestures() {
    let samples = audio(9.0, |t| !(3.0..7.0).contains(&t));
    let ticks = run(&samples, VoiceFollow::NONE);
    assert!(ticks.iter().all(|t| !rest(t.segment)));
    // Resting needs both a time and a cost.
    let no_cost = VoiceFollow {
        rest_cost: 0.0,
        ..FOLLOW
    };
    assert!(run(&samples, no_cost).iter().all(|t| !rest(t.segment)));
}

#[test]
fn the_gesture_shrinks_in_a_pause_and_grows_back_with_the_speech() {
    // Speech 0-3 s, silence 3-7 s, speech 7-9 s.
    let samples = audio(9.0, |t| !(3.0..7.0).contains(&t));
    let ticks = run(&samples, FOLLOW);
    let at = |s: f32| (s * 30.0) as usize;
    let aims: Vec<(usize, f32)> = ticks
        .iter()
        .enumerate()
        .filter_map(|(i, t)| t.gain.map(|g| (i, g)))
        .collect();
    // Before the first syllable nobody has spoken: whatever plays is shown at the size of a
    // gesture the rest caught. The first syllable is heard within a quarter second.
    let first = aims
        .iter()
        .position(|&(_, g)| g != EXPRESSION.caught)
        .unwrap();
    assert!(aims[first].0 <= at(0.25), "{aims:?}");
    // While speaking, within the voice's span (a first syllable's level moves it), down to
    // the pause's size in the quiet between syllables (`follow::QUIET_SPAN`).
    let (lo, hi) = (EXPRESSION.pause, 1.0 + EXPRESSION.span);
    assert!(aims[first..].iter().any(|&(i, _)| i < at(3.0)), "{aims:?}");
    for &(i, g) in aims[first..].iter().filter(|&&(i, _)| i < at(3.0)) {
        assert!((lo..=hi).contains(&g), "gain {g} at tick {i}");
    }
    // The first pause step of the silence (a quarter second, reported at its end) halves the
    // gesture: well before the rest (0.5 s).
    let shrink = aims
        .iter()
        .find(|&&(i, g)| i >= at(3.0) && g == EXPRESSION.pause)
        .copied()
        .unwrap();
    assert!(
        shrink.0 <= at(3.45),
        "shrunk at tick {}: {aims:?}",
        shrink.0
    );
    // Through the silence: resting (from 0.5 s), a quarter while a gesture still plays (its
    // cut into a rest waits for a pause of the hands), the rest's own size once a rest
    // segment plays.
    let silent: Vec<(usize, f32)> = aims
        .iter()
        .copied()
        .filter(|&(i, _)| (shrink.0 + 1..at(6.9)).contains(&i))
        .collect();
    for &(i, g) in &silent {
        let want = if rest(ticks[i].segment) {
            1.0
        } else {
            EXPRESSION.caught
        };
        assert_eq!(g, want, "gain at tick {i}: {:?}", ticks[i]);
    }
    assert!(rest(ticks[at(6.8)].segment));
    assert_eq!(silent.last().map_or(shrink.1, |a| a.1), 1.0);
    // Here the rest caught a gesture: both were aimed.
    assert!(
        silent.iter().any(|a| a.1 == EXPRESSION.caught),
        "{silent:?}"
    );
    // Back on the speech's first onset.
    let back = (at(6.9)..ticks.len()).find(|&i| ticks[i].onset).unwrap();
    let grown = aims.iter().find(|&&(i, _)| i >= at(6.9)).copied().unwrap();
    assert!(
        grown.0 <= back + 1,
        "grown at tick {}, onset {back}",
        grown.0
    );
    // Growing on the onset's tick, and within the voice's span two ticks later (the heard
    // loudness rises over 30 ms from the silence's).
    assert!(grown.1 > EXPRESSION.pause, "{grown:?}");
    assert!(
        aims.iter()
            .any(|&(i, g)| i > back && i <= back + 2 && (1.0 - EXPRESSION.span..=hi).contains(&g)),
        "{aims:?}"
    );
    // Without following the voice, the frames as they are.
    let none = run(&samples, VoiceFollow::NONE);
    assert!(none.iter().all(|t| t.gain.is_none()));
}

#[test]
fn louder_syllables_choose_more_energetic_segments() {
    // Entering 0 (energy 1) costs 1.2, entering 1 (energy 0.5) 1.3: without a voice term 0
    // wins every time; the term adds `-energy_cost * level / VOICE_SPAN` per unit of energy
    // (saturating), so a voice well below its running level brings 1, above it 0.
    let strong = VoiceFollow {
        energy_cost: 4.0,
        rest_ms: 0,
        ..FOLLOW
    };
    let share_of_1 = |scale: f32| {
        let samples: Vec<i16> = audio(8.0, |_| true)
            .iter()
            .enumerate()
            .map(|(i, &v)| {
                if i > 3 * 16000 {
                    (v as f32 * scale) as i16
                } else {
                    v
                }
            })
            .collect();
        let ticks = run(&samples, strong);
        let later = &ticks[(3.5 * 30.0) as usize..];
        later.iter().filter(|t| t.segment == 1).count() as f64 / later.len() as f64
    };
    assert!(run(&audio(8.0, |_| true), VoiceFollow::NONE)
        .iter()
        .all(|t| t.segment == 0));
    let (steady, quiet, loud) = (share_of_1(1.0), share_of_1(0.25), share_of_1(2.0));
    // 12 dB quieter: mostly the calmer gesture; 6 dB louder: no more of it than steady.
    assert!(quiet > 0.6 && quiet > steady + 0.3, "{quiet} vs {steady}");
    assert!(loud <= steady, "{loud} vs {steady}");
}

#[test]
fn speech_from_the_first_sample_decides_at_its_first_syllable() {
    // Speech from the start: before the first syllable nobody has spoken, so the first
    // syllable is the speech's return and decides at once, not at segment 0's first exit
    // point (frame 22, 0.73 s).
    let samples = audio(3.0, |_| true);
    let ticks = run(&samples, FOLLOW);
    let onset = ticks.iter().position(|t| t.onset).unwrap();
    let decided = ticks.iter().position(|t| t.decided).unwrap();
    assert!(onset < 12, "first onset at tick {onset}");
    assert!(decided <= onset + 1, "onset {onset}, decided {decided}");
    // Without the voice followed (the paper's rule) the first decision waits for the exit.
    let ticks = run(&samples, VoiceFollow::NONE);
    assert!(ticks.iter().position(|t| t.decided).unwrap() >= 21);
}
