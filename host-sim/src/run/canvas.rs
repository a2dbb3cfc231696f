//! The drawing surface of the previews and the video: a canvas of palette indices with
//! filled rectangles, Bresenham lines and a 3 x 5 pixel digit font drawn at twice the size
//! (why by hand: [`super::preview`]'s module docs), and where the palette's fixed colours,
//! ramp and reserved entries sit. The colours themselves are set by
//! [`super::preview::palette`], which asks the body and the servo bars for theirs.
//!
//! Nothing here panics: coordinates are clipped to the canvas and lines are bounded.

pub(super) const BG: u8 = 0;
pub(super) const GRID: u8 = 1;
pub(super) const MID: u8 = 2;
pub(super) const INK: u8 = 3;
pub(super) const BLUE: u8 = 4;
pub(super) const SYL: u8 = 5;
pub(super) const RED: u8 = 6;
pub(super) const GREEN: u8 = 7;
pub(super) const PANEL: u8 = 9;
/// Semantic labels: the request and the stroke.
pub(super) const LABEL: u8 = 10;
pub(super) const RAMP0: u8 = 16;
pub(super) const RAMP_N: usize = 64;
pub(super) const PALETTE_LEN: usize = 128;
/// Unused palette entry marking "unchanged since the previous GIF frame" (transparent).
pub(super) const KEEP: u8 = 127;

/// Palette-index pixels.
#[derive(Clone)]
pub(super) struct Canvas {
    pub(super) w: usize,
    pub(super) h: usize,
    pub(super) px: Vec<u8>,
}

/// 3 x 5 digits, '.', 's' (rows top to bottom, 3 bits each, MSB left).
fn glyph(c: char) -> Option<[u8; 5]> {
    Some(match c {
        '0' => [7, 5, 5, 5, 7],
        '1' => [2, 6, 2, 2, 7],
        '2' => [7, 1, 7, 4, 7],
        '3' => [7, 1, 7, 1, 7],
        '4' => [5, 5, 7, 1, 1],
        '5' => [7, 4, 7, 1, 7],
        '6' => [7, 4, 7, 5, 7],
        '7' => [7, 1, 1, 1, 1],
        '8' => [7, 5, 7, 5, 7],
        '9' => [7, 5, 7, 1, 7],
        '.' => [0, 0, 0, 0, 2],
        's' => [0, 3, 6, 3, 6],
        _ => return None,
    })
}

impl Canvas {
    pub(super) fn new(w: usize, h: usize, c: u8) -> Self {
        Self {
            w,
            h,
            px: vec![c; w * h],
        }
    }

    fn set(&mut self, x: i64, y: i64, c: u8) {
        if x >= 0 && y >= 0 && (x as usize) < self.w && (y as usize) < self.h {
            self.px[y as usize * self.w + x as usize] = c;
        }
    }

    pub(super) fn fill(&mut self, x0: i64, y0: i64, x1: i64, y1: i64, c: u8) {
        for y in y0.max(0)..y1.min(self.h as i64) {
            for x in x0.max(0)..x1.min(self.w as i64) {
                self.px[y as usize * self.w + x as usize] = c;
            }
        }
    }

    /// Bresenham's line, endpoints included.
    pub(super) fn line(&mut self, a: (i64, i64), b: (i64, i64), c: u8) {
        let (mut x, mut y) = a;
        let (dx, dy) = ((b.0 - a.0).abs(), -(b.1 - a.1).abs());
        let (sx, sy) = (
            if a.0 < b.0 { 1 } else { -1 },
            if a.1 < b.1 { 1 } else { -1 },
        );
        let mut err = dx + dy;
        // Bounded by the line's length, so a far-off point cannot loop for long.
        for _ in 0..=(dx - dy).min(100_000) {
            self.set(x, y, c);
            if x == b.0 && y == b.1 {
                break;
            }
            let e2 = 2 * err;
            if e2 >= dy {
                err += dy;
                x += sx;
            }
            if e2 <= dx {
                err += dx;
                y += sy;
            }
        }
    }

    /// Digits at 2x scale, top-left at (x, y); returns the width drawn.
    pub(super) fn text(&mut self, x: i64, y: i64, s: &str, c: u8) -> i64 {
        let mut cx = x;
        for ch in s.chars() {
            if let Some(g) = glyph(ch) {
                for (row, bits) in g.iter().enumerate() {
                    for col in 0..3 {
                        if bits & (4 >> col) != 0 {
                            let (px, py) = (cx + 2 * col, y + 2 * row as i64);
                            self.fill(px, py, px + 2, py + 2, c);
                        }
                    }
                }
            }
            cx += 8;
        }
        cx - x
    }
}
