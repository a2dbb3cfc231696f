//! The bake on a small synthetic corpus, and its bookkeeping on known answers.

use super::*;
use crate::corpus::{load_corpus, LoadOptions};
use crate::inference::train::{fit, sequences, FitConfig};
use crate::pack::{pack_model, PackOptions};
use crate::synth::{write_corpus, SynthParams};
use gesture_runtime::policy::DecisionTiming;

/// A blob packed from a synthetic corpus, and the speech of its first take.
fn blob_and_speech() -> (Vec<u8>, Vec<i16>) {
    blob_and_speech_with(&PackOptions::default())
}

/// [`blob_and_speech`] packed with `opts`.
fn blob_and_speech_with(opts: &PackOptions) -> (Vec<u8>, Vec<i16>) {
    let dir = tempfile::tempdir().unwrap();
    let params = SynthParams {
        minutes: 1.0,
        seed: 7,
        take_seconds: 30.0,
    };
    write_corpus(&params, dir.path(), |_, _| {}).unwrap();
    let c = load_corpus(&[dir.path().to_path_buf()], &LoadOptions::default()).unwrap();
    let (seqs, segs) = sequences(&c, None);
    let cfg = FitConfig {
        states: Some(2),
        clusters: Some(2),
        restarts: 1,
        l2: Some(1e-2),
        ..FitConfig::default()
    };
    let (model, _) = fit(&seqs, &segs, &cfg, &|_| {}).unwrap();
    let packed = pack_model(&model, &[dir.path().to_path_buf()], opts).unwrap();
    let mut wavs: Vec<_> = std::fs::read_dir(dir.path())
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|x| x == "wav"))
        .collect();
    wavs.sort();
    let speech = crate::audio::load_wav_at(&wavs[0], model.sample_rate_hz)
        .unwrap()
        .samples;
    (packed.bytes, speech)
}

/// Up to 12 s of `speech`, `silence` samples of silence, the same speech again; and where the
/// silence starts and where the speech returns (samples).
fn speech_silence_speech(speech: &[i16], rate: usize, silence: usize) -> (Vec<i16>, usize, usize) {
    let half = speech.len().min(12 * rate);
    let mut audio = speech[..half].to_vec();
    audio.resize(half + silence, 0);
    audio.extend_from_slice(&speech[..half]);
    (audio, half, half + silence)
}

/// The tick of sample `sample` for `blob` (rounded down).
fn tick_of(blob: &Blob<'_>, sample: usize) -> usize {
    let rate = blob.prosody_config().sample_rate_hz as u64;
    let fps_milli = (blob.fps() * 1000.0).round() as u64;
    (sample as u64 * fps_milli / (rate * 1000)) as usize
}

/// Mean change of the pose per tick (degrees over channels) over a span of ticks.
fn mean_step(poses: &[BakedPose], span: std::ops::Range<usize>) -> f64 {
    let n = span.len() as f64;
    span.map(|k| pose_step(poses, k)).sum::<f64>() / n
}

/// The ticks `speech` spans for `blob` and its timeline.
fn timeline(blob: &Blob<'_>, speech: &[i16]) -> (u64, Timeline) {
    let rate = blob.prosody_config().sample_rate_hz;
    let fps_milli = (blob.fps() * 1000.0).round() as u64;
    let ticks = ticks_of(speech.len(), rate, fps_milli);
    (ticks, Timeline::of(blob, speech, ticks as usize).unwrap())
}

/// How much the pose changes from tick `k - 1` to tick `k` (degrees, summed over channels).
fn pose_step(poses: &[BakedPose], k: usize) -> f64 {
    poses[k]
        .pose
        .iter()
        .zip(&poses[k - 1].pose)
        .map(|(a, b)| (a - b).abs() as f64)
        .sum()
}

/// The beat kernel (width `sigma`, ticks) of tick `t`'s distance to the nearest onset.
fn onset_kernel(onsets: &[f64], t: f64, sigma: f64) -> f64 {
    let d = onsets
        .iter()
        .map(|&o| (o - t).abs())
        .fold(f64::INFINITY, f64::min);
    (-0.5 * (d / sigma).powi(2)).exp()
}

/// Mean over the library strokes shown of the beat kernel (sigma 0.1 s) to the nearest onset.
fn stroke_alignment(blob: &Blob<'_>, poses: &[BakedPose], onsets: &[f64], fps_milli: u64) -> f64 {
    let sigma = 0.1 * fps_milli as f64 / 1000.0;
    let mut v = Vec::new();
    for (k, p) in poses.iter().enumerate() {
        let prev = k.checked_sub(1).map(|j| (poses[j].segment, poses[j].frame));
        if blob.is_peak(p.segment, p.frame) && prev != Some((p.segment, p.frame)) {
            v.push(onset_kernel(onsets, k as f64, sigma));
        }
    }
    assert!(v.len() >= 5, "too few strokes shown: {}", v.len());
    v.iter().sum::<f64>() / v.len() as f64
}

/// Speech, then four seconds of silence, then speech: the baked body moves far less in the
/// silence than in the speech; the run is as long as the audio and its show plays it.
#[test]
fn a_baked_run_rests_in_a_silence() {
    let (bytes, speech) = blob_and_speech();
    let blob = Blob::parse(&bytes).unwrap();
    let rate = blob.prosody_config().sample_rate_hz as usize;
    let (audio, silence_at, _) = speech_silence_speech(&speech, rate, 4 * rate);
    let baked = bake(&blob, &audio).unwrap();
    let fps_milli = (blob.fps() * 1000.0).round() as u64;
    assert_eq!(baked.ticks, ticks_of(audio.len(), rate as u32, fps_milli));
    assert!(baked.commands.windows(2).all(|w| w[0].0 <= w[1].0));
    let poses = baked.play(&blob).unwrap();
    assert_eq!(poses.len() as u64, baked.ticks);
    // Running on into the recorded successor (no blend) only ever follows its segment's
    // last frames, played forward: never a rest played to and fro.
    for &(k, c) in &baked.commands {
        if c == PlayerCommand::RunOn && k > 0 && (k as usize) < poses.len() {
            let before = &poses[k as usize - 1];
            let len = blob.segment_len(before.segment);
            assert!(
                before.frame + 3 >= len && poses[k as usize].segment == before.segment + 1,
                "run-on at tick {k} from frame {} of {len}",
                before.frame
            );
        }
    }
    let tick = |sample: usize| tick_of(&blob, sample);
    let speed = |span: std::ops::Range<usize>| mean_step(&poses, span);
    // From 1.5 s into the silence to its end, against the speech before it.
    let quiet = speed(tick(silence_at + 3 * rate / 2)..tick(silence_at + 4 * rate));
    let speaking = speed(tick(rate)..tick(silence_at));
    assert!(
        quiet < 0.4 * speaking,
        "the pose moves {quiet:.2} per tick in the silence, {speaking:.2} in speech"
    );
}

/// The stroke term is what lands strokes on syllables: the same speech baked without it puts
/// the library's strokes further from the onsets.
#[test]
fn the_stroke_term_lands_strokes_on_onsets() {
    let (bytes, speech) = blob_and_speech();
    let blob = Blob::parse(&bytes).unwrap();
    let (_, tl) = timeline(&blob, &speech);
    let fps_milli = (blob.fps() * 1000.0).round() as u64;
    assert!(tl.onsets.len() >= 20, "{} onsets", tl.onsets.len());
    let with = bake(&blob, &speech).unwrap().play(&blob).unwrap();
    let off = Weights {
        stroke_gain: 0.0,
        ..Weights::default()
    };
    let without = bake_with(&blob, &speech, &off)
        .unwrap()
        .play(&blob)
        .unwrap();
    let (a, b) = (
        stroke_alignment(&blob, &with, &tl.onsets, fps_milli),
        stroke_alignment(&blob, &without, &tl.onsets, fps_milli),
    );
    assert!(a > b + 0.05, "with the stroke term {a:.3}, without {b:.3}");
}

/// The blend term is what puts the hands' speed peak after a cut on a syllable: baked
/// without it, the ticks `BLEND_PEAK_S` after its cuts into gestures lie further from onsets.
#[test]
fn the_blend_term_puts_the_peak_after_a_cut_on_an_onset() {
    let (bytes, speech) = blob_and_speech();
    let blob = Blob::parse(&bytes).unwrap();
    let (_, tl) = timeline(&blob, &speech);
    let fps = blob.fps() as f64;
    let (lag, sigma) = (plan::BLEND_PEAK_S * fps, plan::STROKE_SIGMA_S * fps);
    let after_cuts = |w: &Weights| -> f64 {
        let b = bake_with(&blob, &speech, w).unwrap();
        let rests = RestSet::of(&blob, blob.segment_count());
        let peaks: Vec<f64> = b
            .commands
            .iter()
            .filter_map(|&(k, c)| match c {
                PlayerCommand::Enter { segment, .. } if !rests.contains(segment as usize) => {
                    Some(k as f64 + lag)
                }
                _ => None,
            })
            .collect();
        assert!(peaks.len() >= 5, "{} cuts", peaks.len());
        peaks
            .iter()
            .map(|&t| onset_kernel(&tl.onsets, t, sigma))
            .sum::<f64>()
            / peaks.len() as f64
    };
    let with = after_cuts(&Weights::default());
    let without = after_cuts(&Weights {
        blend_gain: 0.0,
        ..Weights::default()
    });
    assert!(
        with > without + 0.05,
        "blend peaks on onsets: with the term {with:.3}, without {without:.3}"
    );
}

/// The cut term is what puts cuts where the body is still: planned without it, the pose moves
/// more at the ticks its cuts show (one plan each, without the variety lines' prices, whose
/// ascent plans again and moves cuts for its own reasons).
#[test]
fn the_cut_term_puts_cuts_where_the_body_is_still() {
    let (bytes, speech) = blob_and_speech();
    let blob = Blob::parse(&bytes).unwrap();
    let (ticks, tl) = timeline(&blob, &speech);
    let at_cuts = |w: &Weights| -> f64 {
        let (plan, cost) = plan::plan(&blob, &tl, w, &[]);
        let b = Baked::of(&blob, plan, cost, &tl, ticks);
        let poses = b.play(&blob).unwrap();
        let cuts: Vec<usize> = b
            .commands
            .iter()
            .filter(|(_, c)| matches!(c, PlayerCommand::Enter { .. }))
            .map(|&(k, _)| k as usize)
            .filter(|&k| k >= 1 && k < poses.len())
            .collect();
        assert!(cuts.len() >= 5, "{} cuts", cuts.len());
        cuts.iter().map(|&k| pose_step(&poses, k)).sum::<f64>() / cuts.len() as f64
    };
    let with = at_cuts(&Weights::default());
    let without = at_cuts(&Weights {
        cut_cost: 0.0,
        ..Weights::default()
    });
    assert!(
        with < 0.8 * without,
        "motion at cuts: with the cut term {with:.2}, without {without:.2}"
    );
}

/// After a rest (played to and fro), entering the rest's recorded successor is a cut, not a
/// run-on (which would jump from wherever the rest stands to the successor's first frame
/// without a blend); from the end of a segment played forward it is a run-on.
#[test]
fn a_rest_is_left_by_a_cut_and_a_segment_end_runs_on() {
    let (bytes, _) = blob_and_speech();
    let blob = Blob::parse(&bytes).unwrap();
    let r = (0..blob.segments() - 1)
        .find(|&c| blob.continues(c) && blob.segment_len(c) > 20)
        .expect("a segment with a recorded successor");
    let end = blob.exits_of(r).end - 1;
    let d = |tick, act, until| Planned {
        tick,
        exit: end,
        act,
        until,
        candidates: 1,
        cost: 0.0,
    };
    let next = Act::Enter {
        segment: r + 1,
        rate: 1.0,
    };
    let after_rest = commands(
        &blob,
        &[d(10, Act::Rest { segment: r }, 20), d(20, next, 0)],
        40,
        &[],
    );
    assert!(after_rest.contains(&(
        21,
        PlayerCommand::Enter {
            segment: (r + 1) as u16,
            frame: 0
        }
    )));
    assert!(!after_rest.iter().any(|&(_, c)| c == PlayerCommand::RunOn));
    // Entered at tick 10 and played forward to its last frame, then on into the successor.
    let len = blob.segment_len(r) as u64;
    let enter = Act::Enter {
        segment: r,
        rate: 1.0,
    };
    let played = commands(
        &blob,
        &[d(10, enter, 0), d(10 + len, next, 0)],
        len + 30,
        &[],
    );
    assert!(
        played.contains(&(11 + len, PlayerCommand::RunOn)),
        "{played:?}"
    );
}

/// Tick `k` is due at `ceil(k * rate * 1000 / fps_milli)` samples: one second at 16 kHz and
/// 30 fps holds ticks 0..=30; one sample less, 0..=29.
#[test]
fn ticks_of_counts_the_ticks_due() {
    assert_eq!(ticks_of(16_000, 16_000, 30_000), 31);
    assert_eq!(ticks_of(15_999, 16_000, 30_000), 30);
    assert_eq!(ticks_of(0, 16_000, 30_000), 1);
    assert_eq!(ticks_of(100, 0, 30_000), 0);
}

/// The synthetic library has 88 segments and the first take's speech room for about 50
/// entries. Planned with no prices, the file plays under a third of the library (the live
/// costs only discourage repeats); baked, the variety lines' prices bring it to half, with no
/// segment over the cap.
#[test]
fn the_bake_plays_half_the_library_where_the_speech_has_room() {
    let (bytes, speech) = blob_and_speech();
    let blob = Blob::parse(&bytes).unwrap();
    let (ticks, tl) = timeline(&blob, &speech);
    let n = LibraryFrames::segment_count(&blob);
    let (free, _) = plan::plan(&blob, &tl, &Weights::default(), &vec![0.0; n]);
    let free = Played::of(&free, 0, ticks, n);
    assert_eq!(free.distinct_target(), DISTINCT_MIN, "{free:?}");
    assert!(free.distinct() < 0.4, "the free plan: {}", free.distinct());
    let baked = Played::of(&bake(&blob, &speech).unwrap().plan, 0, ticks, n);
    assert!(
        baked.distinct() >= DISTINCT_MIN,
        "baked: {}",
        baked.distinct()
    );
    assert!(baked.largest() <= SHARE_CAP, "baked: {}", baked.largest());
}

/// A file that opens with speech: the plan may leave segment 0 at the first syllable, not
/// only at its first exit point (as live, where before anyone has spoken the first syllable
/// is the speech's return and decides at once). Priced out (as the variety ascent prices a
/// segment over its share), segment 0 is left there. (Cuts at once: the synthetic segment 0
/// has no pause of the hands before its first exit point.)
#[test]
fn a_plan_can_leave_the_first_segment_at_the_first_syllable() {
    let opts = PackOptions {
        timing: DecisionTiming {
            defer_cut_ms: 0,
            ..DecisionTiming::DEFAULT
        },
        ..PackOptions::default()
    };
    let (bytes, speech) = blob_and_speech_with(&opts);
    let blob = Blob::parse(&bytes).unwrap();
    // The speech from 0.1 s before its first syllable.
    let (_, whole) = timeline(&blob, &speech);
    let rate = blob.prosody_config().sample_rate_hz as f64;
    let fps = blob.fps() as f64;
    let lead = ((whole.onsets[0] / fps - 0.1).max(0.0) * rate) as usize;
    let (_, tl) = timeline(&blob, &speech[lead..]);
    let first = tl.onsets[0];
    let e0 = blob.exit_frame(blob.first_exit(0)) as f64;
    assert!(
        first + 8.0 < e0,
        "first onset at tick {first}, segment 0's exit at {e0}"
    );
    let mut prices = vec![0.0f32; LibraryFrames::segment_count(&blob)];
    prices[0] = 100.0;
    let (planned, _) = plan::plan(&blob, &tl, &Weights::default(), &prices);
    let cut = planned
        .iter()
        .find(|p| matches!(p.act, plan::Act::Enter { .. } | plan::Act::Rest { .. }))
        .unwrap();
    assert!(
        cut.tick as f64 <= first,
        "first cut at tick {}, onset {first}",
        cut.tick
    );
}

/// Speech, a silence of 2.5, 3 or 3.5 s, speech: from half a second after the speech's return
/// no rest segment shows and the baked body moves at least 0.4 times as much as in the speech
/// before. (Half, while a rest's posture was blended in at a gesture's pace: the way back out
/// of it added the arms' travel; a rest now holds the gesture's posture, and on the 3 s
/// silence the same plan moved 1.05 times as much before and 0.49 times after.) A calm segment pays the
/// rest cost for every tick it plays while the voice speaks, whether chosen in the speech or
/// in the silence before it: charged only when chosen in the speech, a rest chosen at an exit
/// point just before the return played on through 0.5-1.5 s after it at 0.39 of the speech's
/// motion (and on beat-scott held the hands still for 3 s of speech).
#[test]
fn the_baked_body_moves_again_when_the_speech_returns() {
    let (bytes, speech) = blob_and_speech();
    let blob = Blob::parse(&bytes).unwrap();
    let rate = blob.prosody_config().sample_rate_hz as usize;
    let tick = |sample: usize| tick_of(&blob, sample);
    let mut worst = f64::INFINITY;
    for silence in [5 * rate / 2, 3 * rate, 7 * rate / 2] {
        let (audio, half, back) = speech_silence_speech(&speech, rate, silence);
        let (_, tl) = timeline(&blob, &audio);
        let poses = bake(&blob, &audio).unwrap().play(&blob).unwrap();
        let speed = |span: std::ops::Range<usize>| mean_step(&poses, span);
        let speaking = speed(tick(rate)..tick(half));
        let from = tick(back + rate / 2);
        let after = speed(from..from + tick(rate));
        assert!(!tl.resting_at(from), "the speech has returned at {from}");
        let rests = RestSet::of(&blob, LibraryFrames::segment_count(&blob));
        let shown = &poses[from..from + tick(rate)];
        assert!(
            shown.iter().all(|p| !rests.contains(p.segment)),
            "a rest shown in the speech"
        );
        worst = worst.min(after / speaking);
    }
    assert!(
        worst > 0.4,
        "after the speech returns: {worst:.2} of the speech's motion"
    );
}
