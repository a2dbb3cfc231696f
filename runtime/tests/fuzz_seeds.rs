//! The blob fuzz targets' seeds (`tests/fuzz/seeds/blob_*`) are the small hand-built blobs of
//! these tests in the current format: this test fails when a seed is out of date, and
//! rewrites them when `GESTURE_WRITE_FUZZ_SEEDS=1` is set (after a format change).

mod common;

use common::*;

fn seeds() -> Vec<(&'static str, Vec<u8>)> {
    let golden = Tiny::new();
    let mut styled = Tiny::new();
    styled.styles = Some(TinyStyles::two(4, 6));
    let mut labelled = Tiny::new();
    labelled.label_section = Some(TinyLabels::one());
    vec![
        ("golden.blob", golden.encode()),
        ("styled.blob", styled.encode()),
        ("labelled.blob", labelled.encode()),
    ]
}

#[test]
fn the_blob_fuzz_seeds_are_the_current_format() {
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../tests/fuzz/seeds");
    let write = std::env::var("GESTURE_WRITE_FUZZ_SEEDS").is_ok_and(|v| v == "1");
    for target in ["blob_controller", "blob_repaired"] {
        for (name, bytes) in seeds() {
            gesture_runtime::blob::Blob::parse(&bytes).unwrap();
            let path = dir.join(target).join(name);
            if write {
                std::fs::write(&path, &bytes).unwrap();
            }
            let kept = std::fs::read(&path).unwrap();
            assert!(
                kept == bytes,
                "{} is out of date: run GESTURE_WRITE_FUZZ_SEEDS=1 cargo test -p gesture-runtime \
                 --test fuzz_seeds",
                path.display()
            );
        }
    }
}
