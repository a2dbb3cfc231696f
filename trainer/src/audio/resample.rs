//! Band-limited resampling with rubato's asynchronous sinc interpolator, in two forms: a whole
//! clip with its delay trimmed and its length set exactly (WAV files: timing preserved to
//! half an output frame), and a stream (the live microphone: a shorter kernel for less delay,
//! about 1.3 ms at 48 kHz). One place for both, with one set of kernel settings; and the
//! rates accepted, the output length of a conversion and its error.

use rubato::audioadapter_buffers::direct::SequentialSliceOfSlices;
use rubato::{Async, FixedAsync, Resampler, SincInterpolationParameters, WindowFunction};

/// Lowest accepted file (and target) sample rate in Hz.
pub const MIN_RATE_HZ: u32 = 8_000;
/// Highest accepted file (and target) sample rate in Hz.
pub const MAX_RATE_HZ: u32 = 48_000;

/// Why in-memory samples could not be converted by [`convert`](super::convert).
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum ConvertError {
    /// The source or target rate is outside [`MIN_RATE_HZ`]..=[`MAX_RATE_HZ`].
    #[error("sample rate {0} Hz outside {MIN_RATE_HZ}-{MAX_RATE_HZ} Hz")]
    UnsupportedRate(u32),
    /// The resampler refused the job (a bug: the rates were checked before).
    #[error("resampler failed: {0}")]
    Resampler(String),
}

/// Output length of a conversion: `round(len * to / from)`, in exact integer arithmetic.
pub fn converted_len(len: usize, from_hz: u32, to_hz: u32) -> usize {
    let num = len as u128 * to_hz as u128;
    ((num + from_hz as u128 / 2) / from_hz as u128) as usize
}

/// Sinc filter length of the resampler (taps).
const SINC_LEN: usize = 256;
/// Sinc tables per input sample period (rubato's default).
const OVERSAMPLING: usize = 128;
/// Input frames per resampler call.
const CHUNK: usize = 1024;
/// Sinc length of the streaming resampler (shorter: less delay for live audio).
const STREAM_SINC_LEN: usize = 128;

/// Band-limited resampling of a whole clip with the delay trimmed and the length set to
/// [`converted_len`]. Rates are already validated.
///
/// Delay: rubato computes output frame `j` (before trimming) from the sinc kernel centred on
/// input time `(j + 1) / ratio - L / 2 + 1 / OVERSAMPLING` (`L` = [`SINC_LEN`]), so its true
/// delay is `ratio * (L / 2 - 1 / OVERSAMPLING) - 1` output frames, usually fractional.
/// `process_all` trims `floor(ratio * L / 2)` frames, which leaves events up to ~1 frame early;
/// we trim or pad the difference, rounded, so the residual is at most half an output frame.
/// The impulse test pins this for every rate we accept, so a rubato change that moves the
/// kernel fails loudly.
pub(super) fn resample(
    samples: &[f32],
    from_hz: u32,
    to_hz: u32,
) -> Result<Vec<f32>, ConvertError> {
    let out_len = converted_len(samples.len(), from_hz, to_hz);
    if samples.is_empty() {
        return Ok(Vec::new());
    }
    let err = |e: &dyn std::error::Error| ConvertError::Resampler(e.to_string());
    let ratio = to_hz as f64 / from_hz as f64;
    let params = SincInterpolationParameters::new(SINC_LEN, WindowFunction::BlackmanHarris2)
        .oversampling_factor(OVERSAMPLING);
    let mut resampler = Async::<f32>::new_sinc(ratio, 1.0, &params, CHUNK, 1, FixedAsync::Input)
        .map_err(|e| err(&e))?;
    let channels = [samples];
    let input = SequentialSliceOfSlices::new(&channels, 1, samples.len()).map_err(|e| err(&e))?;
    let exact_delay = ratio * (SINC_LEN as f64 / 2.0 - 1.0 / OVERSAMPLING as f64) - 1.0;
    let correction = (exact_delay - resampler.output_delay() as f64).round() as isize;
    // `process_all` returns ceil(len * ratio) frames after trimming `output_delay()`.
    let out = resampler
        .process_all(&input, samples.len(), None)
        .map_err(|e| err(&e))?;
    let mut data = out.take_data();
    if correction > 0 {
        data.drain(..(correction as usize).min(data.len()));
    } else if correction < 0 {
        data.splice(0..0, std::iter::repeat_n(0.0, correction.unsigned_abs()));
    }
    data.resize(out_len, 0.0);
    Ok(data)
}

/// Streaming resampler to the blob's rate (identity when the rates match).
pub struct StreamResampler {
    inner: Option<Async<f32>>,
    pending: Vec<f32>,
}

impl StreamResampler {
    /// From `from` Hz to `to` Hz.
    pub fn new(from: u32, to: u32) -> Result<Self, ConvertError> {
        if from == to {
            return Ok(Self {
                inner: None,
                pending: Vec::new(),
            });
        }
        for rate in [from, to] {
            if !(MIN_RATE_HZ..=MAX_RATE_HZ).contains(&rate) {
                return Err(ConvertError::UnsupportedRate(rate));
            }
        }
        let err = ConvertError::Resampler;
        let params =
            SincInterpolationParameters::new(STREAM_SINC_LEN, WindowFunction::BlackmanHarris2)
                .oversampling_factor(OVERSAMPLING);
        let chunk = (from as usize / 100).max(16);
        let r = Async::<f32>::new_sinc(
            to as f64 / from as f64,
            1.0,
            &params,
            chunk,
            1,
            FixedAsync::Input,
        )
        .map_err(|e| err(e.to_string()))?;
        Ok(Self {
            inner: Some(r),
            pending: Vec::new(),
        })
    }

    /// Feeds `input`; appends every output sample ready so far to `out`.
    pub fn push(&mut self, input: &[f32], out: &mut Vec<f32>) -> Result<(), ConvertError> {
        let Some(r) = &mut self.inner else {
            out.extend_from_slice(input);
            return Ok(());
        };
        self.pending.extend_from_slice(input);
        loop {
            let need = r.input_frames_next();
            if self.pending.len() < need {
                return Ok(());
            }
            let chans = [&self.pending[..need]];
            let adapter = SequentialSliceOfSlices::new(&chans, 1, need)
                .map_err(|e| ConvertError::Resampler(e.to_string()))?;
            let o = r
                .process(&adapter, None)
                .map_err(|e| ConvertError::Resampler(e.to_string()))?;
            out.extend(o.take_data());
            self.pending.drain(..need);
        }
    }
}
