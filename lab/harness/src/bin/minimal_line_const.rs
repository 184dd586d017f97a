//! Minimal image with the line estimator on a build-time scene: the demo scene
//! prepared on the host (the build script, `misalign_harness::prepared`), its bytes read
//! as from a configuration block and loaded with `from_bytes` (integer checks only),
//! then one sample estimated. `minimal_line` without the f64 preparation: its flash
//! minus `minimal_line`'s estimator flash and `minimal_base` is what loading the
//! bytes costs.
#![no_std]
#![no_main]

use misalign_harness::{io, prepared};

misalign_harness::exit_on_panic!();

#[cfg(target_abi = "eabihf")]
#[cortex_m_rt::entry]
fn main() -> ! {
    use misalign::float::LineScene;
    let Ok(scene) = LineScene::from_bytes(&io::read(&prepared::LINE)) else {
        io::exit(2)
    };
    let (load, phi) = io::sample();
    match scene.estimate(load, phi) {
        Ok(e) => {
            io::emit(e);
            io::exit(0)
        }
        Err(_) => io::exit(1),
    }
}

/// Without an FPU (Cortex-M0, M3) the image holds the fixed-point core.
#[cfg(not(target_abi = "eabihf"))]
#[cortex_m_rt::entry]
fn main() -> ! {
    use misalign::fixed::FixedLineScene;
    let Ok(scene) = FixedLineScene::from_bytes(&io::read(&prepared::FIXED_LINE)) else {
        io::exit(2)
    };
    let (load, angle) = io::counts();
    match scene.estimate(load, angle) {
        Ok(e) => {
            io::emit(e);
            io::exit(0)
        }
        Err(_) => io::exit(1),
    }
}
