//! `gesture-sim run --lookahead-ms all`: the whole recording planned before it is played
//! ([`gesture_trainer::bake`]) and played from its show file by the runtime's `ShowPlayer`
//! on the run's servo rig, so every output of the run (servo.csv, motion.bvh, the timeline,
//! previews, VMC, `--show`) is the baked motion. The front-end's records (frames, steps and
//! beliefs) are those of the run the caller made with the longest look-ahead. Also the
//! show's playback on a servo rig that `play-show` uses (`play_on`).

use gesture_runtime::blob::Blob;
use gesture_runtime::rig::{ChannelCal, ServoRig, MAX_CHANNELS};
use gesture_runtime::show::{Show, ShowPlayer, ShowTick};
use gesture_trainer::bake::{bake, Act};

use super::sim::{DecisionRecord, Simulation};
use crate::servo::VirtualPin;
use crate::style::StyleChange;

/// Refuses what a plan cannot follow: a style other than neutral (`styles`), labels or
/// keywords (`labelled`). The plan is made for the neutral style without labels.
pub fn check_plannable(styles: &[StyleChange], labelled: bool) -> Result<(), String> {
    if labelled || styles.iter().any(|s| s.weights.iter().any(|&w| w != 0.0)) {
        return Err(
            "--lookahead-ms all plans the neutral style without labels: leave out --style, \
             --energy, --style-track, --labels and --keywords, or give a look-ahead in ms"
                .into(),
        );
    }
    Ok(())
}

/// `sim` with its motion, commands and decisions replaced by the bake of `samples`, played on
/// a rig calibrated by `cals` with PWM period `period_us`.
pub fn baked(
    mut sim: Simulation,
    blob: &Blob<'_>,
    samples: &[i16],
    cals: &[ChannelCal],
    period_us: f32,
) -> Result<Simulation, String> {
    let fail = |e: String| format!("--lookahead-ms all: {e}");
    // About a tenth of the audio's duration on a 2-minute file: say what is going on.
    let progress =
        gesture_trainer::progress::spinner("planning the whole file (--lookahead-ms all)");
    let start = std::time::Instant::now();
    let b = bake(blob, samples).map_err(|e| fail(e.to_string()));
    progress.finish_and_clear();
    let b = b?;
    let bytes = b.show(blob).map_err(|e| fail(e.to_string()))?;
    let show = Show::parse(&bytes).map_err(|e| fail(e.to_string()))?;
    let mut player = ShowPlayer::from_blob(&show, blob).map_err(|e| fail(e.to_string()))?;
    let rate = blob.prosody_config().sample_rate_hz;
    let played = play_on(
        &mut player,
        blob,
        samples.len() as u64,
        rate,
        cals,
        period_us,
    )?;
    sim.poses = played.poses;
    sim.shown = played.shown;
    sim.duties = played.duties;
    sim.angles = played.angles;
    sim.plays = b.commands;
    // The run's time includes the planning (the summary's speed is of the whole).
    sim.wall_s += start.elapsed().as_secs_f64();
    let fps = sim.fps.max(1e-9);
    sim.decisions = b
        .plan
        .iter()
        .map(|d| {
            let x = blob.exit(d.exit);
            DecisionRecord {
                tick: d.tick,
                time_s: d.tick as f64 / fps,
                exit: d.exit,
                exit_segment: x.map_or(0, |x| x.segment as usize),
                exit_frame: x.map_or(0, |x| x.frame as usize),
                entered: match d.act {
                    Act::Continue { .. } | Act::Hold => None,
                    Act::Enter { segment, .. } | Act::Rest { segment } => Some(segment),
                },
                candidates: d.candidates,
                cost: d.cost,
                style: 0,
            }
        })
        .collect();
    Ok(sim)
}

/// Plays `samples` samples of the clock through `player` in 10 ms chunks, each pose through
/// the runtime's `ServoRig` on virtual pins as the device loop drives it (neutral at power-up,
/// `dt = 1 / fps`), calibrated by `cals` (per channel; the rest hobby servos) with PWM period
/// `period_us`.
pub(crate) fn play_on(
    player: &mut ShowPlayer<'_, Blob<'_>>,
    blob: &Blob<'_>,
    samples: u64,
    rate: u32,
    cals: &[ChannelCal],
    period_us: f32,
) -> Result<Simulation, String> {
    let channels = blob.channels();
    let mut all = [ChannelCal::HOBBY; MAX_CHANNELS];
    for (a, c) in all.iter_mut().zip(cals) {
        *a = *c;
    }
    let mut rig = ServoRig::new([VirtualPin::default(); MAX_CHANNELS], all, period_us)
        .map_err(|e| e.to_string())?;
    let _ = rig.neutral();
    let dt = 1.0 / blob.fps();
    let mut sim = Simulation {
        sample_rate_hz: rate,
        fps: blob.fps() as f64,
        duration_s: samples as f64 / rate as f64,
        ..Simulation::default()
    };
    let chunk = (rate as u64 / 100).max(1);
    let mut fed = 0u64;
    let mut sink = |t: ShowTick<'_>| {
        // Virtual pins cannot fail.
        let _ = rig.apply(t.pose, dt);
        sim.poses.push(t.pose.to_vec());
        sim.shown.push((t.segment, t.frame));
        sim.duties.push(
            rig.pins()[..channels]
                .iter()
                .map(VirtualPin::duty)
                .collect(),
        );
        sim.angles.push(rig.angles()[..channels].to_vec());
    };
    player.push(0, &mut sink);
    while fed < samples {
        let n = chunk.min(samples - fed);
        fed += n;
        player.push(n as usize, &mut sink);
    }
    Ok(sim)
}
