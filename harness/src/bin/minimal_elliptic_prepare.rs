//! Minimal image that only prepares the elliptic scene and emits it:
//! `minimal_elliptic` minus this is the per-sample estimator (code and tables), this
//! minus `minimal_base` the preparation. It prepares with empty tables
//! ([`EllipticScene::with_tables`], which [`EllipticScene::new`] calls with the full
//! ones), so that the emitted scene keeps no table in the image; without an FPU it
//! prepares the fixed-point core ([`FixedEllipticScene::new`]).
#![no_std]
#![no_main]

use misalign_harness::io;

use misalign::fixed::FixedEllipticScene;
use misalign::float::octave::OctaveTable;
use misalign::float::{EllipticScene, Tables};

/// No rows: the prepared scene links no table.
const EMPTY: Tables<'static> = Tables {
    g: OctaveTable::new(0, &[]),
    theta_of_g: OctaveTable::new(0, &[]),
};

misalign_harness::exit_on_panic!();

#[cortex_m_rt::entry]
fn main() -> ! {
    io::image(
        |s| EllipticScene::with_tables(s, EMPTY),
        FixedEllipticScene::new,
        io::Body::Prepare,
    )
}
