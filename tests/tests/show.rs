//! Show files across the crates: a blob packed by the trainer from its synthetic corpus, its
//! controller run on speech it never saw (a held-out synthetic take; and the shared real
//! recordings when they are present), every `Play` command and pose collected; the show
//! encoded from the commands, parsed, and played by the runtime's `ShowPlayer` fed the same
//! number of samples in odd chunks: the poses are the controller's, bit for bit, tick for
//! tick.

#[path = "../../trainer/tests/common/mod.rs"]
mod common;

use std::path::Path;

use gesture_runtime::blob::Blob;
use gesture_runtime::controller::{BlobController, ControllerEvent};
use gesture_runtime::player::PlayerCommand;
use gesture_runtime::show::{encode, Show, ShowPlayer};
use gesture_trainer::audio::load_wav_at;
use gesture_trainer::pack::{pack_model, PackOptions};
use gesture_trainer::synth::{write_corpus, SynthParams};

/// A pose as its bits, with the tick, segment and frame.
type Pose = (u64, Vec<u32>, usize, usize);

/// The blob packed from a small synthetic corpus (the trainer's defaults: variety, following
/// the voice, decisions on onsets), as bytes.
fn synthetic_blob(dir: &Path) -> Vec<u8> {
    let corpus = common::small_corpus(dir, 5);
    let model = common::small_model(&corpus);
    let mut bvh: Vec<_> = std::fs::read_dir(&corpus)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|x| x == "bvh"))
        .collect();
    bvh.sort();
    pack_model(&model, &bvh, &PackOptions::default())
        .unwrap()
        .bytes
}

/// The controller of `blob` over `samples` in 10 ms chunks: its poses and its commands.
fn controller_run(blob: &Blob<'_>, samples: &[i16]) -> (Vec<Pose>, Vec<(u64, PlayerCommand)>) {
    let mut slot = Box::new(None);
    let c = BlobController::from_blob_in(&mut slot, blob).unwrap();
    let (mut poses, mut plays) = (Vec::new(), Vec::new());
    let mut sink = |e: ControllerEvent<'_>| match e {
        ControllerEvent::Pose {
            tick,
            pose,
            segment,
            frame,
        } => poses.push((
            tick,
            pose.iter().map(|v| v.to_bits()).collect(),
            segment,
            frame,
        )),
        ControllerEvent::Play { tick, command } => plays.push((tick, command)),
        _ => {}
    };
    let chunk = (blob.prosody_config().sample_rate_hz / 100) as usize;
    for ch in samples.chunks(chunk) {
        c.push(ch, &mut sink);
    }
    c.finish(&mut sink);
    (poses, plays)
}

/// Bakes and replays the run of `blob` over `samples`; returns the commands' count.
fn bake_and_replay(blob_bytes: &[u8], samples: &[i16]) -> usize {
    let blob = Blob::parse(blob_bytes).unwrap();
    let (poses, plays) = controller_run(&blob, samples);
    assert!(poses.len() > 100, "{} ticks", poses.len());
    let bytes = encode(poses.len() as u64, &plays, &blob).unwrap();
    let show = Show::parse(&bytes).unwrap();
    assert_eq!(show.ticks(), poses.len() as u64);
    let mut player = ShowPlayer::from_blob(&show, &blob).unwrap();
    let mut played: Vec<Pose> = Vec::new();
    let mut sink = |t: gesture_runtime::show::ShowTick<'_>| {
        played.push((
            t.tick,
            t.pose.iter().map(|v| v.to_bits()).collect(),
            t.segment,
            t.frame,
        ))
    };
    let mut fed = 0usize;
    for n in [1usize, 97, 160, 1023, 4410, 3, 2048].iter().cycle() {
        if fed >= samples.len() {
            break;
        }
        let n = (*n).min(samples.len() - fed);
        player.push(n, &mut sink);
        fed += n;
    }
    assert_eq!(played.len(), poses.len(), "as many ticks as the controller");
    for (a, b) in poses.iter().zip(&played) {
        assert_eq!(a, b, "tick {}", a.0);
    }
    show.header().commands as usize
}

#[test]
fn a_baked_show_of_synthetic_speech_replays_the_controller_bit_for_bit() {
    let dir = tempfile::tempdir().unwrap();
    let blob = synthetic_blob(dir.path());
    let rate = Blob::parse(&blob).unwrap().prosody_config().sample_rate_hz;
    // Held out: another seed's speech.
    let held = dir.path().join("held");
    std::fs::create_dir_all(&held).unwrap();
    let p = SynthParams {
        minutes: 0.5,
        seed: 77,
        take_seconds: 30.0,
    };
    write_corpus(&p, &held, |_, _| {}).unwrap();
    let pcm = load_wav_at(held.join("take_000.wav"), rate).unwrap();
    let commands = bake_and_replay(&blob, &pcm.samples);
    eprintln!("synthetic: {commands} commands replayed");
    assert!(commands > 10, "{commands} commands");
}

#[test]
fn a_baked_show_of_real_speech_replays_the_controller_bit_for_bit() {
    const TEST: &str = "a_baked_show_of_real_speech_replays_the_controller_bit_for_bit";
    let Some(scott) = e2e_tests::shared_data(TEST, "beat-scott") else {
        return;
    };
    let dir = tempfile::tempdir().unwrap();
    let blob = synthetic_blob(dir.path());
    let rate = Blob::parse(&blob).unwrap().prosody_config().sample_rate_hz;
    let pcm = load_wav_at(scott.join("2_scott_0_1_1.wav"), rate).unwrap();
    let commands = bake_and_replay(&blob, &pcm.samples);
    eprintln!("beat-scott: {commands} commands replayed");
    assert!(commands > 10, "{commands} commands");
}
