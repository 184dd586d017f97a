//! [`SensorCalibration`]: a node's whole sensor calibration in one value, as it is
//! stored (`storage::SensorCalibration`'s record) and commissioned over a fieldbus
//! (the Modbus server's sensors' registers).

use super::{
    CalibrationError, Hx711Channel, LoadCalibration, MisalignmentCalibration, SpeedCalibration,
};

/// A node's sensor calibration: what a technician measured on site (docs/SENSORS.md),
/// kept across resets and firmware updates.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct SensorCalibration {
    /// The load cell.
    pub load: LoadCalibration<Hx711Channel>,
    /// The two displacement probes and their span.
    pub misalignment: MisalignmentCalibration,
    /// The tachometer, if the node has one.
    pub speed: Option<SpeedCalibration>,
}

impl SensorCalibration {
    /// Checks every part (each its own `validate`).
    pub fn validate(&self) -> Result<(), CalibrationError> {
        self.load.validate()?;
        self.misalignment.validate()?;
        self.speed
            .as_ref()
            .map_or(Ok(()), SpeedCalibration::validate)
    }
}
