//! Whole-file planning ("bake"; `gesture-sim run --lookahead-ms all`, `eval-motion`'s
//! `lookahead_all` row; docs/method.md "Known audio"): with the whole recording known before
//! it is played, the segments, their paces and the rests are chosen together by dynamic
//! programming ([`plan`]) with the live policy's costs, variety included, and played by the
//! runtime's own player through a show file, so a baked run is exactly what a show board plays.
//!
//! - [`timeline`]: the belief, the voice and the onsets at every tick, from the runtime's own
//!   front-end, normalizer, belief and voice rule run over the audio;
//! - [`plan`]: the dynamic program;
//! - [`variety`]: the whole run's variety lines (no segment over 15 %, half the library
//!   played) as prices on the plan, raised until it meets them (dual ascent);
//! - [`bake`]: both, and the plan as the player's commands ([`Baked::commands`]), with a rest
//!   held until the speech returns played to and fro as the live controller plays it;
//! - [`Baked::show`] and [`Baked::play`]: the show file and its poses
//!   (`runtime::show::ShowPlayer`).
//!
//! Hand-written: the dynamic program is specific to this controller's costs; no crate plans
//! over a segment graph with path-dependent costs.

mod error;
pub mod plan;
pub mod timeline;
pub mod variety;

pub use error::BakeError;

use gesture_runtime::blob::Blob;
use gesture_runtime::controller::{rest_entry, span_ends};
use gesture_runtime::follow::{rest_rate, rest_segments, RestSet};
use gesture_runtime::player::{
    library_speed_cap, within_limits, LibraryFrames, Player, PlayerCommand, MAX_CHANNELS,
};
use gesture_runtime::policy::PolicyTables;
use gesture_runtime::show::{encode, Show, ShowPlayer};

pub use plan::{Act, Planned, Weights};
pub use timeline::Timeline;
use variety::price_rounds;
pub use variety::{Played, Prices, DISTINCT_MIN, SHARE_CAP};

/// A baked run.
#[derive(Clone, Debug)]
pub struct Baked {
    /// The plan's decisions.
    pub plan: Vec<Planned>,
    /// Its total cost.
    pub cost: f32,
    /// The player's commands: the tick each precedes, and the command.
    pub commands: Vec<(u64, PlayerCommand)>,
    /// Poses in the run: the ticks the audio spans, as a live run of it plays.
    pub ticks: u64,
}

impl Baked {
    /// `plan` (of total `cost`, over `ticks` ticks of `tl`) as the player's commands.
    fn of(blob: &Blob<'_>, plan: Vec<Planned>, cost: f32, tl: &Timeline, ticks: u64) -> Self {
        let commands = commands(blob, &plan, ticks, &tl.gain);
        Self {
            plan,
            cost,
            commands,
            ticks,
        }
    }
}

/// One pose of a baked run.
#[derive(Clone, Debug, PartialEq)]
pub struct BakedPose {
    /// Channel values (degrees), within the rig's limits.
    pub pose: Vec<f32>,
    /// Segment and frame shown.
    pub segment: usize,
    /// See `segment`.
    pub frame: usize,
}

/// The ticks `samples` samples at `rate` Hz span at `fps_milli` (tick `k` is due once
/// `ceil(k * rate * 1000 / fps_milli)` samples have arrived).
pub fn ticks_of(samples: usize, rate: u32, fps_milli: u64) -> u64 {
    if rate == 0 || fps_milli == 0 {
        return 0;
    }
    samples as u64 * fps_milli / (rate as u64 * 1000) + 1
}

/// Plans the whole of `samples` (at the blob's rate) for `blob` and turns the plan into the
/// player's commands.
pub fn bake(blob: &Blob<'_>, samples: &[i16]) -> Result<Baked, BakeError> {
    bake_with(blob, samples, &Weights::default())
}

/// [`bake`] of `samples` whose first `lead` ticks are a lead of silence outside the run (as
/// `eval-motion` delays its runs): the variety lines count the ticks after it.
pub fn bake_after(blob: &Blob<'_>, samples: &[i16], lead: u64) -> Result<Baked, BakeError> {
    bake_run(blob, samples, &Weights::default(), lead)
}

/// [`bake`] with the whole file's own terms weighted by `w`.
pub fn bake_with(blob: &Blob<'_>, samples: &[i16], w: &Weights) -> Result<Baked, BakeError> {
    bake_run(blob, samples, w, 0)
}

/// [`bake_with`] with the variety lines counted from tick `from`.
fn bake_run(blob: &Blob<'_>, samples: &[i16], w: &Weights, from: u64) -> Result<Baked, BakeError> {
    let rate = blob.prosody_config().sample_rate_hz;
    let fps_milli = (blob.fps() * 1000.0).round() as u64;
    let ticks = ticks_of(samples.len(), rate, fps_milli);
    let tl = Timeline::of(blob, samples, ticks as usize)?;
    let segments = LibraryFrames::segment_count(blob);
    // The variety lines as constraints (dual ascent, see `variety`) over the run; the plan
    // nearest them is kept.
    let mut prices = Prices::new(segments);
    let mut kept: Option<((f32, f32), Vec<Planned>, f32)> = None;
    for _ in 0..price_rounds(ticks) {
        let (plan, cost) = plan::plan(blob, &tl, w, &prices.per_segment());
        let played = Played::of(&plan, from, ticks, segments);
        let violation = played.violation();
        if kept.as_ref().is_none_or(|k| violation < k.0) {
            kept = Some((violation, plan, cost));
        }
        if violation == (0.0, 0.0) {
            break;
        }
        prices.raise(&played);
    }
    let (_, plan, cost) = kept.unwrap_or(((0.0, 0.0), Vec::new(), 0.0));
    Ok(Baked::of(blob, plan, cost, &tl, ticks))
}

/// The player's commands that carry out `plan` over `ticks` ticks: each decision's after the
/// pose of its tick; a rest played to and fro (turned at its last frame; the player turns
/// forward at its first by itself) until the speech returns; the expression gain the voice
/// asks for at each tick (`gain`, as the live controller aims it: the first with a rest
/// segment playing, the second with a gesture), before its pose.
fn commands(
    blob: &Blob<'_>,
    plan: &[Planned],
    ticks: u64,
    gain: &[(f32, f32)],
) -> Vec<(u64, PlayerCommand)> {
    let mut out: Vec<(u64, PlayerCommand)> = Vec::new();
    let mut player = Player::new();
    let rest = RestSet::of(blob, LibraryFrames::segment_count(blob));
    let fps_milli = (blob.fps() * 1000.0).round() as u64;
    let blend = (blob.blend_ms() as u64 * fps_milli).div_ceil(1_000_000);
    player.set_blend_ticks(blend.min(u32::MAX as u64) as u32);
    player.set_speed_cap(library_speed_cap(blob));
    player.set_rest_segments(rest_segments(
        blob,
        LibraryFrames::segment_count(blob),
        &blob.follow(),
    ));
    let mut pose = [0.0f32; MAX_CHANNELS];
    let (mut next, mut applied) = (0usize, 0usize);
    let mut rate = 1.0f32;
    let mut rest_until = 0u64;
    let mut span = (0usize, usize::MAX);
    for k in 0..ticks {
        if let Some(&(at_rest, in_gesture)) = gain.get(k as usize) {
            let g = if rest.contains(player.segment()) {
                at_rest
            } else {
                in_gesture
            };
            if g != player.gain_aim() {
                out.push((k, PlayerCommand::Gain(g)));
            }
        }
        while applied < out.len() && out[applied].0 <= k {
            player.apply(blob, out[applied].1);
            applied += 1;
        }
        player.tick(blob, &mut pose);
        // A rest plays to and fro among its calm frames (`rest_entry`), as the controller's.
        let (at_end, at_start) = span_ends(blob, &player, span);
        if k + 1 < rest_until && (at_end || (at_start && player.backward())) {
            out.push((k + 1, PlayerCommand::Turn));
        }
        while next < plan.len() && plan[next].tick <= k {
            let d = plan[next];
            next += 1;
            let mut give = |c: PlayerCommand| out.push((k + 1, c));
            let mut pace = |r: f32, give: &mut dyn FnMut(PlayerCommand)| {
                if r != rate {
                    rate = r;
                    give(PlayerCommand::Rate(r));
                }
            };
            match d.act {
                Act::Continue { rate: r } => pace(r, &mut give),
                Act::Enter {
                    segment: c,
                    rate: r,
                } => {
                    let a = player.segment();
                    // Into the recorded successor from the segment's end, played forward:
                    // no cut. After a rest (played to and fro) it is a cut.
                    let run_on = rest_until == 0
                        && blob.exit_is_end(d.exit)
                        && PolicyTables::exit_segment(blob, d.exit) == a
                        && c == a + 1
                        && blob.continues(a)
                        && !player.backward()
                        && player.frame() + 2 >= blob.segment_len(a);
                    give(if run_on {
                        PlayerCommand::RunOn
                    } else {
                        PlayerCommand::Enter {
                            segment: c.min(u16::MAX as usize) as u16,
                            frame: 0,
                        }
                    });
                    pace(r, &mut give);
                    rest_until = 0;
                }
                Act::Hold => rest_until = d.until,
                Act::Rest { segment: r } => {
                    // From the pose shown, within the rig's limits as the controller's is.
                    let mut shown = pose;
                    within_limits(blob, &mut shown);
                    let n = LibraryFrames::channels(blob).min(MAX_CHANNELS);
                    let entry = rest_entry(blob, r, &shown[..n]);
                    span = entry.span;
                    give(PlayerCommand::Enter {
                        segment: r.min(u16::MAX as usize) as u16,
                        frame: entry.frame.min(u16::MAX as usize) as u16,
                    });
                    pace(rest_rate(blob.energy(r)), &mut give);
                    rest_until = d.until;
                }
            }
        }
    }
    out
}

impl Baked {
    /// The show file of the run (docs/show-format.md).
    pub fn show(&self, blob: &Blob<'_>) -> Result<Vec<u8>, BakeError> {
        encode(self.ticks, &self.commands, blob).map_err(|e| BakeError::Show(e.to_string()))
    }

    /// The run's poses, played from its show file by the runtime's `ShowPlayer`.
    pub fn play(&self, blob: &Blob<'_>) -> Result<Vec<BakedPose>, BakeError> {
        let bytes = self.show(blob)?;
        let show = Show::parse(&bytes).map_err(|e| BakeError::Show(e.to_string()))?;
        let mut player =
            ShowPlayer::from_blob(&show, blob).map_err(|e| BakeError::Show(e.to_string()))?;
        let rate = blob.prosody_config().sample_rate_hz as u64;
        let fps_milli = show.header().fps_milli as u64;
        // Enough samples for every tick.
        let samples = (self.ticks * rate * 1000).div_ceil(fps_milli.max(1)) + 1;
        let mut out = Vec::with_capacity(self.ticks as usize);
        player.push(samples as usize, &mut |t| {
            out.push(BakedPose {
                pose: t.pose.to_vec(),
                segment: t.segment,
                frame: t.frame,
            })
        });
        Ok(out)
    }
}

#[cfg(test)]
mod tests;
