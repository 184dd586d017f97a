//! f32 kernels of the per-sample path, one file each, each with its maximum error as a
//! constant beside the code and a test that holds it to that bound (exhaustively over
//! a domain that covers every f32 input by scaling, where the kernel is scale-exact).
//! No kernel calls a library routine; each costs a handful of instructions.

pub mod axial_force;
pub mod cbrt;
pub mod octave;
pub mod small_theta;
pub mod sqrt;
