//! From a sampling interrupt to the main loop: a double buffer of microphone samples, and the
//! conversion of a 12-bit ADC reading of an electret module into a full-scale sample.
//!
//! A board's interrupt (a timer, or an ADC FIFO) [`DoubleBuffer::push`]es each sample into
//! one half while the main loop processes the other, as a DMA double buffer would; a full half
//! that the main loop has not taken when the next one fills is dropped and counted as an
//! overrun. The buffer lives in a `static` behind the board's critical section
//! (`const fn new`), so it costs `2 * N * 2` bytes of RAM and never allocates or panics.

/// Two halves of `N` samples: one being filled by the interrupt, one waiting for the main loop.
#[derive(Clone, Debug)]
pub struct DoubleBuffer<const N: usize> {
    data: [[i16; N]; 2],
    /// The half being filled.
    filling: usize,
    /// Samples in the half being filled.
    pos: usize,
    /// A full half waiting for the main loop.
    ready: Option<usize>,
    /// Full halves dropped because the main loop was late (wrapping).
    overruns: u32,
}

impl<const N: usize> DoubleBuffer<N> {
    /// Empty, no overruns.
    pub const fn new() -> Self {
        Self {
            data: [[0; N]; 2],
            filling: 0,
            pos: 0,
            ready: None,
            overruns: 0,
        }
    }

    /// Appends one sample (from the interrupt). When the half fills it becomes the one the
    /// main loop takes next; one that was still waiting is dropped (an overrun). With `N = 0`
    /// samples are dropped.
    pub fn push(&mut self, s: i16) {
        let Some(slot) = self.data[self.filling].get_mut(self.pos) else {
            return;
        };
        *slot = s;
        self.pos += 1;
        if self.pos == N {
            if self.ready.is_some() {
                self.overruns = self.overruns.wrapping_add(1);
            }
            self.ready = Some(self.filling);
            self.filling ^= 1;
            self.pos = 0;
        }
    }

    /// The full half waiting, if any (copied out, so the interrupt may refill it at once).
    pub fn take(&mut self) -> Option<[i16; N]> {
        self.ready.take().map(|half| self.data[half])
    }

    /// Full halves dropped so far because the main loop was late (wrapping at `u32::MAX`).
    pub fn overruns(&self) -> u32 {
        self.overruns
    }
}

impl<const N: usize> Default for DoubleBuffer<N> {
    fn default() -> Self {
        Self::new()
    }
}

/// A 12-bit ADC reading (0..=4095) of a microphone module biased at half supply, as a
/// full-scale sample: `(raw - 2048) * 16`, saturating (readings above 12 bits clip).
pub fn adc12_sample(raw: u16) -> i16 {
    ((i32::from(raw) - 2048) << 4).clamp(i32::from(i16::MIN), i32::from(i16::MAX)) as i16
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn halves_alternate_and_a_late_loop_loses_the_older_half() {
        let mut b = DoubleBuffer::<3>::new();
        assert_eq!(b.take(), None);
        for s in 1..=3 {
            b.push(s);
        }
        assert_eq!(b.take(), Some([1, 2, 3]));
        assert_eq!(b.take(), None);
        // Two halves fill before the loop takes one: the first is dropped.
        for s in 4..=9 {
            b.push(s);
        }
        assert_eq!(b.overruns(), 1);
        assert_eq!(b.take(), Some([7, 8, 9]));
        // A half part-filled is not handed out.
        b.push(10);
        assert_eq!(b.take(), None);
        b.push(11);
        b.push(12);
        assert_eq!(b.take(), Some([10, 11, 12]));
        assert_eq!(b.overruns(), 1);
    }

    #[test]
    fn an_empty_buffer_drops_samples() {
        let mut b = DoubleBuffer::<0>::new();
        b.push(5);
        assert_eq!(b.take(), None);
        assert_eq!(b.overruns(), 0);
    }

    #[test]
    fn adc_readings_map_around_the_bias() {
        assert_eq!(adc12_sample(2048), 0);
        assert_eq!(adc12_sample(0), -32768);
        assert_eq!(adc12_sample(4095), 32752);
        assert_eq!(adc12_sample(2049), 16);
        assert_eq!(adc12_sample(u16::MAX), i16::MAX);
    }
}
