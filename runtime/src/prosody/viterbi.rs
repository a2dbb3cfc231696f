//! Fixed-lag path finder over pitch candidates (Praat's `Pitch_pathFinder`, made causal).
//!
//! Praat chooses one candidate per frame by a Viterbi search over the whole sound, maximizing
//! the sum of candidate scores minus transition costs (a voiced/unvoiced switch costs
//! `voiced_unvoiced_cost`; between two voiced frames, `octave_jump_cost * |log2(f1/f2)|`).
//! A stream cannot wait for its end, so this runs the same recursion and decides frame `t - LAG`
//! when frame `t` arrives, by tracing back from the best current candidate: a fixed-lag
//! smoother. With [`LAG`] = 5 frames (50 ms) the decisions equal the whole-utterance
//! path on nearly every frame (measured against Praat by the evaluation). At the end of a
//! stream, [`PathFinder::flush`] traces back from the final frame, exactly as Praat does.
//!
//! Scores are re-based every frame (the best becomes 0) so they stay bounded on endless
//! streams; that does not change any decision.
//!
//! Invariants: fixed memory (`LAG + 1` frames of candidates), no allocation, no panics.

use super::pitch::{Candidates, PitchParams, MAX_CANDIDATES};

/// Decision lag in frames.
pub const LAG: usize = 5;
/// Ring capacity: the frames that may still change.
const RING: usize = LAG + 1;

#[derive(Clone, Copy, Debug)]
struct Slot {
    cand: Candidates,
    /// Accumulated score of the best path ending in each candidate.
    acc: [f32; MAX_CANDIDATES],
    /// Best predecessor (index into the previous frame's candidates).
    back: [u8; MAX_CANDIDATES],
}

const EMPTY_SLOT: Slot = Slot {
    cand: Candidates::UNVOICED,
    acc: [0.0; MAX_CANDIDATES],
    back: [0; MAX_CANDIDATES],
};

/// Streaming Viterbi with a fixed decision lag. Frame numbers are the caller's, consecutive.
#[derive(Clone, Debug)]
pub struct PathFinder {
    ring: [Slot; RING],
    /// Number of frames pushed so far.
    count: u64,
    /// Number of frames already decided (emitted).
    decided: u64,
    jump_cost: f32,
    vu_cost: f32,
}

impl PathFinder {
    /// An empty path finder.
    pub fn new(params: &PitchParams) -> Self {
        Self {
            ring: [EMPTY_SLOT; RING],
            count: 0,
            decided: 0,
            jump_cost: params.octave_jump_cost,
            vu_cost: params.voiced_unvoiced_cost,
        }
    }

    /// Forgets all frames.
    pub fn reset(&mut self) {
        self.count = 0;
        self.decided = 0;
    }

    fn transition(&self, prev: &Candidates, a: usize, cur: &Candidates, b: usize) -> f32 {
        let pv = prev.freq[a] > 0.0;
        let cv = cur.freq[b] > 0.0;
        match (pv, cv) {
            (false, false) => 0.0,
            (true, true) => self.jump_cost * (prev.log2f[a] - cur.log2f[b]).abs(),
            _ => self.vu_cost,
        }
    }

    /// Adds the next frame. Returns the decision for the frame `LAG` frames back, once
    /// there is one.
    pub fn push(&mut self, cand: &Candidates) -> Option<Decision> {
        let idx = (self.count % RING as u64) as usize;
        let mut slot = Slot {
            cand: *cand,
            acc: [0.0; MAX_CANDIDATES],
            back: [0; MAX_CANDIDATES],
        };
        let n = cand.len.clamp(1, MAX_CANDIDATES);
        slot.cand.len = n;
        if self.count == 0 {
            slot.acc[..n].copy_from_slice(&cand.score[..n]);
        } else {
            let prev = &self.ring[((self.count - 1) % RING as u64) as usize];
            let pn = prev.cand.len;
            let mut best_overall = f32::NEG_INFINITY;
            for b in 0..n {
                let mut best = f32::NEG_INFINITY;
                let mut arg = 0u8;
                for a in 0..pn {
                    let v = prev.acc[a] - self.transition(&prev.cand, a, cand, b);
                    if v > best {
                        best = v;
                        arg = a as u8;
                    }
                }
                let total = best + cand.score[b];
                slot.acc[b] = total;
                slot.back[b] = arg;
                if total > best_overall {
                    best_overall = total;
                }
            }
            // Re-base so the scores stay bounded on endless streams.
            if best_overall.is_finite() {
                for v in slot.acc[..n].iter_mut() {
                    *v -= best_overall;
                }
            }
        }
        self.ring[idx] = slot;
        self.count += 1;
        if self.count > LAG as u64 {
            let target = self.count - 1 - LAG as u64;
            let d = self.trace(target);
            self.decided = target + 1;
            Some(d)
        } else {
            None
        }
    }

    /// Decision for frame `target` by tracing back from the best candidate of the last frame.
    fn trace(&self, target: u64) -> Decision {
        let last = self.count - 1;
        let slot = &self.ring[(last % RING as u64) as usize];
        let mut place = 0usize;
        for k in 1..slot.cand.len {
            if slot.acc[k] > slot.acc[place] {
                place = k;
            }
        }
        let mut t = last;
        while t > target {
            let s = &self.ring[(t % RING as u64) as usize];
            place = s.back[place.min(MAX_CANDIDATES - 1)] as usize;
            t -= 1;
        }
        let s = &self.ring[(target % RING as u64) as usize];
        let place = place.min(s.cand.len - 1);
        Decision {
            f0_hz: s.cand.freq[place],
        }
    }

    /// Decides every remaining frame (end of stream), oldest first, via `emit`.
    pub fn flush(&mut self, mut emit: impl FnMut(Decision)) {
        while self.decided < self.count {
            let d = self.trace(self.decided);
            self.decided += 1;
            emit(d);
        }
    }
}

/// The path finder's choice for one frame.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Decision {
    /// F0 in Hz, or 0 when unvoiced.
    pub f0_hz: f32,
}

#[cfg(test)]
mod tests {
    use super::*;

    fn frame(cands: &[(f32, f32)], unvoiced: f32) -> Candidates {
        let mut c = Candidates::UNVOICED;
        c.score[0] = unvoiced;
        for (i, &(f, s)) in cands.iter().enumerate() {
            c.freq[i + 1] = f;
            c.log2f[i + 1] = libm::log2f(f);
            c.score[i + 1] = s;
        }
        c.len = cands.len() + 1;
        c
    }

    /// Brute-force best path over all candidate sequences of a short utterance.
    fn brute(frames: &[Candidates], pf: &PathFinder) -> [usize; 6] {
        let mut best = (f32::NEG_INFINITY, [0usize; 6]);
        let n = frames.len();
        let total: usize = frames.iter().map(|f| f.len).product();
        for mut code in 0..total {
            let mut path = [0usize; 6];
            for (t, f) in frames.iter().enumerate() {
                path[t] = code % f.len;
                code /= f.len;
            }
            let mut v = frames[0].score[path[0]];
            for t in 1..n {
                v += frames[t].score[path[t]]
                    - pf.transition(&frames[t - 1], path[t - 1], &frames[t], path[t]);
            }
            if v > best.0 {
                best = (v, path);
            }
        }
        best.1
    }

    #[test]
    fn flush_equals_brute_force_viterbi() {
        let pf0 = PathFinder::new(&PitchParams::PRAAT);
        let frames = [
            frame(&[(100.0, 0.8), (200.0, 0.79)], 0.45),
            frame(&[(101.0, 0.6), (202.0, 0.85)], 0.45),
            frame(&[(99.0, 0.9)], 0.45),
            frame(&[(98.0, 0.3), (300.0, 0.5)], 0.5),
            frame(&[(97.0, 0.7), (195.0, 0.72)], 0.45),
            frame(&[], 1.2),
        ];
        let path = brute(&frames, &pf0);
        // With a lag longer than the utterance, everything is decided at flush.
        let mut pf = PathFinder::new(&PitchParams::PRAAT);
        let mut got = [0.0f32; 6];
        let mut k = 0;
        for f in &frames {
            if let Some(d) = pf.push(f) {
                got[k] = d.f0_hz;
                k += 1;
            }
        }
        pf.flush(|d| {
            got[k] = d.f0_hz;
            k += 1;
        });
        assert_eq!(k, 6);
        // Frame 0 was decided when frame 5 arrived (lag 5), i.e. from the whole utterance;
        // the rest at flush: every decision equals the exhaustive optimum.
        for t in 0..6 {
            assert_eq!(got[t], frames[t].freq[path[t]], "frame {t}");
        }
    }

    #[test]
    fn octave_jumps_are_penalized() {
        // A single frame whose strongest candidate is an octave up should not jump.
        let mut pf = PathFinder::new(&PitchParams::PRAAT);
        let mut out = [0.0f32; 12];
        let mut k = 0;
        for t in 0..12 {
            let f = if t == 6 {
                frame(&[(100.0, 0.70), (200.0, 0.75)], 0.45)
            } else {
                frame(&[(100.0, 0.9), (200.0, 0.5)], 0.45)
            };
            if let Some(d) = pf.push(&f) {
                out[k] = d.f0_hz;
                k += 1;
            }
        }
        pf.flush(|d| {
            out[k] = d.f0_hz;
            k += 1;
        });
        assert!(out.iter().all(|&f| f == 100.0), "{out:?}");
    }
}
