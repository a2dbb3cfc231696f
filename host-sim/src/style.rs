//! The style a run or a live session gives the controller (docs/method.md "Style control"):
//! `--style NAME=W[,NAME=W...]`, `--energy E` and `--style-track CSV`, checked against the
//! blob's tones and turned into a schedule of weight vectors.
//!
//! **Weights.** Each spec names tones of the blob (and optionally `neutral`) with non-negative
//! weights; tones not named weigh 0. If the weights sum to more than 1 they are divided by
//! their sum, and the neutral tables get what is left of 1: `active=1` is fully active,
//! `active=0.5` half active and half neutral, `active=1,sad=1` half each, `neutral=1,active=1`
//! half neutral. The runtime's `Style::new` applies the same rule to what it is given.
//!
//! **Energy** (`--energy E`, -1 to 1): the knob of a blob packed with `gesture-train pack
//! --energy`: `E > 0` is weight `E` on the `energetic` tone, `E < 0` weight `-E` on `calm`. It
//! adds to `--style` (and to every row of a track).
//!
//! **Track** (`--style-track CSV`): a header `time_s,style`, then rows `T,NAME=W[;NAME=W...]`
//! or `T,"NAME=W,NAME=W"` (the rest of the line after the first comma is the spec, with `,` or
//! `;` between tones): from audio time `T` on, that style. Rows must increase in time; the
//! style before the first row is `--style` (neutral if none).
//!
//! Every error is one line naming the flag (or the file and line) and what is wrong; the run
//! stops before anything is written.

use std::path::{Path, PathBuf};

use gesture_trainer::control::style::{
    known_tones, normalized_weights, parse_weights as parse_spec,
};

/// The style flags of `run` and `live`.
#[derive(Debug, Clone, Default, clap::Args)]
pub struct StyleFlags {
    /// The style from the start: tones of the blob with weights, e.g. `active=1` or
    /// `active=0.5,sad=0.5` (weights above a sum of 1 are normalized; `neutral` gets the rest).
    #[arg(long, value_name = "NAME=W[,NAME=W...]")]
    pub style: Option<String>,
    /// The energy knob, -1 (calm) to 1 (energetic), for a blob packed with
    /// `gesture-train pack --energy`.
    #[arg(long, value_name = "E", allow_hyphen_values = true, value_parser = parse_energy)]
    pub energy: Option<f64>,
    /// Style changes over time: CSV with the header `time_s,style` and rows
    /// `T,NAME=W;NAME=W` (from audio time T on).
    #[arg(long, value_name = "CSV")]
    pub style_track: Option<PathBuf>,
}

fn parse_energy(s: &str) -> Result<f64, String> {
    let v: f64 = s.parse().map_err(|_| format!("{s:?} is not a number"))?;
    if v.is_finite() && (-1.0..=1.0).contains(&v) {
        Ok(v)
    } else {
        Err("must be a number from -1 to 1".into())
    }
}

impl StyleFlags {
    /// The schedule for a blob with `tones` ([`schedule`]).
    pub fn schedule(&self, tones: &[&str]) -> Result<Vec<StyleChange>, String> {
        schedule(
            self.style.as_deref(),
            self.energy,
            self.style_track.as_deref(),
            tones,
        )
    }
}

/// One style change: from `time_s` on (audio clock), the tones' weights (one per tone of the
/// blob, in its order; all 0 = neutral).
#[derive(Clone, Debug, PartialEq)]
pub struct StyleChange {
    /// When it takes effect (s).
    pub time_s: f64,
    /// Weight per tone of the blob.
    pub weights: Vec<f32>,
}

/// `weights` with the energy knob `e` added (see the module docs).
pub fn with_energy(weights: &[f32], e: f64, tones: &[&str]) -> Result<Vec<f32>, String> {
    if !(e.is_finite() && (-1.0..=1.0).contains(&e)) {
        return Err(format!("--energy {e}: must be a number from -1 to 1"));
    }
    let name = if e >= 0.0 { "energetic" } else { "calm" };
    let k = tones.iter().position(|t| *t == name).ok_or_else(|| {
        format!(
            "--energy: no tone `{name}` in the blob (pack it with `gesture-train pack --energy`; \
             {})",
            known_tones(tones)
        )
    })?;
    let mut w: Vec<f64> = weights.iter().map(|&v| v as f64).collect();
    w[k] += e.abs();
    let sum: f64 = w.iter().sum();
    Ok(normalized_weights(&w, (1.0 - sum).max(0.0)))
}

/// Reads a style track (see the module docs).
pub fn read_track(path: &Path, tones: &[&str]) -> Result<Vec<StyleChange>, String> {
    let text = std::fs::read_to_string(path).map_err(|e| format!("{}: {e}", path.display()))?;
    let mut out: Vec<StyleChange> = Vec::new();
    let mut lines = text.lines().enumerate();
    match lines.next() {
        Some((_, h)) if h.trim().starts_with("time_s") => {}
        _ => {
            return Err(format!(
                "{}:1: expected the header `time_s,style`",
                path.display()
            ))
        }
    }
    for (i, line) in lines {
        let what = format!("{}:{}", path.display(), i + 1);
        let line = line.trim();
        if line.is_empty() || line.starts_with('#') {
            continue;
        }
        let (t, spec) = line
            .split_once(',')
            .ok_or_else(|| format!("{what}: expected `time_s,NAME=W;NAME=W`"))?;
        let time_s: f64 = t
            .trim()
            .parse()
            .map_err(|_| format!("{what}: `{}` is not a time in seconds", t.trim()))?;
        if !(time_s.is_finite() && time_s >= 0.0) {
            return Err(format!("{what}: the time must be 0 or more seconds"));
        }
        if out.last().is_some_and(|c| c.time_s >= time_s) {
            return Err(format!("{what}: times must increase from row to row"));
        }
        let spec = spec.trim().trim_matches('"');
        out.push(StyleChange {
            time_s,
            weights: parse_spec(spec, tones, &what)?,
        });
    }
    if out.is_empty() {
        return Err(format!("{}: no rows after the header", path.display()));
    }
    Ok(out)
}

/// The style schedule of a run: `--style` (or neutral) from time 0, then the track's rows,
/// each with the energy knob added.
pub fn schedule(
    style: Option<&str>,
    energy: Option<f64>,
    track: Option<&Path>,
    tones: &[&str],
) -> Result<Vec<StyleChange>, String> {
    let mut out = vec![StyleChange {
        time_s: 0.0,
        weights: match style {
            Some(s) => parse_spec(s, tones, &format!("--style {s}"))?,
            None => vec![0.0; tones.len()],
        },
    }];
    if let Some(p) = track {
        for c in read_track(p, tones)? {
            if c.time_s == 0.0 {
                out[0] = c;
            } else {
                out.push(c);
            }
        }
    }
    if let Some(e) = energy {
        for c in &mut out {
            c.weights = with_energy(&c.weights, e, tones)?;
        }
    }
    Ok(out)
}

/// `name=w` of the non-zero weights and `neutral`, for summaries and the timeline.
pub fn describe(weights: &[f32], tones: &[&str]) -> Vec<(String, f32)> {
    let sum: f32 = weights.iter().sum();
    let mut out = vec![("neutral".to_string(), (1.0 - sum).max(0.0))];
    out.extend(
        tones
            .iter()
            .zip(weights)
            .filter(|(_, &w)| w > 0.0)
            .map(|(n, &w)| (n.to_string(), w)),
    );
    out.retain(|(_, w)| *w > 0.0);
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    const TONES: [&str; 4] = ["active", "sad", "energetic", "calm"];

    #[test]
    fn weights_are_normalized_with_neutral_taking_the_rest() {
        assert_eq!(
            parse_spec("active=1", &TONES, "x").unwrap(),
            [1.0, 0.0, 0.0, 0.0]
        );
        assert_eq!(
            parse_spec("active=0.5", &TONES, "x").unwrap(),
            [0.5, 0.0, 0.0, 0.0]
        );
        assert_eq!(
            parse_spec("active=1,sad=1", &TONES, "x").unwrap(),
            [0.5, 0.5, 0.0, 0.0]
        );
        assert_eq!(
            parse_spec("neutral=1; active=1", &TONES, "x").unwrap(),
            [0.5, 0.0, 0.0, 0.0]
        );
        assert_eq!(parse_spec("neutral=1", &TONES, "x").unwrap(), [0.0; 4]);
    }

    #[test]
    fn bad_specs_are_one_line_errors() {
        for (spec, want) in [
            ("happy=1", "no tone `happy`"),
            ("active", "expected NAME=WEIGHT"),
            ("active=x", "not a number"),
            ("active=-1", "at least 0"),
            ("active=nan", "finite"),
            ("active=1,active=0", "given twice"),
        ] {
            let e = parse_spec(spec, &TONES, "--style").unwrap_err();
            assert!(e.contains(want) && !e.contains('\n'), "{spec}: {e}");
        }
        let e = parse_spec("active=1", &[], "--style").unwrap_err();
        assert!(e.contains("has no tones"), "{e}");
    }

    #[test]
    fn energy_adds_to_the_style() {
        assert_eq!(
            with_energy(&[0.0; 4], 0.5, &TONES).unwrap(),
            [0.0, 0.0, 0.5, 0.0]
        );
        assert_eq!(
            with_energy(&[0.0; 4], -1.0, &TONES).unwrap(),
            [0.0, 0.0, 0.0, 1.0]
        );
        // Fully active plus energy 1: half each.
        assert_eq!(
            with_energy(&[1.0, 0.0, 0.0, 0.0], 1.0, &TONES).unwrap(),
            [0.5, 0.0, 0.5, 0.0]
        );
        assert!(with_energy(&[0.0; 2], 0.5, &["active", "sad"])
            .unwrap_err()
            .contains("pack --energy"));
        assert!(with_energy(&[0.0; 4], 2.0, &TONES).is_err());
    }

    #[test]
    fn a_track_is_read_in_order() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("t.csv");
        std::fs::write(
            &p,
            "time_s,style\n0,sad=1\n2.5,\"active=0.5,sad=0.5\"\n# comment\n4,active=1;calm=1\n",
        )
        .unwrap();
        let s = schedule(Some("active=1"), None, Some(&p), &TONES).unwrap();
        assert_eq!(s.len(), 3);
        assert_eq!(
            s[0].weights,
            [0.0, 1.0, 0.0, 0.0],
            "a row at 0 replaces --style"
        );
        assert_eq!(
            (s[1].time_s, s[1].weights.clone()),
            (2.5, vec![0.5, 0.5, 0.0, 0.0])
        );
        assert_eq!(s[2].weights, [0.5, 0.0, 0.0, 0.5]);
        std::fs::write(&p, "time_s,style\n2,sad=1\n1,sad=0\n").unwrap();
        let e = read_track(&p, &TONES).unwrap_err();
        assert!(e.contains("t.csv:3") && e.contains("increase"), "{e}");
        std::fs::write(&p, "when,style\n").unwrap();
        assert!(read_track(&p, &TONES).unwrap_err().contains("header"));
        std::fs::write(&p, "time_s,style\n1,happy=1\n").unwrap();
        let e = read_track(&p, &TONES).unwrap_err();
        assert!(e.contains("t.csv:2") && e.contains("happy"), "{e}");
    }

    #[test]
    fn describe_lists_neutral_and_the_tones_in_force() {
        assert_eq!(
            describe(&[0.25, 0.0, 0.0, 0.0], &TONES),
            [("neutral".to_string(), 0.75), ("active".to_string(), 0.25)]
        );
        assert_eq!(describe(&[], &[]), [("neutral".to_string(), 1.0)]);
    }
}
