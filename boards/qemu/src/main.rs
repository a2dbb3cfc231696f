//! Firmware for QEMU's `mps2-an386` (Cortex-M4F) and `mps2-an505` (Cortex-M33F): the
//! gesture-controller runtime on the device, fed from flash as a microphone DMA would feed it.
//! The target selects the board (`build.rs`: its memory map); the code is the same for both.
//!
//! It embeds a policy blob and two 16 kHz inputs made by `make-assets` (`assets/`, not in
//! git): `speech` (a held-out synthetic take) and `stress` (silence, clipped speech, white
//! noise, full-scale square wave). For each it runs a fresh `Controller` over the samples in
//! 256-sample buffers ([`drive`], shared with the host reference) and prints the decision trace
//! on semihosting stdout. On stderr it prints the peak stack (the stack is painted by
//! `cortex-m-rt` before `main`; the lowest scrubbed word is the peak), split into building the
//! controller and running it (the free stack is painted again in between).
//!
//! Exit status (semihosting `SYS_EXIT`): 0 when every input ran with valid poses; 1 on any
//! error (blob refused, invalid pose, output failure), panic or fault.
//!
//! With the `measure` feature it also times the controller with SysTick under
//! `qemu -icount shift=0` and prints `measure` lines for `report` ([`measure`]).
//!
//! With the `show` feature it is a show board instead: no controller runs; it plays the show
//! `make-assets` baked from the speech input (`assets/speech.show`, `gesture-sim run --show`)
//! with the runtime's `ShowPlayer` over the speech input's sample count ([`show`]), prints
//! `show ticks=N pose_hash=H` and the same `memory` line, and exits (a separate QEMU run in
//! `check`: the player does not fit beside the controller in the M4's code budget).
#![no_std]
#![no_main]
// The `show` build keeps the controller's loop compiled but never calls it.
#![cfg_attr(feature = "show", allow(dead_code))]

mod drive;
#[cfg(feature = "measure")]
mod measure;
#[cfg(feature = "show")]
mod show;

use core::fmt::{self, Write};

use cortex_m_rt::{entry, exception, ExceptionFrame};
use cortex_m_semihosting::{debug, hio};
use drive::Part;

/// The policy blob (`assets/policy.blob`).
static BLOB: &[u8] = include_bytes!(concat!(env!("CARGO_MANIFEST_DIR"), "/assets/policy.blob"));

/// The held-out speech (`assets/speech.raw`).
static SPEECH: &[u8] = include_bytes!(concat!(env!("CARGO_MANIFEST_DIR"), "/assets/speech.raw"));

/// The inputs, little-endian i16 at 16 kHz, in the order they run.
static INPUTS: [(&str, &[u8]); 3] = [
    ("speech", SPEECH),
    // The same speech known half a second ahead (drive.rs LOOKAHEAD_MS).
    ("speech-ahead", SPEECH),
    (
        "stress",
        include_bytes!(concat!(env!("CARGO_MANIFEST_DIR"), "/assets/stress.raw")),
    ),
];

/// The show baked from the speech input (`assets/speech.show`; the `show` build).
#[cfg(feature = "show")]
static SHOW: &[u8] = include_bytes!(concat!(env!("CARGO_MANIFEST_DIR"), "/assets/speech.show"));

/// Semihosting output in whole lines: one `SYS_WRITE` per line instead of one per fragment.
struct HostLines {
    stream: Option<hio::HostStream>,
    buf: [u8; 160],
    len: usize,
}

impl HostLines {
    fn new(stream: Result<hio::HostStream, ()>) -> Self {
        Self {
            stream: stream.ok(),
            buf: [0; 160],
            len: 0,
        }
    }

    fn flush(&mut self) -> fmt::Result {
        let n = core::mem::take(&mut self.len);
        match &mut self.stream {
            Some(s) => s.write_all(&self.buf[..n]).map_err(|()| fmt::Error),
            None => Err(fmt::Error),
        }
    }
}

impl Write for HostLines {
    fn write_str(&mut self, s: &str) -> fmt::Result {
        for &b in s.as_bytes() {
            if self.len == self.buf.len() {
                self.flush()?;
            }
            self.buf[self.len] = b;
            self.len += 1;
            if b == b'\n' {
                self.flush()?;
            }
        }
        Ok(())
    }
}

fn exit(ok: bool) -> ! {
    debug::exit(if ok {
        debug::EXIT_SUCCESS
    } else {
        debug::EXIT_FAILURE
    });
    // Only reached without a semihosting host: stop with a fault.
    cortex_m::asm::udf()
}

extern "C" {
    // Bounds of the stack region, from cortex-m-rt's linker script (the stack grows down from
    // `_stack_start`; `_stack_end` is the end of the statics).
    static _stack_start: u32;
    static mut _stack_end: u32;
}

/// Bytes of stack used since the last painting: from the top of RAM down to the lowest word
/// that no longer holds the paint (cortex-m-rt paints the whole region before `main`).
fn peak_stack_bytes() -> usize {
    // SAFETY: the region between the two linker symbols is RAM; it is read word by word
    // (aligned, in range).
    unsafe {
        let top = core::ptr::addr_of!(_stack_start) as usize;
        let mut p = core::ptr::addr_of!(_stack_end);
        while (p as usize) < top && core::ptr::read_volatile(p) == cortex_m_rt::STACK_PAINT_VALUE {
            p = p.add(1);
        }
        top - p as usize
    }
}

/// Paints the free stack again, below this function's own frame, so that the next
/// [`peak_stack_bytes`] sees only what runs from here on.
#[cfg(not(feature = "measure"))]
#[inline(never)]
fn repaint_stack() {
    let sp = cortex_m::register::msp::read() as usize;
    // SAFETY: writes only below the current stack pointer (minus a margin), i.e. stack memory
    // no live frame uses; interrupts are not enabled, so nothing else can be using it.
    unsafe {
        let mut p = core::ptr::addr_of_mut!(_stack_end);
        let stop = (sp - 64) & !3;
        while (p as usize) < stop {
            core::ptr::write_volatile(p, cortex_m_rt::STACK_PAINT_VALUE);
            p = p.add(1);
        }
    }
}

/// Splits the stack peak into building the controller and running it.
#[cfg(not(feature = "measure"))]
#[derive(Default)]
struct StackProbe {
    /// Peak while building (blob parse, controller), taken when the controller is ready.
    build: usize,
}

#[cfg(not(feature = "measure"))]
impl drive::Probe for StackProbe {
    fn ready(&mut self) {
        self.build = self.build.max(peak_stack_bytes());
        repaint_stack();
    }
}

/// The show board: plays [`SHOW`] over the speech input's samples ([`show::run`]).
#[cfg(feature = "show")]
#[entry]
fn main() -> ! {
    let mut out = HostLines::new(hio::hstdout());
    let mut err = HostLines::new(hio::hstderr());
    let samples = INPUTS[0].1.len() / 2;
    let result = show::run(BLOB, SHOW, samples, &mut out);
    if let Err(e) = &result {
        let _ = writeln!(err, "error: show: {}", e.name());
    }
    let _ = writeln!(
        err,
        "memory peak_stack_bytes={} show_player_bytes={} show_bytes={} blob_bytes={}",
        peak_stack_bytes(),
        core::mem::size_of::<
            gesture_runtime::show::ShowPlayer<'static, gesture_runtime::blob::Blob<'static>>,
        >(),
        SHOW.len(),
        BLOB.len()
    );
    exit(result.is_ok())
}

#[cfg(not(feature = "show"))]
#[entry]
fn main() -> ! {
    let mut out = HostLines::new(hio::hstdout());
    let mut err = HostLines::new(hio::hstderr());
    #[cfg(feature = "measure")]
    let mut clock = measure::Clock::start();
    #[cfg(feature = "measure")]
    measure::calibrate(&mut clock, &mut out);
    #[cfg(feature = "measure")]
    measure::blob_parse(&mut clock, BLOB, &mut out);

    let mut ok = true;
    #[cfg(not(feature = "measure"))]
    let mut stack = StackProbe::default();
    let mut run_stack = 0;
    for (name, audio) in INPUTS.iter() {
        #[cfg(not(feature = "measure"))]
        let result = drive::run(name, BLOB, audio, &mut out, &mut stack);
        #[cfg(feature = "measure")]
        let result = {
            let mut probe = measure::Timing::new(&mut clock);
            let r = drive::run(name, BLOB, audio, &mut out, &mut probe);
            if let Ok(sum) = &r {
                probe.report(name, sum, &mut out);
            }
            r
        };
        run_stack = run_stack.max(peak_stack_bytes());
        if let Err(e) = result {
            // The variant's name, not Display or Debug: formatting the nested errors would
            // link kilobytes of formatting code into the firmware.
            // Strings written as they are: `{}` of a `str` links the padding code.
            for part in ["error: input ", name, ": ", e.name(), "\n"] {
                let _ = err.write_str(part);
            }
            ok = false;
            break;
        }
    }
    #[cfg(not(feature = "measure"))]
    let build_stack = stack.build;
    #[cfg(feature = "measure")]
    let build_stack = 0;
    let device = core::mem::size_of::<drive::BoardDevice<'static, 'static>>()
        + core::mem::size_of::<gesture_runtime::controller::BlobController<'static>>();
    let _ = drive::write_parts(
        &mut err,
        &[
            Part::Text("memory peak_stack_bytes="),
            Part::Dec(build_stack.max(run_stack) as u64),
            Part::Text(" build_stack_bytes="),
            Part::Dec(build_stack as u64),
            Part::Text(" run_stack_bytes="),
            Part::Dec(run_stack as u64),
            Part::Text(" device_bytes="),
            Part::Dec(device as u64),
            Part::Text(" blob_bytes="),
            Part::Dec(BLOB.len() as u64),
            Part::Text("\n"),
        ],
    );
    exit(ok)
}

#[panic_handler]
fn panic(info: &core::panic::PanicInfo) -> ! {
    let mut err = HostLines::new(hio::hstderr());
    // Where, not the message: formatting every panic message's arguments would link the
    // formatting of floats and padded strings into the firmware (kilobytes), and the runtime
    // has no panic to explain.
    let _ = err.write_str("panic at ");
    if let Some(at) = info.location() {
        let at = [
            Part::Text(at.file()),
            Part::Text(":"),
            Part::Dec(at.line() as u64),
            Part::Text("\n"),
        ];
        let _ = drive::write_parts(&mut err, &at);
    }
    exit(false)
}

#[exception]
unsafe fn HardFault(frame: &ExceptionFrame) -> ! {
    let mut err = HostLines::new(hio::hstderr());
    let pc = [
        Part::Text("hard fault at pc=0x"),
        Part::Hex8(frame.pc()),
        Part::Text("\n"),
    ];
    let _ = drive::write_parts(&mut err, &pc);
    exit(false)
}

#[exception]
unsafe fn DefaultHandler(irqn: i16) {
    let mut err = HostLines::new(hio::hstderr());
    let irq = [
        Part::Text("unexpected exception "),
        Part::Text(if irqn < 0 { "-" } else { "" }),
        Part::Dec(irqn.unsigned_abs() as u64),
        Part::Text("\n"),
    ];
    let _ = drive::write_parts(&mut err, &irq);
    exit(false)
}
