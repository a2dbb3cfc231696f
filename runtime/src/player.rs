//! Playing library segments as rig poses, one frame per animation tick, with a short linear
//! blend at cuts so a jump between segments becomes a quick move instead of a snap.
//!
//! Invariants: fixed memory ([`MAX_CHANNELS`] values of state), no allocation, no panics;
//! every output value is finite (non-finite library values are replaced by the previous
//! output).

/// Most rig channels a pose can have.
pub const MAX_CHANNELS: usize = crate::rig::MAX_CHANNELS;
/// Frames over which a cut is blended.
pub const BLEND_FRAMES: usize = 3;

/// The library's frames as the player needs them. Built only from validated data: indices
/// passed in are always in range.
pub trait LibraryFrames {
    /// Channels per pose.
    fn channels(&self) -> usize;
    /// Frames per second of the library.
    fn fps(&self) -> f32;
    /// Number of segments.
    fn segment_count(&self) -> usize;
    /// Frames in segment `c` (at least 1).
    fn segment_len(&self, c: usize) -> usize;
    /// Value of channel `ch` at frame `f` of segment `c` (degrees).
    fn value(&self, c: usize, f: usize, ch: usize) -> f32;
}

/// Segment playback with blending.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Player {
    segment: usize,
    frame: usize,
    last: [f32; MAX_CHANNELS],
    blend_from: [f32; MAX_CHANNELS],
    blend_left: usize,
}

impl Player {
    /// At frame 0 of segment 0, all channels at 0 until the first frame is played.
    pub const fn new() -> Self {
        Self {
            segment: 0,
            frame: 0,
            last: [0.0; MAX_CHANNELS],
            blend_from: [0.0; MAX_CHANNELS],
            blend_left: 0,
        }
    }

    /// Current segment.
    pub fn segment(&self) -> usize {
        self.segment
    }

    /// Current frame within the segment (the next one to be played).
    pub fn frame(&self) -> usize {
        self.frame
    }

    /// Cuts to segment `c` at its first frame, blending from the last output pose.
    pub fn enter(&mut self, c: usize) {
        self.segment = c;
        self.frame = 0;
        self.blend_from = self.last;
        self.blend_left = BLEND_FRAMES;
    }

    /// Plays the current frame into `out[..channels]`, then advances one frame (holding the
    /// last frame if the segment ends without a new decision). Returns the frame played.
    pub fn tick<L: LibraryFrames + ?Sized>(
        &mut self,
        lib: &L,
        out: &mut [f32; MAX_CHANNELS],
    ) -> usize {
        let n = lib.channels().min(MAX_CHANNELS);
        let len = lib.segment_len(self.segment).max(1);
        let f = self.frame.min(len - 1);
        let alpha = if self.blend_left > 0 {
            let k = BLEND_FRAMES - self.blend_left;
            self.blend_left -= 1;
            (k + 1) as f32 / (BLEND_FRAMES + 1) as f32
        } else {
            1.0
        };
        for (ch, o) in out.iter_mut().enumerate().take(n) {
            let v = lib.value(self.segment, f, ch);
            let v = if v.is_finite() { v } else { self.last[ch] };
            *o = self.blend_from[ch] + alpha * (v - self.blend_from[ch]);
            if alpha >= 1.0 {
                *o = v;
            }
            self.last[ch] = *o;
        }
        if self.frame + 1 < len {
            self.frame += 1;
        }
        f
    }
}

impl Default for Player {
    fn default() -> Self {
        Self::new()
    }
}
