//! A validated blob is the controller's policy and library: the [`PolicyTables`] and
//! [`LibraryFrames`] views. Every index the controller passes was range-checked at load, and
//! the blob's accessors return neutral values for anything else, so nothing here can panic.

use super::view::Blob;
use crate::player::LibraryFrames;
use crate::policy::PolicyTables;

impl PolicyTables for Blob<'_> {
    fn states(&self) -> usize {
        Blob::states(self)
    }
    fn exit_count(&self) -> usize {
        self.exit_points()
    }
    fn exit_segment(&self, e: usize) -> usize {
        self.exit(e).map_or(0, |x| x.segment as usize)
    }
    fn exit_frame(&self, e: usize) -> usize {
        self.exit(e).map_or(0, |x| x.frame as usize)
    }
    fn exit_is_end(&self, e: usize) -> bool {
        Blob::exit_is_end(self, e)
    }
    fn first_exit(&self, c: usize) -> usize {
        self.exits_of(c).start
    }
    fn u(&self, c: usize, s: usize) -> f32 {
        Blob::u(self, c, s)
    }
    fn u_cont(&self, e: usize, s: usize) -> f32 {
        Blob::u_cont(self, e, s)
    }
    fn successor_count(&self, e: usize) -> usize {
        Blob::successor_count(self, e)
    }
    fn successor(&self, e: usize, k: usize) -> (usize, f32) {
        Blob::successor(self, e, k).map_or((0, f32::INFINITY), |s| (s.segment as usize, s.cost))
    }
    fn u_dot(&self, c: usize, b: &[f32]) -> f32 {
        Blob::u_dot(self, c, b)
    }
    fn u_cont_dot(&self, e: usize, b: &[f32]) -> f32 {
        Blob::u_cont_dot(self, e, b)
    }
    fn tone_u_dot(&self, m: usize, c: usize, b: &[f32]) -> f32 {
        Blob::tone_u_dot(self, m, c, b)
    }
    fn tone_u_cont_dot(&self, m: usize, e: usize, b: &[f32]) -> f32 {
        Blob::tone_u_cont_dot(self, m, e, b)
    }
    fn tones(&self) -> usize {
        Blob::tones(self)
    }
    fn labels(&self) -> usize {
        Blob::labels(self)
    }
    fn label_of(&self, c: usize) -> u8 {
        Blob::label_of(self, c)
    }
    fn stroke_of(&self, c: usize) -> Option<usize> {
        self.segment(c).and_then(|s| s.stroke).map(usize::from)
    }
    fn semantic_cost(&self) -> f32 {
        Blob::semantic_cost(self)
    }
    fn labelled_count(&self) -> usize {
        Blob::labelled_count(self)
    }
    fn labelled_segment(&self, k: usize) -> usize {
        Blob::labelled_segment(self, k).unwrap_or(0)
    }
    fn label_u_dot(&self, w: usize, c: usize, b: &[f32]) -> f32 {
        Blob::label_u_dot(self, w, c, b)
    }
    fn label_u_cont_dot(&self, w: usize, e: usize, b: &[f32]) -> f32 {
        Blob::label_u_cont_dot(self, w, e, b)
    }
    fn entry(&self, e: usize, k: usize) -> (usize, f32) {
        Blob::entry(self, e, k).unwrap_or((0, f32::INFINITY))
    }
    fn tone_u(&self, m: usize, c: usize, s: usize) -> f32 {
        Blob::tone_u(self, m, c, s)
    }
    fn tone_u_cont(&self, m: usize, e: usize, s: usize) -> f32 {
        Blob::tone_u_cont(self, m, e, s)
    }
    fn energy(&self, c: usize) -> f32 {
        self.segment_energy(c)
    }
}

impl LibraryFrames for Blob<'_> {
    fn channels(&self) -> usize {
        Blob::channels(self)
    }
    fn fps(&self) -> f32 {
        Blob::fps(self)
    }
    fn segment_count(&self) -> usize {
        self.segments()
    }
    fn segment_len(&self, c: usize) -> usize {
        self.segment(c).map_or(1, |s| s.len as usize)
    }
    fn value(&self, c: usize, f: usize, ch: usize) -> f32 {
        self.segment_value(c, f, ch)
    }
    fn continues(&self, c: usize) -> bool {
        Blob::continues(self, c)
    }
    fn is_beat(&self, c: usize, f: usize) -> bool {
        self.table_frame(c, f)
            .is_some_and(|t| self.is_beat_frame(t))
    }
    fn is_calm(&self, c: usize, f: usize) -> bool {
        self.table_frame(c, f)
            .is_some_and(|t| self.is_calm_frame(t))
    }
    fn is_peak(&self, c: usize, f: usize) -> bool {
        self.table_frame(c, f)
            .is_some_and(|t| self.is_peak_frame(t))
    }
    fn calm_beat(&self, c: usize, f: usize) -> (bool, bool) {
        self.table_frame(c, f).map_or((false, false), |t| {
            (self.is_calm_frame(t), self.is_beat_frame(t))
        })
    }
    fn group_count(&self) -> usize {
        Blob::group_count(self)
    }
    fn group(&self, g: usize) -> (usize, [u8; 3]) {
        Blob::group(self, g).unwrap_or((usize::MAX, [0, 1, 2]))
    }
    fn limits(&self, ch: usize) -> (f32, f32, f32) {
        self.calibration(ch).map_or((f32::MIN, f32::MAX, 0.0), |c| {
            (c.min_deg, c.max_deg, c.neutral_deg)
        })
    }
}
