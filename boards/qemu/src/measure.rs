//! Instruction counts on the device (the `measure` build, read by `report`).
//!
//! ## The clock
//!
//! Under `qemu-system-arm -icount shift=0` every guest instruction advances virtual time by
//! exactly 1 ns, and the Cortex-M's DWT cycle counter reads 0. SysTick, free-running from the
//! core clock (25 MHz on `mps2-an386`, 20 MHz on `mps2-an505`), therefore ticks once per 40 (50)
//! instructions, repeatably.
//! [`Clock`] extends its 24-bit down-counter to 64 bits (it is read far more often than it
//! wraps, every 16.7 M ticks) and [`calibrate`] measures the instructions per tick on a loop of
//! known length, so nothing here assumes the 40. Resolution is one tick (40 or 50 instructions).
//!
//! ## What is timed
//!
//! [`Timing`] implements the drive loop's [`Probe`]. It counts only time inside
//! `Controller::push`: the event sink (trace printing, hashes, the servo rig) and the copy into
//! the DMA buffer are excluded. The controller emits, in order within one call: `Frame` then at
//! once `Step` when a step ends (so the gap between them is the syllable detector, the step
//! features, the GMM memberships and the CRF forward step: *inference*), and per animation tick
//! `Pose` then at once `Decision` at an exit point (the gap is the policy's selection and the
//! cut: *policy*). Everything else is the front-end plus the player (*front_end*). A *frame* is
//! the span between two consecutive prosody frames: all the work of one 10 ms hop, whatever
//! else happened in it.

use core::fmt::Write;

use cortex_m::peripheral::syst::SystClkSource;
use cortex_m::peripheral::SYST;
use gesture_runtime::controller::ControllerEvent;

use crate::drive::{Probe, Summary, AUDIO_RATE_HZ};

/// SysTick extended to 64 bits.
pub struct Clock {
    last: u32,
    ticks: u64,
    /// Instructions per `per` ticks, from [`calibrate`].
    instructions: u64,
    per: u64,
}

const RELOAD: u32 = 0x00ff_ffff;

impl Clock {
    /// Starts SysTick free-running from the core clock, without interrupts.
    pub fn start() -> Self {
        // SAFETY: the firmware is single-threaded and nothing else touches SysTick.
        let mut syst = unsafe { cortex_m::Peripherals::steal() }.SYST;
        syst.disable_interrupt();
        syst.set_clock_source(SystClkSource::Core);
        syst.set_reload(RELOAD);
        syst.clear_current();
        syst.enable_counter();
        Self {
            last: SYST::get_current(),
            ticks: 0,
            instructions: 1,
            per: 1,
        }
    }

    /// Ticks since [`Clock::start`].
    #[inline(always)]
    pub fn now(&mut self) -> u64 {
        let cur = SYST::get_current();
        self.ticks += (self.last.wrapping_sub(cur) & RELOAD) as u64;
        self.last = cur;
        self.ticks
    }

    /// Ticks to instructions.
    pub fn instructions(&self, ticks: u64) -> u64 {
        (ticks * self.instructions + self.per / 2) / self.per
    }
}

/// Times a loop of known length (`subs` + `bne`, 2 instructions per turn) and sets the
/// clock's instructions per tick; prints a `calibration` line.
pub fn calibrate(clock: &mut Clock, out: &mut impl Write) {
    const TURNS: u32 = 1_000_000;
    let t0 = clock.now();
    // SAFETY: a register-only countdown loop.
    unsafe {
        core::arch::asm!(
            "2:",
            "subs {n}, #1",
            "bne 2b",
            n = inout(reg) TURNS => _,
            options(nomem, nostack),
        );
    }
    let ticks = (clock.now() - t0).max(1);
    clock.instructions = 2 * TURNS as u64;
    clock.per = ticks;
    let _ = writeln!(
        out,
        "calibration loop_instructions={} ticks={ticks}",
        2 * TURNS
    );
}

/// Times `Blob::parse` (header, CRC-32 and validation: the boot-time cost).
pub fn blob_parse(clock: &mut Clock, blob: &[u8], out: &mut impl Write) {
    let t0 = clock.now();
    let ok = gesture_runtime::blob::Blob::parse(core::hint::black_box(blob)).is_ok();
    let t = clock.now() - t0;
    let _ = writeln!(
        out,
        "measure blob_parse instructions={} ok={ok}",
        clock.instructions(t)
    );
}

/// Accumulated timings of one run (in ticks, inside the controller only).
pub struct Timing<'c> {
    clock: &'c mut Clock,
    /// Ticks spent outside the controller (sinks, DMA copy) so far.
    outside: u64,
    /// Raw clock when the current outside span began.
    outside_from: u64,
    /// Controller time at the end of the previous event.
    last_event: u64,
    chunk_from: u64,
    last_frame: Option<u64>,
    total: u64,
    inference: u64,
    policy: u64,
    worst_chunk: u64,
    worst_frame: u64,
    worst_step: u64,
    worst_decision: u64,
}

impl<'c> Timing<'c> {
    /// No time counted yet.
    pub fn new(clock: &'c mut Clock) -> Self {
        let now = clock.now();
        Self {
            clock,
            outside: 0,
            outside_from: now,
            last_event: 0,
            chunk_from: 0,
            last_frame: None,
            total: 0,
            inference: 0,
            policy: 0,
            worst_chunk: 0,
            worst_frame: 0,
            worst_step: 0,
            worst_decision: 0,
        }
    }

    /// Leaves the controller: returns controller time.
    fn leave(&mut self) -> u64 {
        let now = self.clock.now();
        self.outside_from = now;
        now - self.outside
    }

    /// Re-enters the controller.
    fn enter(&mut self) {
        let now = self.clock.now();
        self.outside += now - self.outside_from;
    }

    /// Prints one `measure` line for input `name` (instructions; per-second figures are per
    /// second of audio).
    pub fn report(&self, name: &str, sum: &Summary, out: &mut impl Write) {
        let c = &*self.clock;
        let per_s = |ticks: u64| c.instructions(ticks) * AUDIO_RATE_HZ as u64 / sum.samples.max(1);
        let front_end = self.total - self.inference - self.policy;
        let _ = writeln!(
            out,
            "measure input={name} samples={} frames={} steps={} decisions={} \
             total_per_s={} front_end_per_s={} inference_per_s={} policy_per_s={} \
             worst_chunk={} worst_frame={} worst_step={} worst_decision={}",
            sum.samples,
            sum.frames,
            sum.steps,
            sum.decisions,
            per_s(self.total),
            per_s(front_end),
            per_s(self.inference),
            per_s(self.policy),
            c.instructions(self.worst_chunk),
            c.instructions(self.worst_frame),
            c.instructions(self.worst_step),
            c.instructions(self.worst_decision),
        );
    }
}

impl Probe for Timing<'_> {
    fn chunk_begin(&mut self) {
        self.enter();
        self.chunk_from = self.clock.now() - self.outside;
    }

    fn chunk_end(&mut self) {
        let t = self.leave();
        let d = t - self.chunk_from;
        self.total += d;
        self.worst_chunk = self.worst_chunk.max(d);
    }

    fn event_begin(&mut self, event: &ControllerEvent<'_>) {
        let t = self.leave();
        let since = t - self.last_event;
        match event {
            ControllerEvent::Frame(_) => {
                if let Some(prev) = self.last_frame {
                    self.worst_frame = self.worst_frame.max(t - prev);
                }
                self.last_frame = Some(t);
            }
            ControllerEvent::Step { .. } => {
                self.inference += since;
                self.worst_step = self.worst_step.max(since);
            }
            ControllerEvent::Decision { .. } => {
                self.policy += since;
                self.worst_decision = self.worst_decision.max(since);
            }
            ControllerEvent::Pose { .. }
            | ControllerEvent::Onset(_)
            | ControllerEvent::Label { .. }
            | ControllerEvent::Play { .. } => {}
        }
        self.last_event = t;
    }

    fn event_end(&mut self) {
        self.enter();
    }
}
