//! The second canary of the no-panic proof: like `nopanic_canary`, but its one panic
//! path is an addition of two counts that can overflow. It must fail to link; if it
//! links, the proof is built without overflow checks and cannot see a wrapped integer,
//! and `cargo xtask nopanic` fails.
#![no_std]
#![no_main]

use panic_never as _;

use misalign_harness::io;

#[cortex_m_rt::entry]
fn main() -> ! {
    let (load, angle) = io::counts();
    // A possible overflow: a panic path with overflow checks, a silent wrap without.
    io::emit(load + angle.unsigned_abs());
    semihosting::process::exit(0)
}
