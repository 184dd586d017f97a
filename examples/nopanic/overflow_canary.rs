//! The second canary of the no-panic proof: like `canary`, but its one panic path is
//! an addition of two counts that can overflow. It must fail to link; if it links, the
//! proof is built without overflow checks and cannot see a wrapped integer, and
//! `cargo xtask nopanic` fails.
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
    let (load, angle) = io::counts();
    // A possible overflow: a panic path with overflow checks, a silent wrap without.
    io::emit(load + angle.unsigned_abs());
    semihosting::process::exit(0)
}

#[cfg(not(target_os = "none"))]
fn main() {
    eprintln!("a firmware image: `cargo xtask nopanic` builds it for Cortex-M");
    std::process::exit(2);
}
