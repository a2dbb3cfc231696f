//! Servos on a PCA9685 16-channel I2C PWM board (the `pca9685` feature), through the
//! `pwm-pca9685` driver (embedded-hal 1.0).
//!
//! Most hobby animatronics drive their servos from a PCA9685 rather than the MCU's timers. The
//! [`ServoRig`](crate::rig::ServoRig) writes duty cycles to `SetDutyCycle` pins; here the pins
//! are [`Pca9685Pin`]s, which only hold their 12-bit "off" count (the board counts 4096 steps
//! per PWM period, every pulse starting at count 0), and [`Pca9685Servos::write`] sends all
//! sixteen channels to the board in one I2C transaction after each tick, so a pose changes on
//! every servo in the same PWM period.
//!
//! **Frequency.** The board's PWM period comes from its prescaler:
//! `prescale = round(25 MHz / (4096 * f)) - 1` (datasheet section 7.3.5, internal 25 MHz
//! oscillator), 121 for 50 Hz, which gives 50.03 Hz: pulses come out 0.06 % shorter than the
//! rig computes with its 20 000 us period, well inside a servo's tolerance.
//! [`Pca9685Servos::actual_period_us`] says what the board really runs at, if a rig wants it
//! exactly.

use core::convert::Infallible;

use embedded_hal::i2c::I2c;
use embedded_hal::pwm::{ErrorType, SetDutyCycle};
use pwm_pca9685::{Error, Pca9685};

/// Channels of one board.
pub const PCA9685_CHANNELS: usize = 16;
/// Counts per PWM period.
pub const PCA9685_COUNTS: u16 = 4096;
/// The internal oscillator (Hz).
pub const PCA9685_OSC_HZ: f32 = 25.0e6;

/// One channel's duty cycle as the board's "off" count (the pulse starts at count 0).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Pca9685Pin {
    off: u16,
}

impl Pca9685Pin {
    /// The count at which the pulse ends (0..=4095).
    pub fn off(&self) -> u16 {
        self.off
    }
}

impl ErrorType for Pca9685Pin {
    type Error = Infallible;
}

impl SetDutyCycle for Pca9685Pin {
    fn max_duty_cycle(&self) -> u16 {
        PCA9685_COUNTS
    }

    fn set_duty_cycle(&mut self, duty: u16) -> Result<(), Infallible> {
        // 4096 would be "always on", which no servo pulse is; the 12-bit register holds 4095.
        self.off = duty.min(PCA9685_COUNTS - 1);
        Ok(())
    }
}

/// The prescaler value for a PWM period of `period_us` (`None` outside the board's 24-1526 Hz).
pub fn prescale_for(period_us: f32) -> Option<u8> {
    if !(period_us.is_finite() && period_us > 0.0) {
        return None;
    }
    let hz = 1.0e6 / period_us;
    let p = libm::roundf(PCA9685_OSC_HZ / (f32::from(PCA9685_COUNTS) * hz)) - 1.0;
    (3.0..=255.0).contains(&p).then_some(p as u8)
}

/// A PCA9685 board driving the servos of a rig.
pub struct Pca9685Servos<I2C> {
    pca: Pca9685<I2C>,
    prescale: u8,
}

impl<I2C, E> Pca9685Servos<I2C>
where
    I2C: I2c<Error = E>,
{
    /// Sets the board at 7-bit `address` (0x40 with no address pins bridged) to the PWM
    /// period `period_us` and starts its oscillator.
    pub fn new(i2c: I2C, address: u8, period_us: f32) -> Result<Self, Error<E>> {
        let prescale = prescale_for(period_us).ok_or(Error::InvalidInputData)?;
        let mut pca = Pca9685::new(i2c, address)?;
        pca.set_prescale(prescale)?;
        pca.enable()?;
        Ok(Self { pca, prescale })
    }

    /// The PWM period the board runs at (us).
    pub fn actual_period_us(&self) -> f32 {
        f32::from(PCA9685_COUNTS) * (f32::from(self.prescale) + 1.0) / PCA9685_OSC_HZ * 1.0e6
    }

    /// Sends the pins' counts, channel `k` = `pins[k]` (missing channels off), in one
    /// transaction.
    pub fn write(&mut self, pins: &[Pca9685Pin]) -> Result<(), Error<E>> {
        let mut off = [0u16; PCA9685_CHANNELS];
        for (o, p) in off.iter_mut().zip(pins) {
            *o = p.off;
        }
        self.pca.set_all_on_off(&[0; PCA9685_CHANNELS], &off)
    }

    /// The I2C bus back.
    pub fn destroy(self) -> I2C {
        self.pca.destroy()
    }
}
