//! Minimal image without the estimator: the baseline of the size table. It reads
//! the scene and a sample and emits them as `minimal_elliptic` and `minimal_line`
//! read theirs and emit their answers.
#![no_std]
#![no_main]

use misalign_harness::io;

misalign_harness::exit_on_panic!();

#[cortex_m_rt::entry]
fn main() -> ! {
    let (r1, r2, g, nu, mu) = io::scene();
    io::emit((r1, r2, g, nu, mu));
    let (load, phi) = io::sample();
    io::emit((load, phi));
    io::exit(0)
}
