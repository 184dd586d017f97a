//! Minimal image that only prepares the line-contact scene ([`LineScene::new`], f64;
//! without an FPU [`FixedLineScene::new`]) and emits it: `minimal_line` minus this is
//! the per-sample estimator, this minus `minimal_base` the preparation.
#![no_std]
#![no_main]

use misalign_harness::io;

use misalign::fixed::FixedLineScene;
use misalign::float::LineScene;

misalign_harness::exit_on_panic!();

#[cortex_m_rt::entry]
fn main() -> ! {
    io::image(LineScene::new, FixedLineScene::new, io::Body::Prepare)
}
