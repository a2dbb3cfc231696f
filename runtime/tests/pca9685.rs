//! The rig's servos on a PCA9685: the exact I2C register writes for known poses, against a
//! mocked bus (embedded-hal-mock).

use embedded_hal_mock::eh1::i2c::{Mock, Transaction};
use gesture_runtime::pca9685::{prescale_for, Pca9685Pin, Pca9685Servos};
use gesture_runtime::rig::{ChannelCal, ServoRig};

const ADDR: u8 = 0x40;
const MODE1: u8 = 0x00;
const PRE_SCALE: u8 = 0xFE;
const LED0_ON_L: u8 = 0x06;

/// The one transaction that sets all sixteen channels: on = 0, off = `offs` (rest 0).
fn all_channels(offs: &[u16]) -> Transaction {
    let mut data = vec![LED0_ON_L];
    for k in 0..16 {
        let off = offs.get(k).copied().unwrap_or(0);
        data.extend_from_slice(&[0, 0, off as u8, (off >> 8) as u8]);
    }
    Transaction::write(ADDR, data)
}

#[test]
fn prescaler_values_from_the_datasheet_formula() {
    // round(25e6 / (4096 * 50)) - 1 = 121; 200 Hz: 30; 1526 Hz is the fastest (3).
    assert_eq!(prescale_for(20_000.0), Some(121));
    assert_eq!(prescale_for(5_000.0), Some(30));
    assert_eq!(prescale_for(1.0e6 / 1526.0), Some(3));
    assert_eq!(prescale_for(1.0e6 / 2000.0), None);
    assert_eq!(prescale_for(1.0e6 / 20.0), None);
    assert_eq!(prescale_for(f32::NAN), None);
}

#[test]
fn known_poses_give_the_known_register_writes() {
    let expect = [
        // new(): the prescaler while the oscillator sleeps (power-up state), then wake it.
        Transaction::write(ADDR, vec![PRE_SCALE, 121]),
        Transaction::write(ADDR, vec![MODE1, 0x01]),
        // First write: auto-increment on, then all channels at once.
        // 0 deg = 1500 us of 20 000 -> 307.2 counts -> 307 (0x133); 45 deg = 1950 us ->
        // 399.36 -> 399 (0x18F).
        Transaction::write(ADDR, vec![MODE1, 0x21]),
        all_channels(&[307, 399]),
        // Next tick: -90 deg = 600 us -> 122.88 -> 123; +90 (past the limit 90: clamped)
        // = 2400 us -> 491.52 -> 492.
        all_channels(&[123, 492]),
    ];
    let mut bus = Mock::new(&expect);
    let mut board = Pca9685Servos::new(bus.clone(), ADDR, 20_000.0).unwrap();
    assert!((board.actual_period_us() - 19_988.48).abs() < 0.01);
    let mut rig =
        ServoRig::new([Pca9685Pin::default(); 2], [ChannelCal::HOBBY; 2], 20_000.0).unwrap();
    // A long tick: no slew limit in the way.
    rig.apply(&[0.0, 45.0], 10.0).unwrap();
    board.write(rig.pins()).unwrap();
    rig.apply(&[-90.0, 120.0], 10.0).unwrap();
    board.write(rig.pins()).unwrap();
    assert_eq!(rig.pins()[1].off(), 492);
    board.destroy();
    bus.done();
}

#[test]
fn a_bad_period_is_refused_before_the_bus_is_touched() {
    let mut bus = Mock::new(&[]);
    assert!(Pca9685Servos::new(bus.clone(), ADDR, 100.0).is_err());
    bus.done();
}
