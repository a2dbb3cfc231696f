//! `gesture-sim eval-prosody`: runs the front-end over the shared real recordings and compares
//! it with Praat (metrics in [`crate::eval`]) and with true syllable counts.
//!
//! For every WAV under the data folder (recursively, in sorted order) that has a reference
//! `reference/praat/<stem>.csv`, our frames are formatted exactly as `gesture-sim prosody`
//! prints them and parsed back, so the numbers equal those of `prosody_compare.py` run on our
//! CSV. Pooled metrics use all matched frames of all files together. Syllables are counted for
//! the files listed in `cmu-arctic/prompts.tsv`.
//!
//! With `--fixed` it evaluates the fixed-point front-end of boards without an FPU
//! (`prosody::arith::Fixed`) too, and prints both reports and, per file, how far the fixed
//! one's voicing agreement and gross pitch errors are from the `f32` one's.
//!
//! The data folder is optional (its licences keep it out of the repository): when the default
//! folder is absent, this prints that nothing was measured and succeeds, so tests can skip; a
//! folder given with `--data` that does not exist or holds no referenced WAV is an error (one
//! line, exit 2).

use std::io::Write;
use std::path::{Path, PathBuf};

use gesture_runtime::prosody::arith::{Fixed, Float};
use gesture_runtime::prosody::{ProsodyConfig, Step};
use gesture_trainer::{audio, features};
use serde_json::{json, Value};

use crate::error::SimError;
use crate::eval::{self, Metrics, Pair, Worst};
use crate::prosody_cmd::write_frames_csv;

/// The default data folder, relative to the current directory.
pub const DEFAULT_DATA_DIR: &str = "../shared/data";
/// The same folder relative to this crate's source (for `cargo run` from anywhere).
pub const SOURCE_DATA_DIR: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/../../shared/data");

/// Where the data folder is, or every place that was tried.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum DataDir {
    /// It exists here.
    Found(PathBuf),
    /// None of these exist.
    Missing(Vec<PathBuf>),
}

/// `explicit` if given, else [`DEFAULT_DATA_DIR`], else [`SOURCE_DATA_DIR`].
pub fn resolve_data_dir(explicit: Option<&Path>) -> DataDir {
    let candidates: Vec<PathBuf> = match explicit {
        Some(p) => vec![p.to_owned()],
        None => vec![DEFAULT_DATA_DIR.into(), SOURCE_DATA_DIR.into()],
    };
    match candidates.iter().find(|p| p.is_dir()) {
        Some(p) => DataDir::Found(p.canonicalize().unwrap_or_else(|_| p.clone())),
        None => DataDir::Missing(candidates),
    }
}

/// One evaluated recording.
#[derive(Clone, Debug, PartialEq)]
pub struct FileResult {
    /// Path relative to the data folder.
    pub file: String,
    /// Its comparison with Praat.
    pub metrics: Metrics,
}

/// Our syllable count against the truth for one recording.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct SyllableResult {
    /// Path relative to the data folder.
    pub file: String,
    /// Syllable steps the front-end reported.
    pub ours: u64,
    /// True syllables.
    pub truth: u64,
}

/// Everything `eval-prosody` measured.
#[derive(Clone, Debug, PartialEq)]
pub struct Report {
    /// The data folder.
    pub data: PathBuf,
    /// Per recording.
    pub files: Vec<FileResult>,
    /// Over all matched frames of all recordings.
    pub pooled: Metrics,
    /// Worst recording per metric.
    pub worst: Vec<Worst>,
    /// Syllable counts (empty when there is no prompts file).
    pub syllables: Vec<SyllableResult>,
}

fn read_text(path: &Path) -> Result<String, SimError> {
    std::fs::read_to_string(path).map_err(|source| SimError::Read {
        path: path.to_owned(),
        source,
    })
}

fn wav_files(dir: &Path, out: &mut Vec<PathBuf>) -> Result<(), SimError> {
    let entries = std::fs::read_dir(dir).map_err(|source| SimError::Read {
        path: dir.to_owned(),
        source,
    })?;
    let mut paths: Vec<PathBuf> = entries.filter_map(|e| e.ok().map(|e| e.path())).collect();
    paths.sort();
    for p in paths {
        if p.is_dir() {
            wav_files(&p, out)?;
        } else if p.extension().is_some_and(|e| e.eq_ignore_ascii_case("wav")) {
            out.push(p);
        }
    }
    Ok(())
}

/// Which front-end arithmetic to evaluate.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Arithmetic {
    /// The `f32` front-end (the reference; what the simulator and the trainer run).
    Float,
    /// The fixed-point front-end of boards without an FPU.
    Fixed,
}

fn analyse(path: &Path, arith: Arithmetic) -> Result<(Vec<eval::TrackFrame>, Vec<Step>), SimError> {
    let config = ProsodyConfig::DEFAULT;
    let pcm = audio::load_wav_at(path, config.sample_rate_hz)?;
    let (frames, steps) = match arith {
        Arithmetic::Float => features::prosody_of_arith::<Float>(&pcm.samples, &config)?,
        Arithmetic::Fixed => features::prosody_of_arith::<Fixed>(&pcm.samples, &config)?,
    };
    // Through the CSV text, so values are rounded exactly as the script would read them.
    let mut csv = Vec::new();
    write_frames_csv(&mut csv, &frames)?;
    let track =
        eval::parse_track_csv(&String::from_utf8_lossy(&csv)).map_err(|source| SimError::Data {
            path: path.to_owned(),
            source,
        })?;
    Ok((track, steps))
}

fn relative(dir: &Path, p: &Path) -> String {
    p.strip_prefix(dir).unwrap_or(p).display().to_string()
}

/// Evaluates every WAV with a Praat reference under `dir`, and the prompts' syllable counts.
pub fn evaluate(dir: &Path) -> Result<Report, SimError> {
    evaluate_with(dir, Arithmetic::Float)
}

/// [`evaluate`] with the front-end arithmetic `arith`.
pub fn evaluate_with(dir: &Path, arith: Arithmetic) -> Result<Report, SimError> {
    let mut wavs = Vec::new();
    wav_files(dir, &mut wavs)?;
    let ref_dir = dir.join("reference").join("praat");
    let mut files = Vec::new();
    let mut all_pairs: Vec<Pair> = Vec::new();
    let mut steps_of: Vec<(PathBuf, Vec<Step>)> = Vec::new();
    for wav in wavs {
        let Some(stem) = wav.file_stem() else {
            continue;
        };
        let ref_path = ref_dir.join(stem).with_extension("csv");
        if !ref_path.is_file() {
            continue;
        }
        let reference =
            eval::parse_track_csv(&read_text(&ref_path)?).map_err(|source| SimError::Data {
                path: ref_path.clone(),
                source,
            })?;
        let (ours, steps) = analyse(&wav, arith)?;
        let pairs = eval::match_frames(&ours, &reference);
        files.push(FileResult {
            file: relative(dir, &wav),
            metrics: eval::metrics(&pairs),
        });
        all_pairs.extend(pairs);
        steps_of.push((wav, steps));
    }
    let prompts_path = dir.join("cmu-arctic").join("prompts.tsv");
    let mut syllables = Vec::new();
    if prompts_path.is_file() {
        let prompts =
            eval::parse_prompts(&read_text(&prompts_path)?).map_err(|source| SimError::Data {
                path: prompts_path.clone(),
                source,
            })?;
        for p in prompts {
            let wav = dir.join("cmu-arctic").join(&p.file);
            let ours = match steps_of.iter().find(|(w, _)| *w == wav) {
                Some((_, steps)) => eval::count_syllables(steps),
                None => eval::count_syllables(&analyse(&wav, arith)?.1),
            };
            syllables.push(SyllableResult {
                file: relative(dir, &wav),
                ours: ours as u64,
                truth: p.syllables as u64,
            });
        }
    }
    let named: Vec<(String, Metrics)> = files.iter().map(|f| (f.file.clone(), f.metrics)).collect();
    Ok(Report {
        data: dir.to_owned(),
        pooled: eval::metrics(&all_pairs),
        worst: eval::worst_files(&named),
        files,
        syllables,
    })
}

fn num(v: f64, decimals: usize) -> String {
    if v.is_nan() {
        "n/a".into()
    } else {
        format!("{v:.decimals$}")
    }
}

fn percent(v: f64) -> String {
    if v.is_nan() {
        "n/a".into()
    } else {
        format!("{:+.1}%", 100.0 * v)
    }
}

fn metric_cells(m: &Metrics) -> String {
    format!(
        "{:>7} {:>7} {:>8} {:>6} {:>6} {:>6} {:>11}",
        m.frames,
        m.voiced_both,
        num(m.voicing, 3),
        num(m.gpe, 3),
        num(m.fine, 3),
        num(m.int_r, 3),
        num(m.int_r_nosil, 3)
    )
}

/// Totals of the syllable table: (ours, truth, relative error).
pub fn syllable_totals(rows: &[SyllableResult]) -> (u64, u64, f64) {
    let ours = rows.iter().map(|r| r.ours).sum();
    let truth = rows.iter().map(|r| r.truth).sum();
    (ours, truth, eval::relative_error(ours, truth))
}

/// The human-readable report.
pub fn write_table(out: &mut impl Write, r: &Report) -> std::io::Result<()> {
    let w = r
        .files
        .iter()
        .map(|f| f.file.len())
        .chain(r.syllables.iter().map(|s| s.file.len()))
        .max()
        .unwrap_or(4)
        .max(22);
    writeln!(
        out,
        "prosody front-end vs Praat 6.3 references in {}",
        r.data.display()
    )?;
    writeln!(
        out,
        "(voicing: agreement where Praat has an intensity; gpe: |F0 error| > 20 %; fine: median \
         relative F0 error of the rest; int_r: Pearson r of intensity; int_r_nosil: same without \
         Praat's -300 dB silence frames)"
    )?;
    writeln!(
        out,
        "{:<w$} {:>7} {:>7} {:>8} {:>6} {:>6} {:>6} {:>11}",
        "file", "frames", "voiced", "voicing", "gpe", "fine", "int_r", "int_r_nosil"
    )?;
    for f in &r.files {
        writeln!(out, "{:<w$} {}", f.file, metric_cells(&f.metrics))?;
    }
    let pooled = format!("pooled ({} files)", r.files.len());
    writeln!(out, "{:<w$} {}", pooled, metric_cells(&r.pooled))?;
    let worst: Vec<String> = r
        .worst
        .iter()
        .map(|x| format!("{} {} ({})", x.metric, num(x.value, 3), x.file))
        .collect();
    writeln!(out, "worst: {}", worst.join("; "))?;
    if !r.syllables.is_empty() {
        writeln!(out)?;
        writeln!(out, "syllables vs cmu-arctic/prompts.tsv")?;
        writeln!(
            out,
            "{:<w$} {:>5} {:>5} {:>8}",
            "file", "ours", "true", "error"
        )?;
        for s in &r.syllables {
            let e = eval::relative_error(s.ours, s.truth);
            writeln!(
                out,
                "{:<w$} {:>5} {:>5} {:>8}",
                s.file,
                s.ours,
                s.truth,
                percent(e)
            )?;
        }
        let (ours, truth, e) = syllable_totals(&r.syllables);
        writeln!(
            out,
            "{:<w$} {:>5} {:>5} {:>8}",
            "total",
            ours,
            truth,
            percent(e)
        )?;
    }
    Ok(())
}

fn metrics_json(m: &Metrics) -> Value {
    // serde_json writes NaN as null.
    json!({
        "frames": m.frames,
        "voiced_both": m.voiced_both,
        "voicing": m.voicing,
        "gpe": m.gpe,
        "fine": m.fine,
        "int_r": m.int_r,
        "int_r_nosil": m.int_r_nosil,
    })
}

/// The machine-readable report.
pub fn to_json(r: &Report) -> Value {
    let files: Vec<Value> = r
        .files
        .iter()
        .map(|f| {
            let mut v = metrics_json(&f.metrics);
            v["file"] = json!(f.file);
            v
        })
        .collect();
    let mut worst = serde_json::Map::new();
    for w in &r.worst {
        worst.insert(w.metric.into(), json!({ "file": w.file, "value": w.value }));
    }
    let rows: Vec<Value> = r
        .syllables
        .iter()
        .map(|s| {
            json!({
                "file": s.file,
                "ours": s.ours,
                "true": s.truth,
                "relative_error": eval::relative_error(s.ours, s.truth),
            })
        })
        .collect();
    let (ours, truth, e) = syllable_totals(&r.syllables);
    json!({
        "measured": true,
        "data": r.data.display().to_string(),
        "files": files,
        "pooled": metrics_json(&r.pooled),
        "worst": worst,
        "syllables": {
            "files": rows,
            "total_ours": ours,
            "total_true": truth,
            "relative_error": e,
        },
    })
}

/// Per file, the fixed-point front-end's voicing agreement and gross pitch error minus the
/// `f32` one's: `(file, voicing delta, gpe delta)` (a worse fixed path has a negative voicing
/// delta and a positive gpe delta).
pub fn fixed_vs_float(float: &Report, fixed: &Report) -> Vec<(String, f64, f64)> {
    float
        .files
        .iter()
        .filter_map(|a| {
            let b = fixed.files.iter().find(|b| b.file == a.file)?;
            Some((
                a.file.clone(),
                b.metrics.voicing - a.metrics.voicing,
                b.metrics.gpe - a.metrics.gpe,
            ))
        })
        .collect()
}

/// The largest shortfalls of the fixed-point front-end against the `f32` one over `deltas`
/// (from [`fixed_vs_float`]): `(voicing loss, its file, gpe increase, its file)`.
pub fn worst_shortfall(deltas: &[(String, f64, f64)]) -> (f64, String, f64, String) {
    let mut worst = (0.0f64, String::new(), 0.0f64, String::new());
    for (file, dv, dg) in deltas {
        if -dv > worst.0 {
            worst.0 = -dv;
            worst.1 = file.clone();
        }
        if *dg > worst.2 {
            worst.2 = *dg;
            worst.3 = file.clone();
        }
    }
    worst
}

fn write_comparison(out: &mut impl Write, deltas: &[(String, f64, f64)]) -> std::io::Result<()> {
    let w = deltas.iter().map(|d| d.0.len()).max().unwrap_or(4).max(22);
    writeln!(out)?;
    writeln!(out, "fixed-point minus f32, per file")?;
    writeln!(out, "{:<w$} {:>9} {:>9}", "file", "voicing", "gpe")?;
    for (file, dv, dg) in deltas {
        writeln!(out, "{:<w$} {:>+9.4} {:>+9.4}", file, dv, dg)?;
    }
    let (lv, fv, lg, fg) = worst_shortfall(deltas);
    writeln!(
        out,
        "largest shortfall: voicing {lv:.4} ({}), gpe {lg:.4} ({})",
        if fv.is_empty() { "none" } else { &fv },
        if fg.is_empty() { "none" } else { &fg }
    )
}

/// Runs the subcommand: resolve the folder, evaluate, print. With `fixed`, both front-ends
/// and their per-file differences.
pub fn run(
    data: Option<&Path>,
    as_json: bool,
    fixed: bool,
    out: &mut impl Write,
) -> Result<(), SimError> {
    let given = |reason: &str| -> SimError {
        SimError::Read {
            path: data.map(Path::to_path_buf).unwrap_or_default(),
            source: std::io::Error::new(std::io::ErrorKind::NotFound, reason.to_string()),
        }
    };
    let dir = match resolve_data_dir(data) {
        DataDir::Found(d) => d,
        DataDir::Missing(_) if data.is_some() => return Err(given("no such data folder")),
        DataDir::Missing(tried) => {
            let tried: Vec<String> = tried.iter().map(|p| p.display().to_string()).collect();
            let reason = format!("no data folder (tried {})", tried.join(", "));
            if as_json {
                let v = json!({ "measured": false, "reason": reason, "tried": tried });
                writeln!(out, "{v}")?;
            } else {
                writeln!(out, "{reason}; nothing was measured")?;
            }
            return Ok(());
        }
    };
    let report = evaluate(&dir)?;
    if report.files.is_empty() && data.is_some() {
        return Err(given(
            "no WAV file here has a reference in reference/praat/",
        ));
    }
    if report.files.is_empty() {
        let reason = format!(
            "no WAV file under {} has a reference in reference/praat/",
            dir.display()
        );
        if as_json {
            writeln!(out, "{}", json!({ "measured": false, "reason": reason }))?;
        } else {
            writeln!(out, "{reason}; nothing was measured")?;
        }
        return Ok(());
    }
    let fixed_report = if fixed {
        Some(evaluate_with(&dir, Arithmetic::Fixed)?)
    } else {
        None
    };
    if as_json {
        let mut v = to_json(&report);
        if let Some(f) = &fixed_report {
            let deltas = fixed_vs_float(&report, f);
            let (lv, fv, lg, fg) = worst_shortfall(&deltas);
            v["fixed"] = to_json(f);
            v["fixed_vs_f32"] = json!({
                "files": deltas
                    .iter()
                    .map(|(file, dv, dg)| json!({"file": file, "voicing": dv, "gpe": dg}))
                    .collect::<Vec<_>>(),
                "voicing_loss": lv,
                "voicing_loss_file": fv,
                "gpe_increase": lg,
                "gpe_increase_file": fg,
            });
        }
        writeln!(out, "{v}")?;
    } else {
        if fixed_report.is_some() {
            writeln!(out, "== f32 front-end ==")?;
        }
        write_table(out, &report)?;
        if let Some(f) = &fixed_report {
            writeln!(out)?;
            writeln!(out, "== fixed-point front-end (boards without an FPU) ==")?;
            write_table(out, f)?;
            write_comparison(out, &fixed_vs_float(&report, f))?;
        }
    }
    Ok(())
}
