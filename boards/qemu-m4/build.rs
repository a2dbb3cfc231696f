//! Puts `memory.x` on the linker's path and checks that the assets exist.

use std::path::PathBuf;
use std::{env, fs};

fn main() {
    let out = PathBuf::from(env::var_os("OUT_DIR").expect("cargo sets OUT_DIR"));
    fs::write(out.join("memory.x"), include_bytes!("memory.x")).expect("writing memory.x");
    println!("cargo:rustc-link-search={}", out.display());
    println!("cargo:rerun-if-changed=memory.x");
    for asset in ["policy.blob", "speech.raw", "stress.raw"] {
        let path = PathBuf::from("assets").join(asset);
        println!("cargo:rerun-if-changed={}", path.display());
        if !path.is_file() {
            panic!(
                "boards/qemu-m4/{} is missing: run boards/qemu-m4/make-assets first",
                path.display()
            );
        }
    }
}
