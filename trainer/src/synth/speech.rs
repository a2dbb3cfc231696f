//! Speech-like audio with known syllables: a small source-filter synthesizer.
//!
//! Each syllable is an onset consonant (a fricative: band-passed noise; a stop: closure then
//! burst; or a voiced nasal-like murmur) and a vowel nucleus (a band-limited sawtooth glottal
//! source through three formant resonators). Syllables come in phrases separated by pauses; F0
//! follows a phrase declination with rise-fall accents on stressed syllables. The planted style
//! state at each syllable sets its pitch level, accent size, loudness, duration and the pauses.
//! A faint noise floor (-66 dBFS) keeps pauses from being digital silence.
//!
//! Hand-written rather than taken from a crate because what matters is control over the
//! ground truth (exact syllable times and states), which speech synthesizers do not expose, and
//! because the signal only needs to look like speech to a prosody front-end.

use rand::Rng;
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, StandardNormal};
use serde::Serialize;

use super::styles::{StateTrack, Style};

/// The voice of a synthetic speaker.
#[derive(Clone, Copy, Debug, Serialize)]
pub struct Speaker {
    /// Base F0 (Hz) before style and intonation.
    pub base_f0: f64,
    /// Speaking-rate factor (durations are multiplied by it).
    pub tempo: f64,
}

impl Speaker {
    /// A speaker drawn from the seed: base F0 95-150 Hz, tempo 0.9-1.1.
    pub fn draw(rng: &mut ChaCha8Rng) -> Self {
        Self {
            base_f0: rng.random_range(95.0..150.0),
            tempo: rng.random_range(0.9..1.1),
        }
    }
}

/// The consonant before a vowel.
#[derive(Clone, Copy, Debug, Serialize, PartialEq)]
#[serde(rename_all = "snake_case")]
pub enum Onset {
    /// Band-passed noise around a centre frequency (Hz).
    Fricative {
        /// Centre frequency (Hz).
        centre_hz: f64,
    },
    /// Silence then a short noise burst.
    Stop,
    /// A quiet voiced murmur (nasal or liquid).
    Voiced,
}

/// One planned syllable (times in seconds from the start of the take).
#[derive(Clone, Debug, Serialize)]
pub struct Syllable {
    /// Onset start.
    pub start_s: f64,
    /// Vowel start (end of the onset).
    pub nucleus_s: f64,
    /// Vowel end = syllable end.
    pub end_s: f64,
    /// Planted state.
    pub state: usize,
    /// Whether the syllable carries an accent.
    pub stressed: bool,
    /// F0 at the start, peak and end of the vowel (Hz).
    pub f0_hz: [f64; 3],
    /// Vowel peak level (dBFS).
    pub level_dbfs: f64,
    /// Onset consonant.
    pub onset: Onset,
    /// Index of the vowel (formant set).
    pub vowel: usize,
}

/// Formants (Hz) of five vowels: a, e, i, o, u.
const VOWELS: [[f64; 3]; 5] = [
    [730.0, 1090.0, 2440.0],
    [530.0, 1840.0, 2480.0],
    [270.0, 2290.0, 3010.0],
    [570.0, 840.0, 2410.0],
    [300.0, 870.0, 2240.0],
];

fn gauss(rng: &mut ChaCha8Rng) -> f64 {
    StandardNormal.sample(rng)
}

/// Plans the syllables of a take: phrases of syllables with pauses between them.
pub fn plan(
    rng: &mut ChaCha8Rng,
    track: &StateTrack,
    styles: &[Style],
    speaker: &Speaker,
    duration_s: f64,
) -> Vec<Syllable> {
    let mut out = Vec::new();
    let mut t = rng.random_range(0.3..0.6);
    while t < duration_s - 0.8 {
        let st = &styles[track.at(t)];
        let n = rng.random_range(st.phrase_len.0..=st.phrase_len.1);
        for i in 0..n {
            let state = track.at(t);
            let s = &styles[state];
            let dur = (s.syllable_s * speaker.tempo * (0.22 * gauss(rng)).exp()).clamp(0.12, 0.5);
            let onset = match rng.random_range(0..4) {
                0 | 1 => Onset::Fricative {
                    centre_hz: if rng.random_bool(0.5) { 4800.0 } else { 2600.0 },
                },
                2 => Onset::Stop,
                _ => Onset::Voiced,
            };
            let onset_s = match onset {
                Onset::Fricative { .. } => rng.random_range(0.06..0.1),
                Onset::Stop => rng.random_range(0.05..0.07),
                Onset::Voiced => rng.random_range(0.05..0.08),
            };
            let end = t + onset_s + dur;
            if end > duration_s - 0.3 {
                break;
            }
            let stressed = rng.random_bool(0.35);
            // Declination over the phrase: 1.08 at its start to 0.92 at its end.
            let decl = 1.08 - 0.16 * (i as f64 / n.max(2) as f64);
            let base = speaker.base_f0 * s.f0_mult * decl * (0.04 * gauss(rng)).exp();
            let peak = if stressed {
                base * (1.0 + s.accent)
            } else {
                base * 1.02
            };
            let level = s.level_dbfs + if stressed { 3.0 } else { 0.0 } + 1.5 * gauss(rng);
            out.push(Syllable {
                start_s: t,
                nucleus_s: t + onset_s,
                end_s: end,
                state,
                stressed,
                f0_hz: [base, peak, base * 0.97],
                level_dbfs: level.min(-3.0),
                onset,
                vowel: rng.random_range(0..VOWELS.len()),
            });
            t = end;
        }
        let s = &styles[track.at(t)];
        t += (s.pause_s * (0.35 * gauss(rng)).exp()).clamp(0.2, 2.5);
    }
    out
}

/// Two-pole resonator (band-pass) with unity peak gain.
#[derive(Clone, Copy, Debug, Default)]
struct Resonator {
    a1: f64,
    a2: f64,
    g: f64,
    y1: f64,
    y2: f64,
}

impl Resonator {
    fn tune(&mut self, f: f64, bw: f64, rate: f64) {
        let r = (-std::f64::consts::PI * bw / rate).exp();
        self.a1 = 2.0 * r * (2.0 * std::f64::consts::PI * f / rate).cos();
        self.a2 = -r * r;
        self.g = 1.0 - r;
    }
    fn step(&mut self, x: f64) -> f64 {
        let y = self.g * x + self.a1 * self.y1 + self.a2 * self.y2;
        self.y2 = self.y1;
        self.y1 = y;
        y
    }
}

/// PolyBLEP correction for a sawtooth's discontinuity (band-limits the source cheaply).
fn poly_blep(t: f64, dt: f64) -> f64 {
    if t < dt {
        let x = t / dt;
        x + x - x * x - 1.0
    } else if t > 1.0 - dt {
        let x = (t - 1.0) / dt;
        x * x + x + x + 1.0
    } else {
        0.0
    }
}

/// Raised-cosine ramp from 0 to 1 over `[0, len]`.
fn ramp(x: f64, len: f64) -> f64 {
    if x <= 0.0 {
        0.0
    } else if x >= len {
        1.0
    } else {
        0.5 - 0.5 * (std::f64::consts::PI * x / len).cos()
    }
}

/// Renders the planned syllables to 16-bit PCM at `rate` Hz, `duration_s` long.
pub fn render(
    rng: &mut ChaCha8Rng,
    syllables: &[Syllable],
    duration_s: f64,
    rate: u32,
) -> Vec<i16> {
    let fs = rate as f64;
    let n = (duration_s * fs).round() as usize;
    let mut out = vec![0.0f64; n];
    let mut formants = [Resonator::default(); 3];
    let mut fric = Resonator::default();
    let mut phase = 0.0f64;
    for syl in syllables {
        let i0 = (syl.start_s * fs) as usize;
        let i1 = ((syl.end_s * fs) as usize).min(n);
        let nucleus = syl.nucleus_s - syl.start_s;
        let vowel_len = syl.end_s - syl.nucleus_s;
        let peak_amp = 10f64.powf(syl.level_dbfs / 20.0);
        let f = VOWELS[syl.vowel];
        for (k, r) in formants.iter_mut().enumerate() {
            r.tune(f[k], 60.0 + 40.0 * k as f64, fs);
        }
        if let Onset::Fricative { centre_hz } = syl.onset {
            fric.tune(centre_hz, 1500.0, fs);
        } else {
            fric.tune(3500.0, 2500.0, fs);
        }
        for (i, o) in out.iter_mut().enumerate().take(i1).skip(i0) {
            let t = i as f64 / fs - syl.start_s;
            let mut v = 0.0;
            // Voicing: F0 contour and envelope.
            // The vowel's attack overlaps the end of the consonant (coarticulation), so the
            // intensity rises steadily from consonant to vowel without a dip between them.
            let (voice_amp, f0) = if t >= nucleus - 0.02 {
                let u = ((t - nucleus) / vowel_len).clamp(0.0, 1.0);
                let f0 = if u < 0.4 {
                    syl.f0_hz[0] + (syl.f0_hz[1] - syl.f0_hz[0]) * (u / 0.4)
                } else {
                    syl.f0_hz[1] + (syl.f0_hz[2] - syl.f0_hz[1]) * ((u - 0.4) / 0.6)
                };
                let env = ramp(t - nucleus + 0.02, 0.04) * ramp(syl.end_s - syl.start_s - t, 0.04);
                (peak_amp * env, f0)
            } else if syl.onset == Onset::Voiced {
                let env = ramp(t, 0.02) * 0.3;
                (peak_amp * env, syl.f0_hz[0])
            } else {
                (0.0, syl.f0_hz[0])
            };
            if voice_amp > 0.0 {
                let dt = f0 / fs;
                phase += dt;
                if phase >= 1.0 {
                    phase -= 1.0;
                }
                let saw = 2.0 * phase - 1.0 - poly_blep(phase, dt);
                let mut s = 0.0;
                for (k, r) in formants.iter_mut().enumerate() {
                    s += r.step(saw) * [1.0, 0.6, 0.3][k];
                }
                v += 2.2 * voice_amp * s;
            }
            // Consonant noise.
            let noise_amp = match syl.onset {
                Onset::Fricative { .. } if t < nucleus + 0.02 => {
                    0.08 * peak_amp * ramp(t, 0.015) * ramp(nucleus + 0.02 - t, 0.04)
                }
                Onset::Stop if t > nucleus - 0.015 && t < nucleus => 0.35 * peak_amp,
                _ => 0.0,
            };
            if noise_amp > 0.0 {
                let w: f64 = gauss(rng);
                v += noise_amp * 3.0 * fric.step(w);
            }
            *o += v;
        }
    }
    out.iter()
        .map(|&v| {
            let floor: f64 = 0.0005 * gauss(rng);
            ((v + floor) * 32767.0).round().clamp(-32768.0, 32767.0) as i16
        })
        .collect()
}
