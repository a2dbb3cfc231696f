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

mod mic;

use core::convert::Infallible;

use cortex_m_rt::entry;
use embedded_hal::pwm::{ErrorType, SetDutyCycle};
use gesture_runtime::blob::Blob;
use gesture_runtime::controller::BlobController;
use gesture_runtime::device::Device;
use panic_halt as _;
use stm32f4xx_hal::gpio::{Output, PushPull, PC13};
use stm32f4xx_hal::pac::{self, TIM3, TIM4};
use stm32f4xx_hal::prelude::*;
use stm32f4xx_hal::rcc::Config;
use stm32f4xx_hal::timer::ErasedChannel;

/// The policy blob (`build.rs`).
static BLOB: &[u8] = include_bytes!(concat!(env!("OUT_DIR"), "/policy.blob"));

use mic::RATE_HZ;
/// Servo channels (the blob's rig must have exactly these, e.g. `rigs/puppet-8ch.toml`).
const CHANNELS: usize = 8;

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
    if mic::start(dp.ADC1, gpioa.pa0, dp.TIM2, &mut rcc).is_err() {
        refuse(&mut led);
    }

    let mut seen_overruns = 0;
    loop {
        let (chunk, overruns) = mic::take();
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
