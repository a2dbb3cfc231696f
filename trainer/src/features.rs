//! Prosody features for training, computed by the runtime's own front-end.
//!
//! This is the one place host code computes prosody: [`prosody_of`] feeds samples to
//! [`gesture_runtime::prosody::FrontEnd`] and collects what it reports. Nothing here
//! re-implements pitch, intensity or syllable detection, so training features and device
//! features cannot drift apart (docs/method.md, "Workspace").
//!
//! Allocates the two output vectors; never panics.

use gesture_runtime::prosody::arith::{Arith, DefaultArith};
use gesture_runtime::prosody::{ConfigError, Event, Frame, FrontEnd, ProsodyConfig, Step};

/// Runs the front-end over a whole stream (`samples` at `config.sample_rate_hz`): pushes
/// everything, then ends the stream, and returns every frame and every step (syllables and
/// pauses) in the order the front-end reported them.
pub fn prosody_of(
    samples: &[i16],
    config: &ProsodyConfig,
) -> Result<(Vec<Frame>, Vec<Step>), ConfigError> {
    prosody_of_arith::<DefaultArith>(samples, config)
}

/// [`prosody_of`] with the front-end arithmetic `A` (`f32` or the fixed-point front-end of
/// boards without an FPU), for evaluations that compare the two; training uses the default.
pub fn prosody_of_arith<A: Arith>(
    samples: &[i16],
    config: &ProsodyConfig,
) -> Result<(Vec<Frame>, Vec<Step>), ConfigError> {
    let mut fe = FrontEnd::<A>::with_arith(config)?;
    let mut frames = Vec::with_capacity(samples.len() / (config.sample_rate_hz as usize / 100) + 1);
    let mut steps = Vec::new();
    let mut sink = |ev: Event| match ev {
        Event::Frame(f) => frames.push(f),
        Event::Step(s) => steps.push(s),
        Event::Onset(_) => {}
    };
    fe.push(samples, &mut sink);
    fe.finish(&mut sink);
    Ok((frames, steps))
}

#[cfg(test)]
mod tests {
    use super::*;
    use gesture_runtime::prosody::StepKind;

    #[test]
    fn one_frame_per_hop_and_steps_in_order() {
        // 1 s of a 150 Hz tone, loud then silent.
        let rate = 16_000;
        let x: Vec<i16> = (0..rate)
            .map(|i| {
                let t = i as f32 / rate as f32;
                let a = if t < 0.5 { 8000.0 } else { 0.0 };
                (a * (2.0 * std::f32::consts::PI * 150.0 * t).sin()) as i16
            })
            .collect();
        let (frames, steps) = prosody_of(&x, &ProsodyConfig::DEFAULT).unwrap();
        assert_eq!(frames.len(), 100);
        assert!(frames
            .iter()
            .enumerate()
            .all(|(i, f)| f.index == i as u32 + 1));
        let voiced: Vec<f32> = frames[10..40].iter().filter_map(|f| f.f0_hz).collect();
        assert!(voiced.len() >= 25, "{} voiced", voiced.len());
        assert!(voiced.iter().all(|f| (f - 150.0).abs() < 3.0), "{voiced:?}");
        assert!(steps.windows(2).all(|w| w[0].end_frame <= w[1].start_frame));
        assert!(steps.iter().any(|s| s.kind == StepKind::Syllable));
    }

    #[test]
    fn refuses_bad_config() {
        let mut c = ProsodyConfig::DEFAULT;
        c.sample_rate_hz = 44_100;
        assert!(prosody_of(&[0; 10], &c).is_err());
    }
}
