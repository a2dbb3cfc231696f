//! `preview.png` (a contact sheet) and `preview.gif` (an animation) of a run.
//!
//! **The contact sheet**, top to bottom: a strip of the body at evenly spaced times (the
//! skeleton's forward kinematics drawn as shaded limbs on a floor with their shadow, seen from
//! the character's front a little above, one scale for the strip: [`super::body`]), each with
//! its time; the intensity curve over the whole audio with the syllables
//! shaded and the figure times as grey lines, "enter" decisions as green ticks along the top,
//! semantic labels as magenta ticks along the bottom joined to a square where their stroke
//! played;
//! the belief as a heat strip (one row per state, the belief held since the last step; the
//! colour is `sqrt(p)` on a dark-blue (0) to yellow (1) ramp, so the spread of a belief over
//! many states still shows); a time axis in seconds.
//!
//! **The animation** (320 x 240, 10 frames per second): the body over the same
//! intensity and belief plot with a red cursor, at true speed. At most [`GIF_MAX_FRAMES`]
//! frames (10 minutes): a longer run is shown as a time-lapse (the frame step grows, the rate
//! stays 10 fps). `preview.mp4` ([`super::video`]) is the same with sound.
//!
//! **Why drawn by hand.** Both pictures are lines, rectangles and a few digits on a fixed
//! palette, so a canvas of palette indices with Bresenham lines is about a hundred lines,
//! and the files are written with the pure-Rust `png` and `gif` encoders (indexed colour:
//! no quantization step, small files). A drawing crate would bring a font stack and an RGBA
//! pipeline for no visible gain. Digits come from a 3 x 5 pixel font drawn at twice the size.
//!
//! Nothing here panics on any simulation: empty runs give a blank plot, coordinates are
//! clipped to the canvas, non-finite positions are skipped.

use std::borrow::Cow;

use gesture_trainer::motion::fk::{all_targets, target_positions};
use gesture_trainer::motion::Motion;

use super::body::{BodyModel, Camera, Painter, View, FLOOR, PITCH, SHADOW};
use super::canvas::{
    Canvas, BG, BLUE, GREEN, GRID, INK, KEEP, LABEL, MID, PALETTE_LEN, PANEL, RAMP0, RAMP_N, RED,
    SYL,
};
use super::servos::ServoBars;
use super::sim::Simulation;
use gesture_trainer::rig::PoseSkeleton;

/// Most frames in the GIF (10 minutes at 10 fps; a longer run becomes a time-lapse).
pub const GIF_MAX_FRAMES: usize = 6000;
/// GIF size.
pub const GIF_W: usize = 320;
/// GIF size.
pub const GIF_H: usize = 240;

/// The palette as RGB triples: fixed colours, then a 64-step dark-blue-to-yellow ramp.
pub(super) fn palette() -> Vec<u8> {
    let mut p = vec![0u8; PALETTE_LEN * 3];
    let fixed: [[u8; 3]; 11] = [
        [250, 250, 247],
        [226, 226, 222],
        [150, 150, 150],
        [30, 30, 30],
        [35, 90, 200],
        [250, 214, 170],
        [215, 30, 30],
        [20, 150, 60],
        // Unused since the figures became bodies (was the stick figure's ink).
        [45, 45, 70],
        [238, 238, 233],
        [190, 40, 190],
    ];
    for (i, c) in fixed.iter().enumerate() {
        p[3 * i..3 * i + 3].copy_from_slice(c);
    }
    super::body::palette_into(&mut p);
    super::servos::palette_into(&mut p);
    // Dark blue -> teal -> green -> yellow (viridis-like stops).
    let stops: [[f64; 3]; 4] = [
        [40.0, 20.0, 80.0],
        [35.0, 110.0, 140.0],
        [60.0, 185.0, 100.0],
        [250.0, 230.0, 40.0],
    ];
    for i in 0..RAMP_N {
        let t = i as f64 / (RAMP_N - 1) as f64 * 3.0;
        let k = (t.floor() as usize).min(2);
        let f = t - k as f64;
        let c: Vec<u8> = (0..3)
            .map(|ch| (stops[k][ch] + f * (stops[k + 1][ch] - stops[k][ch])).round() as u8)
            .collect();
        let at = 3 * (RAMP0 as usize + i);
        p[at..at + 3].copy_from_slice(&c);
    }
    p
}

/// Ramp colour of probability `v` (`sqrt(v)`, see the module docs).
fn ramp(v: f32) -> u8 {
    let v = if v.is_finite() {
        v.clamp(0.0, 1.0).sqrt()
    } else {
        0.0
    };
    RAMP0 + (v * (RAMP_N - 1) as f32).round() as u8
}

/// A body over time, seen by one camera ([`super::body`]): the points of every frame in the
/// camera's frame (right, up, toward it) and one scale for the whole run.
pub(super) struct Figure {
    /// Per frame, per point (joints then end sites).
    frames: Vec<Vec<[f64; 3]>>,
    body: BodyModel,
    /// The floor disk's centre (camera frame).
    floor_centre: [f64; 3],
    /// Bounding box (right, up) over all frames with the limbs' thickness, the floor disk
    /// and the shadow: (x0, y0, x1, y1).
    bbox: (f64, f64, f64, f64),
}

/// The floor disk's radius (body heights).
const FLOOR_RADIUS: f64 = 0.42;

impl Figure {
    /// The figure of `poses` seen from the character's front or, with `side`, from its left.
    pub(super) fn new(
        sk: &PoseSkeleton,
        poses: &[&Vec<f32>],
        fps: f64,
        side: bool,
    ) -> Option<Self> {
        if poses.is_empty() {
            return None;
        }
        let owned: Vec<Vec<f32>> = poses.iter().map(|p| (*p).clone()).collect();
        let motion: Motion = sk.motion(&owned, fps).ok()?;
        let skeleton = sk.skeleton();
        let targets = all_targets(skeleton, true);
        let pos = target_positions(&motion, &targets).ok()?;
        let world: Vec<&[[f64; 3]]> = (0..pos.frames()).map(|f| pos.frame(f)).collect();
        let body = BodyModel::new(skeleton, &targets, &world)?;
        let view = View::new(&body, if side { Camera::Left } else { Camera::Front });
        let frames: Vec<Vec<[f64; 3]>> = world
            .iter()
            .map(|f| f.iter().map(|&p| view.project(p)).collect())
            .collect();
        let root = world[0].first().copied().unwrap_or([0.0; 3]);
        let floor_centre = view.project([root[0], body.floor, root[2]]);
        let (fr, fy) = (
            FLOOR_RADIUS * body.height,
            FLOOR_RADIUS * body.height * PITCH.sin(),
        );
        let mut bbox = (
            floor_centre[0] - fr,
            floor_centre[1] - fy,
            floor_centre[0] + fr,
            floor_centre[1] + fy,
        );
        let pad = 0.07 * body.height;
        for p in frames.iter().flatten() {
            if p[0].is_finite() && p[1].is_finite() {
                bbox = (
                    bbox.0.min(p[0] - pad),
                    bbox.1.min(p[1] - pad),
                    bbox.2.max(p[0] + pad),
                    bbox.3.max(p[1] + pad),
                );
            }
        }
        if !(bbox.0.is_finite() && bbox.1.is_finite() && bbox.2 > bbox.0 && bbox.3 > bbox.1) {
            return None;
        }
        Some(Self {
            frames,
            body,
            floor_centre,
            bbox,
        })
    }

    /// Draws frame `f` into the box (x, y, w, h): the floor disk, the shadow, the body.
    pub(super) fn draw(&self, cv: &mut Canvas, f: usize, (x, y, w, h): (i64, i64, i64, i64)) {
        let Some(pts) = self.frames.get(f) else {
            return;
        };
        let (bw, bh) = (self.bbox.2 - self.bbox.0, self.bbox.3 - self.bbox.1);
        let scale = 0.94 * (w as f64 / bw).min(h as f64 / bh);
        let (cx, cy) = (
            0.5 * (self.bbox.0 + self.bbox.2),
            0.5 * (self.bbox.1 + self.bbox.3),
        );
        let map = |p: [f64; 3]| -> [f64; 3] {
            [
                x as f64 + w as f64 / 2.0 + (p[0] - cx) * scale,
                y as f64 + h as f64 / 2.0 - (p[1] - cy) * scale,
                p[2] * scale,
            ]
        };
        let finite = |p: &[f64; 3]| p.iter().all(|c| c.is_finite());
        let mut painter = Painter::new(cv, (x, y, w, h));
        let fc = map(self.floor_centre);
        let fr = FLOOR_RADIUS * self.body.height * scale;
        painter.ellipse((fc[0], fc[1]), fr, fr * PITCH.sin(), FLOOR);
        // The shadow: every limb dropped straight down onto the floor (light from above).
        let (s, c) = PITCH.sin_cos();
        let on_floor = |p: [f64; 3]| {
            // Back to the distance toward the camera, at the floor's height, projected again.
            let toward = p[2] * c - p[1] * s;
            let fy = self.body.floor;
            map([p[0], fy * c - toward * s, toward * c + fy * s])
        };
        for l in &self.body.limbs {
            if let (Some(a), Some(b)) = (pts.get(l.a), pts.get(l.b)) {
                if finite(a) && finite(b) {
                    let (a, b) = (on_floor(*a), on_floor(*b));
                    painter.flat_capsule(
                        (a[0], a[1]),
                        (b[0], b[1]),
                        0.8 * l.radius * scale,
                        SHADOW,
                    );
                }
            }
        }
        for l in &self.body.limbs {
            if let (Some(a), Some(b)) = (pts.get(l.a), pts.get(l.b)) {
                if finite(a) && finite(b) {
                    painter.capsule(map(*a), map(*b), l.radius * scale);
                }
            }
        }
        for ball in &self.body.balls {
            if let (Some(a), Some(b)) = (pts.get(ball.a), pts.get(ball.b)) {
                let p = [0, 1, 2].map(|k| a[k] + ball.t * (b[k] - a[k]));
                if finite(&p) {
                    let m = map(p);
                    painter.capsule(m, m, ball.radius * scale);
                }
            }
        }
    }
}

/// The time plot of a run: intensity with syllables, decisions, belief heat strip.
pub(super) struct Plot<'a> {
    sim: &'a Simulation,
    top_db: f32,
}

impl<'a> Plot<'a> {
    pub(super) fn new(sim: &'a Simulation) -> Self {
        let top_db = sim
            .frames
            .iter()
            .map(|f| f.intensity_db)
            .filter(|v| v.is_finite() && *v > -200.0)
            .fold(f32::NEG_INFINITY, f32::max);
        Self {
            sim,
            top_db: if top_db.is_finite() {
                top_db + 2.0
            } else {
                80.0
            },
        }
    }

    fn dur(&self) -> f64 {
        self.sim.duration_s.max(1e-3)
    }

    /// Intensity panel in (x, y, w, h); `marks`: times of grey guide lines.
    pub(super) fn intensity(
        &self,
        cv: &mut Canvas,
        (x, y, w, h): (i64, i64, i64, i64),
        marks: &[f64],
    ) {
        cv.fill(x, y, x + w, y + h, PANEL);
        let tx = |t: f64| x + ((t / self.dur()) * (w - 1) as f64).round() as i64;
        for s in &self.sim.steps {
            if s.kind == gesture_runtime::prosody::StepKind::Syllable {
                cv.fill(
                    tx(s.start_s),
                    y,
                    tx(s.end_s).max(tx(s.start_s) + 1),
                    y + h,
                    SYL,
                );
            }
        }
        // Grid every 10 dB below the top.
        for k in 1..6 {
            let gy = y + (k * h) / 6;
            cv.line((x, gy), (x + w - 1, gy), GRID);
        }
        for &t in marks {
            cv.line((tx(t), y), (tx(t), y + h - 1), MID);
        }
        let span = 60.0f32;
        let ty = |db: f32| {
            let v = ((self.top_db - db) / span).clamp(0.0, 1.0);
            y + (v * (h - 1) as f32).round() as i64
        };
        let mut prev: Option<(i64, i64)> = None;
        for f in &self.sim.frames {
            let p = (tx(f.time_s), ty(f.intensity_db));
            if let Some(q) = prev {
                cv.line(q, p, BLUE);
                cv.line((q.0, q.1 + 1), (p.0, p.1 + 1), BLUE);
            }
            prev = Some(p);
        }
        for d in &self.sim.decisions {
            if d.entered.is_some() {
                let px = tx(d.time_s);
                cv.fill(px, y, px + 2, y + (h / 10).max(3), GREEN);
            }
        }
        // Semantic labels: a magenta tick up from the bottom when one is asked for, joined to
        // a square where its stroke plays.
        let (bottom, tick) = (y + h - 1, (h / 6).max(4));
        for l in &self.sim.labels {
            let px = tx(l.time_s);
            cv.fill(px, bottom - tick, px + 2, bottom + 1, LABEL);
            if let Some(st) = l.stroke_s {
                let sx = tx(st);
                cv.line((px, bottom - tick), (sx, bottom - tick), LABEL);
                cv.fill(sx - 2, bottom - tick - 2, sx + 3, bottom - tick + 3, LABEL);
            }
        }
    }

    /// Belief heat strip in (x, y, w, h).
    pub(super) fn belief(&self, cv: &mut Canvas, (x, y, w, h): (i64, i64, i64, i64)) {
        let steps = &self.sim.steps;
        let states = steps.first().map_or(1, |s| s.belief.len().max(1));
        let uniform = 1.0 / states as f32;
        let mut k = 0usize;
        for col in 0..w {
            let t = (col as f64 + 0.5) / w as f64 * self.dur();
            while k < steps.len() && steps[k].detected_s <= t {
                k += 1;
            }
            for s in 0..states {
                let v = if k == 0 {
                    uniform
                } else {
                    steps[k - 1].belief.get(s).copied().unwrap_or(0.0)
                };
                let (r0, r1) = (
                    y + (s as i64 * h) / states as i64,
                    y + ((s as i64 + 1) * h) / states as i64,
                );
                cv.fill(x + col, r0, x + col + 1, r1, ramp(v));
            }
        }
    }

    /// Time axis ticks and labels under (x, w) at row y.
    fn axis(&self, cv: &mut Canvas, x: i64, y: i64, w: i64) {
        let dur = self.dur();
        let step = [0.5, 1.0, 2.0, 5.0, 10.0, 20.0, 30.0, 60.0, 120.0, 300.0]
            .into_iter()
            .find(|s| dur / s <= 12.0)
            .unwrap_or(600.0);
        let mut t = 0.0;
        while t <= dur + 1e-9 {
            let px = x + ((t / dur) * (w - 1) as f64).round() as i64;
            cv.line((px, y), (px, y + 4), INK);
            if px + 2 + 8 * 5 > x + w && t > 0.0 {
                break;
            }
            let label = if step < 1.0 {
                format!("{t:.1}")
            } else {
                format!("{t:.0}")
            };
            cv.text(px + 2, y + 6, &label, INK);
            t += step;
        }
        cv.line((x, y), (x + w - 1, y), INK);
    }
}

/// The contact sheet as PNG bytes (without a skeleton the figure strip is left out and only
/// the plots are drawn).
pub fn contact_sheet(sim: &Simulation, sk: Option<&PoseSkeleton>) -> Result<Vec<u8>, String> {
    const W: i64 = 1200;
    const CELLS: usize = 10;
    let margin = 10i64;
    let cell_w = (W - 2 * margin) / CELLS as i64;
    let fig_h = 170i64;
    let states = sim.steps.first().map_or(1, |s| s.belief.len().max(1)) as i64;
    let belief_h = (states * 8).clamp(40, 160);
    let plot_w = W - 2 * margin;
    let y_fig = margin;
    let y_plot = y_fig + fig_h + 18 + 8;
    let plot_h = 150i64;
    let y_belief = y_plot + plot_h + 6;
    let y_axis = y_belief + belief_h + 2;
    let h = y_axis + 26;
    let mut cv = Canvas::new(W as usize, h as usize, BG);
    let times: Vec<f64> = (0..CELLS)
        .map(|k| (k as f64 + 0.5) / CELLS as f64 * sim.duration_s)
        .collect();
    let ticks: Vec<usize> = times
        .iter()
        .map(|t| ((t * sim.fps).round() as usize).min(sim.poses.len().saturating_sub(1)))
        .collect();
    if let Some(fig) = sk.and_then(|sk| {
        let poses: Vec<&Vec<f32>> = ticks.iter().filter_map(|&i| sim.poses.get(i)).collect();
        Figure::new(sk, &poses, sim.fps, false)
    }) {
        for (k, t) in times.iter().enumerate() {
            let x = margin + k as i64 * cell_w;
            cv.fill(x + 2, y_fig, x + cell_w - 2, y_fig + fig_h, PANEL);
            fig.draw(&mut cv, k, (x + 2, y_fig, cell_w - 4, fig_h));
            cv.text(
                x + cell_w / 2 - 20,
                y_fig + fig_h + 4,
                &format!("{t:.1}s"),
                INK,
            );
        }
    }
    let plot = Plot::new(sim);
    plot.intensity(&mut cv, (margin, y_plot, plot_w, plot_h), &times);
    plot.belief(&mut cv, (margin, y_belief, plot_w, belief_h));
    plot.axis(&mut cv, margin, y_axis, plot_w);
    let mut out = Vec::new();
    {
        let mut enc = png::Encoder::new(&mut out, W as u32, h as u32);
        enc.set_color(png::ColorType::Indexed);
        enc.set_depth(png::BitDepth::Eight);
        enc.set_palette(palette());
        let mut wr = enc.write_header().map_err(|e| e.to_string())?;
        wr.write_image_data(&cv.px).map_err(|e| e.to_string())?;
        wr.finish().map_err(|e| e.to_string())?;
    }
    Ok(out)
}

/// The animation as GIF bytes (with a rig's servo bars at the right of the figure).
pub fn animation(
    sim: &Simulation,
    sk: Option<&PoseSkeleton>,
    servos: Option<&ServoBars>,
) -> Result<Vec<u8>, String> {
    let (w, h) = (GIF_W as i64, GIF_H as i64);
    let dur = sim.duration_s.max(0.1);
    let step = (dur / GIF_MAX_FRAMES as f64).max(0.1);
    let n = ((dur / step).floor() as usize).clamp(1, GIF_MAX_FRAMES);
    let times: Vec<f64> = (0..n).map(|k| k as f64 * step).collect();
    let ticks: Vec<usize> = times
        .iter()
        .map(|t| ((t * sim.fps).round() as usize).min(sim.poses.len().saturating_sub(1)))
        .collect();
    let fig = sk.and_then(|sk| {
        let poses: Vec<&Vec<f32>> = ticks.iter().filter_map(|&i| sim.poses.get(i)).collect();
        Figure::new(sk, &poses, sim.fps, false)
    });
    let fig_h = 150i64;
    let (px, pw) = (6i64, w - 12);
    let (y_plot, plot_h) = (fig_h + 4, 46i64);
    let y_belief = y_plot + plot_h + 3;
    let belief_h = h - y_belief - 4;
    let mut base = Canvas::new(GIF_W, GIF_H, BG);
    let plot = Plot::new(sim);
    plot.intensity(&mut base, (px, y_plot, pw, plot_h), &[]);
    plot.belief(&mut base, (px, y_belief, pw, belief_h));
    let mut out = Vec::new();
    {
        let mut enc = gif::Encoder::new(&mut out, w as u16, h as u16, &palette())
            .map_err(|e| e.to_string())?;
        enc.set_repeat(gif::Repeat::Infinite)
            .map_err(|e| e.to_string())?;
        let mut prev: Option<Vec<u8>> = None;
        for (k, &t) in times.iter().enumerate() {
            let mut cv = base.clone();
            cv.fill(0, 0, w, fig_h, PANEL);
            let fig_w = if servos.is_some() { w * 3 / 4 } else { w };
            if let Some(fig) = &fig {
                fig.draw(&mut cv, k, (0, 2, fig_w, fig_h - 4));
            }
            if let (Some(s), Some(d)) = (servos, sim.duties.get(ticks[k])) {
                s.draw(&mut cv, d, (fig_w, 12, w - fig_w - 6, fig_h - 24));
            }
            cv.text(4, 4, &format!("{t:.1}s"), INK);
            let x = px + ((t / dur) * (pw - 1) as f64).round() as i64;
            cv.line((x, y_plot), (x, h - 4), RED);
            cv.line((x + 1, y_plot), (x + 1, h - 4), RED);
            let frame = delta_frame(prev.as_deref(), &cv);
            enc.write_frame(&frame).map_err(|e| e.to_string())?;
            prev = Some(cv.px);
        }
    }
    Ok(out)
}

/// A GIF frame holding only what changed since `prev`: cropped to the changed pixels'
/// bounding box, unchanged pixels inside it transparent ([`KEEP`]) over the kept previous
/// frame. Long transparent runs compress to almost nothing, so the moving figure and cursor
/// cost a few hundred bytes per frame instead of a whole picture.
fn delta_frame(prev: Option<&[u8]>, cv: &Canvas) -> gif::Frame<'static> {
    let full = |px: Vec<u8>, (l, t, w, h): (usize, usize, usize, usize), transparent| gif::Frame {
        left: l as u16,
        top: t as u16,
        width: w as u16,
        height: h as u16,
        delay: 10,
        dispose: gif::DisposalMethod::Keep,
        transparent,
        buffer: Cow::Owned(px),
        ..gif::Frame::default()
    };
    let Some(prev) = prev.filter(|p| p.len() == cv.px.len()) else {
        return full(cv.px.clone(), (0, 0, cv.w, cv.h), None);
    };
    let (mut x0, mut y0, mut x1, mut y1) = (cv.w, cv.h, 0, 0);
    for y in 0..cv.h {
        for x in 0..cv.w {
            if cv.px[y * cv.w + x] != prev[y * cv.w + x] {
                (x0, y0, x1, y1) = (x0.min(x), y0.min(y), x1.max(x + 1), y1.max(y + 1));
            }
        }
    }
    if x0 >= x1 {
        // Nothing changed: one kept pixel.
        return full(vec![KEEP], (0, 0, 1, 1), Some(KEEP));
    }
    let mut px = Vec::with_capacity((x1 - x0) * (y1 - y0));
    for y in y0..y1 {
        for x in x0..x1 {
            let i = y * cv.w + x;
            px.push(if cv.px[i] == prev[i] { KEEP } else { cv.px[i] });
        }
    }
    full(px, (x0, y0, x1 - x0, y1 - y0), Some(KEEP))
}
