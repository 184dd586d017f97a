//! Minimal image with the line-contact estimator: prepares the scene once
//! ([`LineScene::new`], f64) and estimates one sample; without an FPU (Cortex-M0, M3)
//! the fixed-point core's ([`FixedLineScene::new`]). Its flash minus that of
//! `minimal_line_prepare` is the per-sample estimator (code and tables).
#![no_std]
#![no_main]

use misalign_harness::io;

use misalign::fixed::FixedLineScene;
use misalign::float::LineScene;

misalign_harness::exit_on_panic!();

#[cortex_m_rt::entry]
fn main() -> ! {
    io::image(LineScene::new, FixedLineScene::new, io::Body::Estimate)
}
