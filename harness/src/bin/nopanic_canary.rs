//! The canary of the no-panic proof: like `nopanic`, plus one slice index that the
//! compiler cannot prove in bounds. It must fail to link; if it links, panic-never
//! proves nothing in this build setup and `cargo xtask nopanic` fails.
#![cfg_attr(target_os = "none", no_std)]
#![cfg_attr(target_os = "none", no_main)]

#[cfg(target_os = "none")]
use panic_never as _;

#[cfg(target_os = "none")]
#[path = "../minimal/common.rs"]
mod io;

#[cfg(target_os = "none")]
#[cortex_m_rt::entry]
fn main() -> ! {
    let (load, phi) = io::sample();
    let rows = [1.0f32, 2.0, 3.0];
    // A possible out-of-bounds index: a panic path.
    io::emit(rows[load as usize] * phi);
    semihosting::process::exit(0)
}

#[cfg(not(target_os = "none"))]
fn main() {
    eprintln!("a firmware image: `cargo xtask nopanic` builds it for Cortex-M");
    std::process::exit(2);
}
