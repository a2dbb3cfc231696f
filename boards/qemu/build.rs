//! Puts the board's memory map on the linker's path as `memory.x` and checks that the assets
//! exist. The target selects the board: `thumbv7em-none-eabihf` is QEMU's mps2-an386
//! (Cortex-M4F), `thumbv8m.main-none-eabihf` its mps2-an505 (Cortex-M33F).

use std::path::PathBuf;
use std::{env, fs};

fn main() {
    let out = PathBuf::from(env::var_os("OUT_DIR").expect("cargo sets OUT_DIR"));
    let target = env::var("TARGET").expect("cargo sets TARGET");
    let memory: &[u8] = match target.as_str() {
        "thumbv7em-none-eabihf" => include_bytes!("mps2-an386.x"),
        "thumbv8m.main-none-eabihf" => include_bytes!("mps2-an505.x"),
        // ARMv6-M code on the same board: its Cortex-M4 executes the ARMv6-M subset with the
        // same instruction count (boards/qemu-m0).
        "thumbv6m-none-eabi" => include_bytes!("mps2-an386.x"),
        other => panic!(
            "no QEMU board for target {other}: build with --target thumbv7em-none-eabihf \
             (mps2-an386, boards/qemu-m4) or --target thumbv8m.main-none-eabihf (mps2-an505, \
             boards/qemu-m33)"
        ),
    };
    fs::write(out.join("memory.x"), memory).expect("writing memory.x");
    println!("cargo:rustc-link-search={}", out.display());
    println!("cargo:rerun-if-changed=mps2-an386.x");
    println!("cargo:rerun-if-changed=mps2-an505.x");
    let show = env::var_os("CARGO_FEATURE_SHOW").map(|_| "speech.show");
    for asset in ["policy.blob", "speech.raw", "stress.raw"]
        .into_iter()
        .chain(show)
    {
        let path = PathBuf::from("assets").join(asset);
        println!("cargo:rerun-if-changed={}", path.display());
        if !path.is_file() {
            panic!(
                "boards/qemu/{} is missing: run boards/qemu-m4/make-assets (or qemu-m33's) first",
                path.display()
            );
        }
    }
}
