//! The gesture controller on a WeAct "Black Pill" (STM32F411CEU6, Cortex-M4F at 96 MHz).
//!
//! - **Microphone in**: an analog electret module (MAX9814 or MAX4466, output biased at half
//!   supply) on PA0 / ADC1_IN0, sampled at 16 kHz by TIM2's update interrupt. The interrupt
//!   fills one half of a double buffer of 256 samples (16 ms) while the main loop processes the
//!   other, as a DMA double buffer would; a full buffer the main loop has not taken yet counts
//!   as an overrun (LED toggles).
//! - **Servos out**: eight hobby servos on TIM3 CH1-4 (PA6, PA7, PB0, PB1) and TIM4 CH1-4 (PB6,
//!   PB7, PB8, PB9) at the blob's PWM period, driven by the runtime's device loop
//!   (`device::Device`: the blob's controller and its `ServoRig` with the blob's calibration;
//!   clamped, slew-limited, neutral at power-up).
//! - **Policy**: the blob is `include_bytes!`'d (see `build.rs`), validated once at boot; the
//!   controller is built in place on the stack (`BlobController::from_blob_in`).
//!
//! On a bad blob (refused, not 8 channels, not 16 kHz) the servos stay unpowered (no PWM) and
//! the LED (PC13) blinks fast. Cost, measured on the same runtime under QEMU
//! (`boards/qemu-m4/report`): about 5.8 M instructions per second of audio, i.e. 6% of this
//! core at 96 MHz if it ran one instruction per cycle; RAM about 26 KiB of stack.
#![no_std]
#![no_main]

use core::cell::RefCell;
use core::convert::Infallible;

use cortex_m::interrupt::Mutex;
use cortex_m_rt::entry;
use embedded_hal::pwm::{ErrorType, SetDutyCycle};
use gesture_runtime::blob::Blob;
use gesture_runtime::controller::BlobController;
use gesture_runtime::device::Device;
use panic_halt as _;
use stm32f4xx_hal::adc::config::{AdcConfig, Clock, SampleTime};
use stm32f4xx_hal::adc::Adc;
use stm32f4xx_hal::gpio::{Analog, Output, PushPull, PA0, PC13};
use stm32f4xx_hal::pac::{self, interrupt, Interrupt, ADC1, TIM2, TIM3, TIM4};
use stm32f4xx_hal::prelude::*;
use stm32f4xx_hal::rcc::Config;
use stm32f4xx_hal::timer::{CounterHz, ErasedChannel, Event};

/// The policy blob (`build.rs`).
static BLOB: &[u8] = include_bytes!(concat!(env!("OUT_DIR"), "/policy.blob"));

/// Microphone sample rate (the blob's front-end must run at it).
const RATE_HZ: u32 = 16_000;
/// Samples per buffer (16 ms).
const CHUNK: usize = 256;
/// Servo channels (the blob's rig must have exactly these, e.g. `rigs/puppet-8ch.toml`).
const CHANNELS: usize = 8;

/// What the sampling interrupt owns.
struct Mic {
    adc: Adc<ADC1>,
    pin: PA0<Analog>,
    timer: CounterHz<TIM2>,
}

/// The double buffer between the sampling interrupt and the main loop.
struct Buffers {
    data: [[i16; CHUNK]; 2],
    /// The half being filled.
    filling: usize,
    pos: usize,
    /// A full half waiting for the main loop.
    ready: Option<usize>,
    overruns: u32,
}

impl Buffers {
    const fn new() -> Self {
        Self {
            data: [[0; CHUNK]; 2],
            filling: 0,
            pos: 0,
            ready: None,
            overruns: 0,
        }
    }

    fn push(&mut self, s: i16) {
        self.data[self.filling][self.pos] = s;
        self.pos += 1;
        if self.pos == CHUNK {
            if self.ready.is_some() {
                // The main loop is late: the older buffer is dropped.
                self.overruns = self.overruns.wrapping_add(1);
            }
            self.ready = Some(self.filling);
            self.filling ^= 1;
            self.pos = 0;
        }
    }

    fn take(&mut self) -> Option<[i16; CHUNK]> {
        self.ready.take().map(|half| self.data[half])
    }
}

static MIC: Mutex<RefCell<Option<Mic>>> = Mutex::new(RefCell::new(None));
static BUFFERS: Mutex<RefCell<Buffers>> = Mutex::new(RefCell::new(Buffers::new()));

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
    let raw = mic.adc.convert(&mic.pin, SampleTime::Cycles_28) as i32;
    let s = ((raw - 2048) << 4).clamp(i16::MIN as i32, i16::MAX as i32) as i16;
    cortex_m::interrupt::free(|cs| BUFFERS.borrow(cs).borrow_mut().push(s));
}

/// One servo output: a channel of TIM3 or TIM4 (`ServoRig` wants one pin type).
enum Servo {
    Tim3(ErasedChannel<TIM3>),
    Tim4(ErasedChannel<TIM4>),
}

impl Servo {
    fn enable(&mut self) {
        match self {
            Self::Tim3(c) => c.enable(),
            Self::Tim4(c) => c.enable(),
        }
    }
}

impl ErrorType for Servo {
    type Error = Infallible;
}

impl SetDutyCycle for Servo {
    fn max_duty_cycle(&self) -> u16 {
        match self {
            Self::Tim3(c) => c.max_duty_cycle(),
            Self::Tim4(c) => c.max_duty_cycle(),
        }
    }

    fn set_duty_cycle(&mut self, duty: u16) -> Result<(), Infallible> {
        match self {
            Self::Tim3(c) => c.set_duty_cycle(duty),
            Self::Tim4(c) => c.set_duty_cycle(duty),
        }
    }
}

/// A blob this board cannot run: no PWM, LED blinking fast, forever.
fn refuse(led: &mut PC13<Output<PushPull>>) -> ! {
    loop {
        led.toggle();
        cortex_m::asm::delay(96_000_000 / 10);
    }
}

#[entry]
fn main() -> ! {
    let Some(dp) = pac::Peripherals::take() else {
        loop {
            cortex_m::asm::wfi();
        }
    };
    let mut rcc = dp.RCC.freeze(Config::hse(25.MHz()).sysclk(96.MHz()));
    let gpioa = dp.GPIOA.split(&mut rcc);
    let gpiob = dp.GPIOB.split(&mut rcc);
    let gpioc = dp.GPIOC.split(&mut rcc);
    let mut led = gpioc.pc13.into_push_pull_output();
    led.set_high(); // off (active low)

    // Check once, then trust: everything below reads the validated blob.
    let Ok(blob) = Blob::parse(BLOB) else {
        refuse(&mut led)
    };
    let config = blob.prosody_config();
    if config.sample_rate_hz != RATE_HZ || blob.channels() != CHANNELS {
        refuse(&mut led);
    }
    let period_us = blob.period_us();
    let pwm_hz = (1_000_000.0 / period_us + 0.5) as u32;

    // Servos: the channels start at duty 0 (no pulse, servos idle) until the rig drives them
    // to neutral.
    let (_tim3, (c1, c2, c3, c4)) = dp.TIM3.pwm_hz(pwm_hz.Hz(), &mut rcc);
    let (_tim4, (d1, d2, d3, d4)) = dp.TIM4.pwm_hz(pwm_hz.Hz(), &mut rcc);
    let mut pins = [
        Servo::Tim3(c1.with(gpioa.pa6).erase()),
        Servo::Tim3(c2.with(gpioa.pa7).erase()),
        Servo::Tim3(c3.with(gpiob.pb0).erase()),
        Servo::Tim3(c4.with(gpiob.pb1).erase()),
        Servo::Tim4(d1.with(gpiob.pb6).erase()),
        Servo::Tim4(d2.with(gpiob.pb7).erase()),
        Servo::Tim4(d3.with(gpiob.pb8).erase()),
        Servo::Tim4(d4.with(gpiob.pb9).erase()),
    ];
    pins.iter_mut().for_each(Servo::enable);
    // The controller, in place on this stack frame (about 15 KiB), and the device: the
    // controller with the servo rig (the blob's calibration), which drives them to neutral.
    let mut slot = None;
    let Ok(controller) = BlobController::from_blob_in(&mut slot, &blob) else {
        refuse(&mut led)
    };
    let Ok(mut device) = Device::new(controller, pins) else {
        refuse(&mut led)
    };

    // Microphone: TIM2 at 16 kHz, one ADC conversion per update interrupt.
    // ADC clock 96 MHz / 4 = 24 MHz (at most 36 MHz): a conversion takes (28 + 12) / 24 MHz
    // = 1.7 us of the 62.5 us between samples.
    let adc_config = AdcConfig::default().clock(Clock::Pclk2_div_4);
    let adc = Adc::new(dp.ADC1, true, adc_config, &mut rcc);
    let pin = gpioa.pa0.into_analog();
    let mut timer = dp.TIM2.counter_hz(&mut rcc);
    if timer.start(RATE_HZ.Hz()).is_err() {
        refuse(&mut led);
    }
    timer.listen(Event::Update);
    cortex_m::interrupt::free(|cs| MIC.borrow(cs).replace(Some(Mic { adc, pin, timer })));
    // SAFETY: the handler only touches what was moved into MIC and BUFFERS (both behind
    // critical sections); unmasking cannot break a critical section in progress.
    unsafe { cortex_m::peripheral::NVIC::unmask(Interrupt::TIM2) };

    let mut seen_overruns = 0;
    loop {
        let (chunk, overruns) = cortex_m::interrupt::free(|cs| {
            let mut b = BUFFERS.borrow(cs).borrow_mut();
            (b.take(), b.overruns)
        });
        if overruns != seen_overruns {
            seen_overruns = overruns;
            led.toggle();
        }
        match chunk {
            // Timer channels cannot fail; nothing else to do per event.
            Some(samples) => {
                let _ = device.push(&samples, &mut |_| {});
            }
            None => cortex_m::asm::wfi(),
        }
    }
}
