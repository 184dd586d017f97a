//! The two displacement probes of the sensor tests (feature `sensors`): on an
//! ADS1115-like 16-bit ADC, probe 1 reads 1e-7 m per count from 800 counts at 0 m,
//! probe 2 1.25e-7 m per count from -400 counts, 0 to 2 mm each, 0.4 m apart.

use misalign::sensors::{MisalignmentCalibration, ProbeCalibration, ProbeSpec};

/// The probes' range and linearity limit (m).
pub const PROBE: ProbeSpec = ProbeSpec {
    min_m: 0.0,
    max_m: 2e-3,
    linearity_m: 4e-6,
};

/// Their two-point calibrations, 0.4 m apart, with this zero offset (m).
pub fn probe_calibration(zero_offset_m: f32) -> MisalignmentCalibration {
    MisalignmentCalibration {
        probe1: ProbeCalibration::two_point((800.0, 0.0), (20_800.0, 2e-3), PROBE).unwrap(),
        probe2: ProbeCalibration::two_point((-400.0, 0.0), (15_600.0, 2e-3), PROBE).unwrap(),
        span_m: 0.4,
        zero_offset_m,
    }
}
