//! Virtual servo pins: [`VirtualPin`] implements `embedded_hal::pwm::SetDutyCycle` with a
//! 16-bit timer (`max_duty_cycle` = 65535, the usual STM32 setting) and only remembers what
//! it was told, so the simulator's `servo.csv` shows exactly the duty cycles a board running
//! the same blob would write. The runtime's device loop drives them through its own
//! `ServoRig` (capacity fixed at compile time: channels past the blob's idle at a hobby
//! servo's neutral and are never reported), powering up at neutral and applying one pose per
//! animation tick with `dt = 1 / fps`, so clamping and the slew limit act as on the device.

use std::convert::Infallible;

use embedded_hal::pwm::{ErrorType, SetDutyCycle};

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

#[cfg(test)]
mod tests {
    use super::*;

    use gesture_runtime::rig::{ChannelCal, ServoRig};

    #[test]
    fn neutral_then_slew_limited_steps() {
        let cal = ChannelCal {
            max_slew_deg_per_s: 30.0,
            ..ChannelCal::HOBBY
        };
        let mut rig = ServoRig::new(
            [VirtualPin::default(); 2],
            [cal, ChannelCal::HOBBY],
            20_000.0,
        )
        .unwrap();
        rig.neutral().unwrap();
        let duties = |r: &ServoRig<VirtualPin, 2>| r.pins().map(|p| p.duty());
        // 1500 us of 20000 us at 16 bits.
        assert_eq!(duties(&rig), [4915, 4915]);
        rig.apply(&[90.0, 10.0], 0.1).unwrap();
        // 3 degrees (30 deg/s x 0.1 s) = 30 us on channel 0; channel 1 reaches 10 deg.
        assert_eq!(duties(&rig), [4915 + 98, 4915 + 328]);
        assert!((rig.angles()[0] - 3.0).abs() < 1e-4);
        assert_eq!(rig.pins()[0].writes(), 2);
    }
}
