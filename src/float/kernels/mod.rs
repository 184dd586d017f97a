//! f32 kernels of the per-sample path, one file each, each with its maximum error as a
//! constant beside the code and a test that holds it to that bound (exhaustively over
//! a domain that covers every f32 input by scaling, where the kernel is scale-exact).
//! They call no library routine except `small_theta`, which takes `logf` from libm
//! below the tables' range (theta < 2^-32), never on the tables' path. The axial force
//! reads its two polynomials from the core's generated tables (`super::tables`), which
//! import no kernel, and so does `theta_top` its table of theta(g)'s top octave.

pub mod axial_force;
pub mod axial_force_inverse;
pub mod cbrt;
pub mod small_theta;
pub mod sqrt;
pub mod theta_top;
