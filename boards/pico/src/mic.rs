//! The microphone: an analog electret module on GP26 / ADC0, sampled at 16 kHz by the ADC in
//! free-running mode into its FIFO; the FIFO interrupt moves the samples into a double buffer
//! of 256 samples (16 ms) that the main loop takes.
//!
//! The ADC runs from the 48 MHz USB PLL: with the divider at 2999 it starts a conversion every
//! 3000 cycles, exactly 16 kHz, paced by hardware, so the interrupt's latency does not jitter
//! the sampling (rp2040-hal's `AdcFifoBuilder::clock_divider`).

use core::cell::RefCell;

use gesture_runtime::mic::{adc12_sample, DoubleBuffer};

use critical_section::Mutex;
use rp2040_hal::adc::{Adc, AdcChannel, AdcFifo};
use rp2040_hal::pac::{self, interrupt};

/// Microphone sample rate (the blob's front-end must run at it).
pub const RATE_HZ: u32 = 16_000;
/// Samples per buffer (16 ms).
pub const CHUNK: usize = 256;
/// The ADC clock (the USB PLL, as `init_clocks_and_plls` sets it).
const ADC_CLOCK_HZ: u32 = 48_000_000;

/// What the interrupt owns: the running FIFO (it borrows the `Adc` for ever).
static FIFO: Mutex<RefCell<Option<AdcFifo<'static, u16>>>> = Mutex::new(RefCell::new(None));
static BUFFERS: Mutex<RefCell<DoubleBuffer<CHUNK>>> = Mutex::new(RefCell::new(DoubleBuffer::new()));

/// The ADC FIFO interrupt: at least one sample is waiting; take all of them.
#[interrupt]
fn ADC_IRQ_FIFO() {
    critical_section::with(|cs| {
        let mut fifo = FIFO.borrow_ref_mut(cs);
        let Some(fifo) = fifo.as_mut() else {
            return;
        };
        let mut buffers = BUFFERS.borrow_ref_mut(cs);
        while fifo.len() > 0 {
            // A conversion error (ERR bit) reads as the module's bias: silence, not a click.
            // 12 bits around the module's half-supply bias, to full-scale i16.
            buffers.push(adc12_sample(fifo.read().unwrap_or(2048)));
        }
    });
}

/// Starts sampling `pin` (GP26, an `AdcPin`) at [`RATE_HZ`] into the double buffer. `adc`
/// must live for ever (the running FIFO borrows it; `cortex_m::singleton!` gives one).
pub fn start(adc: &'static mut Adc, pin: &mut impl AdcChannel) {
    let fifo = adc
        .build_fifo()
        // rate = 48 MHz / (1 + int + frac / 256)
        .clock_divider((ADC_CLOCK_HZ / RATE_HZ - 1) as u16, 0)
        .set_channel(pin)
        .enable_interrupt(1)
        .start();
    critical_section::with(|cs| FIFO.borrow(cs).replace(Some(fifo)));
    // SAFETY: the handler only touches what is behind FIFO and BUFFERS (critical sections);
    // unmasking cannot break a critical section in progress.
    unsafe { cortex_m::peripheral::NVIC::unmask(pac::Interrupt::ADC_IRQ_FIFO) };
}

/// The next full buffer, if any, and the overruns so far.
pub fn take() -> (Option<[i16; CHUNK]>, u32) {
    critical_section::with(|cs| {
        let mut b = BUFFERS.borrow_ref_mut(cs);
        (b.take(), b.overruns())
    })
}
