//! The gesture controller on a Raspberry Pi Pico (RP2040, Cortex-M0+ at 125 MHz, no FPU).
//!
//! - **Microphone in**: an analog electret module (MAX9814 or MAX4466, output biased at half
//!   supply) on GP26 / ADC0, sampled at 16 kHz by the ADC's own pacing timer into its FIFO;
//!   the FIFO interrupt fills one half of a double buffer of 256 samples (16 ms) while the
//!   main loop processes the other ([`mic`]); a full buffer the main loop has not taken yet
//!   counts as an overrun (LED toggles).
//! - **Servos out**: eight hobby servos on PWM slices 0-3, channels A and B (GP0-GP7), each
//!   slice counting at 1 MHz with its period the blob's, driven by the runtime's device loop
//!   (`device::Device`: the blob's controller and its `ServoRig` with the blob's calibration;
//!   clamped, slew-limited, neutral at power-up).
//! - **Policy**: the blob is `include_bytes!`'d (see `build.rs`), validated once at boot; the
//!   controller is built in place on the stack (`BlobController::from_blob_in`).
//!
//! On a bad blob (refused, not 8 channels, not 16 kHz, a period over 65.5 ms) the servos stay
//! unpowered (no pulses) and the LED (GP25) blinks fast. The setup follows rp2040-hal's
//! examples (`pwm_blink_embedded_hal_1`, `adc_fifo_irq`, `gpio_irq_example`).
//!
//! **No FPU.** The runtime is built with its `fixed` feature: the front-end's per-sample and
//! per-frame work is integer (`prosody::arith::Fixed`), the rest (a few hundred `f32`
//! operations per syllable and per decision) soft-float. Cost, measured on the same runtime
//! built the same way as ARMv6-M code under QEMU (`boards/qemu-m0/report`): about 22 M
//! instructions per second of audio, under a fifth of this core at 125 MHz if it ran one
//! instruction per cycle (most Cortex-M0+ instructions take one); a worst decision under 1 M
//! instructions (8 ms); RAM about 24 KiB of stack.
#![no_std]
#![no_main]

mod mic;

use core::convert::Infallible;

use embedded_hal::delay::DelayNs;
use embedded_hal::digital::StatefulOutputPin;
use embedded_hal::pwm::SetDutyCycle;
use gesture_runtime::blob::Blob;
use gesture_runtime::controller::BlobController;
use gesture_runtime::device::Device;
use panic_halt as _;
use rp2040_hal::{self as hal, Clock};

/// The second-stage bootloader for the Pico's W25Q080 flash, first in flash (`memory.x`).
#[link_section = ".boot2"]
#[used]
pub static BOOT2: [u8; 256] = rp2040_boot2::BOOT_LOADER_W25Q080;

/// The policy blob (`build.rs`).
static BLOB: &[u8] = include_bytes!(concat!(env!("OUT_DIR"), "/policy.blob"));

/// The Pico's crystal.
const XTAL_FREQ_HZ: u32 = 12_000_000;
/// Servo channels (the blob's rig must have exactly these, e.g. `rigs/puppet-8ch.toml`).
const CHANNELS: usize = 8;
/// The PWM counters' rate: one count per microsecond, so a period is its length in us.
const PWM_COUNT_HZ: u32 = 1_000_000;

/// A blob this board cannot run: no pulses, LED blinking fast, forever.
fn refuse(led: &mut impl StatefulOutputPin, delay: &mut impl DelayNs) -> ! {
    loop {
        let _ = led.toggle();
        delay.delay_ms(100);
    }
}

#[hal::entry]
fn main() -> ! {
    let Some(mut pac) = hal::pac::Peripherals::take() else {
        loop {
            cortex_m::asm::wfi();
        }
    };
    let mut watchdog = hal::Watchdog::new(pac.WATCHDOG);
    // 125 MHz system clock, 48 MHz USB (and ADC) clock.
    let Ok(clocks) = hal::clocks::init_clocks_and_plls(
        XTAL_FREQ_HZ,
        pac.XOSC,
        pac.CLOCKS,
        pac.PLL_SYS,
        pac.PLL_USB,
        &mut pac.RESETS,
        &mut watchdog,
    ) else {
        loop {
            cortex_m::asm::wfi();
        }
    };
    let sio = hal::Sio::new(pac.SIO);
    let pins = hal::gpio::Pins::new(
        pac.IO_BANK0,
        pac.PADS_BANK0,
        sio.gpio_bank0,
        &mut pac.RESETS,
    );
    let mut led = pins.gpio25.into_push_pull_output();
    let mut timer = hal::Timer::new(pac.TIMER, &mut pac.RESETS, &clocks);

    // Check once, then trust: everything below reads the validated blob.
    let Ok(blob) = Blob::parse(BLOB) else {
        refuse(&mut led, &mut timer)
    };
    let config = blob.prosody_config();
    let period = (blob.period_us() + 0.5) as u32;
    let divider = clocks.system_clock.freq().to_Hz() / PWM_COUNT_HZ;
    if config.sample_rate_hz != mic::RATE_HZ
        || blob.channels() != CHANNELS
        || !(1..=65_536).contains(&period)
        || !(1..=255).contains(&divider)
    {
        refuse(&mut led, &mut timer);
    }

    // Servos: slices 0-3 count at 1 MHz up to the blob's period; their channels start at duty
    // 0 (no pulse, servos idle) until the rig drives them to neutral.
    let mut slices = hal::pwm::Slices::new(pac.PWM, &mut pac.RESETS);
    slices.pwm0.channel_a.output_to(pins.gpio0);
    slices.pwm0.channel_b.output_to(pins.gpio1);
    slices.pwm1.channel_a.output_to(pins.gpio2);
    slices.pwm1.channel_b.output_to(pins.gpio3);
    slices.pwm2.channel_a.output_to(pins.gpio4);
    slices.pwm2.channel_b.output_to(pins.gpio5);
    slices.pwm3.channel_a.output_to(pins.gpio6);
    slices.pwm3.channel_b.output_to(pins.gpio7);
    macro_rules! servo_slice {
        ($($slice:ident),*) => {$(
            slices.$slice.set_div_int(divider as u8);
            slices.$slice.set_top((period - 1) as u16);
            slices.$slice.enable();
        )*};
    }
    servo_slice!(pwm0, pwm1, pwm2, pwm3);
    // `ServoRig` wants one pin type; every channel is a different type, so they are lent as
    // trait objects (`&mut dyn SetDutyCycle` is one).
    let s = &mut slices;
    let servos: [&mut dyn SetDutyCycle<Error = Infallible>; CHANNELS] = [
        &mut s.pwm0.channel_a,
        &mut s.pwm0.channel_b,
        &mut s.pwm1.channel_a,
        &mut s.pwm1.channel_b,
        &mut s.pwm2.channel_a,
        &mut s.pwm2.channel_b,
        &mut s.pwm3.channel_a,
        &mut s.pwm3.channel_b,
    ];
    // The controller (with the fixed-point front-end: the `fixed` feature in Cargo.toml), in
    // place on this stack frame (about 15 KiB), and the device: the
    // controller with the servo rig (the blob's calibration), which drives them to neutral.
    let mut slot = None;
    let Ok(controller) = BlobController::from_blob_in(&mut slot, &blob) else {
        refuse(&mut led, &mut timer)
    };
    let Ok(mut device) = Device::new(controller, servos) else {
        refuse(&mut led, &mut timer)
    };

    // Microphone: the ADC free-running at 16 kHz on GP26, its FIFO drained by interrupt.
    let Some(adc) = cortex_m::singleton!(: hal::Adc = hal::Adc::new(pac.ADC, &mut pac.RESETS))
    else {
        refuse(&mut led, &mut timer)
    };
    let Ok(mut mic_pin) = hal::adc::AdcPin::new(pins.gpio26.into_floating_input()) else {
        refuse(&mut led, &mut timer)
    };
    mic::start(adc, &mut mic_pin);

    let mut seen_overruns = 0;
    loop {
        let (chunk, overruns) = mic::take();
        if overruns != seen_overruns {
            seen_overruns = overruns;
            let _ = led.toggle();
        }
        match chunk {
            // PWM channels cannot fail; nothing else to do per event.
            Some(samples) => {
                let _ = device.push(&samples, &mut |_| {});
            }
            None => cortex_m::asm::wfi(),
        }
    }
}
