//! The whole-file plan: dynamic programming over (tick, exit point) with the live policy's
//! costs, its variety costs carried along each path, and what only the whole file knows.
//!
//! A decision at exit point `e` (or at the end of a held rest) at tick `t` chooses an action
//! and a pace, and reaches the next decision point at a later tick. Its cost, in the policy's
//! units:
//!
//! - **the policy's**: the live candidate cost `S(e, c) + b . U(c)` (continuing `b . U_cont(e)`,
//!   a rest while resting the exit's largest successor cost plus `b . U(r)`), less the best
//!   candidate's at that decision, so a decision the live policy would make costs nothing;
//!   `b` is the belief of the step spoken at `t`;
//! - **variety**: the live recency and usage costs (`policy::Penalties`) of the path's own
//!   history, the last `policy::HISTORY` entries along the best path into the state (a DP with
//!   path-dependent costs keeps the best path per state: exact for the policy's costs, a close
//!   approximation for the variety costs, as in Viterbi decoding with history features);
//! - **the voice**: the live energy term `w E_c`, with `w` averaged over the ticks the choice
//!   plays (the live controller knows only the last syllable), in proportion to how long it
//!   plays over the library's mean interval between exit points, and the live rest penalty for
//!   every tick a rest-like segment plays while the voice speaks, wherever it was chosen;
//! - **strokes on syllables**: each library stroke (`library.peaks`) the choice plays earns
//!   `STROKE_GAIN` times a Gaussian (sigma `STROKE_SIGMA_S`, the width of `eval-motion`'s beat
//!   kernel) of its distance to the nearest syllable onset;
//! - **the blend's peak**: a cut into a gesture brings the hands' speed to a peak about
//!   `BLEND_PEAK_S` later (the blend closing the posture, the new segment's first motion),
//!   which the eye reads as a stroke as much as the library's own; it earns `BLEND_GAIN` of a
//!   stroke's gain at its distance to the nearest onset;
//! - **pace**: each choice plays at one of `RATES`, costing `PACE_COST * |ln rate|`, so a stroke
//!   is moved only when it lands better;
//! - **cuts**: a cut waits for the hands' next pause, as live (`defer_cut_ms`), and costs
//!   `CUT_COST` times the pose's motion per frame on its two sides (the frame cut from and the
//!   frame cut to, over the library's median), so cuts fall where the body is still; running on
//!   into the recorded successor is no cut.
//!
//! While the voice rests the calmest segments are candidates (as live) and are held, played to
//! and fro at their rest pace, until the speech returns or they have played there and back once;
//! then the rest holds on, or another rest takes over (a cut between calm frames), so a long
//! pause need not show one segment throughout. A rest, played to and fro, is left by a cut to a
//! successor of any of its exit points.

use gesture_runtime::blob::Blob;
use gesture_runtime::follow::{rest_rate, RestSet, Voice};
use gesture_runtime::player::LibraryFrames;
use gesture_runtime::policy::{History, Penalties, PolicyTables, Variety, Visit, HISTORY};
use gesture_runtime::rotation::wrap_deg;

use super::timeline::Timeline;

/// What only the whole file adds to the live costs (see the module docs).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Weights {
    /// What a stroke on a syllable onset earns.
    pub stroke_gain: f32,
    /// Cost per unit of `|ln rate|`.
    pub pace_cost: f32,
    /// Cost of a cut per unit of the pose's motion on its two sides (over the library's
    /// median motion per frame).
    pub cut_cost: f32,
    /// What the hands' speed peak after a cut into a gesture earns on a syllable onset, as a
    /// share of what a stroke earns.
    pub blend_gain: f32,
}

impl Default for Weights {
    fn default() -> Self {
        Self {
            stroke_gain: STROKE_GAIN,
            pace_cost: PACE_COST,
            cut_cost: CUT_COST,
            blend_gain: BLEND_GAIN,
        }
    }
}

/// How far the pose moves from frame `f` of segment `c` to the next (from the one before at
/// the segment's last frame): degrees summed over the channels, each angle's change the short
/// way round; a non-finite value counts as none.
fn frame_motion(blob: &Blob<'_>, c: usize, f: usize) -> f32 {
    let len = blob.segment_len(c);
    let (a, b) = if f + 1 < len {
        (f, f + 1)
    } else {
        (f.saturating_sub(1), f)
    };
    (0..blob.channels())
        .map(|ch| wrap_deg(blob.value(c, b, ch) - blob.value(c, a, ch)).abs())
        .filter(|d| d.is_finite())
        .sum()
}

/// Cost of a cut per unit of motion carried over (see [`Weights::cut_cost`]).
pub const CUT_COST: f32 = 0.5;
/// The paces a choice may play at (frames per tick).
pub const RATES: [f32; 5] = [0.8, 0.9, 1.0, 1.12, 1.25];
/// Cost per unit of `|ln rate|` of a choice.
pub const PACE_COST: f32 = 1.0;
/// What a stroke on a syllable onset earns (cost units).
pub const STROKE_GAIN: f32 = 2.0;
/// Width of the stroke-to-onset kernel (s).
pub const STROKE_SIGMA_S: f64 = 0.1;
/// What the speed peak after a cut earns, as a share of a stroke's gain (see
/// [`Weights::blend_gain`]).
pub const BLEND_GAIN: f32 = 0.5;
/// How long after a cut the hands' speed peaks (s): the blend closing the posture and the new
/// segment's first motion (docs/method.md, "Onsets at their syllable").
pub const BLEND_PEAK_S: f64 = 0.17;

/// An action of the plan.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Act {
    /// Play on to the segment's next exit point at a pace.
    Continue {
        /// Frames per tick.
        rate: f32,
    },
    /// Enter a segment at its first frame at a pace.
    Enter {
        /// The segment.
        segment: usize,
        /// Frames per tick.
        rate: f32,
    },
    /// Enter a rest segment and hold it (to and fro at its rest pace) until the speech returns
    /// or it has played there and back once.
    Rest {
        /// The rest segment.
        segment: usize,
    },
    /// The held rest goes on (no cut) until the speech returns or it has played there and back
    /// once more.
    Hold,
}

/// One decision of the plan: after the pose of `tick`, at exit point `exit` (or, after a
/// rest, the rest segment's last exit point).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Planned {
    /// The tick whose pose precedes the decision.
    pub tick: u64,
    /// The exit point decided at.
    pub exit: usize,
    /// What was chosen.
    pub act: Act,
    /// Until when a rest holds (ticks; 0 otherwise).
    pub until: u64,
    /// Candidates weighed (continuing, the successors, the rests while resting).
    pub candidates: usize,
    /// What the decision added to the plan's cost.
    pub cost: f32,
}

/// A state's best path: its cost, the state it came from and the action, and its entries.
#[derive(Clone, Copy, Debug)]
struct Cell {
    cost: f32,
    prev: u32,
    act: Option<Act>,
    /// The tick the way in was decided at (a cut waits for the hands' pause).
    tick: u32,
    /// Candidates at that decision.
    candidates: u16,
    /// The entries before this state's way in (an index into the entry arena).
    chain: u32,
}

const NONE: u32 = u32::MAX;

/// The plan over `tl` for `blob` and its total cost; `prices[c]` (cost units per mean
/// interval between exit points, empty: none; a negative price is a prize) is charged for
/// every tick segment `c` plays.
pub fn plan(blob: &Blob<'_>, tl: &Timeline, w: &Weights, prices: &[f32]) -> (Vec<Planned>, f32) {
    let t_end = tl.ticks;
    let exits = PolicyTables::exit_count(blob);
    let segments = LibraryFrames::segment_count(blob);
    if exits == 0 || segments == 0 || t_end == 0 {
        return (Vec::new(), 0.0);
    }
    let rest = RestSet::of(blob, segments);
    let extras: Vec<usize> = rest.extras().iter().map(|&s| s as usize).collect();
    // States: exit points, then "a held rest of extras[k] ends".
    let n = exits + extras.len();
    let follow = blob.follow();
    let variety: Variety = blob.variety();
    let ms_ticks = |ms: u32| (ms as u64 * tl.fps_milli).div_ceil(1_000_000) as u32;
    let (recency, usage) = (ms_ticks(variety.recency_ms), ms_ticks(variety.usage_ms));
    let fps = tl.fps_milli as f64 / 1000.0;
    let (stroke_gain, pace_cost) = (w.stroke_gain, w.pace_cost);
    let sigma = (STROKE_SIGMA_S * fps).max(1e-3);
    // The library's mean interval between exit points (frames).
    let mean_interval =
        (0..segments).map(|c| blob.segment_len(c)).sum::<usize>() as f32 / exits as f32;
    let mean_interval = mean_interval.max(1.0);
    let peaks: Vec<Vec<usize>> = (0..segments)
        .map(|c| {
            (0..blob.segment_len(c))
                .filter(|&f| blob.is_peak(c, f))
                .collect()
        })
        .collect();
    let energy: Vec<f32> = (0..segments).map(|c| blob.energy(c)).collect();
    let price = |c: usize| prices.get(c).copied().unwrap_or(0.0);
    // How fast the pose moves at each frame (degrees per frame over the channels; an angle's
    // wrap counts the short way), over the library's median: what a cut there carries over.
    let motion: Vec<Vec<f32>> = (0..segments)
        .map(|c| {
            (0..blob.segment_len(c))
                .map(|f| frame_motion(blob, c, f))
                .collect()
        })
        .collect();
    let median_motion = {
        let mut all: Vec<f32> = motion.iter().flatten().copied().collect();
        all.sort_by(f32::total_cmp);
        all.get(all.len() / 2).copied().unwrap_or(1.0).max(1e-6)
    };
    let cut_cost = w.cut_cost / median_motion;
    // A cut's blend peak: `onset_gain` is a stroke's, so this is its share.
    let (blend_gain, blend_lag) = (w.blend_gain, BLEND_PEAK_S * fps);
    // Where a cut from frame `f` of segment `c` falls: the frame itself if the hands pause
    // there, else the first calm frame, else the first motion beat, else the last frame, within
    // the live controller's deferral window (`None`: none does; the cut cannot be made here;
    // without a window, the frame itself).
    let defer = ms_ticks(blob.timing().defer_cut_ms) as usize;
    let len_of: Vec<usize> = (0..segments).map(|c| blob.segment_len(c)).collect();
    let pause_from = |c: usize, f: usize| -> Option<usize> {
        let len = len_of[c];
        let pause = |g: usize| blob.is_beat(c, g) || blob.is_calm(c, g) || g + 1 >= len;
        // (Without a deferral window, live cuts at once.)
        if pause(f) || defer == 0 {
            return Some(f);
        }
        let last = f.saturating_add(defer).min(len.saturating_sub(1));
        let mut beat = None;
        for g in f + 1..=last {
            let (calm, is_beat) = blob.calm_beat(c, g);
            if calm {
                return Some(g);
            }
            if beat.is_none() && is_beat {
                beat = Some(g);
            }
        }
        beat.or((last + 1 >= len && last > f).then_some(last))
    };
    // Ticks a rest plays there and back at its rest pace.
    let rest_cycle: Vec<usize> = (0..segments)
        .map(|c| {
            let len = blob.segment_len(c).saturating_sub(1).max(1) as f32;
            ((2.0 * len / rest_rate(blob.energy(c)).max(0.1)).ceil() as usize).max(2)
        })
        .collect();
    let last_exit: Vec<usize> = (0..segments)
        .map(|c| blob.exits_of(c).end.saturating_sub(1))
        .collect();
    // Prefix sums of the voice's weight; the next speaking tick from each tick.
    let mut wsum = vec![0.0f64; t_end + 1];
    for k in 0..t_end {
        wsum[k + 1] = wsum[k] + tl.weight[k] as f64;
    }
    // Speaking ticks before each tick (a calm segment pays the rest cost for each it plays).
    let mut spoken = vec![0u32; t_end + 2];
    for k in 0..=t_end {
        spoken[k + 1] = spoken[k] + u32::from(!tl.resting_at(k));
    }
    let mut speaks = vec![t_end; t_end + 1];
    for k in (0..t_end).rev() {
        speaks[k] = if tl.resting[k] { speaks[k + 1] } else { k };
    }
    let w_mean = |a: usize, b: usize| -> f32 {
        let (a, b) = (a.min(t_end), b.min(t_end));
        if b <= a {
            return tl.weight.get(a.min(t_end - 1)).copied().unwrap_or(0.0);
        }
        ((wsum[b] - wsum[a]) / (b - a) as f64) as f32
    };
    // Onset kernel at a (fractional) tick.
    let onset_gain = |tick: f64| -> f32 {
        let o = &tl.onsets;
        let i = o.partition_point(|&x| x < tick);
        let mut d = f64::INFINITY;
        if i < o.len() {
            d = d.min(o[i] - tick);
        }
        if i > 0 {
            d = d.min(tick - o[i - 1]);
        }
        (stroke_gain as f64 * (-0.5 * (d / sigma).powi(2)).exp()) as f32
    };
    // Ticks to play from frame `a` (shown now) until frame `b` is shown, at `rate`.
    let ticks_to = |a: usize, b: usize, rate: f32| -> usize {
        let d = b.saturating_sub(a) as f32 / rate;
        (d - 1e-4).ceil().max(1.0) as usize
    };
    let mut cells = vec![
        Cell {
            cost: f32::INFINITY,
            prev: NONE,
            act: None,
            tick: 0,
            candidates: 0,
            chain: NONE,
        };
        (t_end + 1) * n
    ];
    // Segment entries: (segment, tick, parent).
    let mut arena: Vec<(u16, u32, u32)> = vec![(0, 0, NONE)];
    // The player starts at segment 0's first frame: its first exit is reached at its frame
    // (segment 0 charged its price for the ticks it plays, as every choice is).
    let e0 = blob.first_exit(0);
    let t0 = blob.exit_frame(e0).min(t_end);
    let opening = |k: usize| {
        let speaking = spoken[(k + 1).min(t_end + 1)].saturating_sub(spoken[1]) as f32;
        let rest_cost = if energy[0] <= rest.energy() {
            follow.rest_cost * speaking
        } else {
            0.0
        };
        (w_mean(1, k + 1) * energy[0] * k as f32 + price(0) * k as f32 + rest_cost) / mean_interval
    };
    let start = |k: usize| Cell {
        cost: opening(k),
        prev: NONE,
        act: None,
        tick: 0,
        candidates: 0,
        chain: 0,
    };
    cells[t0 * n + e0] = start(t0);
    // Segment 0 plays from the start. If the speech returns from a pause before its first
    // exit point, the plan may also decide then (at that exit point, which the player is
    // heading for: live, the speech's return decides at once), cutting from the frame shown;
    // else a file that opens with a pause starts late.
    let silent = Voice::silent(&follow).resting();
    let early = (0..t0)
        .find(|&k| !tl.resting_at(k) && k.checked_sub(1).map_or(silent, |j| tl.resting_at(j)));
    if let Some(k) = early {
        cells[k * n + e0] = start(k);
    }
    // A state's entries once it is expanded (every way into it is known by then).
    let mut cand: Vec<(Act, f32, usize)> = Vec::new();
    for t in 0..t_end {
        for s in 0..n {
            let here = cells[t * n + s];
            if !here.cost.is_finite() {
                continue;
            }
            // The path's history (with the entry of the way in) and its variety costs now.
            let here_chain = match here.act {
                Some(Act::Enter { segment, .. }) | Some(Act::Rest { segment }) => {
                    let t_in = here.tick as usize + 1;
                    push(&mut arena, segment, t_in, here.chain)
                }
                _ => here.chain,
            };
            let mut hist = History::new();
            let mut chain = Vec::with_capacity(HISTORY);
            let mut p = here_chain;
            while p != NONE && chain.len() < HISTORY {
                let (seg, tick, parent) = arena[p as usize];
                chain.push(Visit { segment: seg, tick });
                p = parent;
            }
            for v in chain.iter().rev() {
                hist.write(*v);
            }
            let pen = Penalties::new(&variety, &hist, t as u32, recency, usage);
            let b = tl.belief(t);
            let resting = tl.resting_at(t + 1);
            // Candidates: (action, live cost, source exit).
            cand.clear();
            let (e, playing) = if s < exits {
                (s, blob.exit_segment(s))
            } else {
                let r = extras[s - exits];
                (last_exit[r], r)
            };
            // The early decision at segment 0's first exit point, before it is reached (above):
            // the player shows frame `t`, and continuing is left to the way in at the exit.
            let early_here = early == Some(t) && s == e0 && here.prev == NONE;
            if s < exits && !blob.exit_is_end(e) && !early_here {
                cand.push((
                    Act::Continue { rate: 1.0 },
                    blob.u_cont_dot(e, b) + pen.continuing(playing),
                    e,
                ));
            }
            let mut worst = 0.0f32;
            // After a rest, which has played to and fro, the successors of any of its exit
            // points (each at its cheapest); at an exit point, its own.
            let sources = if s < exits {
                e..e + 1
            } else {
                blob.exits_of(playing)
            };
            for x in sources {
                for k in 0..blob.successor_count(x) {
                    let (c, sc) = PolicyTables::successor(blob, x, k);
                    worst = worst.max(sc);
                    let v = sc + blob.u_dot(c, b) + pen.of(c);
                    let known = cand
                        .iter()
                        .position(|a| matches!(a.0, Act::Enter { segment, .. } if segment == c));
                    match known {
                        Some(i) if cand[i].1 <= v => {}
                        Some(i) => cand[i] = (cand[i].0, v, x),
                        None => cand.push((
                            Act::Enter {
                                segment: c,
                                rate: 1.0,
                            },
                            v,
                            x,
                        )),
                    }
                }
            }
            if cand.is_empty() {
                // No successor (a blob whose pruning left none): segment 0, as live.
                cand.push((
                    Act::Enter {
                        segment: 0,
                        rate: 1.0,
                    },
                    0.0,
                    e,
                ));
            }
            if resting {
                for &r in &extras {
                    if s >= exits && r == playing {
                        // Holding on costs what continuing does.
                        cand.push((Act::Hold, blob.u_dot(r, b) + pen.continuing(r), e));
                    } else {
                        cand.push((
                            Act::Rest { segment: r },
                            worst + blob.u_dot(r, b) + pen.of(r),
                            e,
                        ));
                    }
                }
            }
            let best = cand.iter().map(|x| x.1).fold(f32::INFINITY, f32::min);
            if !best.is_finite() {
                continue;
            }
            // A cut waits for the hands' next pause, as live: the tick it falls at.
            let (cut_at, cut_frame) = if s < exits {
                let x = if early_here { t } else { blob.exit_frame(e) };
                let r_in = match here.act {
                    Some(Act::Continue { rate }) | Some(Act::Enter { rate, .. }) => rate,
                    _ => 1.0,
                };
                let g = pause_from(playing, x);
                (
                    g.map(|g| t + ticks_to(x, g, r_in) * usize::from(g > x)),
                    g.unwrap_or(x),
                )
            } else {
                (Some(t), 0)
            };
            let out_motion = motion[playing].get(cut_frame).copied().unwrap_or(0.0);
            let run_on = s < exits && blob.exit_is_end(e) && blob.continues(playing);
            let cand_n = cand.len();
            for &(act, q, e) in &cand {
                let base = here.cost + (q - best).max(0.0);
                let tc = match (act, cut_at) {
                    (Act::Continue { .. } | Act::Hold, _) => t,
                    (_, Some(tc)) if tc < t_end => tc,
                    _ => continue,
                };
                // The wait plays the current segment on; a cut carries the motion on both
                // sides of it (running on into the recorded successor is no cut).
                let mut base = base + price(playing) * (tc - t) as f32 / mean_interval;
                if let Act::Enter { segment: c, .. } | Act::Rest { segment: c } = act {
                    if !(run_on && c == playing + 1) {
                        let in_motion = motion[c].first().copied().unwrap_or(0.0);
                        base += cut_cost * (out_motion + in_motion);
                        if matches!(act, Act::Enter { .. }) {
                            base -= blend_gain * onset_gain(tc as f64 + blend_lag);
                        }
                    }
                }
                match act {
                    Act::Rest { .. } | Act::Hold => {
                        let r = match act {
                            Act::Rest { segment } => segment,
                            _ => playing,
                        };
                        let until = speaks[(tc + 1).min(t_end)]
                            .max(tc + 1)
                            .min(tc + rest_cycle[r]);
                        let k = extras.iter().position(|&x| x == r).unwrap_or(0);
                        let dur = (until - tc) as f32 / mean_interval;
                        let v = (w_mean(tc + 1, until) * energy[r] + price(r)) * dur;
                        relax(
                            &mut cells,
                            n,
                            (t * n + s, tc, cand_n),
                            until,
                            exits + k,
                            base + v,
                            act,
                            here_chain,
                        );
                    }
                    Act::Continue { .. } | Act::Enter { .. } => {
                        let (seg, from, to, lead) = match act {
                            Act::Enter { segment: c, .. } => {
                                (c, 0, blob.exit_frame(blob.first_exit(c)), 1)
                            }
                            _ => (playing, blob.exit_frame(e), blob.exit_frame(e + 1), 0),
                        };
                        let chain = here_chain;
                        let target = match act {
                            Act::Continue { .. } => e + 1,
                            _ => blob.first_exit(seg),
                        };
                        let calm = energy[seg] <= rest.energy();
                        let t0 = t;
                        let t = tc;
                        for &rate in &RATES {
                            let t2 = t + lead + ticks_to(from, to, rate);
                            let dur = (t2 - t) as f32 / mean_interval;
                            let mut v = (w_mean(t + 1, t2 + 1) * energy[seg] + price(seg)) * dur;
                            if calm {
                                // Every tick it plays while the voice speaks, wherever decided.
                                let (a, b) = ((t + 1).min(t_end + 1), (t2 + 1).min(t_end + 1));
                                let speaking = spoken[b].saturating_sub(spoken[a]) as f32;
                                v += follow.rest_cost * speaking / mean_interval;
                            }
                            v += pace_cost * rate.ln().abs();
                            // Strokes played on the way: frame f shows at tick t + lead +
                            // (f - from) / rate.
                            let lo = if lead == 0 { from + 1 } else { from };
                            for &f in peaks[seg].iter().filter(|&&f| f >= lo && f <= to) {
                                let at = (t + lead) as f64 + (f - from) as f64 / rate as f64;
                                v -= onset_gain(at);
                            }
                            let act = match act {
                                Act::Continue { .. } => Act::Continue { rate },
                                _ => Act::Enter { segment: seg, rate },
                            };
                            relax(
                                &mut cells,
                                n,
                                (t0 * n + s, tc, cand_n),
                                t2.min(t_end),
                                target,
                                base + v,
                                act,
                                chain,
                            );
                        }
                    }
                }
            }
        }
    }
    // The best state at the end; walk back.
    let (mut best, mut at) = (f32::INFINITY, NONE);
    for s in 0..n {
        let c = cells[t_end * n + s];
        if c.cost < best {
            best = c.cost;
            at = (t_end * n + s) as u32;
        }
    }
    let mut out = Vec::new();
    while at != NONE {
        let c = cells[at as usize];
        if c.prev == NONE {
            break;
        }
        let s = c.prev as usize % n;
        let before = cells[c.prev as usize].cost;
        if let Some(act) = c.act {
            let exit = if s < exits {
                s
            } else {
                last_exit[extras[s - exits]]
            };
            let until = match act {
                Act::Rest { .. } | Act::Hold => (at as usize / n) as u64,
                _ => 0,
            };
            out.push(Planned {
                tick: c.tick as u64,
                exit,
                act,
                until,
                candidates: c.candidates as usize,
                cost: c.cost - before,
            });
        }
        at = c.prev;
    }
    out.reverse();
    (out, best)
}

/// A new entry of `segment` at `tick` after the entries `parent`.
fn push(arena: &mut Vec<(u16, u32, u32)>, segment: usize, tick: usize, parent: u32) -> u32 {
    arena.push((
        segment.min(u16::MAX as usize) as u16,
        tick.min(u32::MAX as usize) as u32,
        parent,
    ));
    (arena.len() - 1) as u32
}

/// Keeps the cheaper way into state `s2` at `t2`, from cell `from` decided at tick `tick`.
#[allow(clippy::too_many_arguments)]
fn relax(
    cells: &mut [Cell],
    n: usize,
    (from, tick, candidates): (usize, usize, usize),
    t2: usize,
    s2: usize,
    cost: f32,
    act: Act,
    chain: u32,
) {
    let i = t2 * n + s2;
    if cost < cells[i].cost {
        cells[i] = Cell {
            cost,
            prev: from as u32,
            act: Some(act),
            tick: tick.min(u32::MAX as usize) as u32,
            candidates: candidates.min(u16::MAX as usize) as u16,
            chain,
        };
    }
}
