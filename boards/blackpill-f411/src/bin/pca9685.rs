//! The gesture controller on a Black Pill with the servos on a PCA9685 16-channel I2C board
//! (the usual hobby animatronics setup) instead of the MCU's timers.
//!
//! - **Microphone in**: as in the main firmware (`src/mic.rs`: PA0, 16 kHz).
//! - **Servos out**: a PCA9685 board at I2C address 0x40 on I2C1 (SCL PB6, SDA PB7, 400 kHz,
//!   the board's pull-ups), up to 16 servos on its channels 0-15 in the blob's rig order (e.g.
//!   `rigs/puppet-pca9685.toml`). The runtime's `ServoRig` computes the clamped, slew-limited
//!   duty cycles into `Pca9685Pin`s; after each tick all channels go to the board in one I2C
//!   write (`gesture_runtime::pca9685`), at the blob's PWM period (prescaler 121 for 50 Hz).
//!
//! On a bad blob (refused, more than 16 channels, not 16 kHz) or no board answering, the LED
//! (PC13) blinks fast.
#![no_std]
#![no_main]

#[path = "../mic.rs"]
mod mic;

use cortex_m_rt::entry;
use gesture_runtime::blob::Blob;
use gesture_runtime::controller::BlobController;
use gesture_runtime::device::{Device, DeviceEvent};
use gesture_runtime::pca9685::{Pca9685Pin, Pca9685Servos, PCA9685_CHANNELS};
use panic_halt as _;
use stm32f4xx_hal::gpio::{Output, PushPull, PC13};
use stm32f4xx_hal::pac;
use stm32f4xx_hal::prelude::*;
use stm32f4xx_hal::rcc::Config;

/// The policy blob (`build.rs`).
static BLOB: &[u8] = include_bytes!(concat!(env!("OUT_DIR"), "/policy.blob"));

/// The board's 7-bit address with no address pads bridged.
const PCA9685_ADDRESS: u8 = 0x40;

/// Something this board cannot run: LED blinking fast, forever.
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

    let Ok(blob) = Blob::parse(BLOB) else {
        refuse(&mut led)
    };
    if blob.prosody_config().sample_rate_hz != mic::RATE_HZ || blob.channels() > PCA9685_CHANNELS {
        refuse(&mut led);
    }
    let i2c = dp.I2C1.i2c((gpiob.pb6, gpiob.pb7), 400.kHz(), &mut rcc);
    let Ok(mut board) = Pca9685Servos::new(i2c, PCA9685_ADDRESS, blob.period_us()) else {
        refuse(&mut led)
    };
    let mut slot = None;
    let Ok(controller) = BlobController::from_blob_in(&mut slot, &blob) else {
        refuse(&mut led)
    };
    let Ok(mut device) = Device::new(controller, [Pca9685Pin::default(); PCA9685_CHANNELS]) else {
        refuse(&mut led)
    };
    // Channels past the blob's rig get no pulse at all.
    let channels = blob.channels();
    // The rig starts at neutral: send it before the first tick.
    if board.write(&device.rig().pins()[..channels]).is_err() {
        refuse(&mut led);
    }
    if mic::start(dp.ADC1, gpioa.pa0, dp.TIM2, &mut rcc).is_err() {
        refuse(&mut led);
    }

    let mut seen_overruns = 0;
    let mut bus_errors = 0u32;
    loop {
        let (chunk, overruns) = mic::take();
        if overruns != seen_overruns {
            seen_overruns = overruns;
            led.toggle();
        }
        match chunk {
            Some(samples) => {
                let _ = device.push(&samples, &mut |e| {
                    if let DeviceEvent::Servos { rig, .. } = e {
                        // A failed write leaves the servos at the last pose; the next tick
                        // tries again.
                        if board.write(&rig.pins()[..channels]).is_err() {
                            bus_errors = bus_errors.wrapping_add(1);
                        }
                    }
                });
            }
            None => cortex_m::asm::wfi(),
        }
    }
}
