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
