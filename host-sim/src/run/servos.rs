//! A rig run's servo channels as moving bars, in the previews and `viewer.html`: per channel,
//! the pulse it is sent (from the duty cycles of `servo.csv`) between the pulses of its
//! limits, with a tick at its neutral pulse. Shown for a blob packed with a rig file; the
//! full-skeleton rig's channels are the BVH's joint rotations, not servos, and have none.
//!
//! The limits are the blob's calibration (a `--rig` override changes the duty cycles of
//! `servo.csv` but not these bars' scale). Nothing here panics: a degenerate range gives a
//! bar at its middle.

use gesture_runtime::blob::Blob;
use gesture_runtime::rig::ChannelCal;
use serde::Serialize;

use super::canvas::{Canvas, GRID, INK};
use super::sim::Simulation;
use crate::servo::MAX_DUTY;

/// `servo.csv` of a run.
pub fn servo_csv(sim: &Simulation, names: &[&str]) -> String {
    let mut s = String::from("tick,time_s");
    for n in names {
        s.push(',');
        s.push_str(n);
    }
    s.push('\n');
    for (tick, row) in sim.duties.iter().enumerate() {
        s.push_str(&format!("{tick},{:.4}", tick as f64 / sim.fps));
        for d in row {
            s.push_str(&format!(",{d}"));
        }
        s.push('\n');
    }
    s
}

/// The name of the rig `pack` makes without a rig file.
pub const FULL_SKELETON: &str = "full-skeleton";

/// The servo channels of a blob with a rig.
#[derive(Clone, Debug, Serialize)]
pub struct ServoBars {
    /// Channel names.
    pub names: Vec<String>,
    /// Pulse at the lower end of each bar (us).
    pub lo_us: Vec<f32>,
    /// Pulse at the upper end (us).
    pub hi_us: Vec<f32>,
    /// Neutral pulse (us).
    pub neutral_us: Vec<f32>,
    /// PWM period (us).
    pub period_us: f32,
}

impl ServoBars {
    /// The bars of `blob`'s rig; `None` for the full-skeleton rig.
    pub fn new(blob: &Blob<'_>) -> Option<Self> {
        if blob.rig_name() == FULL_SKELETON || blob.channels() == 0 {
            return None;
        }
        let cals: Vec<ChannelCal> = (0..blob.channels())
            .map(|c| blob.calibration(c).unwrap_or(ChannelCal::HOBBY))
            .collect();
        let ends = |c: &ChannelCal| {
            let (a, b) = (c.pulse_us(c.min_deg), c.pulse_us(c.max_deg));
            (a.min(b), a.max(b))
        };
        Some(Self {
            names: blob.channel_names().map(str::to_string).collect(),
            lo_us: cals.iter().map(|c| ends(c).0).collect(),
            hi_us: cals.iter().map(|c| ends(c).1).collect(),
            neutral_us: cals.iter().map(|c| c.pulse_neutral_us).collect(),
            period_us: blob.period_us(),
        })
    }

    /// The pulse (us) of a duty cycle.
    pub fn pulse_us(&self, duty: u16) -> f32 {
        duty as f32 / MAX_DUTY as f32 * self.period_us
    }

    /// Where `pulse` is between channel `c`'s limits (0..=1).
    fn level(&self, c: usize, pulse: f32) -> f32 {
        let (lo, hi) = (self.lo_us[c], self.hi_us[c]);
        if hi - lo > 1e-3 && pulse.is_finite() {
            ((pulse - lo) / (hi - lo)).clamp(0.0, 1.0)
        } else {
            0.5
        }
    }

    /// Draws one vertical bar per channel into the box (x, y, w, h), filled up to the pulse
    /// of `duties` (one tick's duty cycles), with the neutral as a tick.
    pub(super) fn draw(&self, cv: &mut Canvas, duties: &[u16], (x, y, w, h): (i64, i64, i64, i64)) {
        let n = self.names.len() as i64;
        if n == 0 || w < n || h < 4 {
            return;
        }
        let pitch = w / n;
        let bar = (pitch * 2 / 3).max(2);
        for c in 0..self.names.len() {
            let bx = x + c as i64 * pitch + (pitch - bar) / 2;
            cv.fill(bx, y, bx + bar, y + h, GRID);
            let at = |v: f32| y + h - 1 - (v * (h - 1) as f32).round() as i64;
            if let Some(&d) = duties.get(c) {
                let top = at(self.level(c, self.pulse_us(d)));
                cv.fill(bx, top, bx + bar, y + h, BAR);
            }
            let t = at(self.level(c, self.neutral_us[c]));
            cv.fill(bx - 1, t, bx + bar + 1, t + 1, INK);
        }
    }
}

/// The bars' fill (palette index).
pub(super) const BAR: u8 = 13;

/// The bars' colour.
pub(super) fn palette_into(p: &mut [u8]) {
    p[3 * BAR as usize..3 * BAR as usize + 3].copy_from_slice(&[224, 120, 40]);
}

#[cfg(test)]
mod tests {
    use super::*;

    fn bars() -> ServoBars {
        ServoBars {
            names: vec!["a".into(), "b".into()],
            lo_us: vec![1000.0, 1500.0],
            hi_us: vec![2000.0, 1500.0],
            neutral_us: vec![1500.0, 1500.0],
            period_us: 20_000.0,
        }
    }

    #[test]
    fn a_pulse_is_placed_between_the_limits() {
        let b = bars();
        assert!((b.pulse_us(MAX_DUTY) - 20_000.0).abs() < 1e-2);
        assert_eq!(b.level(0, 1250.0), 0.25);
        assert_eq!(b.level(0, 5000.0), 1.0);
        assert_eq!(
            b.level(1, 1700.0),
            0.5,
            "a channel without travel sits in the middle"
        );
    }

    #[test]
    fn the_bar_fills_up_to_the_pulse() {
        let b = bars();
        let mut cv = Canvas::new(20, 11, 0);
        // 1750 us of 20 000: three quarters of the first bar's travel.
        let duty = (1750.0 / 20_000.0 * MAX_DUTY as f32).round() as u16;
        b.draw(&mut cv, &[duty, 0], (0, 0, 20, 11));
        let column: Vec<u8> = (0..11).map(|y| cv.px[y * 20 + 4]).collect();
        // Rows 0..=10; 0.75 of the travel is row 3 (the duty's rounding keeps it just under);
        // the neutral tick (row 5) is drawn over the fill.
        assert_eq!(column[..3], [GRID; 3], "{column:?}");
        assert!(
            column[3..].iter().all(|&c| c == BAR || c == INK),
            "{column:?}"
        );
        assert_eq!(column[5], INK, "{column:?}");
    }
}
