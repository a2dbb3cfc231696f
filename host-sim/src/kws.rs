//! Keyword spotting on the speech (`--keywords FILE`, docs/method.md "Semantic labels"): CMU
//! PocketSphinx listens for key phrases in the same 10 ms chunks the controller gets, and
//! each detection becomes a label at the time it was made (the end of the chunk that
//! completed it).
//!
//! **Keywords file.** One phrase per line, `phrase<TAB>label[<TAB>threshold]`: the phrase in
//! the recognizer's dictionary (lower case), the blob's label it brings, and PocketSphinx's
//! keyphrase threshold (default 1e-20; smaller detects more and false-alarms more). `#` starts
//! a comment.
//!
//! **The binding.** A small FFI module of our own (the feature `kws`): the system's
//! `libpocketsphinx` 5prealpha (Debian's `libpocketsphinx-dev`; no maintained Rust binding
//! builds against it), in keyphrase-search mode over the US English model of
//! `pocketsphinx-en-us` (`/usr/share/pocketsphinx/model/en-us`, or `POCKETSPHINX_MODEL`).
//! Without the feature, `--keywords` says in one line how to enable it.

use std::path::Path;

/// One key phrase.
#[derive(Clone, Debug, PartialEq)]
pub struct Keyword {
    /// The phrase (lower case words of the recognizer's dictionary).
    pub phrase: String,
    /// The blob's label it brings.
    pub label: String,
    /// PocketSphinx's keyphrase threshold.
    pub threshold: f64,
}

/// A detection: when (s, the end of the chunk that completed it) and which keyword.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Detection {
    /// Time (s).
    pub time_s: f64,
    /// Index into the keywords.
    pub keyword: usize,
}

/// Default keyphrase threshold.
pub const DEFAULT_THRESHOLD: f64 = 1e-20;

/// Reads a keywords file (see the module docs).
pub fn read_keywords(path: &Path) -> Result<Vec<Keyword>, String> {
    let text = std::fs::read_to_string(path).map_err(|e| format!("{}: {e}", path.display()))?;
    let mut out = Vec::new();
    for (i, line) in text.lines().enumerate() {
        let what = format!("{}:{}", path.display(), i + 1);
        let line = line.trim_end();
        if line.trim().is_empty() || line.trim_start().starts_with('#') {
            continue;
        }
        let f: Vec<&str> = line.split('\t').map(str::trim).collect();
        if f.len() < 2 || f.len() > 3 || f[0].is_empty() || f[1].is_empty() {
            return Err(format!(
                "{what}: expected `phrase<TAB>label[<TAB>threshold]`"
            ));
        }
        if !f[0]
            .chars()
            .all(|c| c.is_ascii_lowercase() || c == ' ' || c == '\'')
        {
            return Err(format!(
                "{what}: `{}`: a phrase is lower-case words (letters, apostrophes, spaces)",
                f[0]
            ));
        }
        let threshold = match f.get(2) {
            Some(t) => t
                .parse::<f64>()
                .ok()
                .filter(|v| v.is_finite() && *v > 0.0 && *v <= 1.0)
                .ok_or_else(|| format!("{what}: `{t}`: a threshold is a number in (0, 1]"))?,
            None => DEFAULT_THRESHOLD,
        };
        out.push(Keyword {
            phrase: f[0].split_whitespace().collect::<Vec<_>>().join(" "),
            label: f[1].into(),
            threshold,
        });
    }
    if out.is_empty() {
        return Err(format!("{}: no keywords", path.display()));
    }
    Ok(out)
}

/// How to get keyword spotting when the feature is off.
pub const NO_KWS: &str = "--keywords needs keyword spotting: build with the `kws` feature \
     (`cargo run --release -p host-sim --features kws -- ...`, after `sudo apt-get install \
     libpocketsphinx-dev pocketsphinx-en-us`)";

/// A streaming spotter: 16 kHz samples in, the keywords heard out.
pub struct Stream {
    #[cfg(feature = "kws")]
    spotter: ffi::Spotter,
    keywords: Vec<Keyword>,
}

impl std::fmt::Debug for Stream {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Stream")
            .field("keywords", &self.keywords)
            .finish_non_exhaustive()
    }
}

impl Stream {
    /// A spotter for `keywords` (without the `kws` feature: the one-line [`NO_KWS`]).
    pub fn new(keywords: &[Keyword]) -> Result<Self, String> {
        #[cfg(feature = "kws")]
        {
            Ok(Self {
                spotter: ffi::Spotter::new(keywords)?,
                keywords: keywords.to_vec(),
            })
        }
        #[cfg(not(feature = "kws"))]
        {
            let _ = keywords;
            Err(NO_KWS.into())
        }
    }

    /// Feeds 16 kHz samples; the index of the keyword they completed, if any.
    pub fn push(&mut self, samples: &[i16]) -> Result<Option<usize>, String> {
        #[cfg(feature = "kws")]
        {
            Ok(self
                .spotter
                .push(samples)?
                .and_then(|p| self.keywords.iter().position(|kw| kw.phrase == p)))
        }
        #[cfg(not(feature = "kws"))]
        {
            let _ = (samples, &self.keywords);
            Err(NO_KWS.into())
        }
    }
}

/// Spots `keywords` in `samples` (16 kHz mono) fed in chunks of `chunk` samples.
pub fn spot(samples: &[i16], chunk: usize, keywords: &[Keyword]) -> Result<Vec<Detection>, String> {
    let mut s = Stream::new(keywords)?;
    let mut out = Vec::new();
    let mut fed = 0usize;
    for c in samples.chunks(chunk.max(1)) {
        fed += c.len();
        if let Some(k) = s.push(c)? {
            out.push(Detection {
                time_s: fed as f64 / 16_000.0,
                keyword: k,
            });
        }
    }
    Ok(out)
}

#[cfg(feature = "kws")]
#[allow(unsafe_code)]
mod ffi {
    //! The few PocketSphinx 5prealpha calls keyphrase search needs.
    use std::ffi::{c_char, c_int, c_void, CStr, CString};
    use std::io::Write;

    use super::Keyword;

    #[link(name = "pocketsphinx")]
    #[link(name = "sphinxbase")]
    extern "C" {
        fn ps_args() -> *const c_void;
        fn cmd_ln_init(inout: *mut c_void, defn: *const c_void, strict: c_int, ...) -> *mut c_void;
        fn cmd_ln_free_r(cmdln: *mut c_void) -> c_int;
        fn ps_init(config: *mut c_void) -> *mut c_void;
        fn ps_free(ps: *mut c_void) -> c_int;
        fn ps_start_utt(ps: *mut c_void) -> c_int;
        fn ps_end_utt(ps: *mut c_void) -> c_int;
        fn ps_process_raw(
            ps: *mut c_void,
            data: *const i16,
            n_samples: usize,
            no_search: c_int,
            full_utt: c_int,
        ) -> c_int;
        fn ps_get_hyp(ps: *mut c_void, out_best_score: *mut i32) -> *const c_char;
    }

    /// A keyphrase decoder (owns its configuration and decoder; freed on drop).
    pub struct Spotter {
        config: *mut c_void,
        ps: *mut c_void,
        _kws: tempfile::NamedTempFile,
    }

    fn model_dir() -> String {
        std::env::var("POCKETSPHINX_MODEL")
            .unwrap_or_else(|_| "/usr/share/pocketsphinx/model/en-us".into())
    }

    impl Spotter {
        pub fn new(keywords: &[Keyword]) -> Result<Self, String> {
            let model = model_dir();
            let hmm = format!("{model}/en-us");
            let dict = format!("{model}/cmudict-en-us.dict");
            if !std::path::Path::new(&hmm).is_dir() || !std::path::Path::new(&dict).is_file() {
                return Err(format!(
                    "no PocketSphinx model at {model} (install pocketsphinx-en-us, or set \
                     POCKETSPHINX_MODEL)"
                ));
            }
            let words = std::fs::read_to_string(&dict).map_err(|e| format!("{dict}: {e}"))?;
            for kw in keywords {
                for w in kw.phrase.split(' ') {
                    // `word` or one of its variants `word(2)`, ...
                    let variant = format!("{w}(");
                    let known = words.lines().any(|l| {
                        l.split_whitespace()
                            .next()
                            .is_some_and(|d| d == w || d.starts_with(&variant))
                    });
                    if !known {
                        return Err(format!(
                            "keyword `{}`: `{w}` is not in the recognizer's dictionary ({dict})",
                            kw.phrase
                        ));
                    }
                }
            }
            let mut kws = tempfile::NamedTempFile::new().map_err(|e| e.to_string())?;
            for kw in keywords {
                writeln!(kws, "{} /{:e}/", kw.phrase, kw.threshold).map_err(|e| e.to_string())?;
            }
            kws.flush().map_err(|e| e.to_string())?;
            let arg = |s: &str| CString::new(s).map_err(|e| e.to_string());
            let (k_hmm, v_hmm) = (arg("-hmm")?, arg(&hmm)?);
            let (k_dict, v_dict) = (arg("-dict")?, arg(&dict)?);
            let (k_kws, v_kws) = (arg("-kws")?, arg(&kws.path().to_string_lossy())?);
            let (k_log, v_log) = (arg("-logfn")?, arg("/dev/null")?);
            // SAFETY: every argument is a NUL-terminated string that outlives the call, the
            // list ends with a null pointer as cmd_ln_init requires, and ps_args() is the
            // library's own argument table.
            let config = unsafe {
                cmd_ln_init(
                    std::ptr::null_mut(),
                    ps_args(),
                    1,
                    k_hmm.as_ptr(),
                    v_hmm.as_ptr(),
                    k_dict.as_ptr(),
                    v_dict.as_ptr(),
                    k_kws.as_ptr(),
                    v_kws.as_ptr(),
                    k_log.as_ptr(),
                    v_log.as_ptr(),
                    std::ptr::null::<c_char>(),
                )
            };
            if config.is_null() {
                return Err("PocketSphinx refused its configuration".into());
            }
            // SAFETY: `config` is a valid configuration (checked above).
            let ps = unsafe { ps_init(config) };
            if ps.is_null() {
                // SAFETY: `config` is valid and no longer used.
                unsafe { cmd_ln_free_r(config) };
                return Err("PocketSphinx could not start (model or keyphrase file)".into());
            }
            // SAFETY: `ps` is a valid decoder.
            if unsafe { ps_start_utt(ps) } < 0 {
                // SAFETY: both valid, freed once.
                unsafe {
                    ps_free(ps);
                    cmd_ln_free_r(config);
                }
                return Err("PocketSphinx could not start an utterance".into());
            }
            Ok(Self {
                config,
                ps,
                _kws: kws,
            })
        }

        /// Feeds samples; returns the key phrase detected in them, if any (the search then
        /// starts over).
        pub fn push(&mut self, samples: &[i16]) -> Result<Option<String>, String> {
            // SAFETY: `ps` is valid; the slice is valid for `len` samples.
            let r = unsafe { ps_process_raw(self.ps, samples.as_ptr(), samples.len(), 0, 0) };
            if r < 0 {
                return Err("PocketSphinx failed to process audio".into());
            }
            // SAFETY: `ps` is valid; the score pointer may be null.
            let hyp = unsafe { ps_get_hyp(self.ps, std::ptr::null_mut()) };
            if hyp.is_null() {
                return Ok(None);
            }
            // SAFETY: a non-null hypothesis is a NUL-terminated string owned by the decoder,
            // valid until the next call on it; copied at once.
            let phrase = unsafe { CStr::from_ptr(hyp) }
                .to_string_lossy()
                .into_owned();
            // SAFETY: `ps` is valid.
            unsafe {
                ps_end_utt(self.ps);
                ps_start_utt(self.ps);
            }
            Ok(Some(phrase.trim().to_string()))
        }
    }

    impl Drop for Spotter {
        fn drop(&mut self) {
            // SAFETY: both were created in `new`, are valid and are freed once, here.
            unsafe {
                ps_end_utt(self.ps);
                ps_free(self.ps);
                cmd_ln_free_r(self.config);
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn keywords_files_are_read_and_checked() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("k.tsv");
        std::fs::write(
            &p,
            "# key phrases\nhello there\tbye\nfashion\twave\t1e-10\n",
        )
        .unwrap();
        let k = read_keywords(&p).unwrap();
        assert_eq!(k.len(), 2);
        assert_eq!(
            (k[0].phrase.as_str(), k[0].threshold),
            ("hello there", 1e-20)
        );
        assert_eq!((k[1].label.as_str(), k[1].threshold), ("wave", 1e-10));
        for (text, want) in [
            ("hello\n", "expected `phrase"),
            ("Hello\tbye\n", "lower-case"),
            ("hello\tbye\t2\n", "threshold"),
            ("# nothing\n", "no keywords"),
        ] {
            std::fs::write(&p, text).unwrap();
            let e = read_keywords(&p).unwrap_err();
            assert!(e.contains(want) && !e.contains('\n'), "{text:?}: {e}");
        }
    }
}
