//! The microphone: an analog electret module on PA0 / ADC1_IN0, sampled at 16 kHz by TIM2's
//! update interrupt into a double buffer of 256 samples (16 ms) that the main loop takes.
//! Shared by both firmwares of this board.

use core::cell::RefCell;

use gesture_runtime::mic::{adc12_sample, DoubleBuffer};

use cortex_m::interrupt::Mutex;
use stm32f4xx_hal::adc::config::{AdcConfig, Clock, SampleTime};
use stm32f4xx_hal::adc::Adc;
use stm32f4xx_hal::gpio::{Analog, PA0};
use stm32f4xx_hal::pac::{interrupt, Interrupt, ADC1, TIM2};
use stm32f4xx_hal::prelude::*;
use stm32f4xx_hal::rcc::Rcc;
use stm32f4xx_hal::timer::{CounterHz, Event};

/// Microphone sample rate (the blob's front-end must run at it).
pub const RATE_HZ: u32 = 16_000;
/// Samples per buffer (16 ms).
pub const CHUNK: usize = 256;

/// What the sampling interrupt owns.
struct Mic {
    adc: Adc<ADC1>,
    pin: PA0<Analog>,
    timer: CounterHz<TIM2>,
}

static MIC: Mutex<RefCell<Option<Mic>>> = Mutex::new(RefCell::new(None));
static BUFFERS: Mutex<RefCell<DoubleBuffer<CHUNK>>> = Mutex::new(RefCell::new(DoubleBuffer::new()));

#[interrupt]
fn TIM2() {
    static mut LOCAL: Option<Mic> = None;
    if LOCAL.is_none() {
        *LOCAL = cortex_m::interrupt::free(|cs| MIC.borrow(cs).replace(None));
    }
    let Some(mic) = LOCAL.as_mut() else {
        return;
    };
    let _ = mic.timer.wait();
    // 12 bits around the module's half-supply bias, to full-scale i16.
    let s = adc12_sample(mic.adc.convert(&mic.pin, SampleTime::Cycles_28));
    cortex_m::interrupt::free(|cs| BUFFERS.borrow(cs).borrow_mut().push(s));
}

/// Starts sampling: TIM2 at 16 kHz, one ADC conversion per update interrupt. ADC clock
/// 96 MHz / 4 = 24 MHz (at most 36 MHz): a conversion takes (28 + 12) / 24 MHz = 1.7 us of the
/// 62.5 us between samples.
pub fn start<M: stm32f4xx_hal::gpio::PinMode>(
    adc1: ADC1,
    pa0: PA0<M>,
    tim2: TIM2,
    rcc: &mut Rcc,
) -> Result<(), ()> {
    let adc_config = AdcConfig::default().clock(Clock::Pclk2_div_4);
    let adc = Adc::new(adc1, true, adc_config, rcc);
    let pin = pa0.into_analog();
    let mut timer = tim2.counter_hz(rcc);
    timer.start(RATE_HZ.Hz()).map_err(|_| ())?;
    timer.listen(Event::Update);
    cortex_m::interrupt::free(|cs| MIC.borrow(cs).replace(Some(Mic { adc, pin, timer })));
    // SAFETY: the handler only touches what was moved into MIC and BUFFERS (both behind
    // critical sections); unmasking cannot break a critical section in progress.
    unsafe { cortex_m::peripheral::NVIC::unmask(Interrupt::TIM2) };
    Ok(())
}

/// The next full buffer, if any, and the overruns so far.
pub fn take() -> (Option<[i16; CHUNK]>, u32) {
    cortex_m::interrupt::free(|cs| {
        let mut b = BUFFERS.borrow(cs).borrow_mut();
        (b.take(), b.overruns())
    })
}
