//! Minimal image without the estimator: the baseline of the size table. It reads
//! the scene and a sample and emits them as `minimal_elliptic` and `minimal_line`
//! read theirs and emit their answers.
#![cfg_attr(target_os = "none", no_std)]
#![cfg_attr(target_os = "none", no_main)]

#[cfg(target_os = "none")]
mod common;
#[cfg(target_os = "none")]
mod panic;

#[cfg(target_os = "none")]
#[cortex_m_rt::entry]
fn main() -> ! {
    let (r1, r2, g, nu, mu) = common::scene();
    common::emit((r1, r2, g, nu, mu));
    let (load, phi) = common::sample();
    common::emit((load, phi));
    common::exit(0)
}

#[cfg(not(target_os = "none"))]
fn main() {
    eprintln!("a firmware image: `cargo xtask firmware` builds it for Cortex-M");
    std::process::exit(2);
}
