//! Packing to a byte budget: the blob fits it, the successor lists are cut no further than
//! needed, a budget too small for one successor per exit is refused, and `--max-successors`
//! still bounds the lists when a budget is given too.

mod common;

use gesture_runtime::blob::Blob;
use gesture_trainer::pack::{pack_model, PackOptions, Packed};

/// The longest successor list of the blob.
fn longest_list(p: &Packed) -> usize {
    let blob = Blob::parse(&p.bytes).unwrap();
    (0..blob.exit_points())
        .map(|e| blob.successor_count(e))
        .max()
        .unwrap()
}

#[test]
fn a_budget_cuts_the_successor_lists_and_max_successors_still_bounds_them() {
    let dir = tempfile::tempdir().unwrap();
    let c = common::small_corpus(dir.path(), 11);
    let m = common::small_model(&c);
    let lib = std::slice::from_ref(&c);
    let pack = |budget: Option<usize>, max: Option<usize>| {
        let mut opts = PackOptions {
            budget_bytes: budget,
            ..PackOptions::default()
        };
        opts.control.max_successors = max;
        pack_model(&m, lib, &opts)
    };

    let full = pack(None, None).unwrap();
    let most = longest_list(&full);
    assert!(
        most >= 3,
        "the synthetic library should keep several successors: {most}"
    );

    // A budget a little under the full blob: it fits, and the lists are cut.
    let budget = full.bytes.len() - 1;
    let cut = pack(Some(budget), None).unwrap();
    assert!(cut.bytes.len() <= budget, "{} > {budget}", cut.bytes.len());
    let k = cut.report.successors_per_exit.expect("a cut is reported");
    assert!(k < most, "{k} successors per exit of {most}");
    assert_eq!(longest_list(&cut), k);

    // A budget the full blob fits: nothing is cut.
    let roomy = pack(Some(full.bytes.len()), None).unwrap();
    assert_eq!(roomy.bytes, full.bytes);
    assert_eq!(roomy.report.successors_per_exit, None);

    // With --max-successors as well, the lists are no longer than it, budget or not.
    let max = 2;
    let capped = pack(None, Some(max)).unwrap();
    let both = pack(Some(full.bytes.len()), Some(max)).unwrap();
    assert_eq!(longest_list(&capped), max);
    assert_eq!(both.bytes, capped.bytes);
    assert_eq!(both.report.successors_per_exit, Some(max));

    // A budget too small for one successor per exit is refused, with the sizes.
    let Err(e) = pack(Some(64), None) else {
        panic!("64 bytes cannot hold a blob");
    };
    let text = e.to_string();
    assert!(text.contains("64"), "{text}");
}
