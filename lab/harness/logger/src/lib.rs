//! The defmt global logger of the images that log (the firmware example, the
//! on-target tests, the benchmark image): defmt over semihosting, for QEMU
//! (`lab/qemu-run` decodes it with defmt-print), or over RTT with the feature `rtt`,
//! for a real board (e.g. `probe-rs run`, which also serves the semihosting exit).
//! An image links it with `use misalign_logger as _;`.
//!
//! A crate of its own: a logger is linked into every image whose crates name it, and
//! its code has panic paths, so the images of the size table and of the no-panic
//! proof must not name it.
#![no_std]

#[cfg(feature = "rtt")]
use defmt_rtt as _;
#[cfg(not(feature = "rtt"))]
use defmt_semihosting as _;
