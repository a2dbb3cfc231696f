//! What the whole file says at every animation tick: the belief, the voice (resting, energy
//! weight) and the syllable onsets, all from the runtime's own code run over the audio.
//!
//! The blob's controller is run live over the samples (its front-end, step normalizer and
//! belief are the board's) and its reports are put back at the speech's own time, as the
//! look-ahead controller puts them (`runtime::controller::Lookahead`): a step's voice effect
//! at its end, an onset at its frame, both `VOICE_LEAD_MS` early; the belief of the step
//! being spoken at every tick. The voice is followed by the runtime's [`Voice`].

use gesture_runtime::blob::Blob;
use gesture_runtime::controller::{BlobController, ControllerEvent};
use gesture_runtime::follow::{Expressive, Voice, VoiceFollow};
use gesture_runtime::inference::StepNormalizer;
use gesture_runtime::prosody::StepKind;

use super::error::BakeError;

/// How long before the speech the voice acts (ms): the look-ahead controller's default.
pub const VOICE_LEAD_MS: u32 = 250;

/// The whole file, tick by tick.
#[derive(Clone, Debug)]
pub struct Timeline {
    /// Animation ticks the audio spans.
    pub ticks: usize,
    /// The library's frame rate in thousandths, as the controller rounds it.
    pub fps_milli: u64,
    /// Per tick: resting (the voice's pause reached `rest_ms`).
    pub resting: Vec<bool>,
    /// Per tick: the voice's energy weight of a decision (`follow::Voice::weight`).
    pub weight: Vec<f32>,
    /// Per tick: the expression gain the voice asks for (`follow::Voice::gain`), with a rest
    /// segment playing and (the second) with a gesture playing.
    pub gain: Vec<(f32, f32)>,
    /// Per tick: index into `beliefs` of the step spoken then.
    pub belief_at: Vec<usize>,
    /// The belief after each step (at least one: the uniform belief when there is no step).
    pub beliefs: Vec<Vec<f32>>,
    /// Syllable starts (ticks, fractional), sorted.
    pub onsets: Vec<f64>,
}

/// The tick at which 10 ms frame `frame` starts (as the controller's look-ahead rounds it).
fn frame_tick(frame: u32, fps_milli: u64) -> u64 {
    (frame as u64 * fps_milli + 50_000) / 100_000
}

/// A voice effect at its tick.
#[derive(Clone, Copy, Debug)]
enum Item {
    Step { pause: bool, level: f32 },
    Onset,
}

impl Timeline {
    /// The timeline of `samples` (at the blob's rate) for `blob`, `ticks` ticks long.
    pub fn of(blob: &Blob<'_>, samples: &[i16], ticks: usize) -> Result<Self, BakeError> {
        let mut slot = Box::new(None);
        let controller = BlobController::from_blob_in(&mut slot, blob)
            .map_err(|e| BakeError::Blob(e.to_string()))?;
        let fps_milli = (blob.fps() * 1000.0).round() as u64;
        let lead = VOICE_LEAD_MS as u64 * fps_milli / 1_000_000;
        let states = blob.states().max(1);
        let mut norm = StepNormalizer::new();
        // (due tick, report order, effect), steps as (start tick, belief).
        let mut items: Vec<(u64, usize, Item)> = Vec::new();
        let mut steps: Vec<(u64, Vec<f32>)> = Vec::new();
        let mut onsets = Vec::new();
        let mut sink = |ev: ControllerEvent<'_>| match ev {
            ControllerEvent::Step { step, belief } => {
                let x = norm.push(&step);
                let at = frame_tick(step.end_frame, fps_milli).saturating_sub(lead);
                let n = items.len();
                items.push((
                    at,
                    n,
                    Item::Step {
                        pause: x.pause,
                        level: x.obs[0],
                    },
                ));
                steps.push((frame_tick(step.start_frame, fps_milli), belief.to_vec()));
                if step.kind != StepKind::Pause {
                    onsets.push(step.start_frame as f64 * fps_milli as f64 / 100_000.0);
                }
            }
            ControllerEvent::Onset(frame) => {
                let at = frame_tick(frame, fps_milli).saturating_sub(lead);
                let n = items.len();
                items.push((at, n, Item::Onset));
            }
            _ => {}
        };
        controller.push(samples, &mut sink);
        controller.finish(&mut sink);
        items.sort_by_key(|&(at, n, _)| (at, n));
        onsets.sort_by(f64::total_cmp);
        let follow: VoiceFollow = blob.follow();
        let pause_ms = blob
            .prosody_config()
            .syllables
            .pause_frames
            .saturating_mul(10);
        let mut voice = Voice::silent(&follow);
        let expression = Expressive::of(&follow);
        let (mut resting, mut weight, mut gain, mut belief_at) = (
            Vec::with_capacity(ticks),
            Vec::with_capacity(ticks),
            Vec::with_capacity(ticks),
            Vec::with_capacity(ticks),
        );
        let (mut next, mut step) = (0usize, 0usize);
        for k in 0..ticks as u64 {
            while next < items.len() && items[next].0 <= k {
                match items[next].2 {
                    Item::Step { pause, level } => voice.step(&follow, pause, level, pause_ms),
                    Item::Onset => voice.onset(),
                }
                next += 1;
            }
            while step + 1 < steps.len() && steps[step + 1].0 <= k {
                step += 1;
            }
            resting.push(voice.resting());
            weight.push(voice.weight(&follow));
            gain.push((
                voice.gain(&expression, true),
                voice.gain(&expression, false),
            ));
            belief_at.push(step);
        }
        let mut beliefs: Vec<Vec<f32>> = steps.into_iter().map(|(_, b)| b).collect();
        if beliefs.is_empty() {
            beliefs.push(vec![1.0 / states as f32; states]);
        }
        Ok(Self {
            ticks,
            fps_milli,
            resting,
            weight,
            gain,
            belief_at,
            beliefs,
            onsets,
        })
    }

    /// The belief at tick `k` (the last tick's past the end).
    pub fn belief(&self, k: usize) -> &[f32] {
        let i = self
            .belief_at
            .get(k)
            .or(self.belief_at.last())
            .copied()
            .unwrap_or(0);
        &self.beliefs[i.min(self.beliefs.len() - 1)]
    }

    /// Whether tick `k` rests (not past the end).
    pub fn resting_at(&self, k: usize) -> bool {
        self.resting.get(k).copied().unwrap_or(false)
    }
}
