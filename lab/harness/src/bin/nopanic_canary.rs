//! The canary of the no-panic proof: like `nopanic`, plus one slice index that the
//! compiler cannot prove in bounds. It must fail to link; if it links, panic-never
//! proves nothing in this build setup and `cargo xtask nopanic` fails.
#![no_std]
#![no_main]

use panic_never as _;

use misalign_harness::io;

#[cortex_m_rt::entry]
fn main() -> ! {
    let (load, phi) = io::sample();
    let rows = [1.0f32, 2.0, 3.0];
    // A possible out-of-bounds index: a panic path.
    io::emit(rows[load as usize] * phi);
    semihosting::process::exit(0)
}
