//! Puts `memory.x` on the linker's path and the policy blob into `OUT_DIR/policy.blob`.
//!
//! The blob is `$GESTURE_BLOB` if set, else the QEMU firmware's (`../qemu/assets/policy.blob`,
//! made by `boards/qemu-m0/make-assets`, the same as qemu-m4's), so a fresh checkout builds after
//! one script.

use std::path::PathBuf;
use std::{env, fs};

fn main() {
    let out = PathBuf::from(env::var_os("OUT_DIR").expect("cargo sets OUT_DIR"));
    fs::write(out.join("memory.x"), include_bytes!("memory.x")).expect("writing memory.x");
    println!("cargo:rustc-link-search={}", out.display());
    println!("cargo:rerun-if-changed=memory.x");

    println!("cargo:rerun-if-env-changed=GESTURE_BLOB");
    let blob = env::var_os("GESTURE_BLOB")
        .map(PathBuf::from)
        .unwrap_or_else(|| PathBuf::from("../qemu/assets/policy.blob"));
    println!("cargo:rerun-if-changed={}", blob.display());
    match fs::read(&blob) {
        Ok(bytes) => fs::write(out.join("policy.blob"), bytes).expect("writing the blob"),
        Err(e) => panic!(
            "policy blob {}: {e}. Set GESTURE_BLOB to a blob from `gesture-train pack` (8 \
             servo channels, e.g. --rig rigs/puppet-8ch.toml), or run \
             boards/qemu-m0/make-assets for the example one",
            blob.display()
        ),
    }
}
