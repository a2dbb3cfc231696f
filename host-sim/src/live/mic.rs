//! The microphone through cpal (the `mic` feature): [`CpalSource`], [`input_devices`] and
//! `gesture-sim devices`. See the parent module for the real-time design.

use std::io::Write;
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

use super::source::{AudioSource, LiveError};

/// Runs `f` with ALSA's stderr diagnostics captured (Linux), so a failure is our one line.
fn quiet_alsa<T>(f: impl FnOnce() -> T) -> T {
    #[cfg(target_os = "linux")]
    let _guard = alsa::Output::local_error_handler().ok();
    f()
}

/// A device's identifier (ALSA: the PCM name, e.g. `hw:CARD=USB,DEV=0`) and description.
fn device_id(d: &cpal::Device) -> (String, String) {
    use cpal::traits::DeviceTrait;
    match d.description() {
        Ok(desc) => (
            desc.driver().unwrap_or(desc.name()).to_string(),
            desc.name().to_string(),
        ),
        Err(_) => (String::new(), String::new()),
    }
}

/// ALSA's `null` PCM "captures" endless zeros: it is there on machines without any sound card
/// and is no microphone, so it is never listed or opened.
fn is_dummy(d: &cpal::Device) -> bool {
    device_id(d).0 == "null"
}

/// The usable input devices: (identifier, description, is the default).
pub fn input_devices() -> Result<Vec<(String, String, bool)>, LiveError> {
    use cpal::traits::{DeviceTrait, HostTrait};
    quiet_alsa(|| {
        let host = cpal::default_host();
        let default = host.default_input_device().map(|d| device_id(&d).0);
        let devices = host
            .input_devices()
            .map_err(|e| LiveError::Backend(e.to_string()))?;
        Ok(devices
            .filter(|d| !is_dummy(d) && d.supports_input())
            .map(|d| {
                let (id, name) = device_id(&d);
                let is_default = default.as_deref() == Some(id.as_str());
                (id, name, is_default)
            })
            .collect())
    })
}

/// `gesture-sim devices`: prints the input devices (`*` marks the default), or fails with
/// [`LiveError::NoDevice`] when there is none.
pub fn devices(out: &mut dyn Write) -> Result<(), LiveError> {
    let list = input_devices()?;
    if list.is_empty() {
        return Err(LiveError::NoDevice);
    }
    for (id, name, d) in list {
        writeln!(out, "{}{id}  ({name})", if d { "* " } else { "  " })?;
    }
    Ok(())
}

/// A cpal input stream as an [`AudioSource`]. Keep it on the thread that opened it.
pub struct CpalSource {
    _stream: cpal::Stream,
    rx: rtrb::Consumer<f32>,
    rate_hz: u32,
    errors: Arc<Mutex<Option<String>>>,
    failed: Arc<AtomicBool>,
    dropped: Arc<AtomicU64>,
}

impl CpalSource {
    /// Opens the device named `name` (or the default input device) at its default config.
    pub fn open(name: Option<&str>) -> Result<Self, LiveError> {
        use cpal::traits::{DeviceTrait, HostTrait, StreamTrait};
        use cpal::SampleFormat;
        quiet_alsa(|| {
            let host = cpal::default_host();
            let device = match name {
                None => host
                    .default_input_device()
                    .filter(|d| !is_dummy(d))
                    .ok_or(LiveError::NoDevice)?,
                Some(n) => {
                    let all: Vec<cpal::Device> = host
                        .input_devices()
                        .map_err(|e| LiveError::Backend(e.to_string()))?
                        .filter(|d| !is_dummy(d))
                        .collect();
                    let names: Vec<String> = all.iter().map(|d| device_id(d).0).collect();
                    let found = all.into_iter().find(|d| {
                        let (id, desc) = device_id(d);
                        id == n || desc == n
                    });
                    match found {
                        Some(d) => d,
                        None if names.is_empty() => return Err(LiveError::NoDevice),
                        None => {
                            return Err(LiveError::DeviceNotFound {
                                name: n.to_string(),
                                available: names.join(", "),
                            })
                        }
                    }
                }
            };
            let supported = device.default_input_config().map_err(|e| match name {
                None => LiveError::NoDevice,
                Some(_) => LiveError::Backend(e.to_string()),
            })?;
            let config = supported.config();
            let channels = config.channels.max(1) as usize;
            let rate_hz = config.sample_rate;
            // Two seconds of mono audio: the controller thread drains it every 200 ms.
            let (tx, rx) = rtrb::RingBuffer::<f32>::new((2 * rate_hz as usize).max(4096));
            let errors = Arc::new(Mutex::new(None));
            let failed = Arc::new(AtomicBool::new(false));
            let dropped = Arc::new(AtomicU64::new(0));
            let (e2, f2, d2) = (errors.clone(), failed.clone(), dropped.clone());
            // Not on the data path: cpal reports stream errors from its own context.
            let on_error = move |e: cpal::Error| {
                if let Ok(mut g) = e2.lock() {
                    g.get_or_insert(e.to_string());
                }
                f2.store(true, Ordering::Release);
            };
            // Mixes a block to mono into the ring without allocating, locking or blocking.
            fn sender<T: Copy + Send + 'static>(
                mut tx: rtrb::Producer<f32>,
                dropped: Arc<AtomicU64>,
                channels: usize,
                to_f32: fn(T) -> f32,
            ) -> impl FnMut(&[T], &cpal::InputCallbackInfo) + Send + 'static {
                move |data: &[T], _: &cpal::InputCallbackInfo| {
                    let scale = 1.0 / channels as f32;
                    let mut lost = 0u64;
                    for frame in data.chunks(channels) {
                        let mono = frame.iter().map(|&x| to_f32(x)).sum::<f32>() * scale;
                        if tx.push(mono).is_err() {
                            lost += 1;
                        }
                    }
                    if lost > 0 {
                        dropped.fetch_add(lost, Ordering::Relaxed);
                    }
                }
            }
            let backend = |e: cpal::Error| LiveError::Backend(e.to_string());
            let stream = match supported.sample_format() {
                SampleFormat::F32 => device.build_input_stream(
                    config,
                    sender::<f32>(tx, d2, channels, |x| x),
                    on_error,
                    None,
                ),
                SampleFormat::I16 => device.build_input_stream(
                    config,
                    sender::<i16>(tx, d2, channels, |x| x as f32 / 32768.0),
                    on_error,
                    None,
                ),
                SampleFormat::I32 => device.build_input_stream(
                    config,
                    sender::<i32>(tx, d2, channels, |x| x as f32 / 2_147_483_648.0),
                    on_error,
                    None,
                ),
                SampleFormat::U16 => device.build_input_stream(
                    config,
                    sender::<u16>(tx, d2, channels, |x| (x as f32 - 32768.0) / 32768.0),
                    on_error,
                    None,
                ),
                other => {
                    return Err(LiveError::Backend(format!(
                        "unsupported sample format {other}"
                    )))
                }
            }
            .map_err(backend)?;
            stream.play().map_err(backend)?;
            Ok(Self {
                _stream: stream,
                rx,
                rate_hz,
                errors,
                failed,
                dropped,
            })
        })
    }

    /// Samples dropped because the controller fell behind.
    pub fn dropped_samples(&self) -> u64 {
        self.dropped.load(Ordering::Relaxed)
    }
}

impl AudioSource for CpalSource {
    fn rate_hz(&self) -> u32 {
        self.rate_hz
    }

    fn read(&mut self, out: &mut Vec<f32>, timeout: Duration) -> Result<bool, LiveError> {
        let start = Instant::now();
        loop {
            if self.failed.load(Ordering::Acquire) {
                let e = self.errors.lock().ok().and_then(|mut g| g.take());
                return Err(LiveError::Backend(
                    e.unwrap_or_else(|| "the input stream failed".into()),
                ));
            }
            let n = self.rx.slots();
            if n > 0 {
                if let Ok(chunk) = self.rx.read_chunk(n) {
                    let (a, b) = chunk.as_slices();
                    out.extend_from_slice(a);
                    out.extend_from_slice(b);
                    chunk.commit_all();
                }
                return Ok(true);
            }
            if self.rx.is_abandoned() {
                return Ok(false);
            }
            if start.elapsed() >= timeout {
                return Ok(true);
            }
            std::thread::sleep(Duration::from_millis(5));
        }
    }
}
