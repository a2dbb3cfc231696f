//! `preview.mp4`: the run as a video with the speech as its sound track, at real-time length.
//!
//! Each frame (640 x 360, 30 frames per second of audio): the character's body seen from the
//! front and from its left side (the skeleton's forward kinematics drawn by [`super::body`],
//! one scale per view for the whole run), a rig's servo channels as bars
//! ([`super::servos`]), the time in seconds, and the run's timeline under it (the intensity with the syllables
//! shaded and the "enter" decisions as green ticks, the belief as a heat strip, a red cursor at
//! the frame's time), drawn with the same canvas as `preview.png` and `preview.gif`.
//!
//! **Why through the `ffmpeg` program.** Encoding H.264 and AAC and muxing them is ffmpeg's
//! job; a pure-Rust stack for it does not exist in a usable state, and binding libav would make
//! the build need system libraries. So the frames are piped to an `ffmpeg` process as raw RGB
//! with the audio file as its second input; when `ffmpeg` is not on `PATH` the run says so in
//! one line and writes everything else. The encoded file goes to a temporary file (removed on
//! every path) and comes back as bytes, so the run's outputs stay all-or-nothing.

use std::io::{Read, Write};
use std::path::Path;
use std::process::{Command, Stdio};

use gesture_trainer::rig::PoseSkeleton;

use super::canvas::{Canvas, BG, INK, PANEL, RED};
use super::preview::{palette, Figure, Plot};
use super::servos::ServoBars;
use super::sim::Simulation;

/// Video size.
pub const VIDEO_W: usize = 640;
/// Video size.
pub const VIDEO_H: usize = 360;
/// Video frames per second.
pub const VIDEO_FPS: f64 = 30.0;

/// Whether an `ffmpeg` program runs from `PATH`.
pub fn ffmpeg_available() -> bool {
    Command::new("ffmpeg")
        .arg("-version")
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .status()
        .is_ok_and(|s| s.success())
}

/// The line a run prints when it cannot make the video.
pub const NO_FFMPEG: &str = "no preview.mp4: the `ffmpeg` program is not on PATH (Debian/Ubuntu: \
                             `sudo apt-get install ffmpeg`; macOS: `brew install ffmpeg`; or \
                             pass --no-video)";

/// The frames of the video, as palette-index canvases, one per call of `each`.
fn frames(
    sim: &Simulation,
    sk: Option<&PoseSkeleton>,
    servos: Option<&ServoBars>,
    mut each: impl FnMut(&Canvas) -> Result<(), String>,
) -> Result<(), String> {
    let (w, h) = (VIDEO_W as i64, VIDEO_H as i64);
    let dur = sim.duration_s.max(1.0 / VIDEO_FPS);
    let n = (dur * VIDEO_FPS).ceil() as usize;
    let last = sim.poses.len().saturating_sub(1);
    let ticks: Vec<usize> = (0..n)
        .map(|k| ((k as f64 / VIDEO_FPS * sim.fps).round() as usize).min(last))
        .collect();
    let poses: Vec<&Vec<f32>> = ticks.iter().filter_map(|&i| sim.poses.get(i)).collect();
    let front = sk.and_then(|sk| Figure::new(sk, &poses, sim.fps, false));
    let side = sk.and_then(|sk| Figure::new(sk, &poses, sim.fps, true));
    let fig_h = 240i64;
    let (px, pw) = (8i64, w - 16);
    let (y_plot, plot_h) = (fig_h + 6, 60i64);
    let y_belief = y_plot + plot_h + 4;
    let belief_h = h - y_belief - 6;
    let mut base = Canvas::new(VIDEO_W, VIDEO_H, BG);
    let plot = Plot::new(sim);
    plot.intensity(&mut base, (px, y_plot, pw, plot_h), &[]);
    plot.belief(&mut base, (px, y_belief, pw, belief_h));
    for (k, &tick) in ticks.iter().enumerate() {
        let t = k as f64 / VIDEO_FPS;
        let mut cv = base.clone();
        cv.fill(0, 0, w, fig_h, PANEL);
        // Two views, and a rig's servo bars in the last sixth.
        let view_w = if servos.is_some() { w * 5 / 12 } else { w / 2 };
        cv.line((view_w, 8), (view_w, fig_h - 8), BG);
        if let Some(f) = &front {
            f.draw(&mut cv, k, (0, 4, view_w, fig_h - 8));
        }
        if let Some(f) = &side {
            f.draw(&mut cv, k, (view_w, 4, view_w, fig_h - 8));
        }
        if let (Some(s), Some(d)) = (servos, sim.duties.get(tick)) {
            cv.line((2 * view_w, 8), (2 * view_w, fig_h - 8), BG);
            s.draw(
                &mut cv,
                d,
                (2 * view_w + 6, 24, w - 2 * view_w - 12, fig_h - 48),
            );
        }
        cv.text(6, 6, &format!("{t:.1}s"), INK);
        let x = px + ((t / dur) * (pw - 1) as f64).round() as i64;
        cv.line((x, y_plot), (x, h - 6), RED);
        cv.line((x + 1, y_plot), (x + 1, h - 6), RED);
        each(&cv)?;
    }
    Ok(())
}

/// Encodes the run with `audio` as its sound track; the MP4's bytes.
pub fn render_mp4(
    sim: &Simulation,
    sk: Option<&PoseSkeleton>,
    servos: Option<&ServoBars>,
    audio: &Path,
) -> Result<Vec<u8>, String> {
    let tmp = tempfile::Builder::new()
        .prefix("gesture-sim-preview-")
        .suffix(".mp4")
        .tempfile()
        .map_err(|e| format!("temporary file: {e}"))?;
    let size = format!("{VIDEO_W}x{VIDEO_H}");
    let rate = format!("{VIDEO_FPS}");
    let mut child = Command::new("ffmpeg")
        .args(["-hide_banner", "-loglevel", "error", "-y"])
        .args([
            "-f", "rawvideo", "-pix_fmt", "rgb24", "-s", &size, "-r", &rate,
        ])
        .args(["-i", "-", "-i"])
        .arg(audio)
        .args([
            "-map", "0:v", "-map", "1:a", "-c:v", "libx264", "-preset", "veryfast",
        ])
        .args([
            "-crf", "23", "-pix_fmt", "yuv420p", "-c:a", "aac", "-b:a", "128k",
        ])
        .args(["-shortest", "-movflags", "+faststart", "-f", "mp4"])
        .arg(tmp.path())
        .stdin(Stdio::piped())
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .map_err(|e| format!("cannot start ffmpeg: {e}"))?;
    let pal = palette();
    let mut rgb = vec![0u8; VIDEO_W * VIDEO_H * 3];
    let written = {
        let mut stdin = child.stdin.take().ok_or("ffmpeg has no input pipe")?;
        frames(sim, sk, servos, |cv| {
            for (o, &i) in rgb.chunks_exact_mut(3).zip(&cv.px) {
                o.copy_from_slice(&pal[3 * i as usize..3 * i as usize + 3]);
            }
            stdin.write_all(&rgb).map_err(|e| e.to_string())
        })
    };
    let mut err = String::new();
    if let Some(mut e) = child.stderr.take() {
        let _ = e.read_to_string(&mut err);
    }
    let status = child.wait().map_err(|e| format!("ffmpeg: {e}"))?;
    let first = err.lines().next().unwrap_or("").to_string();
    if !status.success() {
        return Err(format!("ffmpeg failed ({status}): {first}"));
    }
    written.map_err(|e| format!("piping frames to ffmpeg: {e}"))?;
    std::fs::read(tmp.path()).map_err(|e| format!("reading ffmpeg's output: {e}"))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn one_frame_per_thirtieth_of_a_second_of_audio() {
        let sim = Simulation {
            duration_s: 2.0,
            fps: 30.0,
            ..Simulation::default()
        };
        let mut n = 0;
        frames(&sim, None, None, |cv| {
            assert_eq!((cv.w, cv.h), (VIDEO_W, VIDEO_H));
            n += 1;
            Ok(())
        })
        .unwrap();
        assert_eq!(n, 60);
    }
}
