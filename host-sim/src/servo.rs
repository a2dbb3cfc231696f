//! The virtual servo rig: the runtime's own [`ServoRig`] driving PWM pins that only remember
//! what they were told, so the simulator's `servo.csv` shows exactly the duty cycles a board
//! running the same blob would write.
//!
//! [`VirtualPin`] implements `embedded_hal::pwm::SetDutyCycle` with a 16-bit timer
//! (`max_duty_cycle` = 65535, the usual STM32 setting). [`VirtualRig`] holds a
//! `ServoRig<VirtualPin, MAX_CHANNELS>`: the rig's capacity is fixed at compile time, so the
//! channels past the blob's are padded with a hobby-servo calibration and never reported.
//! It powers up at neutral (as firmware should) and then applies one pose per animation tick
//! with `dt = 1 / fps`, so clamping and the slew limit act exactly as on the device.

use std::convert::Infallible;

use embedded_hal::pwm::{ErrorType, SetDutyCycle};
use gesture_runtime::rig::{ChannelCal, RigError, ServoRig, MAX_CHANNELS};

/// Full scale of the virtual timer.
pub const MAX_DUTY: u16 = u16::MAX;

/// A PWM output that records the last duty cycle written.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct VirtualPin {
    duty: u16,
    writes: u64,
}

impl VirtualPin {
    /// The last duty cycle written (0 before any write).
    pub fn duty(&self) -> u16 {
        self.duty
    }

    /// How many times the pin was written.
    pub fn writes(&self) -> u64 {
        self.writes
    }
}

impl ErrorType for VirtualPin {
    type Error = Infallible;
}

impl SetDutyCycle for VirtualPin {
    fn max_duty_cycle(&self) -> u16 {
        MAX_DUTY
    }

    fn set_duty_cycle(&mut self, duty: u16) -> Result<(), Infallible> {
        self.duty = duty;
        self.writes += 1;
        Ok(())
    }
}

/// The runtime's `ServoRig` over virtual pins, for `channels` real channels.
pub struct VirtualRig {
    rig: Box<ServoRig<VirtualPin, MAX_CHANNELS>>,
    channels: usize,
    dt_s: f32,
}

impl VirtualRig {
    /// A rig for `cals` (at most [`MAX_CHANNELS`]) with PWM period `period_us`, stepped every
    /// `dt_s` seconds; every pin is set to its neutral duty (power-up).
    pub fn new(cals: &[ChannelCal], period_us: f32, dt_s: f32) -> Result<Self, RigError> {
        if cals.len() > MAX_CHANNELS {
            return Err(RigError::TooManyChannels);
        }
        let mut all = [ChannelCal::HOBBY; MAX_CHANNELS];
        all[..cals.len()].copy_from_slice(cals);
        let mut rig = Box::new(ServoRig::new(
            [VirtualPin::default(); MAX_CHANNELS],
            all,
            period_us,
        )?);
        // Infallible pins.
        let _ = rig.neutral();
        Ok(Self {
            rig,
            channels: cals.len(),
            dt_s,
        })
    }

    /// Applies one tick's pose (degrees per channel) and returns the duty cycles written.
    pub fn apply(&mut self, pose: &[f32]) -> Vec<u16> {
        let n = self.channels.min(pose.len());
        let _ = self.rig.apply(&pose[..n], self.dt_s);
        self.duties()
    }

    /// The current duty cycle of every channel.
    pub fn duties(&self) -> Vec<u16> {
        self.rig.pins()[..self.channels]
            .iter()
            .map(VirtualPin::duty)
            .collect()
    }

    /// The commanded angles (degrees).
    pub fn angles(&self) -> &[f32] {
        &self.rig.angles()[..self.channels]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn neutral_then_slew_limited_steps() {
        let cal = ChannelCal {
            max_slew_deg_per_s: 30.0,
            ..ChannelCal::HOBBY
        };
        let mut rig = VirtualRig::new(&[cal, ChannelCal::HOBBY], 20_000.0, 0.1).unwrap();
        // 1500 us of 20000 us at 16 bits.
        assert_eq!(rig.duties(), vec![4915, 4915]);
        let d = rig.apply(&[90.0, 10.0]);
        // 3 degrees (30 deg/s x 0.1 s) = 30 us on channel 0; channel 1 reaches 10 deg.
        assert_eq!(d, vec![4915 + 98, 4915 + 328]);
        assert!((rig.angles()[0] - 3.0).abs() < 1e-4);
    }
}
