//! Show files replay the controller: the `Play` commands of a run over a small hand-built
//! library (cuts, run-ons, rests played to and fro at a slower rate, holds at beats) and over
//! the golden blob (blends, speed cap), encoded, parsed and played by a `ShowPlayer` fed the
//! same samples in other chunks, give the controller's poses bit for bit, tick for tick; and
//! no bytes make `Show::parse` or the player panic or leave the rig's limits.

mod common;

use gesture_runtime::blob::Blob;
use gesture_runtime::controller::{Controller, ControllerEvent, DecisionTiming};
use gesture_runtime::follow::VoiceFollow;
use gesture_runtime::inference::{CrfWeights, GmmComponent, I16Table};
use gesture_runtime::player::{LibraryFrames, PlayerCommand};
use gesture_runtime::policy::{PolicyTables, Variety};
use gesture_runtime::prosody::ProsodyConfig;
use gesture_runtime::show::{encode, encode_show, Show, ShowInfo, ShowPlayer};
use proptest::prelude::*;

/// Segments 0 and 1 gesture, 2 and 3 are calm; 0 runs on into 1.
const LENS: [usize; 4] = [45, 36, 30, 24];
const ENERGY: [f32; 4] = [1.0, 0.5, -2.0, -1.5];
/// Channel 1 is limited to -40..=60 degrees (its frames go beyond: the clamp shows).
const LIMITS: [(f32, f32, f32); 2] = [(-1000.0, 1000.0, 0.0), (-40.0, 60.0, 5.0)];

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
    fn u(&self, c: usize, s: usize) -> f32 {
        [1.0, 1.2, 1.0, 1.0][c] + 0.3 * s as f32
    }
    fn u_cont(&self, e: usize, _s: usize) -> f32 {
        1.05 + 0.02 * e as f32
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

struct Lib;

impl LibraryFrames for Lib {
    fn channels(&self) -> usize {
        2
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
    fn value(&self, c: usize, f: usize, ch: usize) -> f32 {
        let t = f as f32 / 7.0 + c as f32;
        if ch == 0 {
            30.0 * t.sin() + 10.0 * c as f32
        } else {
            80.0 * (1.3 * t).cos()
        }
    }
    fn continues(&self, c: usize) -> bool {
        c == 0
    }
    fn is_calm(&self, c: usize, _f: usize) -> bool {
        ENERGY[c] < 0.0
    }
    fn is_beat(&self, _c: usize, f: usize) -> bool {
        f % 8 == 7
    }
    fn limits(&self, ch: usize) -> (f32, f32, f32) {
        LIMITS[ch]
    }
}

/// Syllables at 3.5 Hz while `speaking(t)`, silence otherwise (16 kHz).
fn audio(seconds: f32, speaking: impl Fn(f32) -> bool) -> Vec<i16> {
    let n = (seconds * 16000.0) as usize;
    let mut ph = 0.0f32;
    (0..n)
        .map(|i| {
            let t = i as f32 / 16000.0;
            ph += 2.0 * std::f32::consts::PI * (125.0 + 20.0 * (0.7 * t).sin()) / 16000.0;
            let env = if speaking(t) {
                (2.0 * std::f32::consts::PI * 3.5 * t).sin().max(0.0)
            } else {
                0.0
            };
            (env * 9000.0 * (ph.sin() + 0.4 * (2.0 * ph).sin())) as i16
        })
        .collect()
}

/// A pose as its bits, with the segment and frame it showed.
type Shown = (u64, Vec<u32>, usize, usize);

/// What a controller run gave: its poses and its player commands.
struct Recorded {
    poses: Vec<Shown>,
    plays: Vec<(u64, PlayerCommand)>,
}

fn record<L: LibraryFrames + ?Sized, T: PolicyTables + ?Sized>(
    c: &mut Controller<'_, T, L>,
    samples: &[i16],
    chunk: usize,
) -> Recorded {
    let mut r = Recorded {
        poses: Vec::new(),
        plays: Vec::new(),
    };
    let mut sink = |e: ControllerEvent<'_>| match e {
        ControllerEvent::Pose {
            tick,
            pose,
            segment,
            frame,
        } => r.poses.push((
            tick,
            pose.iter().map(|v| v.to_bits()).collect(),
            segment,
            frame,
        )),
        ControllerEvent::Play { tick, command } => r.plays.push((tick, command)),
        _ => {}
    };
    for ch in samples.chunks(chunk) {
        c.push(ch, &mut sink);
    }
    r
}

/// Plays `show` fed `total` samples in the chunk sizes of `chunks` (cycled), checking after
/// each chunk that exactly the ticks due have played.
fn play<L: LibraryFrames + ?Sized>(
    player: &mut ShowPlayer<'_, L>,
    total: usize,
    chunks: &[usize],
) -> Vec<Shown> {
    let mut out = Vec::new();
    let mut sink = |t: gesture_runtime::show::ShowTick<'_>| {
        out.push((
            t.tick,
            t.pose.iter().map(|v| v.to_bits()).collect(),
            t.segment,
            t.frame,
        ))
    };
    let ticks = player.ticks_played() + 1_000_000;
    player.push(0, &mut sink);
    assert_eq!(player.ticks_played(), 1, "tick 0 is due at once");
    let mut fed = 0usize;
    let mut sizes = chunks.iter().cycle();
    while fed < total {
        let n = (*sizes.next().unwrap()).min(total - fed);
        fed += n;
        player.push(n, &mut sink);
        // Tick k is due at ceil(k * 16000 / 30) samples: floor(fed * 30 / 16000) + 1 ticks.
        let due = fed as u64 * 30 / 16_000 + 1;
        assert!(player.ticks_played() == due.min(ticks) || player.finished());
    }
    out
}

fn kinds(plays: &[(u64, PlayerCommand)]) -> [usize; 6] {
    let mut k = [0; 6];
    for (_, c) in plays {
        k[match c {
            PlayerCommand::Enter { .. } => 0,
            PlayerCommand::RunOn => 1,
            PlayerCommand::Turn => 2,
            PlayerCommand::Rate(_) => 3,
            PlayerCommand::Hold => 4,
            PlayerCommand::Gain(_) => 5,
        }] += 1;
    }
    k
}

const ODD_CHUNKS: [usize; 6] = [1, 7, 333, 1024, 59, 4801];

#[test]
fn a_show_of_a_run_over_a_hand_built_library_replays_its_poses_exactly() {
    let t = Tables::new();
    let zeros = [0u8; 8];
    let crf = CrfWeights::new(
        2,
        2,
        1,
        I16Table::new(&zeros[..4], 1e-3, 2).unwrap(),
        I16Table::new(&zeros, 1e-3, 4).unwrap(),
        I16Table::new(&zeros, 1e-3, 4).unwrap(),
    )
    .unwrap();
    let g = [GmmComponent::default(), GmmComponent::default()];
    let mut c = Controller::new(&ProsodyConfig::DEFAULT, &g, crf, &t, &Lib).unwrap();
    c.set_variety(Variety::NONE);
    c.set_follow(VoiceFollow {
        rest_ms: 500,
        rest_cost: 4.0,
        energy_cost: 1.0,
    });
    c.set_timing(DecisionTiming {
        beat_hold_ms: 150,
        ..DecisionTiming::DEFAULT
    });
    // Speech, a long pause (a rest, played to and fro), speech again.
    let samples = audio(14.0, |t| !(3.0..8.0).contains(&t));
    let run = record(&mut c, &samples, 160);
    let k = kinds(&run.plays);
    assert!(
        k[0] > 0 && k[2] > 0 && k[3] > 0 && k[4] > 0 && k[5] > 0,
        "cuts, turns, rates, holds and gains all happen: {k:?}"
    );
    let info = ShowInfo {
        blob_crc: 0,
        sample_rate_hz: 16_000,
        fps_milli: 30_000,
        ticks: run.poses.len() as u64,
    };
    let bytes = encode_show(&info, &run.plays).unwrap();
    let show = Show::parse(&bytes).unwrap();
    assert_eq!(show.ticks(), run.poses.len() as u64);
    let mut player = ShowPlayer::new(&show, &Lib, 0, 0.0).unwrap();
    let played = play(&mut player, samples.len(), &ODD_CHUNKS);
    assert_eq!(played.len(), run.poses.len());
    for (a, b) in run.poses.iter().zip(&played) {
        assert_eq!(a, b, "tick {}", a.0);
    }
    assert!(
        played.iter().any(|p| f32::from_bits(p.1[1]) == 60.0),
        "the clamp to the limits shows"
    );
}

#[test]
fn a_show_of_a_run_of_the_golden_blob_replays_its_blends_exactly() {
    let tiny = common::Tiny::new();
    let bytes = tiny.encode();
    let blob = Blob::parse(&bytes).unwrap();
    let mut c = Controller::from_blob(&blob).unwrap();
    let samples = audio(12.0, |t| !(4.0..7.0).contains(&t));
    let run = record(&mut c, &samples, 256);
    let k = kinds(&run.plays);
    assert!(k[0] > 3, "{k:?}");
    let show_bytes = encode(run.poses.len() as u64, &run.plays, &blob).unwrap();
    let show = Show::parse(&show_bytes).unwrap();
    let mut player = ShowPlayer::from_blob(&show, &blob).unwrap();
    let played = play(&mut player, samples.len(), &ODD_CHUNKS);
    assert_eq!(played, run.poses);
    // More samples after the end: nothing more, the last pose held.
    let last = player.pose().to_vec();
    player.push(1 << 20, &mut |_| panic!("a tick after the end"));
    assert_eq!(player.pose(), last);
}

/// A valid show of `plays` over `ticks` ticks of [`Lib`].
fn lib_show(ticks: u64, plays: &[(u64, PlayerCommand)]) -> Vec<u8> {
    let info = ShowInfo {
        blob_crc: 7,
        sample_rate_hz: 16_000,
        fps_milli: 30_000,
        ticks,
    };
    encode_show(&info, plays).unwrap()
}

/// Plays at most 400 ticks of `bytes` over [`Lib`] if it parses and fits; every pose finite
/// and within the limits.
fn play_bounded(bytes: &[u8]) {
    let Ok(show) = Show::parse(bytes) else {
        return;
    };
    let Ok(mut player) = ShowPlayer::new(&show, &Lib, 8, 3.0) else {
        return;
    };
    let mut n = 0;
    while n < 400 && !player.finished() {
        player.push(533, &mut |t| {
            n += 1;
            for (ch, v) in t.pose.iter().enumerate() {
                let (lo, hi, _) = LIMITS[ch];
                assert!(v.is_finite() && (lo..=hi).contains(v), "{v} on {ch}");
            }
        });
    }
}

fn command() -> impl Strategy<Value = PlayerCommand> {
    prop_oneof![
        (0u16..5, 0u16..50).prop_map(|(segment, frame)| PlayerCommand::Enter { segment, frame }),
        Just(PlayerCommand::RunOn),
        Just(PlayerCommand::Turn),
        (0.5f32..=1.5).prop_map(PlayerCommand::Rate),
        Just(PlayerCommand::Hold),
        (0.0f32..=2.0).prop_map(PlayerCommand::Gain),
    ]
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(256))]

    #[test]
    fn any_bytes_parse_or_are_refused_without_a_panic(bytes in proptest::collection::vec(any::<u8>(), 0..200)) {
        let _ = Show::parse(&bytes);
        play_bounded(&bytes);
    }

    #[test]
    fn any_commands_encode_parse_and_play_within_the_limits(
        gaps in proptest::collection::vec((0u64..20, command()), 0..60),
        extra in 1u64..200,
    ) {
        let mut tick = 0;
        let plays: Vec<(u64, PlayerCommand)> = gaps.iter().map(|&(g, c)| { tick += g; (tick, c) }).collect();
        let bytes = lib_show(tick + extra, &plays);
        let show = Show::parse(&bytes).unwrap();
        prop_assert_eq!(show.commands().collect::<Vec<_>>(), plays.clone());
        play_bounded(&bytes);
    }

    #[test]
    fn a_show_with_bytes_changed_and_its_crc_fixed_never_panics(
        gaps in proptest::collection::vec((0u64..20, command()), 1..30),
        flips in proptest::collection::vec((any::<usize>(), any::<u8>()), 1..6),
    ) {
        let mut tick = 0;
        let plays: Vec<(u64, PlayerCommand)> = gaps.iter().map(|&(g, c)| { tick += g; (tick, c) }).collect();
        let mut bytes = lib_show(tick + 5, &plays);
        let n = bytes.len() - 4;
        for (at, v) in flips {
            bytes[at % n] ^= v;
        }
        let crc = gesture_runtime::blob::crc32(&bytes[..n]);
        bytes[n..].copy_from_slice(&crc.to_le_bytes());
        play_bounded(&bytes);
    }
}
