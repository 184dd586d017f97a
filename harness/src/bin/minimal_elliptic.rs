//! Minimal image with the elliptic estimator: prepares the scene once
//! ([`EllipticScene::new`], f64) and estimates one sample; without an FPU (Cortex-M0,
//! M3) the fixed-point core's ([`FixedEllipticScene::new`]). Its flash minus that of
//! `minimal_elliptic_prepare` is the per-sample estimator (code and tables).
#![no_std]
#![no_main]

use misalign_harness::io;

use misalign::fixed::FixedEllipticScene;
use misalign::float::EllipticScene;

misalign_harness::exit_on_panic!();

#[cortex_m_rt::entry]
fn main() -> ! {
    io::image(
        EllipticScene::new,
        FixedEllipticScene::new,
        io::Body::Estimate,
    )
}
