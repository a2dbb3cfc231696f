//! `ServoRig` against a mock PWM pin that records every duty cycle written to it.

use core::convert::Infallible;

use embedded_hal::pwm::{ErrorKind, ErrorType, SetDutyCycle};
use gesture_runtime::rig::{
    duty_cycle, CalError, ChannelCal, RigError, ServoRig, MAX_CHANNELS, PULSE_MAX_US, SLEW_SLACK,
};

/// A 16-bit PWM channel that remembers every duty it was given.
#[derive(Debug, Default)]
struct MockPin {
    max: u16,
    written: Vec<u16>,
}

impl MockPin {
    fn new(max: u16) -> MockPin {
        MockPin {
            max,
            written: Vec::new(),
        }
    }

    fn last(&self) -> u16 {
        *self.written.last().expect("the pin was written")
    }
}

impl ErrorType for MockPin {
    type Error = Infallible;
}

impl SetDutyCycle for MockPin {
    fn max_duty_cycle(&self) -> u16 {
        self.max
    }

    fn set_duty_cycle(&mut self, duty: u16) -> Result<(), Infallible> {
        assert!(duty <= self.max, "duty {duty} above max {}", self.max);
        self.written.push(duty);
        Ok(())
    }
}

/// A pin that fails every write.
#[derive(Debug, Default)]
struct BrokenPin {
    attempts: usize,
}

impl ErrorType for BrokenPin {
    type Error = ErrorKind;
}

impl SetDutyCycle for BrokenPin {
    fn max_duty_cycle(&self) -> u16 {
        1000
    }

    fn set_duty_cycle(&mut self, _duty: u16) -> Result<(), ErrorKind> {
        self.attempts += 1;
        Err(ErrorKind::Other)
    }
}

const PERIOD: f32 = 20_000.0;

fn cal(min: f32, max: f32, slew: f32) -> ChannelCal {
    ChannelCal {
        min_deg: min,
        max_deg: max,
        max_slew_deg_per_s: slew,
        ..ChannelCal::HOBBY
    }
}

/// The duty a pulse of `us` gives in the 20 ms period on a 16-bit timer, by hand.
fn duty_of(us: f64) -> u16 {
    (us / 20_000.0 * 65_535.0).round() as u16
}

#[test]
fn duty_math_matches_hand_computed_values() {
    // 1500 us of 20 000 us at full scale 65535: 4915.125 -> 4915.
    assert_eq!(duty_cycle(1500.0, 20_000.0, 65_535), 4915);
    // 1000 us -> 3276.75 -> 3277; 2000 us -> 6553.5 -> 6554 (half away from zero).
    assert_eq!(duty_cycle(1000.0, 20_000.0, 65_535), 3277);
    assert_eq!(duty_cycle(2000.0, 20_000.0, 65_535), 6554);
    // Saturation and garbage.
    assert_eq!(duty_cycle(30_000.0, 20_000.0, 1000), 1000);
    assert_eq!(duty_cycle(-5.0, 20_000.0, 1000), 0);
    assert_eq!(duty_cycle(f32::NAN, 20_000.0, 1000), 0);
    assert_eq!(duty_cycle(1500.0, 0.0, 1000), 0);

    let mut rig = ServoRig::new([MockPin::new(65_535)], [ChannelCal::HOBBY], PERIOD).unwrap();
    rig.neutral().unwrap();
    assert_eq!(rig.pins()[0].last(), 4915);
    // 10 deg at 10 us/deg = 1600 us -> 5242.8 -> 5243.
    rig.apply(&[10.0], 1.0).unwrap();
    assert_eq!(rig.pins()[0].last(), 5243);
    assert_eq!(rig.pins()[0].last(), duty_of(1600.0));
}

#[test]
fn targets_are_clamped_to_the_limits() {
    let mut rig = ServoRig::new(
        [MockPin::new(65_535), MockPin::new(65_535)],
        [cal(-30.0, 45.0, 1000.0), cal(-30.0, 45.0, 1000.0)],
        PERIOD,
    )
    .unwrap();
    // A whole second at 1000 deg/s: the slew limit does not bind, the limits do.
    rig.apply(&[200.0, -1e30], 1.0).unwrap();
    assert_eq!(rig.angles(), &[45.0, -30.0]);
    assert_eq!(rig.pins()[0].last(), duty_of(1950.0));
    assert_eq!(rig.pins()[1].last(), duty_of(1200.0));
}

#[test]
fn slew_limit_reaches_a_step_in_the_expected_number_of_ticks() {
    let slew = 250.0_f32;
    let dt = 0.02_f32;
    let target = 60.0_f32;
    let mut rig = ServoRig::new([MockPin::new(65_535)], [cal(-90.0, 90.0, slew)], PERIOD).unwrap();
    // ceil(60 / (250 * 0.02)) = ceil(60 / 5) = 12 ticks.
    let expected_ticks = (target / (slew * dt)).ceil() as usize;
    assert_eq!(expected_ticks, 12);
    let mut prev = rig.angles()[0];
    let mut ticks = 0;
    while rig.angles()[0] != target {
        rig.apply(&[target], dt).unwrap();
        let a = rig.angles()[0];
        assert!(
            a - prev <= slew * dt * (1.0 + SLEW_SLACK),
            "tick {ticks}: moved {} deg, more than {}",
            a - prev,
            slew * dt
        );
        assert!(a > prev, "tick {ticks}: no progress");
        prev = a;
        ticks += 1;
        assert!(ticks <= 100, "never reached the target");
    }
    assert_eq!(ticks, expected_ticks);
    assert_eq!(rig.pins()[0].written.len(), expected_ticks);

    // A step that is not a multiple of the per-tick limit: ceil(7 / 5) = 2 ticks back.
    let back = target - 7.0;
    rig.apply(&[back], dt).unwrap();
    assert_eq!(rig.angles()[0], target - 5.0);
    rig.apply(&[back], dt).unwrap();
    assert_eq!(rig.angles()[0], back);

    // No time, no movement; garbage time counts as no time.
    for bad_dt in [0.0, -1.0, f32::NAN, f32::INFINITY] {
        rig.apply(&[0.0], bad_dt).unwrap();
        assert_eq!(rig.angles()[0], back, "dt {bad_dt}");
    }
}

#[test]
fn direction_inverts_the_pulse_around_neutral() {
    let plus = ChannelCal {
        neutral_deg: 10.0,
        pulse_neutral_us: 1400.0,
        ..cal(-80.0, 80.0, 1e6)
    };
    let minus = ChannelCal {
        direction: -1.0,
        ..plus
    };
    let mut rig = ServoRig::new(
        [MockPin::new(65_535), MockPin::new(65_535)],
        [plus, minus],
        PERIOD,
    )
    .unwrap();
    rig.apply(&[30.0, 30.0], 1.0).unwrap();
    // 20 deg past neutral at 10 us/deg: 1400 +- 200 us.
    assert_eq!(rig.pins()[0].last(), duty_of(1600.0));
    assert_eq!(rig.pins()[1].last(), duty_of(1200.0));
    rig.apply(&[10.0, 10.0], 1.0).unwrap();
    assert_eq!(rig.pins()[0].last(), duty_of(1400.0));
    assert_eq!(rig.pins()[1].last(), duty_of(1400.0));
}

#[test]
fn non_finite_or_missing_targets_hold_the_current_angle() {
    let mut rig = ServoRig::new(
        [
            MockPin::new(65_535),
            MockPin::new(65_535),
            MockPin::new(65_535),
        ],
        [cal(-90.0, 90.0, 1e6); 3],
        PERIOD,
    )
    .unwrap();
    rig.apply(&[20.0, -20.0, 5.0], 1.0).unwrap();
    rig.apply(&[f32::NAN, f32::INFINITY], 1.0).unwrap();
    assert_eq!(rig.angles(), &[20.0, -20.0, 5.0]);
    rig.apply(&[f32::NEG_INFINITY, 1.0, 2.0, 99.0], 1.0)
        .unwrap();
    assert_eq!(rig.angles(), &[20.0, 1.0, 2.0]);
    assert!(rig.angles().iter().all(|a| a.is_finite()));
    let pin = &rig.pins()[0];
    assert_eq!(pin.written.len(), 3);
    assert!(pin.written.iter().all(|&d| d == duty_of(1700.0)));
}

#[test]
fn neutral_on_fault_ignores_the_slew_limit() {
    let c = ChannelCal {
        neutral_deg: -10.0,
        ..cal(-90.0, 90.0, 50.0)
    };
    let mut rig =
        ServoRig::new([MockPin::new(65_535), MockPin::new(4095)], [c, c], PERIOD).unwrap();
    for _ in 0..100 {
        rig.apply(&[80.0, 80.0], 0.1).unwrap();
    }
    assert_eq!(rig.angles(), &[80.0, 80.0]);
    rig.neutral().unwrap();
    assert_eq!(rig.angles(), &[-10.0, -10.0]);
    assert_eq!(rig.pins()[0].last(), duty_of(1500.0));
    // A 12-bit timer: 1500 / 20000 * 4095 = 307.125 -> 307.
    assert_eq!(rig.pins()[1].last(), 307);
}

#[test]
fn every_pin_is_written_even_when_one_fails() {
    let mut rig = ServoRig::new(
        [BrokenPin::default(), BrokenPin::default()],
        [ChannelCal::HOBBY; 2],
        PERIOD,
    )
    .unwrap();
    assert_eq!(rig.apply(&[1.0, 2.0], 0.1), Err(ErrorKind::Other));
    assert_eq!(rig.neutral(), Err(ErrorKind::Other));
    let pins = rig.release();
    assert!(pins.iter().all(|p| p.attempts == 2));
}

#[test]
fn invalid_calibrations_and_periods_are_refused() {
    let ok = ChannelCal::HOBBY;
    assert_eq!(ok.validate(), Ok(()));
    let cases = [
        (
            ChannelCal {
                min_deg: 10.0,
                max_deg: -10.0,
                ..ok
            },
            CalError::EmptyRange,
        ),
        (
            ChannelCal {
                neutral_deg: f32::NAN,
                ..ok
            },
            CalError::NotFinite,
        ),
        (
            ChannelCal {
                neutral_deg: 95.0,
                ..ok
            },
            CalError::NeutralOutsideLimits,
        ),
        (
            ChannelCal {
                direction: 0.5,
                ..ok
            },
            CalError::BadDirection,
        ),
        (
            ChannelCal {
                us_per_deg: 0.0,
                ..ok
            },
            CalError::BadScale,
        ),
        (
            ChannelCal {
                max_slew_deg_per_s: 0.0,
                ..ok
            },
            CalError::BadSlew,
        ),
        (
            // +-120 deg at 10 us/deg reaches 300 and 2700 us.
            ChannelCal {
                min_deg: -120.0,
                max_deg: 120.0,
                ..ok
            },
            CalError::PulseOutOfRange,
        ),
    ];
    for (c, want) in cases {
        assert_eq!(c.validate(), Err(want), "{c:?}");
        let err = ServoRig::new([MockPin::new(100), MockPin::new(100)], [ok, c], PERIOD)
            .expect_err("refused");
        assert_eq!(
            err,
            RigError::Calibration {
                channel: 1,
                error: want
            }
        );
        assert!(err.to_string().starts_with("channel 1: "), "{err}");
    }
    for period in [f32::NAN, 0.0, PULSE_MAX_US, 1e9] {
        assert_eq!(
            ServoRig::new([MockPin::new(100)], [ok], period).err(),
            Some(RigError::BadPeriod)
        );
    }
    let many: Result<ServoRig<MockPin, { MAX_CHANNELS + 1 }>, _> = ServoRig::new(
        core::array::from_fn(|_| MockPin::new(100)),
        [ok; MAX_CHANNELS + 1],
        PERIOD,
    );
    assert_eq!(many.err(), Some(RigError::TooManyChannels));
}

#[test]
fn random_garbage_never_leaves_the_limits_or_produces_nan() {
    // A small LCG so the test needs no RNG crate.
    let mut s: u64 = 0x1234_5678;
    let mut next = move || {
        s = s
            .wrapping_mul(6_364_136_223_846_793_005)
            .wrapping_add(1_442_695_040_888_963_407);
        f32::from_bits((s >> 32) as u32)
    };
    let cals = [cal(-45.0, 60.0, 300.0), ChannelCal::HOBBY];
    let mut rig =
        ServoRig::new([MockPin::new(65_535), MockPin::new(65_535)], cals, PERIOD).unwrap();
    for _ in 0..10_000 {
        let pose = [next(), next()];
        rig.apply(&pose, next()).unwrap();
        for (a, c) in rig.angles().iter().zip(cals.iter()) {
            assert!(a.is_finite() && *a >= c.min_deg && *a <= c.max_deg, "{a}");
        }
    }
}
