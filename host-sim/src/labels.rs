//! Semantic labels a run gives the controller (docs/method.md "Semantic labels"):
//! `--labels CSV`, what a remote operator or a chat bot would send, checked against the
//! blob's label names.
//!
//! The file has the header `time_s,label` and one row per label: from audio time `time_s` on,
//! the controller is asked for that label (`Controller::push_label`). Rows must not go back in
//! time. Every error is one line naming the file and line; nothing is written.

use std::path::Path;

use crate::run::sim::LabelPush;

/// The blob's label names, for messages.
fn known(names: &[&str]) -> String {
    if names.is_empty() {
        "the blob has no labels (pack it with --label NAME=PATTERN)".into()
    } else {
        format!("the blob's labels: {}", names.join(", "))
    }
}

/// Reads a label track for a blob whose labels are `names`.
pub fn read_label_track(path: &Path, names: &[&str]) -> Result<Vec<LabelPush>, String> {
    let text = std::fs::read_to_string(path).map_err(|e| format!("{}: {e}", path.display()))?;
    let mut lines = text.lines().enumerate();
    match lines.next() {
        Some((_, h)) if h.trim().starts_with("time_s") => {}
        _ => {
            return Err(format!(
                "{}:1: expected the header `time_s,label`",
                path.display()
            ))
        }
    }
    let mut out: Vec<LabelPush> = Vec::new();
    for (i, line) in lines {
        let what = format!("{}:{}", path.display(), i + 1);
        let line = line.trim();
        if line.is_empty() || line.starts_with('#') {
            continue;
        }
        let (t, name) = line
            .split_once(',')
            .ok_or_else(|| format!("{what}: expected `time_s,label`"))?;
        let time_s: f64 = t
            .trim()
            .parse()
            .ok()
            .filter(|v: &f64| v.is_finite() && *v >= 0.0)
            .ok_or_else(|| format!("{what}: `{}` is not a time of 0 or more seconds", t.trim()))?;
        if out.last().is_some_and(|l| l.time_s > time_s) {
            return Err(format!("{what}: times must not go back"));
        }
        let name = name.trim();
        let label = names
            .iter()
            .position(|n| *n == name)
            .ok_or_else(|| format!("{what}: no label `{name}` in the blob ({})", known(names)))?;
        out.push(LabelPush {
            time_s,
            label,
            source: "track".into(),
        });
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_track_is_read_and_checked() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("l.csv");
        std::fs::write(&p, "time_s,label\n1.5,bye\n# x\n1.5, wave \n4,bye\n").unwrap();
        let t = read_label_track(&p, &["wave", "bye"]).unwrap();
        let got: Vec<(f64, usize)> = t.iter().map(|l| (l.time_s, l.label)).collect();
        assert_eq!(got, [(1.5, 1), (1.5, 0), (4.0, 1)]);
        for (text, want) in [
            ("time_s,label\n1,hello\n", "l.csv:2: no label `hello`"),
            (
                "time_s,label\n2,bye\n1,bye\n",
                "l.csv:3: times must not go back",
            ),
            ("time_s,label\n-1,bye\n", "not a time"),
            ("time_s,label\n1\n", "expected `time_s,label`"),
            ("when,label\n", "header"),
        ] {
            std::fs::write(&p, text).unwrap();
            let e = read_label_track(&p, &["wave", "bye"]).unwrap_err();
            assert!(e.contains(want) && !e.contains('\n'), "{text:?}: {e}");
        }
        std::fs::write(&p, "time_s,label\n1,bye\n").unwrap();
        assert!(read_label_track(&p, &[])
            .unwrap_err()
            .contains("has no labels"));
    }
}
