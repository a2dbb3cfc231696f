//! Properties of the streaming front-end that hold for any input: chunking invariance,
//! silence, clipping, DC offset, pure tones of known pitch, and garbage that must not panic.

use gesture_runtime::prosody::{Event, Frame, FrontEnd, ProsodyConfig, Step, StepKind};

const RATE: f32 = 16_000.0;

/// Deterministic generator (64-bit LCG), so every test input is reproducible.
struct Lcg(u64);
impl Lcg {
    fn next_u32(&mut self) -> u32 {
        self.0 = self
            .0
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (self.0 >> 33) as u32
    }
    /// Uniform in [-1, 1).
    fn uniform(&mut self) -> f32 {
        self.next_u32() as f32 / (1u64 << 31) as f32 - 1.0
    }
}

/// Speech-like audio: a harmonic source with a gliding F0, ~4 Hz syllable envelope,
/// noise bursts and pauses.
fn speechlike(seconds: f32, seed: u64) -> Vec<i16> {
    let n = (seconds * RATE) as usize;
    let mut rng = Lcg(seed);
    let mut phase = 0.0f32;
    let mut out = Vec::with_capacity(n);
    for i in 0..n {
        let t = i as f32 / RATE;
        let f0 = 140.0 + 60.0 * (0.7 * t).sin() + 20.0 * (3.1 * t).sin();
        phase += 2.0 * std::f32::consts::PI * f0 / RATE;
        if phase > 2.0 * std::f32::consts::PI {
            phase -= 2.0 * std::f32::consts::PI;
        }
        let mut v = 0.0;
        for h in 1..8 {
            v += (h as f32 * phase).sin() / h as f32;
        }
        let syl = (2.0 * std::f32::consts::PI * 4.0 * t).sin().max(0.0);
        let pause = if (t % 3.0) > 2.4 { 0.0 } else { 1.0 };
        let noise = if (t * 4.0) % 1.0 < 0.15 { 0.3 } else { 0.02 };
        let x = 0.3 * v * syl * pause + noise * rng.uniform() * pause.max(0.05);
        out.push((x * 20000.0).clamp(-32768.0, 32767.0) as i16);
    }
    out
}

fn tone(freq: f32, seconds: f32, amp: f32, dc: f32) -> Vec<i16> {
    let n = (seconds * RATE) as usize;
    (0..n)
        .map(|i| {
            let v = dc + amp * (2.0 * std::f32::consts::PI * freq * i as f32 / RATE).sin();
            v.round().clamp(-32768.0, 32767.0) as i16
        })
        .collect()
}

fn run_chunked(samples: &[i16], chunk: usize) -> Vec<Event> {
    let mut fe = FrontEnd::new(&ProsodyConfig::DEFAULT).unwrap();
    let mut events = Vec::new();
    let mut sink = |e: Event| events.push(e);
    for c in samples.chunks(chunk.max(1)) {
        fe.push(c, &mut sink);
    }
    fe.finish(&mut sink);
    events
}

fn frames(events: &[Event]) -> Vec<Frame> {
    events
        .iter()
        .filter_map(|e| match e {
            Event::Frame(f) => Some(*f),
            _ => None,
        })
        .collect()
}

fn steps(events: &[Event]) -> Vec<Step> {
    events
        .iter()
        .filter_map(|e| match e {
            Event::Step(s) => Some(*s),
            _ => None,
        })
        .collect()
}

fn median(mut v: Vec<f32>) -> f32 {
    v.sort_by(|a, b| a.partial_cmp(b).unwrap());
    v[v.len() / 2]
}

#[test]
fn chunking_does_not_change_any_result() {
    let x = speechlike(4.0, 7);
    let whole = run_chunked(&x, x.len());
    assert!(
        steps(&whole).len() > 5,
        "the input should contain syllables"
    );
    assert_eq!(frames(&whole).len(), 400);
    for chunk in [1usize, 7, 160, 4096] {
        let got = run_chunked(&x, chunk);
        // Bitwise identical (f32 equality; no NaN can occur).
        assert_eq!(got, whole, "chunk size {chunk}");
    }
    // Irregular chunk sizes too.
    let mut fe = FrontEnd::new(&ProsodyConfig::DEFAULT).unwrap();
    let mut events = Vec::new();
    let mut rng = Lcg(99);
    let mut pos = 0;
    while pos < x.len() {
        let n = (rng.next_u32() % 997) as usize;
        let end = (pos + n).min(x.len());
        fe.push(&x[pos..end], &mut |e| events.push(e));
        pos = end;
    }
    fe.finish(&mut |e| events.push(e));
    assert_eq!(events, whole);
}

#[test]
fn finish_resets_for_the_next_stream() {
    let x = speechlike(1.5, 3);
    let mut fe = FrontEnd::new(&ProsodyConfig::DEFAULT).unwrap();
    let mut a = Vec::new();
    fe.push(&x, &mut |e| a.push(e));
    fe.finish(&mut |e| a.push(e));
    let mut b = Vec::new();
    fe.push(&x, &mut |e| b.push(e));
    fe.finish(&mut |e| b.push(e));
    assert_eq!(a, b);
}

#[test]
fn silence_is_unvoiced_at_praat_floor_with_pause_steps() {
    let x = vec![0i16; 16_000 * 2];
    let ev = run_chunked(&x, 512);
    let fr = frames(&ev);
    assert_eq!(fr.len(), 200);
    assert!(fr
        .iter()
        .all(|f| f.f0_hz.is_none() && f.intensity_db == -300.0));
    let st = steps(&ev);
    assert!(st.iter().all(|s| s.kind == StepKind::Pause));
    // One pause step per 250 ms of silence.
    assert_eq!(st.len(), 8);
    for (i, s) in st.iter().enumerate() {
        assert_eq!(s.end_frame - s.start_frame, 25);
        assert_eq!(s.start_frame, 1 + 25 * i as u32);
    }
}

/// Frames whose analysis windows lie entirely inside the signal.
fn steady(fr: &[Frame], seconds: f32) -> Vec<Frame> {
    fr.iter()
        .filter(|f| f.time_s() > 0.06 && f.time_s() < seconds as f64 - 0.06)
        .copied()
        .collect()
}

#[test]
fn pure_tones_have_their_pitch() {
    for f in [80.0f32, 110.0, 150.0, 220.0, 310.0, 440.0, 550.0] {
        let x = tone(f, 1.0, 8000.0, 0.0);
        let fr = steady(&frames(&run_chunked(&x, 333)), 1.0);
        let voiced: Vec<f32> = fr.iter().filter_map(|fr| fr.f0_hz).collect();
        assert_eq!(voiced.len(), fr.len(), "{f} Hz: every steady frame voiced");
        for v in &voiced {
            assert!((v - f).abs() / f < 0.005, "{f} Hz: frame says {v}");
        }
        // Intensity of a sine of amplitude A (full scale 32768 = 1 Pa):
        // 10 log10((A/32768)^2 / 2 / 4e-10).
        let a = 8000.0f32 / 32768.0;
        let want = 10.0 * (a * a / 2.0 / 4.0e-10).log10();
        for fr in &fr {
            assert!(
                (fr.intensity_db - want).abs() < 0.1,
                "{f} Hz: {}",
                fr.intensity_db
            );
        }
    }
}

#[test]
fn clipping_keeps_the_pitch() {
    // A tone driven 8x past full scale is nearly a square wave.
    let x = tone(150.0, 1.0, 8.0 * 32767.0, 0.0);
    assert!(x.iter().filter(|&&s| s == 32767 || s == -32768).count() > 10_000);
    let fr = steady(&frames(&run_chunked(&x, 160)), 1.0);
    let voiced: Vec<f32> = fr.iter().filter_map(|f| f.f0_hz).collect();
    assert_eq!(voiced.len(), fr.len());
    assert!((median(voiced) - 150.0).abs() < 1.0);
    for f in &fr {
        // A full-scale square wave is 93.98 dB; the clipped sine is just below.
        assert!(
            f.intensity_db > 92.0 && f.intensity_db < 94.0,
            "{}",
            f.intensity_db
        );
    }
}

#[test]
fn dc_offset_changes_nothing() {
    let clean = frames(&run_chunked(&tone(180.0, 1.0, 3000.0, 0.0), 4096));
    let offset = frames(&run_chunked(&tone(180.0, 1.0, 3000.0, 20000.0), 4096));
    let (clean, offset) = (steady(&clean, 1.0), steady(&offset, 1.0));
    assert_eq!(clean.len(), offset.len());
    for (a, b) in clean.iter().zip(&offset) {
        let (fa, fb) = (a.f0_hz.unwrap(), b.f0_hz.unwrap());
        assert!((fa - fb).abs() / fa < 0.002, "{fa} vs {fb}");
        assert!((a.intensity_db - b.intensity_db).abs() < 0.05);
    }
}

#[test]
fn noise_is_mostly_unvoiced() {
    let mut rng = Lcg(5);
    let x: Vec<i16> = (0..32_000)
        .map(|_| (rng.uniform() * 20000.0) as i16)
        .collect();
    let fr = frames(&run_chunked(&x, 160));
    let voiced = fr.iter().filter(|f| f.f0_hz.is_some()).count();
    assert!(
        voiced * 20 < fr.len(),
        "{voiced} of {} noise frames voiced",
        fr.len()
    );
}

#[test]
fn garbage_never_panics_and_outputs_stay_in_range() {
    let mut rng = Lcg(1234);
    for round in 0..20 {
        let n = 2000 + (rng.next_u32() % 20_000) as usize;
        let x: Vec<i16> = (0..n)
            .map(|i| match round % 5 {
                0 => rng.next_u32() as i16,
                1 => {
                    if i % 2 == 0 {
                        i16::MAX
                    } else {
                        i16::MIN
                    }
                }
                2 => {
                    if rng.next_u32() % 500 == 0 {
                        i16::MIN
                    } else {
                        0
                    }
                }
                3 => i16::MIN,
                _ => ((i as f32 * 0.001).sin() * 32767.0) as i16,
            })
            .collect();
        let chunk = 1 + (rng.next_u32() % 5000) as usize;
        let ev = run_chunked(&x, chunk);
        let fr = frames(&ev);
        assert_eq!(fr.len(), n / 160);
        for f in &fr {
            assert!(f.intensity_db.is_finite() && f.intensity_db <= 100.0);
            if let Some(f0) = f.f0_hz {
                assert!(f0.is_finite() && (37.5..=600.0).contains(&f0), "{f0}");
            }
        }
        for s in steps(&ev) {
            assert!(s.start_frame < s.end_frame && s.intensity_db.is_finite());
            assert!(s.f0_hz.is_none_or(|f| f.is_finite()));
        }
    }
}

#[test]
fn speech_like_input_gives_syllables_at_a_speech_rate() {
    // 4 Hz envelope with a 0.6 s pause every 3 s: about 4 syllables per voiced second.
    let x = speechlike(12.0, 11);
    let st = steps(&run_chunked(&x, 160));
    let syl = st.iter().filter(|s| s.kind == StepKind::Syllable).count();
    // 12 s with 9.6 s of envelope at 4 Hz = ~38 humps.
    assert!((30..=46).contains(&syl), "{syl} syllables");
    let pauses = st.iter().filter(|s| s.kind == StepKind::Pause).count();
    assert!(pauses >= 4, "{pauses} pause steps");
    for s in st.iter().filter(|s| s.kind == StepKind::Syllable) {
        assert!(s.length_s() >= 0.06 && s.length_s() < 1.0, "{s:?}");
    }
}

#[test]
fn every_syllable_start_is_reported_as_an_onset_before_the_syllable() {
    let audio = speechlike_for_onsets();
    let mut fe = FrontEnd::new(&ProsodyConfig::DEFAULT).unwrap();
    let mut events = Vec::new();
    fe.push(&audio, &mut |e| events.push(e));
    fe.finish(&mut |e| events.push(e));
    let mut syllables = 0;
    for (i, e) in events.iter().enumerate() {
        if let Event::Step(s) = e {
            if s.kind == StepKind::Syllable {
                syllables += 1;
                assert!(
                    events[..i].contains(&Event::Onset(s.start_frame)),
                    "syllable at frame {} has no onset before it",
                    s.start_frame
                );
            }
        }
    }
    assert!(syllables >= 8, "{syllables} syllables");
    // Onsets come in frame order, each after the frame it starts at was reported.
    let mut last = 0;
    for (i, e) in events.iter().enumerate() {
        if let Event::Onset(k) = e {
            assert!(*k >= last);
            last = *k;
            assert!(events[..i]
                .iter()
                .any(|f| matches!(f, Event::Frame(fr) if fr.index == *k)));
        }
    }
}

/// Four bursts of 3 Hz syllables separated by silence.
fn speechlike_for_onsets() -> Vec<i16> {
    let rate = 16_000.0f32;
    (0..(4.0 * rate) as usize)
        .map(|i| {
            let t = i as f32 / rate;
            let env = (2.0 * std::f32::consts::PI * 3.0 * t).sin().max(0.0)
                * if t % 1.0 < 0.75 { 1.0 } else { 0.0 };
            (env * 8000.0 * (2.0 * std::f32::consts::PI * 140.0 * t).sin()) as i16
        })
        .collect()
}
