//! `viewer.html`: one self-contained page (no network) that plays the run's skeleton in sync
//! with its speech, in any browser.
//!
//! The page holds everything it needs: the speech as an embedded WAV (the 16-bit samples the
//! controller heard, at the blob's rate), the skeleton's joint positions per frame (forward
//! kinematics of the played poses, at most [`VIEWER_FPS`] frames per second, millimetre
//! precision), its bones, and the timeline (intensity, syllables, decisions, the belief after
//! each step). A small script draws the skeleton for the audio's current time on a canvas as a
//! body ([`super::body`]'s model: limbs as shaded capsules sorted back to front, a shaded
//! head, the floor disk and the limbs' shadow on it; orthographic, first seen from the
//! character's front a little above; drag to orbit, wheel to zoom, double-click to reset),
//! a rig's servo channels as moving bars beside it ([`super::servos`]: the pulse each is sent
//! between its limits), and the timeline under it with a cursor (click or drag to scrub;
//! space plays and pauses). Written as text with
//! `serde_json` and `base64`; no template engine (the page is one string with one data slot).

use base64::Engine;
use serde::Serialize;

use gesture_runtime::prosody::StepKind;
use gesture_trainer::motion::fk::{all_targets, target_positions};
use gesture_trainer::rig::PoseSkeleton;

use super::body::BodyModel;
use super::servos::ServoBars;
use super::sim::Simulation;

/// Most skeleton frames per second in the page.
pub const VIEWER_FPS: f64 = 30.0;

/// What the page's script reads (`DATA` in the page).
#[derive(Debug, Serialize)]
pub struct ViewerData {
    /// Title line.
    pub title: String,
    /// Seconds of audio.
    pub duration_s: f64,
    /// Skeleton frames per second.
    pub fps: f64,
    /// Points (joints and end sites) per frame.
    pub points: usize,
    /// Per frame, `points * 3` coordinates (x, y, z; skeleton units, Y up), rounded to 0.1.
    pub frames: Vec<Vec<f32>>,
    /// Limbs: point indices and radius (skeleton units).
    pub limbs: Vec<(usize, usize, f32)>,
    /// Balls (the head first, the hands) at `a + t (b - a)`: a, b, t, radius.
    pub balls: Vec<(usize, usize, f32, f32)>,
    /// Floor height (Y).
    pub floor: f32,
    /// Body height (skeleton units).
    pub height: f32,
    /// The camera's first yaw (rad): looking at the character's front.
    pub yaw: f32,
    /// A rig's servo channels and their pulses (us) per frame.
    pub servos: Option<ServoView>,
    /// Intensity (dB) every 20 ms from 0 s.
    pub intensity: Vec<f32>,
    /// Syllables: start and end (s).
    pub syllables: Vec<[f64; 2]>,
    /// Decisions: time (s) and whether a segment was entered (else the running one went on).
    pub decisions: Vec<(f64, bool)>,
    /// Belief after each step: time it was known (s) and the distribution.
    pub beliefs: Vec<(f64, Vec<f32>)>,
}

/// A rig's servo bars in the page.
#[derive(Debug, Serialize)]
pub struct ServoView {
    /// Names and limits.
    #[serde(flatten)]
    pub bars: ServoBars,
    /// Per skeleton frame (or per [`VIEWER_FPS`] frame without a skeleton), each channel's
    /// pulse (us, rounded).
    pub pulses: Vec<Vec<f32>>,
}

/// The page's data from a run (`sk`: the blob's skeleton; without one, no figure; `servos`:
/// the rig's bars, if it has servos).
pub fn data(
    sim: &Simulation,
    sk: Option<&PoseSkeleton>,
    servos: Option<&ServoBars>,
    title: &str,
) -> ViewerData {
    let mut d = ViewerData {
        title: title.to_string(),
        duration_s: sim.duration_s,
        fps: VIEWER_FPS.min(sim.fps.max(1.0)),
        points: 0,
        frames: Vec::new(),
        limbs: Vec::new(),
        balls: Vec::new(),
        floor: 0.0,
        height: 1.0,
        yaw: 0.0,
        servos: None,
        intensity: Vec::new(),
        syllables: Vec::new(),
        decisions: sim
            .decisions
            .iter()
            .map(|x| (x.time_s, x.entered.is_some()))
            .collect(),
        beliefs: sim
            .steps
            .iter()
            .map(|s| (s.detected_s, s.belief.clone()))
            .collect(),
    };
    d.syllables = sim
        .steps
        .iter()
        .filter(|s| s.kind == StepKind::Syllable)
        .map(|s| [s.start_s, s.end_s])
        .collect();
    let step = 0.02;
    let mut k = 0usize;
    let n = (sim.duration_s / step).ceil() as usize;
    for i in 0..n {
        let t = i as f64 * step;
        while k + 1 < sim.frames.len() && sim.frames[k + 1].time_s <= t {
            k += 1;
        }
        let v = sim.frames.get(k).map_or(-300.0, |f| f.intensity_db);
        d.intensity
            .push(if v.is_finite() { v.max(-300.0) } else { -300.0 });
    }
    let n = (sim.duration_s * d.fps).ceil() as usize;
    let last = sim.poses.len().saturating_sub(1);
    let ticks: Vec<usize> = (0..n)
        .map(|k| ((k as f64 / d.fps * sim.fps).round() as usize).min(last))
        .collect();
    d.servos = servos.map(|b| ServoView {
        bars: b.clone(),
        pulses: ticks
            .iter()
            .filter_map(|&t| sim.duties.get(t))
            .map(|row| row.iter().map(|&x| b.pulse_us(x).round()).collect())
            .collect(),
    });
    let Some(sk) = sk else {
        return d;
    };
    let poses: Vec<Vec<f32>> = ticks
        .iter()
        .filter_map(|&tick| sim.poses.get(tick).cloned())
        .collect();
    let Ok(motion) = sk.motion(&poses, d.fps) else {
        return d;
    };
    let skeleton = sk.skeleton();
    let targets = all_targets(skeleton, true);
    let Ok(pos) = target_positions(&motion, &targets) else {
        return d;
    };
    let world: Vec<&[[f64; 3]]> = (0..pos.frames()).map(|f| pos.frame(f)).collect();
    if let Some(body) = BodyModel::new(skeleton, &targets, &world) {
        d.limbs = body
            .limbs
            .iter()
            .map(|l| (l.a, l.b, l.radius as f32))
            .collect();
        d.balls = body
            .balls
            .iter()
            .map(|b| (b.a, b.b, b.t as f32, b.radius as f32))
            .collect();
        d.floor = body.floor as f32;
        d.height = body.height as f32;
        d.yaw = body.left[2].atan2(body.left[0]) as f32;
    }
    d.points = targets.len();
    d.frames = (0..pos.frames())
        .map(|f| {
            pos.frame(f)
                .iter()
                .flat_map(|p| p.iter().map(|&c| ((c * 10.0).round() / 10.0) as f32))
                .map(|c| if c.is_finite() { c } else { 0.0 })
                .collect()
        })
        .collect();
    d
}

/// The 16-bit mono WAV of `samples` at `rate_hz`, as bytes.
pub fn wav_bytes(samples: &[i16], rate_hz: u32) -> Result<Vec<u8>, String> {
    let spec = hound::WavSpec {
        channels: 1,
        sample_rate: rate_hz,
        bits_per_sample: 16,
        sample_format: hound::SampleFormat::Int,
    };
    let mut cur = std::io::Cursor::new(Vec::new());
    {
        let mut w = hound::WavWriter::new(&mut cur, spec).map_err(|e| e.to_string())?;
        for &s in samples {
            w.write_sample(s).map_err(|e| e.to_string())?;
        }
        w.finalize().map_err(|e| e.to_string())?;
    }
    Ok(cur.into_inner())
}

/// The page: `data` and the speech (`samples` at `rate_hz`) in one HTML file.
pub fn page(data: &ViewerData, samples: &[i16], rate_hz: u32) -> Result<String, String> {
    let json = serde_json::to_string(data).map_err(|e| e.to_string())?;
    // Inside a <script> element only "</" could end it early.
    let json = json.replace("</", "<\\/");
    let wav = base64::engine::general_purpose::STANDARD.encode(wav_bytes(samples, rate_hz)?);
    Ok(PAGE
        .replace("@TITLE@", &html_escape(&data.title))
        .replace("@AUDIO@", &wav)
        .replace("@DATA@", &json))
}

fn html_escape(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
        .replace('"', "&quot;")
}

const PAGE: &str = include_str!("viewer.html");

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_wav_holds_the_samples() {
        let bytes = wav_bytes(&[0, 1000, -1000, i16::MAX], 16000).unwrap();
        let r = hound::WavReader::new(std::io::Cursor::new(bytes)).unwrap();
        assert_eq!(r.spec().sample_rate, 16000);
        let s: Vec<i16> = r.into_samples().map(Result::unwrap).collect();
        assert_eq!(s, [0, 1000, -1000, i16::MAX]);
    }

    #[test]
    fn script_end_tags_in_titles_and_data_cannot_close_the_script() {
        let sim = Simulation {
            duration_s: 0.1,
            fps: 30.0,
            ..Simulation::default()
        };
        let d = data(&sim, None, None, "</script><b>");
        let html = page(&d, &[0; 160], 16000).unwrap();
        assert_eq!(html.matches("</script>").count(), 1);
        assert!(html.contains("&lt;/script&gt;&lt;b&gt;"));
    }
}
