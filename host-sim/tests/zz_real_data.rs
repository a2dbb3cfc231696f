//! The last test binary of a plain workspace `cargo test` (cargo runs test binaries in the
//! order of their package's and target's names; hence the name): one line on stderr, past the
//! test harness's capture, saying how many real-data tests of this run skipped and why (see
//! `e2e_tests`). Nothing when none skipped.

#[test]
fn real_data_skips_are_counted() {
    e2e_tests::print_skipped_summary();
}
