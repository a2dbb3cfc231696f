//! The Controller over small in-memory tables: chunking invariance, decisions exactly at exit
//! frames, finite poses, a blend at cuts, garbage audio never breaking it, decisions timed on
//! syllable onsets.

use gesture_runtime::controller::{Controller, ControllerEvent, DecisionTiming};
use gesture_runtime::inference::{CrfWeights, GmmComponent, I16Table};
use gesture_runtime::player::LibraryFrames;
use gesture_runtime::policy::{Choice, PolicyTables, Variety};
use gesture_runtime::prosody::ProsodyConfig;

/// Three segments of 20, 12 and 30 frames; exits at interruption frames and ends.
struct Tables {
    exits: Vec<(usize, usize, bool)>,
    first: Vec<usize>,
    u: Vec<[f32; 2]>,
    u_cont: Vec<[f32; 2]>,
    succ: Vec<Vec<(usize, f32)>>,
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
        self.first[c]
    }
    fn u(&self, c: usize, s: usize) -> f32 {
        self.u[c][s]
    }
    fn u_cont(&self, e: usize, s: usize) -> f32 {
        self.u_cont[e][s]
    }
    fn successor_count(&self, e: usize) -> usize {
        self.succ[e].len()
    }
    fn successor(&self, e: usize, k: usize) -> (usize, f32) {
        self.succ[e][k]
    }
}

struct Lib {
    lens: [usize; 3],
    /// Every `beat_every`-th frame (from frame `beat_every - 1`) is a motion beat (0: none).
    beat_every: usize,
    /// Frames 2, 8, 14, ... are calm.
    calm: bool,
}

impl Lib {
    /// Segments of 20, 12 and 30 frames, no beats, no calm frames.
    fn plain() -> Self {
        Self {
            lens: [20, 12, 30],
            beat_every: 0,
            calm: false,
        }
    }
}

impl LibraryFrames for Lib {
    fn channels(&self) -> usize {
        2
    }
    fn fps(&self) -> f32 {
        30.0
    }
    fn segment_count(&self) -> usize {
        3
    }
    fn segment_len(&self, c: usize) -> usize {
        self.lens[c]
    }
    fn value(&self, c: usize, f: usize, ch: usize) -> f32 {
        (c * 100 + f) as f32 + 1000.0 * ch as f32
    }
    /// Segment 1 is segment 0's recorded successor, 2 is 1's; 2 ends a clip.
    fn continues(&self, c: usize) -> bool {
        c < 2
    }
    fn is_beat(&self, _c: usize, f: usize) -> bool {
        self.beat_every > 0 && f % self.beat_every == self.beat_every - 1
    }
    fn is_calm(&self, _c: usize, f: usize) -> bool {
        self.calm && f % 6 == 2
    }
}

fn tables() -> Tables {
    let exits = vec![
        (0, 9, false),
        (0, 19, true),
        (1, 11, true),
        (2, 14, false),
        (2, 29, true),
    ];
    let all: Vec<(usize, f32)> = vec![(0, 0.5), (1, 0.2), (2, 0.4)];
    Tables {
        first: vec![0, 2, 3],
        u: vec![[1.0, 3.0], [2.0, 1.0], [1.5, 1.5]],
        u_cont: vec![[1.6, 1.6], [0.0, 0.0], [0.0, 0.0], [0.5, 5.0], [0.0, 0.0]],
        succ: vec![all.clone(), all.clone(), all.clone(), all.clone(), all],
        exits,
    }
}

fn gmm() -> [GmmComponent; 2] {
    let c = |m: f32| GmmComponent {
        log_voiced: -1.0,
        log_unvoiced: -1.0,
        mean: [m, -1.2],
        inv_chol: [1.0, 0.0, 1.0],
        log_norm: -1.8,
        coef: [0.0, 0.0, 0.0],
        inv_sd: 2.0,
        log_norm_f0: -0.2,
    };
    [c(-0.5), c(0.5)]
}

fn speech(seconds: f32) -> Vec<i16> {
    let n = (seconds * 16000.0) as usize;
    let mut ph = 0.0f32;
    (0..n)
        .map(|i| {
            let t = i as f32 / 16000.0;
            ph += 2.0 * std::f32::consts::PI * (120.0 + 30.0 * (t * 0.9).sin()) / 16000.0;
            let env = (2.0 * std::f32::consts::PI * 3.5 * t).sin().max(0.0)
                * if t % 2.0 < 1.6 { 1.0 } else { 0.0 };
            (env * 9000.0 * (ph.sin() + 0.4 * (2.0 * ph).sin())) as i16
        })
        .collect()
}

#[derive(Debug, PartialEq)]
enum Rec {
    Decision(u64, usize, Choice),
    Pose(u64, Vec<f32>),
    Step(u32, Vec<f32>),
    /// An onset (its frame) reported before the pose of this tick.
    Onset(u64, u32),
    /// The library segment and frame a tick showed.
    Shown(u64, usize, usize),
}

fn run(audio: &[i16], chunk: usize) -> Vec<Rec> {
    run_with(audio, chunk, false)
}

fn run_with(audio: &[i16], chunk: usize, finish: bool) -> Vec<Rec> {
    run_timed(audio, chunk, finish, DecisionTiming::DEFAULT)
}

fn run_timed(audio: &[i16], chunk: usize, finish: bool, timing: DecisionTiming) -> Vec<Rec> {
    run_on(
        &Lib::plain(),
        audio,
        chunk,
        finish,
        timing,
        Variety::NONE,
        None,
        false,
    )
}

/// A run over `lib`; with `shown`, each pose is followed by what it showed
/// ([`Rec::Shown`]).
#[allow(clippy::too_many_arguments)]
fn run_on(
    lib: &Lib,
    audio: &[i16],
    chunk: usize,
    finish: bool,
    timing: DecisionTiming,
    variety: Variety,
    held: Option<&[f32]>,
    shown: bool,
) -> Vec<Rec> {
    run_over(
        &tables(),
        lib,
        (audio, chunk, finish),
        timing,
        variety,
        held,
        shown,
        0,
    )
}

/// [`run_on`] over tables `t`, cuts blending over `blend_ms`.
#[allow(clippy::too_many_arguments)]
fn run_over(
    t: &Tables,
    lib: &Lib,
    (audio, chunk, finish): (&[i16], usize, bool),
    timing: DecisionTiming,
    variety: Variety,
    held: Option<&[f32]>,
    shown: bool,
    blend_ms: u32,
) -> Vec<Rec> {
    let crf_bytes_init = [0u8; 4];
    let mut trans = Vec::new();
    for v in [400i16, -400, -400, 400] {
        trans.extend_from_slice(&v.to_le_bytes());
    }
    let mut obs = Vec::new();
    for v in [800i16, -800, -800, 800] {
        obs.extend_from_slice(&v.to_le_bytes());
    }
    let crf = CrfWeights::new(
        2,
        2,
        1,
        I16Table::new(&crf_bytes_init, 1e-3, 2).unwrap(),
        I16Table::new(&trans, 1e-3, 4).unwrap(),
        I16Table::new(&obs, 1e-3, 4).unwrap(),
    )
    .unwrap();
    let g = gmm();
    let mut c = Controller::new(&ProsodyConfig::DEFAULT, &g, crf, t, lib).unwrap();
    assert_eq!(c.timing(), DecisionTiming::DEFAULT);
    c.set_timing(timing);
    c.set_blend_ms(blend_ms);
    c.set_variety(variety);
    c.hold_belief(held);
    let mut out = Vec::new();
    let mut next_tick = 0u64;
    let mut sink = |e: ControllerEvent<'_>| match e {
        ControllerEvent::Decision { tick, decision } => {
            out.push(Rec::Decision(tick, decision.exit, decision.choice))
        }
        ControllerEvent::Pose {
            tick,
            pose,
            segment,
            frame,
        } => {
            next_tick = tick + 1;
            out.push(Rec::Pose(tick, pose.to_vec()));
            if shown {
                out.push(Rec::Shown(tick, segment, frame));
            }
        }
        ControllerEvent::Step { step, belief } => {
            out.push(Rec::Step(step.end_frame, belief.to_vec()))
        }
        ControllerEvent::Onset(frame) => out.push(Rec::Onset(next_tick, frame)),
        ControllerEvent::Label { .. } | ControllerEvent::Play { .. } => {}
        ControllerEvent::Frame(_) => {}
    };
    for ch in audio.chunks(chunk.max(1)) {
        c.push(ch, &mut sink);
    }
    if finish {
        c.finish(&mut sink);
    }
    out
}

#[test]
fn finish_reports_the_last_steps_without_a_tick() {
    // Speech that stops mid-syllable (the 3.5 Hz envelope is up at 1.25 s): the open syllable
    // only ends at `finish`.
    let audio = speech(1.25);
    let open = run_with(&audio, 160, false);
    let done = run_with(&audio, 160, true);
    assert_eq!(&done[..open.len()], &open[..]);
    let extra = &done[open.len()..];
    assert!(!extra.is_empty());
    assert!(
        extra
            .iter()
            .all(|r| matches!(r, Rec::Step(..) | Rec::Onset(..))),
        "{extra:?}"
    );
    for r in extra {
        if let Rec::Step(end, b) = r {
            assert!(*end as f32 * 0.01 <= 1.26 + 0.1, "{end}");
            assert!((b.iter().sum::<f32>() - 1.0).abs() < 1e-4);
        }
    }
}

#[test]
fn chunking_does_not_change_decisions_or_poses() {
    let audio = speech(6.0);
    let whole = run(&audio, audio.len());
    assert!(
        whole
            .iter()
            .filter(|r| matches!(r, Rec::Decision(..)))
            .count()
            > 5
    );
    for chunk in [1usize, 7, 160, 533, 4096] {
        assert_eq!(run(&audio, chunk), whole, "chunk {chunk}");
    }
}

#[test]
fn one_pose_per_tick_and_decisions_at_exit_frames() {
    let audio = speech(4.0);
    let recs = run_timed(&audio, 1000, false, DecisionTiming::IMMEDIATE);
    let poses: Vec<&Vec<f32>> = recs
        .iter()
        .filter_map(|r| {
            if let Rec::Pose(_, p) = r {
                Some(p)
            } else {
                None
            }
        })
        .collect();
    // 4 s at 30 fps: ticks 0..=120 (tick k is due after ceil(k * 16000 / 30) samples).
    assert_eq!(poses.len(), 121);
    assert!(poses
        .iter()
        .all(|p| p.len() == 2 && p.iter().all(|v| v.is_finite())));
    // The first decision is at exit 0 (frame 9 of segment 0): after the pose of tick 9.
    let first = recs.iter().find_map(|r| {
        if let Rec::Decision(t, e, _) = r {
            Some((*t, *e))
        } else {
            None
        }
    });
    assert_eq!(first, Some((9, 0)));
    // Poses follow the library frames (channel 0 = segment * 100 + frame) except while blending.
    if let Rec::Pose(_, p) = &recs.iter().find(|r| matches!(r, Rec::Pose(0, _))).unwrap() {
        assert_eq!(p[0], 0.0);
    }
}

#[test]
fn garbage_audio_keeps_producing_valid_poses() {
    let mut x = 12345u32;
    let audio: Vec<i16> = (0..48_000)
        .map(|i| {
            x = x.wrapping_mul(1664525).wrapping_add(1013904223);
            match (i / 8000) % 3 {
                0 => (x >> 16) as i16,
                1 => i16::MIN,
                _ => 0,
            }
        })
        .collect();
    for r in run(&audio, 777) {
        match r {
            Rec::Pose(_, p) => assert!(p.iter().all(|v| v.is_finite())),
            Rec::Step(_, b) => {
                let s: f32 = b.iter().sum();
                assert!((s - 1.0).abs() < 1e-4 && b.iter().all(|v| v.is_finite()));
            }
            Rec::Decision(_, e, _) => assert!(e < 5),
            Rec::Onset(..) | Rec::Shown(..) => {}
        }
    }
}

#[test]
fn new_in_builds_in_place_what_new_builds() {
    let t = tables();
    let lib = Lib::plain();
    let init = [0u8; 4];
    let mut trans = Vec::new();
    for v in [400i16, -400, -400, 400] {
        trans.extend_from_slice(&v.to_le_bytes());
    }
    let mut obs = Vec::new();
    for v in [800i16, -800, -800, 800] {
        obs.extend_from_slice(&v.to_le_bytes());
    }
    let crf = || {
        CrfWeights::new(
            2,
            2,
            1,
            I16Table::new(&init, 1e-3, 2).unwrap(),
            I16Table::new(&trans, 1e-3, 4).unwrap(),
            I16Table::new(&obs, 1e-3, 4).unwrap(),
        )
        .unwrap()
    };
    let g = gmm();
    let audio = speech(4.0);
    // A slot that already holds a used controller: everything must be rebuilt.
    let mut slot = Some(Controller::new(&ProsodyConfig::DEFAULT, &g, crf(), &t, &lib).unwrap());
    if let Some(c) = slot.as_mut() {
        c.push(&audio[..20_000], &mut |_| {});
    }
    let c = Controller::new_in(&mut slot, &ProsodyConfig::DEFAULT, &g, crf(), &t, &lib).unwrap();
    let mut out = Vec::new();
    let mut sink = |e: ControllerEvent<'_>| match e {
        ControllerEvent::Decision { tick, decision } => {
            out.push(Rec::Decision(tick, decision.exit, decision.choice))
        }
        ControllerEvent::Pose { tick, pose, .. } => out.push(Rec::Pose(tick, pose.to_vec())),
        ControllerEvent::Step { step, belief } => {
            out.push(Rec::Step(step.end_frame, belief.to_vec()))
        }
        ControllerEvent::Onset(_)
        | ControllerEvent::Frame(_)
        | ControllerEvent::Label { .. }
        | ControllerEvent::Play { .. } => {}
    };
    for ch in audio.chunks(333) {
        c.push(ch, &mut sink);
    }
    let expected: Vec<Rec> = run(&audio, 333)
        .into_iter()
        .filter(|r| !matches!(r, Rec::Onset(..)))
        .collect();
    assert_eq!(out, expected);

    // Refused settings or dimensions leave the slot empty.
    let mut bad = ProsodyConfig::DEFAULT;
    bad.sample_rate_hz = 12_345;
    assert!(Controller::new_in(&mut slot, &bad, &g, crf(), &t, &lib).is_err());
    assert!(slot.is_none());
    assert!(
        Controller::new_in(&mut slot, &ProsodyConfig::DEFAULT, &g[..1], crf(), &t, &lib).is_err()
    );
    assert!(slot.is_none());
}

/// Exit points of `tables()`: `(segment, frame, end)`.
const EXITS: [(usize, usize, bool); 5] = [
    (0, 9, false),
    (0, 19, true),
    (1, 11, true),
    (2, 14, false),
    (2, 29, true),
];

/// The tick at or before `t` that last showed frame `frame` of segment `seg` (channel 0 =
/// segment * 100 + frame).
fn frame_tick(recs: &[Rec], seg: usize, frame: usize, t: u64) -> Option<u64> {
    let value = (seg * 100 + frame) as f32;
    recs.iter()
        .filter_map(|r| match r {
            Rec::Pose(k, p) if *k <= t && p[0] == value => Some(*k),
            _ => None,
        })
        .max()
}

/// The tick at or before `t` that last showed segment `seg`'s last frame.
fn last_frame_tick(recs: &[Rec], seg: usize, t: u64) -> Option<u64> {
    frame_tick(recs, seg, [20, 12, 30][seg] - 1, t)
}

/// The ticks at which syllable onsets were detected.
fn onset_ticks(recs: &[Rec]) -> Vec<u64> {
    recs.iter()
        .filter_map(|r| match r {
            Rec::Onset(t, _) => Some(*t),
            _ => None,
        })
        .collect()
}

#[test]
fn in_silence_interruptions_pass_and_segment_ends_wait_running_on() {
    // No speech, no onsets: interruption exits are passed without deciding; a segment end
    // with a recorded successor waits 300 ms (9 ticks at 30 fps) for an onset, the body
    // running on into the successor meanwhile; a segment end without one decides at once.
    let recs = run(&vec![0i16; 16_000 * 4], 500);
    assert!(!recs.iter().any(|r| matches!(r, Rec::Onset(..))));
    let decisions: Vec<(u64, usize)> = recs
        .iter()
        .filter_map(|r| match r {
            Rec::Decision(t, e, _) => Some((*t, *e)),
            _ => None,
        })
        .collect();
    assert!(decisions.len() >= 3, "{decisions:?}");
    assert!(decisions.iter().all(|&(_, e)| EXITS[e].2), "{decisions:?}");
    // Segment 0 starts at tick 0 and reaches its last frame (19) at tick 19: decided at 28.
    assert_eq!(decisions[0], (28, 1));
    // Ticks 20..=28 run on into segment 1 (frames 0..=8): the body never freezes.
    for r in &recs {
        if let Rec::Pose(t, p) = r {
            if (20..=28).contains(t) {
                assert_eq!(p[0], (100 + t - 20) as f32, "tick {t}");
            }
        }
    }
    // No pose repeats the one before it (hard cuts here: no blending).
    let poses: Vec<f32> = recs
        .iter()
        .filter_map(|r| match r {
            Rec::Pose(_, p) => Some(p[0]),
            _ => None,
        })
        .collect();
    assert!(poses.windows(2).all(|w| w[0] != w[1]), "a frozen frame");
    // Every decision: 9 ticks after its segment's last frame showed if that segment has a
    // recorded successor, at once if not.
    for &(t, e) in &decisions {
        let seg = EXITS[e].0;
        let shown = last_frame_tick(&recs, seg, t).expect("the last frame was shown");
        let wait = if seg < 2 { 9 } else { 0 };
        assert_eq!(t, shown + wait, "decision at exit {e}, tick {t}");
    }
    // Deciding at once: the first decision is the interruption exit at tick 9.
    let now = run_timed(
        &vec![0i16; 16_000 * 4],
        500,
        false,
        DecisionTiming::IMMEDIATE,
    );
    let first = now.iter().find_map(|r| match r {
        Rec::Decision(t, e, _) => Some((*t, *e)),
        _ => None,
    });
    assert_eq!(first, Some((9, 0)));
}

#[test]
fn with_speech_every_decision_follows_an_onset_or_the_longest_wait() {
    let audio = speech(8.0);
    let recs = run(&audio, 160);
    let onsets = onset_ticks(&recs);
    assert!(onsets.len() >= 15, "{} onsets", onsets.len());
    let pose_at = |tick: u64| {
        recs.iter().find_map(|r| match r {
            Rec::Pose(t, p) if *t == tick => Some(p[0]),
            _ => None,
        })
    };
    let (mut fresh, mut waited) = (0, 0);
    for r in &recs {
        let Rec::Decision(t, e, _) = *r else {
            continue;
        };
        // Fresh: an onset arrived for this tick or the one before (within 50 ms at 30 fps).
        if onsets.iter().any(|&o| o <= t && t - o <= 1) {
            fresh += 1;
            continue;
        }
        // Otherwise only a segment end decides: after running on for 9 ticks into its recorded
        // successor, or at once at the end of a clip.
        let (seg, _, end) = EXITS[e];
        assert!(
            end,
            "interruption exit {e} decided at tick {t} without an onset"
        );
        let shown = last_frame_tick(&recs, seg, t).expect("the last frame was shown");
        if seg < 2 {
            assert_eq!(t, shown + 9, "tick {t}");
            assert!(
                (shown + 1..=t)
                    .all(|k| pose_at(k) == Some((100 * (seg + 1)) as f32 + (k - shown - 1) as f32)),
                "tick {t}: not running on"
            );
        } else {
            assert_eq!(t, shown, "tick {t}");
        }
        waited += 1;
    }
    assert!(fresh > 0, "no decision on an onset");
    eprintln!("{fresh} decisions on onsets, {waited} after the longest wait");
}

fn entries(recs: &[Rec]) -> Vec<(u64, usize)> {
    recs.iter()
        .filter_map(|r| match r {
            Rec::Decision(t, _, Choice::Enter(c)) => Some((*t, *c)),
            _ => None,
        })
        .collect()
}

#[test]
fn the_pure_policy_repeats_itself_and_recency_costs_stop_it() {
    // In silence the belief settles on pause steps: at every end the pure policy enters the
    // same cheapest segment, over and over (a loop).
    let silence = vec![0i16; 16_000 * 6];
    let pure = entries(&run_timed(&silence, 500, false, DecisionTiming::IMMEDIATE));
    assert!(pure.len() >= 8, "{pure:?}");
    assert!(pure.iter().all(|&(_, c)| c == pure[0].1), "{pure:?}");
    // A recency cost larger than the cost differences (5 s window at 30 fps): no segment is
    // entered again within 5 s while another one is free... but there are only three.
    let v = Variety {
        recency_cost: 2.0,
        recency_ms: 5000,
        usage_cost: 0.0,
        usage_ms: 0,
    };
    let varied = entries(&run_on(
        &Lib::plain(),
        &silence,
        500,
        false,
        DecisionTiming::IMMEDIATE,
        v,
        None,
        false,
    ));
    let distinct: std::collections::BTreeSet<usize> = varied.iter().map(|&(_, c)| c).collect();
    assert_eq!(distinct.len(), 3, "{varied:?}");
    // Never the segment just left at an end (a self-loop would be the most recent entry).
    for w in varied.windows(2) {
        assert_ne!(w[0].1, w[1].1, "{varied:?}");
    }
}

#[test]
fn a_held_belief_decides_instead_of_the_crf() {
    // Belief held on state 0: segment 0 costs 1.0 + 0.5, segment 1 2.0 + 0.2, segment 2
    // 1.5 + 0.4: always segment 0. Held on state 1: segment 1 (1.0 + 0.2).
    let silence = vec![0i16; 16_000 * 4];
    for (held, want) in [([1.0f32, 0.0], 0usize), ([0.0, 1.0], 1)] {
        let e = entries(&run_on(
            &Lib::plain(),
            &silence,
            500,
            false,
            DecisionTiming::IMMEDIATE,
            Variety::NONE,
            Some(&held),
            false,
        ));
        assert!(!e.is_empty());
        assert!(e.iter().all(|&(_, c)| c == want), "{held:?}: {e:?}");
    }
}

#[test]
fn an_interruption_exit_stays_armed_for_an_onset_within_the_longest_wait() {
    // Past an interruption frame without an onset, the segment plays on and the exit is
    // decided on an onset that comes within 300 ms (9 ticks) and before the next exit.
    let audio = speech(8.0);
    let recs = run(&audio, 160);
    let onsets = onset_ticks(&recs);
    let mut armed = 0;
    for r in &recs {
        let Rec::Decision(t, e, _) = *r else {
            continue;
        };
        let (seg, frame, end) = EXITS[e];
        if end {
            continue;
        }
        let shown = frame_tick(&recs, seg, frame, t).expect("the exit frame was shown");
        assert!(t - shown <= 9, "exit {e} decided {} ticks late", t - shown);
        assert!(
            onsets.iter().any(|&o| o <= t && t - o <= 1),
            "exit {e} at tick {t} without an onset"
        );
        if t > shown {
            armed += 1;
        }
    }
    assert!(armed > 0, "no interruption exit decided after its frame");
}

/// Ticks of 400 ms at 30 fps: the default longest delay of a cut.
const DEFER_TICKS: u64 = 12;

/// Per tick from 0, the (segment, frame) shown.
fn shown(recs: &[Rec]) -> Vec<(usize, usize)> {
    recs.iter()
        .filter_map(|r| match *r {
            Rec::Shown(_, s, f) => Some((s, f)),
            _ => None,
        })
        .collect()
}

/// For each cut decided at tick `t` (an entry, but not a choice of the recorded successor
/// the player ran on into): the decided exit, `t`, and the first tick after `t` that does not
/// show the next frame of the playing segment (the cut), if the run reached it.
fn cuts(recs: &[Rec]) -> Vec<(usize, u64, Option<u64>)> {
    let sh = shown(recs);
    recs.iter()
        .filter_map(|r| match *r {
            Rec::Decision(t, e, Choice::Enter(c)) => Some((t, e, c)),
            _ => None,
        })
        .filter(|&(t, e, c)| {
            let seg = sh[t as usize].0;
            !(seg != EXITS[e].0 && c == seg)
        })
        .map(|(t, e, _)| {
            let (seg, frame) = sh[t as usize];
            let cut = (t + 1..sh.len() as u64)
                .find(|&u| sh[u as usize] != (seg, frame + (u - t) as usize));
            (e, t, cut)
        })
        .collect()
}

#[test]
fn a_cut_decided_mid_segment_waits_for_the_hands_to_pause() {
    let audio = speech(12.0);
    let run = |beat_every: usize, calm: bool, timing: DecisionTiming| {
        let lib = Lib {
            lens: [20, 12, 30],
            beat_every,
            calm,
        };
        // State 1 held: leaving at interruption exits is cheaper than continuing.
        let held = [0.0, 1.0];
        run_on(
            &lib,
            &audio,
            160,
            false,
            timing,
            Variety::NONE,
            Some(&held),
            true,
        )
    };
    let at_once = DecisionTiming {
        defer_cut_ms: 0,
        ..DecisionTiming::DEFAULT
    };
    assert_eq!(DecisionTiming::DEFAULT.defer_cut_ms, 400);
    // Cut at once: every entry shows on the next tick.
    let recs = run(5, true, at_once);
    let c = cuts(&recs);
    assert!(
        c.iter().any(|&(e, _, _)| !EXITS[e].2),
        "no entry at an interruption"
    );
    for &(e, t, cut) in &c {
        assert_eq!(cut, Some(t + 1), "exit {e} at tick {t}");
    }
    // Deferred: at once if the decision's tick showed a pause of the hands (a beat, a calm
    // frame or the segment's last frame); else the cut shows on the tick after the playing
    // segment reaches its first calm frame within 400 ms of frames, else its first beat
    // there, else its last frame there, else the first pause that comes, however late.
    for (beat_every, calm) in [(5, false), (0, true), (0, false), (5, true)] {
        let recs = run(beat_every, calm, DecisionTiming::DEFAULT);
        let sh = shown(&recs);
        let lib = Lib {
            lens: [20, 12, 30],
            beat_every,
            calm,
        };
        let (mut deferred, mut by_beat) = (0, 0);
        for (e, t, cut) in cuts(&recs) {
            let Some(cut) = cut else { continue };
            let (seg, f0) = sh[t as usize];
            let last = lib.lens[seg] - 1;
            let pause = |f: usize| lib.is_beat(seg, f) || lib.is_calm(seg, f) || f == last;
            let window = f0 + 1..=(f0 + DEFER_TICKS as usize).min(last);
            let target = if pause(f0) {
                f0
            } else {
                window
                    .clone()
                    .find(|&f| lib.is_calm(seg, f))
                    .or_else(|| window.clone().find(|&f| lib.is_beat(seg, f)))
                    .or_else(|| window.clone().find(|&f| f == last))
                    .unwrap_or_else(|| (f0 + 1..=last).find(|&f| pause(f)).unwrap_or(last))
            };
            let u = (t..sh.len() as u64)
                .find(|&u| sh[u as usize] == (seg, target))
                .unwrap();
            assert_eq!(
                cut,
                u + 1,
                "beats every {beat_every}, calm {calm}: exit {e} at tick {t}"
            );
            if cut > t + 1 {
                deferred += 1;
                by_beat += (lib.is_beat(seg, target) || lib.is_calm(seg, target)) as usize;
            }
        }
        assert!(deferred > 0, "beats every {beat_every}: no cut deferred");
        assert_eq!(
            by_beat > 0,
            beat_every > 0 || calm,
            "beats every {beat_every}"
        );
    }
}

/// No cut follows another within a quarter of the blend: segment 2's first interruption exit
/// point is 2 frames in, and a cut's blend is 400 ms (12 ticks at 30 fps); after a cut into
/// segment 2 that exit point is passed by (its next one, frame 29, decides), where with hard
/// cuts it decides (and, leaving being cheaper there, cuts again).
#[test]
fn an_exit_point_early_in_a_cut_s_blend_is_passed_by() {
    let mut t = tables();
    t.exits[3] = (2, 2, false);
    // Segment 2 is the cheapest choice and leaving it at its interruption the cheaper action.
    t.u = vec![[3.0, 3.0], [3.0, 3.0], [0.0, 0.0]];
    t.u_cont[3] = [5.0, 5.0];
    let audio = speech(12.0);
    let held = [0.0, 1.0];
    let run = |blend_ms: u32| {
        run_over(
            &t,
            &Lib::plain(),
            (&audio, 160, false),
            DecisionTiming::IMMEDIATE,
            Variety::NONE,
            Some(&held),
            true,
            blend_ms,
        )
    };
    // Decisions at exit 3 (segment 2, frame 2) on a visit that entered segment 2 by a cut.
    let early = |recs: &[Rec]| {
        let sh = shown(recs);
        let entered_2 = recs
            .iter()
            .any(|r| matches!(r, Rec::Decision(_, _, Choice::Enter(2))));
        let at_3 = recs
            .iter()
            .filter(|r| matches!(r, Rec::Decision(t, 3, _) if sh[*t as usize].0 == 2))
            .count();
        (entered_2, at_3)
    };
    let (entered, hard) = early(&run(0));
    assert!(
        entered && hard > 0,
        "hard cuts: entered 2 {entered}, decisions at exit 3 {hard}"
    );
    let (entered, blended) = early(&run(400));
    assert!(entered, "no entry into segment 2");
    assert_eq!(blended, 0);
}
