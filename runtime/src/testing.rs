//! Fixtures the unit tests of several modules share (compiled for tests only).

use crate::policy::PolicyTables;

/// Policy tables that hold only segment energies (one state, one exit point, no successors):
/// what the rest set and the voice's weights read.
pub(crate) struct Energies(pub &'static [f32]);

impl PolicyTables for Energies {
    fn states(&self) -> usize {
        1
    }
    fn exit_count(&self) -> usize {
        1
    }
    fn exit_segment(&self, _: usize) -> usize {
        0
    }
    fn exit_frame(&self, _: usize) -> usize {
        0
    }
    fn exit_is_end(&self, _: usize) -> bool {
        true
    }
    fn first_exit(&self, _: usize) -> usize {
        0
    }
    fn u(&self, _: usize, _: usize) -> f32 {
        0.0
    }
    fn u_cont(&self, _: usize, _: usize) -> f32 {
        0.0
    }
    fn successor_count(&self, _: usize) -> usize {
        0
    }
    fn successor(&self, _: usize, _: usize) -> (usize, f32) {
        (0, 0.0)
    }
    fn energy(&self, c: usize) -> f32 {
        self.0.get(c).copied().unwrap_or(0.0)
    }
}
