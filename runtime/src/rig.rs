//! The servo rig: pose angles in, PWM duty cycles out, through
//! [`embedded_hal::pwm::SetDutyCycle`] (docs/method.md, "The runtime").
//!
//! Owns the per-channel calibration ([`ChannelCal`]), its validation, and [`ServoRig`], which
//! clamps each target angle to the channel's limits, limits how fast it may change (slew) and
//! maps the angle to a pulse width and then to a duty cycle.
//!
//! ## Units and the mapping
//!
//! A channel carries one pose angle in degrees (the rig file's joint rotation about one axis).
//! With calibration `c`, an angle `a` (already clamped to `[c.min_deg, c.max_deg]`) becomes
//!
//! ```text
//! pulse_us = c.pulse_neutral_us + c.direction * c.us_per_deg * (a - c.neutral_deg)
//! duty     = round(pulse_us / period_us * max_duty_cycle), clamped to 0..=max_duty_cycle
//! ```
//!
//! so a 1500 us pulse in a 20 000 us period on a 16-bit timer (`max_duty_cycle` 65535) is
//! duty 4915. `direction = -1` mirrors a servo mounted the other way round.
//!
//! ## Invariants
//!
//! - A [`ChannelCal`] that passed [`ChannelCal::validate`] has finite fields, `min < max`,
//!   neutral within the limits, a positive slew rate and scale, and pulses within
//!   [`PULSE_MIN_US`]..=[`PULSE_MAX_US`] over its whole range. [`ServoRig::new`] is the gate:
//!   it accepts only validated calibrations and a sane period, after which nothing fails
//!   except the pins themselves.
//! - Commanded angles are always finite and within the channel's limits: a NaN or infinite
//!   target means "hold the current angle"; a non-finite or negative `dt_s` means no time has
//!   passed (the servos hold).
//! - Per call, a channel moves by at most `max_slew_deg_per_s * dt_s` degrees (times
//!   `1 + SLEW_SLACK`, 1e-4, so rounding cannot add an extra tick to a step), except in
//!   [`ServoRig::neutral`], the fault path, which goes to neutral at once.
//! - No allocation, no panics, no floating-point operation that could produce NaN from valid
//!   state; cost is O(N) per call. Safe to call from a timer interrupt.
//!
//! ## Choices
//!
//! [`ServoRig::new`] does not touch the pins (it cannot report a pin error); it assumes the
//! servos start at neutral, so call [`ServoRig::neutral`] once at power-up to make that true.
//! The duty is computed in `f32` and rounded to the nearest step (`libm::roundf`), rather than
//! with `set_duty_cycle_fraction`, whose integer division truncates and whose 16-bit
//! numerator would lose the fractional microseconds.

use core::fmt;

use embedded_hal::pwm::SetDutyCycle;

/// Relative slack on the per-call slew limit that absorbs `f32` rounding (see
/// [`ServoRig::apply`]).
pub const SLEW_SLACK: f32 = 1e-4;

/// Most channels a rig (and so a pose) may have; the rig file and the blob are checked
/// against it. Large enough for the full-skeleton rig of a 75-joint body with fingers
/// (ZeroEGGS: 225 rotation channels), which the simulator uses for BVH output; a pose of this
/// size is 1 KiB of `f32`.
pub const MAX_CHANNELS: usize = 256;

/// Shortest pulse a calibration may ask for (us); hobby servos accept 500..=2500 us.
pub const PULSE_MIN_US: f32 = 500.0;
/// Longest pulse a calibration may ask for (us).
pub const PULSE_MAX_US: f32 = 2500.0;
/// Longest PWM period [`ServoRig::new`] accepts (us): 10 Hz.
pub const PERIOD_MAX_US: f32 = 100_000.0;

/// Calibration of one servo channel. Angles are pose angles in degrees (the joint rotation the
/// rig file maps to this channel), pulses are in microseconds.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ChannelCal {
    /// Pose angle that the neutral pulse represents (deg).
    pub neutral_deg: f32,
    /// Lowest pose angle the channel will be driven to (deg).
    pub min_deg: f32,
    /// Highest pose angle the channel will be driven to (deg).
    pub max_deg: f32,
    /// `+1.0` or `-1.0`: whether a larger angle lengthens or shortens the pulse.
    pub direction: f32,
    /// Pulse width at the neutral angle (us).
    pub pulse_neutral_us: f32,
    /// Pulse change per degree (us/deg, positive; the sign is `direction`).
    pub us_per_deg: f32,
    /// Fastest the commanded angle may change (deg/s, positive).
    pub max_slew_deg_per_s: f32,
}

impl ChannelCal {
    /// A standard hobby servo: neutral 0 deg at 1500 us, 10 us/deg, limits +-90 deg
    /// (600..=2400 us), 250 deg/s.
    pub const HOBBY: ChannelCal = ChannelCal {
        neutral_deg: 0.0,
        min_deg: -90.0,
        max_deg: 90.0,
        direction: 1.0,
        pulse_neutral_us: 1500.0,
        us_per_deg: 10.0,
        max_slew_deg_per_s: 250.0,
    };

    /// Checks the invariants listed in the module docs.
    pub fn validate(&self) -> Result<(), CalError> {
        let fields = [
            self.neutral_deg,
            self.min_deg,
            self.max_deg,
            self.direction,
            self.pulse_neutral_us,
            self.us_per_deg,
            self.max_slew_deg_per_s,
        ];
        if fields.iter().any(|v| !v.is_finite()) {
            return Err(CalError::NotFinite);
        }
        if self.min_deg >= self.max_deg {
            return Err(CalError::EmptyRange);
        }
        if self.neutral_deg < self.min_deg || self.neutral_deg > self.max_deg {
            return Err(CalError::NeutralOutsideLimits);
        }
        if self.direction != 1.0 && self.direction != -1.0 {
            return Err(CalError::BadDirection);
        }
        if self.us_per_deg <= 0.0 {
            return Err(CalError::BadScale);
        }
        if self.max_slew_deg_per_s <= 0.0 {
            return Err(CalError::BadSlew);
        }
        // The map is linear, so the extreme pulses are at the limits (and neutral between).
        for p in [self.pulse_us(self.min_deg), self.pulse_us(self.max_deg)] {
            if !(PULSE_MIN_US..=PULSE_MAX_US).contains(&p) {
                return Err(CalError::PulseOutOfRange);
            }
        }
        Ok(())
    }

    /// `angle_deg` clamped to the limits; a non-finite angle gives `None`.
    pub fn clamp(&self, angle_deg: f32) -> Option<f32> {
        if !angle_deg.is_finite() {
            return None;
        }
        Some(angle_deg.max(self.min_deg).min(self.max_deg))
    }

    /// Pulse width (us) for a pose angle, without clamping (see the module docs).
    pub fn pulse_us(&self, angle_deg: f32) -> f32 {
        self.pulse_neutral_us + self.direction * self.us_per_deg * (angle_deg - self.neutral_deg)
    }
}

/// Duty cycle for a pulse of `pulse_us` in a period of `period_us` on a timer whose full scale
/// is `max_duty`: `round(pulse_us / period_us * max_duty)`, clamped to `0..=max_duty`
/// (0 if the arguments are not finite or the period is not positive).
pub fn duty_cycle(pulse_us: f32, period_us: f32, max_duty: u16) -> u16 {
    if !(pulse_us.is_finite() && period_us.is_finite() && period_us > 0.0) {
        return 0;
    }
    let max = f32::from(max_duty);
    let d = libm::roundf(pulse_us / period_us * max);
    if d <= 0.0 {
        0
    } else if d >= max {
        max_duty
    } else {
        // In range and integral, so the cast is exact.
        d as u16
    }
}

/// Checks a PWM period (us): finite, longer than [`PULSE_MAX_US`] and at most
/// [`PERIOD_MAX_US`].
pub fn validate_period(period_us: f32) -> Result<(), RigError> {
    if period_us.is_finite() && period_us > PULSE_MAX_US && period_us <= PERIOD_MAX_US {
        Ok(())
    } else {
        Err(RigError::BadPeriod)
    }
}

/// What is wrong with a [`ChannelCal`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum CalError {
    /// A field is NaN or infinite.
    NotFinite,
    /// `min_deg` is not below `max_deg`.
    EmptyRange,
    /// `neutral_deg` lies outside `[min_deg, max_deg]`.
    NeutralOutsideLimits,
    /// `direction` is neither `1` nor `-1`.
    BadDirection,
    /// `us_per_deg` is not positive.
    BadScale,
    /// `max_slew_deg_per_s` is not positive.
    BadSlew,
    /// The pulse at `min_deg` or `max_deg` is outside 500..=2500 us.
    PulseOutOfRange,
}

impl fmt::Display for CalError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            CalError::NotFinite => "a calibration value is NaN or infinite",
            CalError::EmptyRange => "min_deg must be below max_deg",
            CalError::NeutralOutsideLimits => "neutral_deg must lie within min_deg..=max_deg",
            CalError::BadDirection => "direction must be 1 or -1",
            CalError::BadScale => "us_per_deg must be positive",
            CalError::BadSlew => "max_slew_deg_per_s must be positive",
            CalError::PulseOutOfRange => {
                "the pulse at min_deg or max_deg falls outside 500..=2500 us: narrow the limits \
                 or lower us_per_deg"
            }
        })
    }
}

impl core::error::Error for CalError {}

/// Why a [`ServoRig`] could not be built.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum RigError {
    /// Channel `channel`'s calibration is invalid.
    Calibration {
        /// Index of the channel.
        channel: usize,
        /// What is wrong with it.
        error: CalError,
    },
    /// The PWM period is not finite, not longer than the longest pulse (2500 us) or longer
    /// than [`PERIOD_MAX_US`].
    BadPeriod,
    /// More channels than [`MAX_CHANNELS`].
    TooManyChannels,
}

impl fmt::Display for RigError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            RigError::Calibration { channel, error } => write!(f, "channel {channel}: {error}"),
            RigError::BadPeriod => f.write_str(
                "the PWM period must be finite, longer than 2500 us and at most 100000 us \
                 (20000 us is standard for hobby servos)",
            ),
            RigError::TooManyChannels => {
                write!(f, "a rig has at most {MAX_CHANNELS} channels")
            }
        }
    }
}

impl core::error::Error for RigError {}

/// `N` servos on `SetDutyCycle` pins with their calibrations (see the module docs).
#[derive(Debug)]
pub struct ServoRig<P, const N: usize> {
    pins: [P; N],
    cals: [ChannelCal; N],
    period_us: f32,
    angles: [f32; N],
}

impl<P: SetDutyCycle, const N: usize> ServoRig<P, N> {
    /// Checks `cals` and `period_us` (the PWM period in us, e.g. 20 000 for 50 Hz) and builds
    /// the rig. The pins are not written; the commanded angles start at neutral.
    pub fn new(pins: [P; N], cals: [ChannelCal; N], period_us: f32) -> Result<Self, RigError> {
        Self::check(&cals, period_us)?;
        Ok(Self::new_unchecked(pins, cals, period_us))
    }

    /// The checks of [`new`](Self::new).
    pub(crate) fn check(cals: &[ChannelCal; N], period_us: f32) -> Result<(), RigError> {
        if N > MAX_CHANNELS {
            return Err(RigError::TooManyChannels);
        }
        validate_period(period_us)?;
        for (channel, cal) in cals.iter().enumerate() {
            cal.validate()
                .map_err(|error| RigError::Calibration { channel, error })?;
        }
        Ok(())
    }

    /// [`new`](Self::new) after [`check`](Self::check) passed.
    #[inline(always)]
    pub(crate) fn new_unchecked(pins: [P; N], cals: [ChannelCal; N], period_us: f32) -> Self {
        let mut angles = [0.0; N];
        for (a, c) in angles.iter_mut().zip(cals.iter()) {
            *a = c.neutral_deg;
        }
        ServoRig {
            pins,
            cals,
            period_us,
            angles,
        }
    }

    /// Moves every channel toward its target in `pose_deg` (one angle per channel, degrees)
    /// by at most its slew limit times `dt_s` (seconds since the last call), within its
    /// limits, and writes the duty cycles. A NaN or infinite target, or a channel past the end
    /// of `pose_deg`, holds its current angle; extra entries are ignored.
    ///
    /// Every pin is written even if one fails; the first pin error is returned.
    pub fn apply(&mut self, pose_deg: &[f32], dt_s: f32) -> Result<(), P::Error> {
        let dt = if dt_s.is_finite() && dt_s > 0.0 {
            dt_s
        } else {
            0.0
        };
        for (k, (angle, cal)) in self.angles.iter_mut().zip(self.cals.iter()).enumerate() {
            let current = *angle;
            let target = pose_deg
                .get(k)
                .and_then(|&t| cal.clamp(t))
                .unwrap_or(current);
            // Both factors are finite and non-negative; an overflow to +inf only means "no
            // limit", which the comparisons below handle.
            let max_step = cal.max_slew_deg_per_s * dt;
            let step = target - current;
            // A target within the step (plus rounding slack) is reached exactly, so a step
            // of d degrees takes ceil(d / (slew * dt)) calls even when `slew * dt` is not
            // exact in binary (0.02 s ticks).
            let reach = max_step * (1.0 + SLEW_SLACK);
            let next = if step > reach {
                current + max_step
            } else if step < -reach {
                current - max_step
            } else {
                target
            };
            // Rounding in `current +- max_step` must not leave the limits.
            *angle = next.max(cal.min_deg).min(cal.max_deg);
        }
        self.write_all()
    }

    /// Drives every channel to its neutral angle at once, ignoring the slew limit: the fault
    /// path (bad blob, lost audio, watchdog). Every pin is written even if one fails; the first
    /// pin error is returned.
    pub fn neutral(&mut self) -> Result<(), P::Error> {
        for (a, c) in self.angles.iter_mut().zip(self.cals.iter()) {
            *a = c.neutral_deg;
        }
        self.write_all()
    }

    fn write_all(&mut self) -> Result<(), P::Error> {
        let mut result = Ok(());
        for ((pin, cal), &angle) in self
            .pins
            .iter_mut()
            .zip(self.cals.iter())
            .zip(self.angles.iter())
        {
            let duty = duty_cycle(cal.pulse_us(angle), self.period_us, pin.max_duty_cycle());
            let r = pin.set_duty_cycle(duty);
            if result.is_ok() {
                result = r;
            }
        }
        result
    }

    /// The commanded angle of every channel (deg): what the servos were last told.
    pub fn angles(&self) -> &[f32; N] {
        &self.angles
    }

    /// The calibrations.
    pub fn cals(&self) -> &[ChannelCal; N] {
        &self.cals
    }

    /// The PWM period (us).
    pub fn period_us(&self) -> f32 {
        self.period_us
    }

    /// The pins, e.g. for a simulator to read back what was written.
    pub fn pins(&self) -> &[P; N] {
        &self.pins
    }

    /// Gives the pins back.
    pub fn release(self) -> [P; N] {
        self.pins
    }
}
