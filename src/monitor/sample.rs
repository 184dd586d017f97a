//! One sample of the roller pair and the node's free-running millisecond clock.

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

/// How a timestamp relates to the previous one.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Step {
    /// The first sample since start or restore.
    First,
    /// Forward by this many ms (across a wrap too).
    Forward(u32),
    /// The same timestamp again.
    Repeated,
    /// Backwards: the counter jumped back (a reset), not a wrap.
    Backwards,
}

/// The clock: last raw timestamp and the monotonic time since the monitor started.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Clock {
    /// The last accepted raw timestamp (ms), `None` before the first sample.
    pub last_time_ms: Option<u32>,
    /// Monotonic time since the first sample (ms), the sum of forward steps.
    pub elapsed_ms: u64,
}

impl Clock {
    /// Steps the clock to `time_ms`. A u32 counter difference below 2^31 ms (24.8
    /// days) is a forward step, across a wrap too; a larger one is the counter going
    /// backwards. A backwards step re-anchors the clock at the new timestamp (after a
    /// counter reset the following samples go forward again) and adds no time.
    pub(crate) fn step(&mut self, time_ms: u32) -> Step {
        let step = match self.last_time_ms {
            None => Step::First,
            Some(last) => match time_ms.wrapping_sub(last) {
                0 => Step::Repeated,
                d if d < 1 << 31 => Step::Forward(d),
                _ => Step::Backwards,
            },
        };
        if let Step::Forward(d) = step {
            // Forward steps below 2^31 ms: u64 cannot wrap in 500 000 years.
            self.elapsed_ms = self.elapsed_ms.wrapping_add(u64::from(d));
        }
        if step != Step::Repeated {
            self.last_time_ms = Some(time_ms);
        }
        step
    }
}
