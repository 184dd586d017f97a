//! The Pico's memory layout for cortex-m-rt's link.x, and embassy-rp's link-rp.x (the
//! second-stage bootloader's section). The repository's .cargo/config.toml adds link.x
//! and defmt.x for every thumb target.
use std::path::PathBuf;

fn main() {
    let out = PathBuf::from(std::env::var_os("OUT_DIR").expect("cargo sets OUT_DIR"));
    std::fs::copy("memory.x", out.join("memory.x")).expect("copy memory.x");
    println!("cargo:rustc-link-search={}", out.display());
    println!("cargo:rustc-link-arg-bins=-Tlink-rp.x");
    println!("cargo:rerun-if-changed=memory.x");
}
