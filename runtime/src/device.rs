//! The one device path: a validated blob becomes a [`BlobController`] (the blob's front-end,
//! tables and decision timing) and a [`ServoRig`] (the blob's calibration and PWM period),
//! and [`Device::push`] runs samples through both: every pose of an animation tick is applied
//! to the rig with `dt = 1 / fps` before the tick's event reaches the caller, who then sees
//! the controller's events and the servos' state.
//!
//! The simulator, live mode, the boards and every evaluation run this loop, so what is
//! measured on the desktop is what the board does.
//!
//! **Invariants.** Fixed memory (the controller, `N` pins and calibrations); no allocation,
//! no panics; pin errors do not stop the controller: the first one of a call is returned
//! after every event of that call was delivered. Rig channels beyond the blob's (`N` larger
//! than the blob's channel count) idle at a hobby servo's neutral.
//!
//! Building: the controller (about 15 KiB) is built in place in a caller's `Option` with
//! [`Controller::from_blob_in`] (on the stack or in a `static`, its tables written where
//! they stay), and the device borrows it with the rig beside it ([`Device::new`]):
//!
//! ```ignore
//! let blob = Blob::parse(BYTES)?;
//! let mut slot = None;
//! let controller = Controller::from_blob_in(&mut slot, &blob)?;
//! let mut device = Device::new(controller, pins)?;
//! device.push(&samples, &mut |event| { /* poses, decisions, servos */ })?;
//! ```

use core::fmt;

use embedded_hal::pwm::{ErrorType, SetDutyCycle};

#[cfg(doc)]
use crate::controller::Controller;
use crate::controller::{BlobController, ControllerError, ControllerEvent};
use crate::prosody::arith::{Arith, DefaultArith};
use crate::rig::{ChannelCal, RigError, ServoRig};

/// Why a device could not be built from a blob (the controller's errors come from
/// [`Controller::from_blob_in`]; they are carried here so one error type covers both steps).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum DeviceError {
    /// The controller refused the blob's tables.
    Controller(ControllerError),
    /// The blob drives more channels than the device has pins.
    TooManyChannels {
        /// The blob's channel count.
        blob: usize,
        /// The device's pins.
        pins: usize,
    },
    /// The servo rig refused the blob's calibration.
    Rig(RigError),
}

impl fmt::Display for DeviceError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::Controller(e) => write!(f, "controller: {e}"),
            Self::TooManyChannels { blob, pins } => write!(
                f,
                "the blob drives {blob} channels, the device has {pins} servo outputs"
            ),
            Self::Rig(e) => write!(f, "servo rig: {e}"),
        }
    }
}

impl core::error::Error for DeviceError {}

/// What a [`Device`] reports, in time order.
pub enum DeviceEvent<'e, P, const N: usize> {
    /// An event of the controller (frames, steps, decisions, onsets, poses).
    Controller(ControllerEvent<'e>),
    /// The servos after the pose of `tick` was applied (read the pins or the commanded
    /// angles from the rig).
    Servos {
        /// The animation tick.
        tick: u64,
        /// The rig.
        rig: &'e ServoRig<P, N>,
    },
}

/// A PWM output that does nothing: a device whose servos nobody reads (evaluations).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct NullPin;

impl ErrorType for NullPin {
    type Error = core::convert::Infallible;
}

impl SetDutyCycle for NullPin {
    fn max_duty_cycle(&self) -> u16 {
        u16::MAX
    }
    fn set_duty_cycle(&mut self, _duty: u16) -> Result<(), Self::Error> {
        Ok(())
    }
}

/// A blob's controller driving `N` servo pins (see the module docs).
pub struct Device<'c, 'a, P, const N: usize, A: Arith = DefaultArith> {
    controller: &'c mut BlobController<'a, A>,
    rig: ServoRig<P, N>,
    dt_s: f32,
}

impl<'c, 'a, P: SetDutyCycle, const N: usize, A: Arith> Device<'c, 'a, P, N, A> {
    /// The device for the blob `controller` runs (build the controller in place with
    /// [`Controller::from_blob_in`]) on `pins`, with the blob's calibration and PWM period;
    /// drives the servos to neutral (power-up).
    pub fn new(
        controller: &'c mut BlobController<'a, A>,
        pins: [P; N],
    ) -> Result<Self, DeviceError> {
        Self::calibrated(controller, pins, None)
    }

    /// [`new`](Self::new) with the servo calibration of a rig file instead of the blob's:
    /// `cals` (one per blob channel, checked by the rig) and the PWM period.
    pub fn calibrated(
        controller: &'c mut BlobController<'a, A>,
        pins: [P; N],
        calibration: Option<(&[ChannelCal], f32)>,
    ) -> Result<Self, DeviceError> {
        let blob = controller.tables();
        let channels = blob.channels();
        if channels > N {
            return Err(DeviceError::TooManyChannels {
                blob: channels,
                pins: N,
            });
        }
        let mut cals = [ChannelCal::HOBBY; N];
        for (ch, c) in cals.iter_mut().enumerate().take(channels) {
            // Validated with the blob: every channel has a calibration.
            *c = blob.calibration(ch).unwrap_or(ChannelCal::HOBBY);
        }
        let mut period = blob.period_us();
        if let Some((given, p)) = calibration {
            if given.len() != channels {
                return Err(DeviceError::TooManyChannels {
                    blob: channels,
                    pins: given.len(),
                });
            }
            cals[..channels].copy_from_slice(given);
            period = p;
        }
        let mut rig = ServoRig::new(pins, cals, period).map_err(DeviceError::Rig)?;
        // Power-up: the servos start where the rig assumes they are. A pin error here shows
        // again on the first push.
        let _ = rig.neutral();
        Ok(Self {
            dt_s: 1.0 / blob.fps(),
            controller,
            rig,
        })
    }

    /// Feeds samples (at the blob's rate, any chunk size); reports the controller's events
    /// and, after each pose, the servos. Returns the first pin error of the call.
    pub fn push(
        &mut self,
        samples: &[i16],
        sink: &mut impl FnMut(DeviceEvent<'_, P, N>),
    ) -> Result<(), P::Error> {
        let (controller, rig, dt) = (&mut *self.controller, &mut self.rig, self.dt_s);
        let mut result = Ok(());
        controller.push(samples, &mut |ev| {
            Self::route(rig, dt, &mut result, sink, ev);
        });
        result
    }

    /// Ends the input stream ([`Controller::finish`]); no tick is played.
    pub fn finish(&mut self, sink: &mut impl FnMut(DeviceEvent<'_, P, N>)) -> Result<(), P::Error> {
        let (controller, rig, dt) = (&mut *self.controller, &mut self.rig, self.dt_s);
        let mut result = Ok(());
        controller.finish(&mut |ev| {
            Self::route(rig, dt, &mut result, sink, ev);
        });
        result
    }

    fn route(
        rig: &mut ServoRig<P, N>,
        dt: f32,
        result: &mut Result<(), P::Error>,
        sink: &mut impl FnMut(DeviceEvent<'_, P, N>),
        ev: ControllerEvent<'_>,
    ) {
        if let ControllerEvent::Pose { tick, pose, .. } = ev {
            let r = rig.apply(pose, dt);
            if result.is_ok() {
                *result = r;
            }
            sink(DeviceEvent::Controller(ev));
            sink(DeviceEvent::Servos { tick, rig: &*rig });
        } else {
            sink(DeviceEvent::Controller(ev));
        }
    }

    /// The controller (its belief, timing, ...).
    pub fn controller(&self) -> &BlobController<'a, A> {
        self.controller
    }

    /// The controller, to change its settings (e.g. [`Controller::set_timing`]).
    pub fn controller_mut(&mut self) -> &mut BlobController<'a, A> {
        self.controller
    }

    /// The servo rig.
    pub fn rig(&self) -> &ServoRig<P, N> {
        &self.rig
    }

    /// Drives every servo to neutral at once (the fault path).
    pub fn neutral(&mut self) -> Result<(), P::Error> {
        self.rig.neutral()
    }
}
