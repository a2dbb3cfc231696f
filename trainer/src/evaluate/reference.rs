//! The hand-speed reference of `eval-motion` without a capture of the speech: the library's
//! capture in its syllables and in its pauses, weighed as the new speech has them
//! ([`speech_matched_reference`]), each taken as the character shows it
//! ([`translation_held`], [`shown_speed_histogram`]); see [`super::motion`] for why.

use gesture_runtime::prosody::{ProsodyConfig, Step, StepKind};

use super::signals::{speed_histogram, speed_histogram_where};
use super::trace::Trace;
use crate::motion::{EffectorSpec, Motion};
use crate::pack::library::hold_lower_bodies;

/// `f` of the normalized `spoken` histogram and `1 - f` of the normalized `paused` one;
/// `None` when either is empty.
pub fn mix_by_speech(spoken: &[f64], paused: &[f64], f: f64) -> Option<Vec<f64>> {
    let (zs, zp) = (spoken.iter().sum::<f64>(), paused.iter().sum::<f64>());
    (zs > 0.0 && zp > 0.0).then(|| {
        spoken
            .iter()
            .zip(paused)
            .map(|(s, p)| f * s / zs + (1.0 - f) * p / zp)
            .collect()
    })
}

/// Share of `seconds` that the syllables of `steps` cover.
fn syllable_share(steps: &[Step], seconds: f64) -> f64 {
    let spoken: f64 = steps
        .iter()
        .filter(|s| s.kind == StepKind::Syllable)
        .map(|s| s.end_s().min(seconds) - s.start_s().min(seconds))
        .sum();
    (spoken / seconds.max(1e-9)).clamp(0.0, 1.0)
}

/// `m` with every translation channel held at its first frame's value: the capture as a
/// blob's character shows it (a blob's frames hold rotations only; the character stays where
/// it is). The hands' speeds in the capture itself include the speaker walking and swaying
/// (the 067 take's root moves at a median 8.5 cm/s), which no played motion can show.
pub fn translation_held(m: &Motion) -> Motion {
    let (skeleton, frame_time, frames, mut data) = m.clone().into_parts();
    let n = skeleton.channel_count();
    let moves: Vec<usize> = skeleton
        .joints
        .iter()
        .flat_map(|j| j.channels.iter())
        .enumerate()
        .filter(|(_, c)| !c.is_rotation())
        .map(|(k, _)| k)
        .collect();
    if n > 0 && data.len() >= n {
        let (first, rest) = data.split_at_mut(n);
        for row in rest.chunks_mut(n) {
            for &k in &moves {
                row[k] = first[k];
            }
        }
    }
    Motion::new(skeleton, frame_time, frames, data)
        .map(|held| held.with_source(m.source()))
        .unwrap_or_else(|_| m.clone())
}

/// The hands' speed histogram of a capture as a blob's character shows it: the lower body
/// held as `pack` holds a library's, then [`translation_held`]. The reference of a run
/// against its speech's own capture (`eval-motion --mocap`, `gesture-sim metrics --mocap`).
pub fn shown_speed_histogram(m: &Motion, effectors: &EffectorSpec) -> Result<Vec<f64>, String> {
    let mut held = [m.clone()];
    hold_lower_bodies(&mut held, effectors);
    let t = Trace::from_motion(&translation_held(&held[0]), effectors, Vec::new())?;
    Ok(speed_histogram(&t.hands, t.fps))
}

/// What the library's character does in speech like the new speech, as the reference of the
/// hands' speeds when the speech has no capture of its own: the library's capture split
/// into the frames spoken in syllables and those in pauses (its own speech, the WAV beside
/// each BVH, through the blob's front-end), the two histograms weighted by the share of the
/// new speech in syllables. People gesture while they speak and rest while they pause, so a
/// take with long pauses is not what the same person does through a monologue. When a take
/// has no speech beside it (a gesture library of clips), the library's whole capture.
pub fn speech_matched_reference(
    lib: &crate::control::library::Library,
    config: &ProsodyConfig,
    rate: u32,
    steps: &[Step],
    seconds: f64,
    effectors: &EffectorSpec,
) -> Vec<f64> {
    // The takes as the blob's character shows them (pack has held the library's lower
    // bodies already).
    let shown: Vec<Vec<Vec<[f64; 3]>>> = lib
        .takes
        .iter()
        .map(|t| {
            Trace::from_motion(&translation_held(&t.motion), effectors, Vec::new())
                .map(|tr| tr.hands)
                .unwrap_or_else(|_| {
                    let pos = &t.analysis.positions;
                    (0..pos.frames()).map(|f| pos.frame(f).to_vec()).collect()
                })
        })
        .collect();
    let whole = || speed_histogram(&shown.concat(), lib.fps);
    let mut spoken = vec![0.0; 26];
    let mut paused = vec![0.0; 26];
    for (t, hands) in lib.takes.iter().zip(&shown) {
        let wav = t.source.with_extension("wav");
        let Ok(pcm) = crate::audio::load_wav_at(&wav, rate) else {
            return whole();
        };
        let Ok((_, own)) = crate::features::prosody_of(&pcm.samples, config) else {
            return whole();
        };
        // Syllable spans in time order (steps tile the speech in order).
        let spans: Vec<(f64, f64)> = own
            .iter()
            .filter(|s| s.kind == StepKind::Syllable)
            .map(|s| (s.start_s(), s.end_s()))
            .collect();
        let in_syllable = |time: f64| {
            let k = spans.partition_point(|&(a, _)| a <= time);
            k > 0 && time < spans[k - 1].1
        };
        let fps = t.motion.fps();
        // Each take weighs by its frames in syllables and in pauses.
        let frame_steps = hands.len().saturating_sub(1);
        let n_spoken = (0..frame_steps)
            .filter(|&i| in_syllable((i + 1) as f64 / fps))
            .count() as f64;
        let hs = speed_histogram_where(hands, fps, in_syllable);
        let hp = speed_histogram_where(hands, fps, |time| !in_syllable(time));
        for k in 0..26 {
            spoken[k] += n_spoken * hs[k];
            paused[k] += (frame_steps as f64 - n_spoken) * hp[k];
        }
    }
    mix_by_speech(&spoken, &paused, syllable_share(steps, seconds)).unwrap_or_else(whole)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_capture_as_shown_keeps_its_rotations_and_drops_its_walk() {
        // A root walking 3 units per frame along X and turning 10 degrees per frame about Y,
        // with an arm of length 2 along X: in the capture the hand moves by the walk plus
        // the turn; held, only by the turn (a chord of 2 sin(5 deg) * 2 per frame).
        let text = "HIERARCHY\nROOT Hips\n{\n\tOFFSET 0 0 0\n\tCHANNELS 6 Xposition Yposition \
                    Zposition Zrotation Yrotation Xrotation\n\tJOINT RightHand\n\t{\n\t\t\
                    OFFSET 2 0 0\n\t\tCHANNELS 3 Zrotation Xrotation Yrotation\n\t\tEnd Site\n\
                    \t\t{\n\t\t\tOFFSET 0 0 0\n\t\t}\n\t}\n}\nMOTION\nFrames: 3\n\
                    Frame Time: 0.1\n0 5 0 0 0 0 0 0 0\n3 5 0 0 10 0 0 0 0\n6 5 0 0 20 0 0 0 0\n";
        let m = crate::motion::parse_bvh(text, "walk.bvh").unwrap();
        let held = translation_held(&m);
        assert_eq!(held.source(), "walk.bvh");
        for f in 0..3 {
            let (a, b) = (m.frame(f).unwrap(), held.frame(f).unwrap());
            // Translations are the first frame's; rotations untouched.
            assert_eq!(&b[..3], &[0.0, 5.0, 0.0]);
            assert_eq!(&b[3..], &a[3..]);
        }
        let hand = |mo: &Motion, f: usize| {
            let p = crate::motion::FkPlan::new(mo.skeleton(), &[crate::motion::Target::Joint(1)])
                .unwrap()
                .positions(mo)
                .unwrap();
            p.frame(f)[0]
        };
        let step = |mo: &Motion| {
            let (p, q) = (hand(mo, 1), hand(mo, 2));
            ((p[0] - q[0]).powi(2) + (p[1] - q[1]).powi(2) + (p[2] - q[2]).powi(2)).sqrt()
        };
        let chord = 2.0 * 2.0 * (5.0f64.to_radians()).sin();
        assert!((step(&held) - chord).abs() < 1e-9, "{}", step(&held));
        assert!(step(&m) > 2.5, "the walk is in the capture: {}", step(&m));
    }

    #[test]
    fn the_speech_matched_reference_weighs_speech_and_pauses_as_the_new_speech_has_them() {
        // Hands still in the capture's pauses (bin 0) and at 55 units/s in its syllables
        // (bin 5), in any proportion: new speech spoken 70 % of its time gets 0.7 in bin 5.
        let mut spoken = vec![0.0; 26];
        let mut paused = vec![0.0; 26];
        spoken[5] = 300.0;
        paused[0] = 900.0;
        let r = mix_by_speech(&spoken, &paused, 0.7).unwrap();
        assert!((r[5] - 0.7).abs() < 1e-12 && (r[0] - 0.3).abs() < 1e-12);
        assert!((r.iter().sum::<f64>() - 1.0).abs() < 1e-12);
        // A capture without pauses (or without speech) cannot be split.
        assert_eq!(mix_by_speech(&spoken, &[0.0; 26], 0.7), None);
        // Syllables of 0.5 s and 1 s and a pause step of 0.5 s in 4 s of speech: 3/8 spoken.
        let step = |kind, a: u32, b: u32| Step {
            kind,
            start_frame: a,
            end_frame: b,
            f0_hz: None,
            intensity_db: 60.0,
        };
        let steps = [
            step(StepKind::Syllable, 0, 50),
            step(StepKind::Pause, 50, 100),
            step(StepKind::Syllable, 100, 200),
        ];
        assert!((syllable_share(&steps, 4.0) - 0.375).abs() < 1e-12);
        // Past the end of the audio nothing counts: 0.5 s + 0.5 s of 1.5 s.
        assert!((syllable_share(&steps, 1.5) - 2.0 / 3.0).abs() < 1e-12);
    }
}
