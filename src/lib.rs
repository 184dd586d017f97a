//! `misalign`: microslip, critical misalignment angle and axial force of two
//! misaligned rolling cylinders, after "The rolling contact of misaligned elastic
//! cylinders" (Hertz ellipse, Kalker's line integrals), for condition-monitoring
//! firmware.
//!
//! ```
//! use misalign::{reference, Scene};
//!
//! // Two steel rollers of 50 mm radius, mu = 0.3.
//! let scene = Scene::new(0.05, 0.05, 79.3e9, 0.3, 0.3)?;
//! // 1 kN load, 0.2 mrad misalignment: part of the contact still sticks.
//! let e = reference::elliptic(&scene, 1e3, 2e-4)?;
//! assert!(e.slip_ratio > 0.0 && e.axial_force > 0.0 && e.axial_force < 0.3 * 1e3);
//! let phi0 = e.critical_angle.expect("a critical angle exists at this load");
//! assert_eq!(e.regime, reference::Regime::Partial);
//! assert!(2e-4 < phi0); // phi0 = 0.41 mrad at this load
//! # Ok::<(), misalign::Error>(())
//! ```
//!
//! Layers: [`scene`] (one installation, validated), [`reference`](mod@reference) (the
//! whole paper in f64), [`float`] (the f32 core), [`fixed`] (the fixed-point core),
//! [`estimator`] (the contract both cores implement). Each core keeps its kernels and
//! generated tables inside it. See ARCHITECTURE.md for which module owns what.
//!
//! The hidden feature `_internals` makes the cores' kernels and tables public for the
//! workspace's own tooling (table generator, sweeps, benchmark, fuzzing). It is not
//! part of the API: no semver promise, not for users.
#![no_std]
#![forbid(unsafe_code)]
#![deny(missing_docs)]

#[cfg(any(test, feature = "std"))]
#[cfg_attr(test, macro_use)]
extern crate std;

/// A module that only the workspace's tooling reaches into: public (and hidden from
/// the docs) with the feature `_internals`, crate-private without it.
macro_rules! internal {
    ($(#[$attr:meta])* mod $name:ident;) => {
        #[cfg(feature = "_internals")]
        #[doc(hidden)]
        $(#[$attr])*
        pub mod $name;
        #[cfg(not(feature = "_internals"))]
        #[allow(dead_code)]
        $(#[$attr])*
        pub(crate) mod $name;
    };
}

mod error;
pub mod estimator;
pub mod fixed;
pub mod float;
#[cfg(feature = "modbus")]
pub mod modbus;
pub mod monitor;
pub mod prepared;
mod recip;
pub mod reference;
pub mod scene;
mod sensor_fault;
#[cfg(feature = "sensors")]
pub mod sensors;
#[cfg(feature = "sequential-storage")]
pub mod storage;

pub use error::Error;
pub use estimator::{Estimate, Estimator, FrictionInverse};

/// The README's examples run as doctests.
#[cfg(doctest)]
#[doc = include_str!("../README.md")]
struct ReadmeDoctests;
pub use scene::{Scene, ThetaRelation};
