//! One sample of the roller pair: the node's timestamp and what the sensors read.

use crate::sensor_fault::SensorFault;

/// A measured channel, named in sensor faults.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Channel {
    /// The normal load P (N).
    Load,
    /// The misalignment phi (rad).
    Angle,
    /// The rolling speed V (m/s).
    Speed,
    /// The measured axial force F (N).
    AxialForce,
}

/// One sample: the node's timestamp, load, misalignment and the optional channels.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Sample {
    /// Free-running counter in ms (u32, wraps every 49.7 days; a wrap is not time
    /// going backwards).
    pub time_ms: u32,
    /// Normal load P (N; N/m for line contact without a length).
    pub load: f32,
    /// Misalignment phi (rad, signed).
    pub phi: f32,
    /// Measured rolling speed V (m/s); `None`: the configuration's nominal speed.
    pub speed: Option<f32>,
    /// Measured axial force F (N). When present it replaces the estimated F in the
    /// wear integral (the hook for tracking mu from a measured F).
    pub axial_force: Option<f32>,
    /// A fault a sensor driver reported for this sample, naming the channel: the
    /// sample counts as a sensor fault whatever its values.
    pub driver_fault: Option<Channel>,
    /// A fault a sensor's own detection found (which sensor, what kind): the sample
    /// counts as a sensor fault naming that sensor, whatever its values.
    pub sensor_fault: Option<SensorFault>,
}

impl Sample {
    /// A sample with load and misalignment only (speed nominal, no measured F).
    pub const fn new(time_ms: u32, load: f32, phi: f32) -> Self {
        Sample {
            time_ms,
            load,
            phi,
            speed: None,
            axial_force: None,
            driver_fault: None,
            sensor_fault: None,
        }
    }

    /// The sample the sensors gave (feature `sensors`), stamped `time_ms`: load P (N),
    /// misalignment phi (rad), the measured speed V (m/s) if any, and the sensors'
    /// first fault, which makes the sample a sensor fault naming the sensor (its
    /// faulty quantity holds 0 and is never estimated).
    #[cfg(feature = "sensors")]
    pub const fn from_sensors(time_ms: u32, sensors: &crate::sensors::SensorSample) -> Self {
        Sample {
            time_ms,
            load: sensors.load_n,
            phi: sensors.phi_rad,
            speed: sensors.speed_m_s,
            axial_force: None,
            driver_fault: None,
            sensor_fault: sensors.fault,
        }
    }

    /// The same sample with a sensor's fault: a sensor fault naming the sensor.
    pub const fn with_sensor_fault(mut self, fault: SensorFault) -> Self {
        self.sensor_fault = Some(fault);
        self
    }

    /// The same sample with a measured rolling speed (m/s).
    pub const fn with_speed(mut self, speed: f32) -> Self {
        self.speed = Some(speed);
        self
    }

    /// The same sample with a measured axial force (N).
    pub const fn with_axial_force(mut self, force: f32) -> Self {
        self.axial_force = Some(force);
        self
    }
}
