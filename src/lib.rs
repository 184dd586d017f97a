#![doc = include_str!("../README.md")]
#![no_std]
#![forbid(unsafe_code)]
#![deny(missing_docs)]

#[cfg(test)]
#[macro_use]
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

pub mod batch;
pub mod bytes;
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

pub use scene::{SHORT_ROLLER_PRESSURE, Scene, ThetaRelation};

/// Every error type of the crate is a `core::error::Error` (so a `std::error::Error` on
/// the host) with no feature, and a `defmt::Format` with `defmt`: checked wherever the
/// crate compiles, for the features it compiles with. (`u8` stands for a driver's
/// error in the generic ones.)
const _: () = {
    const fn error<E: core::error::Error>() {}
    #[cfg(feature = "defmt")]
    const fn format<E: defmt::Format>() {}
    macro_rules! every_error {
        ($($e:ty),* $(,)?) => {
            $(
                error::<$e>();
                #[cfg(feature = "defmt")]
                format::<$e>();
            )*
        };
    }
    every_error!(
        Error,
        crate::bytes::FieldError,
        crate::prepared::PreparedError,
        crate::monitor::ConfigError,
        crate::sensor_fault::SensorFault,
    );
    #[cfg(feature = "sensors")]
    every_error!(
        crate::sensors::AdcError<u8>,
        crate::sensors::PinError<u8, u8>,
        crate::sensors::CalibrationError,
    );
    #[cfg(feature = "_sim")]
    every_error!(crate::sensors::sim::SimError);
    #[cfg(feature = "sequential-storage")]
    every_error!(
        crate::storage::CodecError,
        crate::storage::StoreConfigError,
        crate::storage::StorageError<u8>,
    );
    #[cfg(feature = "_mock-flash")]
    every_error!(crate::storage::MockError);
    #[cfg(feature = "modbus")]
    every_error!(crate::modbus::ServerConfigError, crate::modbus::DecodeError,);
};

/// The firmware guide's examples run as doctests, as the README's do.
#[cfg(doctest)]
#[doc = include_str!("../docs/firmware.md")]
struct FirmwareGuideDoctests;

/// The integrator's page's Rust snippets (the application's storage loop, its boot,
/// the byte loop) compile against the server's and the storage's API
/// (`cargo test --features modbus,_mock-flash --doc ModbusGuideDoctests`).
#[cfg(all(doctest, feature = "modbus", feature = "_mock-flash"))]
#[doc = include_str!("../docs/modbus.md")]
struct ModbusGuideDoctests;

/// The technician's page's firmware outline compiles against the sensors' API
/// (`cargo test --features sensors,_sim,ads1x1x --doc SensorsGuideDoctests`).
#[cfg(all(doctest, feature = "sensors", feature = "ads1x1x"))]
#[doc = include_str!("../docs/SENSORS.md")]
struct SensorsGuideDoctests;
