//! The firmware's built-in trace: the samples it estimates, as a sensor would deliver
//! them. Shared by the firmware (`examples/firmware/main.rs`) and the build script,
//! which evaluates the f64 reference on the host for the same samples and writes the
//! expected answers into OUT_DIR.

/// The demo installation: two steel printing-press rollers, R1 = R2 = 50 mm,
/// G = 79.3 GPa, nu = 0.3, mu = 0.3: `(R1, R2, G, nu, mu)` in SI units.
pub const SCENE: (f64, f64, f64, f64, f64) = (0.05, 0.05, 79.3e9, 0.3, 0.3);

/// Elliptic contact: `(load P in N, misalignment phi in rad)`. A sweep over the demo's
/// range (P from 100 N to 5 kN, phi from 0.01 to 2 mrad: partial and gross slip), then
/// the edges: a negative angle, zero angle, zero load, an angle deep in the small-theta
/// asymptotics, and a load so high that no critical angle exists.
pub const ELLIPTIC: [(f32, f32); 36] = [
    (100.0, 1e-5),
    (100.0, 6e-5),
    (100.0, 2e-4),
    (100.0, 4e-4),
    (100.0, 8e-4),
    (100.0, 2e-3),
    (400.0, 1e-5),
    (400.0, 6e-5),
    (400.0, 2e-4),
    (400.0, 4e-4),
    (400.0, 8e-4),
    (400.0, 2e-3),
    (1000.0, 1e-5),
    (1000.0, 6e-5),
    (1000.0, 2e-4),
    (1000.0, 4e-4),
    (1000.0, 8e-4),
    (1000.0, 2e-3),
    (2500.0, 1e-5),
    (2500.0, 6e-5),
    (2500.0, 2e-4),
    (2500.0, 4e-4),
    (2500.0, 8e-4),
    (2500.0, 2e-3),
    (5000.0, 1e-5),
    (5000.0, 6e-5),
    (5000.0, 2e-4),
    (5000.0, 4e-4),
    (5000.0, 8e-4),
    (5000.0, 2e-3),
    (1000.0, -3e-4),
    (1000.0, 0.0),
    (0.0, 2e-4),
    (0.0, 0.0),
    (1000.0, 1e-13),
    (1e14, 1e-3),
];

/// Line contact of the same rollers without a length: `(load per unit length P in N/m,
/// phi in rad)`. A sweep over both regimes, then a negative angle, zero angle, zero
/// load and a subnormal load.
pub const LINE: [(f32, f32); 20] = [
    (1e4, 1e-4),
    (1e4, 5e-4),
    (1e4, 2e-3),
    (1e4, 8e-3),
    (5e4, 1e-4),
    (5e4, 5e-4),
    (5e4, 2e-3),
    (5e4, 8e-3),
    (2e5, 1e-4),
    (2e5, 5e-4),
    (2e5, 2e-3),
    (2e5, 8e-3),
    (1e6, 1e-4),
    (1e6, 5e-4),
    (1e6, 2e-3),
    (1e6, 8e-3),
    (2e5, -2e-3),
    (2e5, 0.0),
    (0.0, 1e-3),
    (1e-40, 1e-30),
];
