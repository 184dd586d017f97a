//! The measurement images of `misalign` (Cortex-M only; `src/bin/`): the minimal images
//! of the size table, the benchmark image, the no-panic image and its canary. The
//! library part is what they, the firmware example and the on-target tests share:
//!
//! - [`support`]: the defmt logger (semihosting, or RTT with the feature `rtt`), exit
//!   through semihosting, stack painting and an instruction counter;
//! - [`log_panics_and_faults!`] and [`exit_on_panic!`]: the panic (and HardFault)
//!   handlers, as macros, since an image has exactly one and the no-panic images have
//!   panic-never's;
//! - [`io`]: the minimal and no-panic images' inputs (volatile reads) and outputs;
//! - [`prepared`]: the demo scene prepared at build time (bytes from the build script);
//! - [`shapes`]: evaluators of every table shape that `cargo xtask shapes` weighs (the
//!   `shapes` image; xtask compiles the same file for the host's error).
//!
//! Its build script writes the memory layout for every image that depends on it (the
//! firmware example and the on-target tests too): `MISALIGN_MEMORY_X`, or the QEMU
//! board of the target.
#![no_std]

pub mod io;
pub mod node_samples;
mod panic;
pub mod prepared;
pub mod shapes;
pub mod support;

/// The runtime, for the handler macros.
#[doc(hidden)]
pub use cortex_m_rt;
