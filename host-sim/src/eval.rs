//! Accuracy of the prosody front-end against Praat: pure functions, no I/O.
//!
//! The metrics are the usual comparison of a pitch/intensity track with Praat's, defined here
//! so that `gesture-sim eval-prosody` and a comparison of `gesture-sim prosody x.wav` with a
//! Praat CSV by the same rules print the same numbers:
//!
//! - frames are matched by nearest time: each reference frame takes the closer of the two
//!   neighbouring frames of ours (the earlier one on a tie) if it lies within 6 ms;
//! - **voicing** agreement over matched frames where Praat has an intensity (inside the signal);
//! - **gpe**, gross pitch error: share of frames voiced in both whose F0 differs by more than
//!   20 % of Praat's;
//! - **fine**: the median relative F0 error of the remaining both-voiced frames (the upper
//!   median, `sorted[n / 2]`, as the script takes it);
//! - **int_r**: Pearson r of intensity over frames where both are finite.
//!
//! Added here: **int_r_nosil**, the same r without frames where Praat reports its -300 dB
//! digital-silence sentinel (a handful of such frames dominate the variance and inflate r).
//!
//! Undefined values follow the script: voicing and gpe are 0 over no frames; fine and the r
//! values are NaN when there is nothing to measure (r also needs at least 3 frames and
//! non-zero variance on both sides). Reference CSVs are parsed by header name, like the
//! script's `csv.DictReader`; a malformed row is an error naming its line.
//!
//! Hand-written rather than a `csv` crate: the files are three numeric columns without quoting,
//! and the parser is ten lines.

use gesture_runtime::prosody::{Step, StepKind};

/// Frames match when their times differ by at most this (seconds).
pub const MATCH_TOLERANCE_S: f64 = 0.006;
/// A pitch error above this fraction of the reference F0 is gross.
pub const GROSS_ERROR: f64 = 0.2;
/// Praat's intensity for digital silence (dB).
pub const PRAAT_SILENCE_DB: f64 = -300.0;

/// One row of a per-frame prosody CSV (`time_s,f0_hz,intensity_db`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TrackFrame {
    /// Frame centre (s).
    pub time_s: f64,
    /// F0 (Hz), `None` when unvoiced.
    pub f0_hz: Option<f64>,
    /// Intensity (dB), `None` when undefined (Praat leaves the first frames empty).
    pub intensity_db: Option<f64>,
}

/// Why a CSV or TSV could not be parsed.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum ParseError {
    /// The header lacks a required column.
    #[error("header has no `{0}` column")]
    MissingColumn(&'static str),
    /// A row is malformed.
    #[error("line {line}: {reason}")]
    BadRow {
        /// 1-based line number.
        line: usize,
        /// What is wrong.
        reason: String,
    },
}

/// Parses a per-frame CSV with a `time_s` column and optional `f0_hz` and `intensity_db`
/// columns (any order; empty cells are `None`; blank lines are skipped).
pub fn parse_track_csv(text: &str) -> Result<Vec<TrackFrame>, ParseError> {
    let mut lines = text
        .lines()
        .enumerate()
        .filter(|(_, l)| !l.trim().is_empty());
    let Some((_, header)) = lines.next() else {
        return Err(ParseError::MissingColumn("time_s"));
    };
    let cols: Vec<&str> = header.split(',').map(str::trim).collect();
    let col = |name| cols.iter().position(|c| *c == name);
    let t_col = col("time_s").ok_or(ParseError::MissingColumn("time_s"))?;
    let (f_col, i_col) = (col("f0_hz"), col("intensity_db"));
    let mut rows = Vec::new();
    for (i, line) in lines {
        let fields: Vec<&str> = line.split(',').map(str::trim).collect();
        let bad = |reason: String| ParseError::BadRow {
            line: i + 1,
            reason,
        };
        let num = |c: Option<usize>, name: &str| -> Result<Option<f64>, ParseError> {
            match c.and_then(|c| fields.get(c)).copied().unwrap_or("") {
                "" => Ok(None),
                s => s
                    .parse::<f64>()
                    .map(Some)
                    .map_err(|_| bad(format!("{name} {s:?} is not a number"))),
            }
        };
        let time_s = num(Some(t_col), "time_s")?.ok_or_else(|| bad("empty time_s".into()))?;
        rows.push(TrackFrame {
            time_s,
            f0_hz: num(f_col, "f0_hz")?,
            intensity_db: num(i_col, "intensity_db")?,
        });
    }
    Ok(rows)
}

/// A reference frame and the frame of ours matched to it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Pair {
    /// Our frame.
    pub ours: TrackFrame,
    /// Praat's frame.
    pub reference: TrackFrame,
}

/// Matches every reference frame to the nearest of our frames within [`MATCH_TOLERANCE_S`]
/// (`ours` sorted by time). Reference frames without a match are dropped.
pub fn match_frames(ours: &[TrackFrame], reference: &[TrackFrame]) -> Vec<Pair> {
    let mut pairs = Vec::with_capacity(reference.len());
    for r in reference {
        let t = r.time_s;
        let i = ours.partition_point(|o| o.time_s < t);
        let mut best: Option<usize> = None;
        for j in [i.wrapping_sub(1), i] {
            let Some(o) = ours.get(j) else { continue };
            let d = (o.time_s - t).abs();
            if d <= MATCH_TOLERANCE_S && best.is_none_or(|b| d < (ours[b].time_s - t).abs()) {
                best = Some(j);
            }
        }
        if let Some(b) = best {
            pairs.push(Pair {
                ours: ours[b],
                reference: *r,
            });
        }
    }
    pairs
}

/// The comparison of one file (or of pooled files).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Metrics {
    /// Matched frames.
    pub frames: usize,
    /// Frames voiced in both.
    pub voiced_both: usize,
    /// Voicing agreement over frames where Praat has an intensity.
    pub voicing: f64,
    /// Gross pitch error rate among frames voiced in both.
    pub gpe: f64,
    /// Median relative F0 error of the frames without a gross error.
    pub fine: f64,
    /// Pearson r of intensity where both are finite.
    pub int_r: f64,
    /// Pearson r of intensity where both are finite and Praat's is not -300 dB.
    pub int_r_nosil: f64,
}

/// The script's metrics (and `int_r_nosil`) over matched pairs.
pub fn metrics(pairs: &[Pair]) -> Metrics {
    let voicing_pairs: Vec<(bool, bool)> = pairs
        .iter()
        .filter(|p| p.reference.intensity_db.is_some())
        .map(|p| (p.ours.f0_hz.is_some(), p.reference.f0_hz.is_some()))
        .collect();
    let agree = voicing_pairs.iter().filter(|(a, b)| a == b).count();
    let both: Vec<(f64, f64)> = pairs
        .iter()
        .filter_map(|p| Some((p.ours.f0_hz?, p.reference.f0_hz?)))
        .collect();
    let rel: Vec<f64> = both.iter().map(|(a, b)| (a - b).abs() / b).collect();
    let gross = rel.iter().filter(|&&e| e > GROSS_ERROR).count();
    let mut fine: Vec<f64> = rel.iter().copied().filter(|&e| e <= GROSS_ERROR).collect();
    fine.sort_by(f64::total_cmp);
    let ints = |skip_silence: bool| -> Vec<(f64, f64)> {
        pairs
            .iter()
            .filter_map(|p| Some((p.ours.intensity_db?, p.reference.intensity_db?)))
            .filter(|(a, b)| a.is_finite() && b.is_finite())
            .filter(|&(_, b)| !(skip_silence && b == PRAAT_SILENCE_DB))
            .collect()
    };
    Metrics {
        frames: pairs.len(),
        voiced_both: both.len(),
        voicing: agree as f64 / voicing_pairs.len().max(1) as f64,
        gpe: gross as f64 / both.len().max(1) as f64,
        fine: upper_median(&fine),
        int_r: pearson(&ints(false)),
        int_r_nosil: pearson(&ints(true)),
    }
}

/// `sorted[len / 2]`, NaN when empty (the script's median).
pub fn upper_median(sorted: &[f64]) -> f64 {
    sorted.get(sorted.len() / 2).copied().unwrap_or(f64::NAN)
}

/// Pearson correlation of `(x, y)` pairs; NaN for fewer than 3 pairs or zero variance.
pub fn pearson(xy: &[(f64, f64)]) -> f64 {
    if xy.len() <= 2 {
        return f64::NAN;
    }
    let n = xy.len() as f64;
    let mx = xy.iter().map(|p| p.0).sum::<f64>() / n;
    let my = xy.iter().map(|p| p.1).sum::<f64>() / n;
    let (mut sxy, mut sxx, mut syy) = (0.0, 0.0, 0.0);
    for &(x, y) in xy {
        sxy += (x - mx) * (y - my);
        sxx += (x - mx) * (x - mx);
        syy += (y - my) * (y - my);
    }
    if sxx > 0.0 && syy > 0.0 {
        sxy / (sxx * syy).sqrt()
    } else {
        f64::NAN
    }
}

/// One line of `prompts.tsv`: a file, its true syllable count and its text.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Prompt {
    /// WAV file name (relative to the prompts file's folder).
    pub file: String,
    /// True syllable count.
    pub syllables: u32,
    /// The sentence.
    pub text: String,
}

/// Parses a tab-separated prompts file with header `file, syllables, text`.
pub fn parse_prompts(text: &str) -> Result<Vec<Prompt>, ParseError> {
    let mut lines = text
        .lines()
        .enumerate()
        .filter(|(_, l)| !l.trim().is_empty());
    let Some((_, header)) = lines.next() else {
        return Err(ParseError::MissingColumn("file"));
    };
    let cols: Vec<&str> = header.split('\t').map(str::trim).collect();
    let col = |name| cols.iter().position(|c| *c == name);
    let f = col("file").ok_or(ParseError::MissingColumn("file"))?;
    let s = col("syllables").ok_or(ParseError::MissingColumn("syllables"))?;
    let t = col("text");
    lines
        .map(|(i, line)| {
            let fields: Vec<&str> = line.split('\t').collect();
            let bad = |reason: String| ParseError::BadRow {
                line: i + 1,
                reason,
            };
            let file = fields.get(f).map(|v| v.trim()).filter(|v| !v.is_empty());
            let file = file.ok_or_else(|| bad("no file name".into()))?;
            let count = fields.get(s).map(|v| v.trim()).unwrap_or("");
            let syllables = count
                .parse()
                .map_err(|_| bad(format!("syllable count {count:?} is not a whole number")))?;
            Ok(Prompt {
                file: file.to_owned(),
                syllables,
                text: t
                    .and_then(|t| fields.get(t))
                    .unwrap_or(&"")
                    .trim()
                    .to_owned(),
            })
        })
        .collect()
}

/// Syllable steps among `steps` (pause steps are not counted).
pub fn count_syllables(steps: &[Step]) -> usize {
    steps
        .iter()
        .filter(|s| s.kind == StepKind::Syllable)
        .count()
}

/// `(ours - truth) / truth`; NaN when the truth is 0.
pub fn relative_error(ours: u64, truth: u64) -> f64 {
    if truth == 0 {
        f64::NAN
    } else {
        (ours as f64 - truth as f64) / truth as f64
    }
}

/// The worst file for one metric.
#[derive(Clone, Debug, PartialEq)]
pub struct Worst {
    /// Metric name (`voicing`, `gpe`, `fine`, `int_r`, `int_r_nosil`).
    pub metric: &'static str,
    /// The file.
    pub file: String,
    /// Its value.
    pub value: f64,
}

/// For every metric, the file where it is worst (lowest agreement or r, highest error);
/// files where the metric is NaN are ignored, metrics that are NaN everywhere are left out.
pub fn worst_files(files: &[(String, Metrics)]) -> Vec<Worst> {
    type Get = fn(&Metrics) -> f64;
    let table: [(&'static str, Get, bool); 5] = [
        ("voicing", |m| m.voicing, false),
        ("gpe", |m| m.gpe, true),
        ("fine", |m| m.fine, true),
        ("int_r", |m| m.int_r, false),
        ("int_r_nosil", |m| m.int_r_nosil, false),
    ];
    table
        .iter()
        .filter_map(|&(metric, get, higher_is_worse)| {
            files
                .iter()
                .filter(|(_, m)| !get(m).is_nan())
                .max_by(|a, b| {
                    let o = get(&a.1).total_cmp(&get(&b.1));
                    if higher_is_worse {
                        o
                    } else {
                        o.reverse()
                    }
                })
                .map(|(file, m)| Worst {
                    metric,
                    file: file.clone(),
                    value: get(m),
                })
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn fr(t: f64, f0: Option<f64>, db: Option<f64>) -> TrackFrame {
        TrackFrame {
            time_s: t,
            f0_hz: f0,
            intensity_db: db,
        }
    }

    fn pair(ours: TrackFrame, reference: TrackFrame) -> Pair {
        Pair { ours, reference }
    }

    #[test]
    fn parses_reference_csv_by_header() {
        let text = "time_s,f0_hz,intensity_db\n0.0200,,\n0.0300,,-300.00\n0.5300,123.45,67.89\n\n";
        let rows = parse_track_csv(text).unwrap();
        assert_eq!(
            rows,
            vec![
                fr(0.02, None, None),
                fr(0.03, None, Some(-300.0)),
                fr(0.53, Some(123.45), Some(67.89)),
            ]
        );
        // Columns in another order, intensity missing.
        let rows = parse_track_csv("f0_hz,time_s\n100,0.01\n").unwrap();
        assert_eq!(rows, vec![fr(0.01, Some(100.0), None)]);
    }

    #[test]
    fn csv_errors_name_the_line() {
        assert_eq!(
            parse_track_csv("f0_hz\n1\n"),
            Err(ParseError::MissingColumn("time_s"))
        );
        let e = parse_track_csv("time_s,f0_hz\n0.01,100\n0.02,abc\n").unwrap_err();
        assert!(matches!(e, ParseError::BadRow { line: 3, .. }), "{e:?}");
        assert!(e.to_string().starts_with("line 3:"), "{e}");
        assert!(parse_track_csv("time_s\n\n,\n").is_err());
    }

    #[test]
    fn matches_nearest_within_6_ms() {
        let ours: Vec<TrackFrame> = (1..=5).map(|k| fr(k as f64 * 0.01, None, None)).collect();
        let reference = [
            fr(0.0237, Some(1.0), None), // nearest is 0.02 (3.7 ms)
            fr(0.0262, Some(2.0), None), // nearest is 0.03 (3.8 ms)
            fr(0.0561, Some(4.0), None), // 0.06 does not exist; 0.05 is 6.1 ms away
            fr(0.0545, Some(5.0), None), // 0.05 is 4.5 ms away
            fr(0.0045, Some(6.0), None), // before the first frame, 5.5 ms away
            fr(0.0030, Some(7.0), None), // 7 ms before the first: unmatched
        ];
        let pairs = match_frames(&ours, &reference);
        let got: Vec<(f64, f64)> = pairs
            .iter()
            .map(|p| (p.reference.f0_hz.unwrap(), p.ours.time_s))
            .collect();
        assert_eq!(
            got,
            vec![(1.0, 0.02), (2.0, 0.03), (5.0, 0.05), (6.0, 0.01)]
        );
        assert!(match_frames(&[], &reference).is_empty());
        // An exact tie (binary fractions) goes to the earlier frame, as in the script.
        let ours = [fr(1.0, Some(1.0), None), fr(1.0078125, Some(2.0), None)];
        let pairs = match_frames(&ours, &[fr(1.00390625, None, None)]);
        assert_eq!(pairs[0].ours.f0_hz, Some(1.0));
    }

    #[test]
    fn voicing_agreement_three_of_four() {
        let db = Some(60.0);
        let pairs = [
            pair(fr(0.01, Some(100.0), db), fr(0.01, Some(100.0), db)), // agree
            pair(fr(0.02, None, db), fr(0.02, None, db)),               // agree
            pair(fr(0.03, Some(100.0), db), fr(0.03, None, db)),        // disagree
            pair(fr(0.04, None, db), fr(0.04, None, db)),               // agree
            // Praat has no intensity here: not counted for voicing.
            pair(fr(0.05, Some(100.0), db), fr(0.05, None, None)),
        ];
        let m = metrics(&pairs);
        assert_eq!(m.frames, 5);
        assert_eq!(m.voicing, 0.75);
        assert_eq!(m.voiced_both, 1);
    }

    #[test]
    fn gross_error_above_20_percent_and_fine_median() {
        let db = Some(60.0);
        let p = |ours: f64, praat: f64| pair(fr(0.0, Some(ours), db), fr(0.0, Some(praat), db));
        let pairs = [
            p(125.0, 100.0), // 25 %: gross
            p(119.0, 100.0), // 19 %: fine
            p(200.0, 100.0), // octave: gross
            p(101.0, 100.0), // 1 %
            p(97.0, 100.0),  // 3 %
            p(100.0, 100.0), // 0 %
        ];
        let m = metrics(&pairs);
        assert_eq!(m.voiced_both, 6);
        assert!((m.gpe - 2.0 / 6.0).abs() < 1e-12);
        // Fine errors sorted: 0, 0.01, 0.03, 0.19 -> upper median is 0.03.
        assert!((m.fine - 0.03).abs() < 1e-12, "{}", m.fine);
        assert_eq!(upper_median(&[1.0, 2.0, 3.0]), 2.0);
        assert!(upper_median(&[]).is_nan());
    }

    #[test]
    fn pearson_known_answers() {
        let lin: Vec<(f64, f64)> = (0..10).map(|i| (i as f64, 3.0 * i as f64 - 7.0)).collect();
        assert!((pearson(&lin) - 1.0).abs() < 1e-12);
        let neg: Vec<(f64, f64)> = (0..10).map(|i| (i as f64, -0.5 * i as f64)).collect();
        assert!((pearson(&neg) + 1.0).abs() < 1e-12);
        // x = (1, 2, 3, 4), y = (1, 3, 2, 4): r = 0.8.
        let r = pearson(&[(1.0, 1.0), (2.0, 3.0), (3.0, 2.0), (4.0, 4.0)]);
        assert!((r - 0.8).abs() < 1e-12, "{r}");
        assert!(pearson(&[(1.0, 1.0), (2.0, 2.0)]).is_nan());
        assert!(pearson(&[(1.0, 5.0), (2.0, 5.0), (3.0, 5.0)]).is_nan());
    }

    #[test]
    fn silence_sentinel_only_affects_int_r_nosil() {
        // Linear except for two digital-silence frames where ours is far off.
        let mut pairs: Vec<Pair> = (0..20)
            .map(|i| {
                let x = 40.0 + i as f64;
                pair(fr(0.0, None, Some(x)), fr(0.0, None, Some(2.0 * x + 1.0)))
            })
            .collect();
        for ours_db in [10.0, 90.0] {
            pairs.push(pair(
                fr(0.0, None, Some(ours_db)),
                fr(0.0, None, Some(PRAAT_SILENCE_DB)),
            ));
        }
        // Frames without a Praat intensity are ignored by both.
        pairs.push(pair(fr(0.0, None, Some(0.0)), fr(0.0, None, None)));
        let m = metrics(&pairs);
        assert!((m.int_r_nosil - 1.0).abs() < 1e-12);
        assert!(m.int_r < 0.9, "{}", m.int_r);
    }

    #[test]
    fn worst_file_per_metric() {
        let m = |voicing, gpe, int_r| Metrics {
            frames: 10,
            voiced_both: 5,
            voicing,
            gpe,
            fine: f64::NAN,
            int_r,
            int_r_nosil: int_r,
        };
        let files = vec![
            ("a".to_string(), m(0.9, 0.05, 0.99)),
            ("b".to_string(), m(0.8, 0.01, f64::NAN)),
            ("c".to_string(), m(0.95, 0.10, 0.97)),
        ];
        let w = worst_files(&files);
        let get = |name| {
            w.iter()
                .find(|w| w.metric == name)
                .map(|w| (w.file.as_str(), w.value))
        };
        assert_eq!(get("voicing"), Some(("b", 0.8)));
        assert_eq!(get("gpe"), Some(("c", 0.10)));
        assert_eq!(get("int_r"), Some(("c", 0.97)));
        assert_eq!(get("fine"), None);
    }

    #[test]
    fn empty_input_follows_the_script() {
        let m = metrics(&[]);
        assert_eq!(
            (m.frames, m.voiced_both, m.voicing, m.gpe),
            (0, 0, 0.0, 0.0)
        );
        assert!(m.fine.is_nan() && m.int_r.is_nan() && m.int_r_nosil.is_nan());
    }

    #[test]
    fn prompts_and_syllable_counts() {
        let text =
            "file\tsyllables\ttext\na.wav\t14\tAuthor of the danger trail.\nb.wav\t7\tWill we.\n";
        let p = parse_prompts(text).unwrap();
        assert_eq!(p.len(), 2);
        assert_eq!((p[0].file.as_str(), p[0].syllables), ("a.wav", 14));
        assert_eq!(p[1].text, "Will we.");
        let e = parse_prompts("file\tsyllables\nx.wav\tmany\n").unwrap_err();
        assert!(matches!(e, ParseError::BadRow { line: 2, .. }), "{e:?}");
        assert_eq!(
            parse_prompts("name\tsyllables\n"),
            Err(ParseError::MissingColumn("file"))
        );

        let step = |kind| Step {
            kind,
            start_frame: 1,
            end_frame: 2,
            f0_hz: None,
            intensity_db: 0.0,
        };
        let steps = [
            step(StepKind::Syllable),
            step(StepKind::Pause),
            step(StepKind::Syllable),
        ];
        assert_eq!(count_syllables(&steps), 2);
        assert!((relative_error(21, 20) - 0.05).abs() < 1e-12);
        assert!(relative_error(3, 0).is_nan());
    }
}
