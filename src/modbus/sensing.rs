//! The node's sensor settings (sample period and calibration: load cell, the two
//! displacement probes, the tachometer): commissioned configuration, staged under the
//! unlock and committed with the rest (`config_*` beside `active_*`), kept in the
//! committed image. Each value is checked when written (exception 03 outside its
//! domain: never a NaN, a zero scale or a negative span), so that whatever is staged is
//! a calibration the sensors' drivers take. The server owns no sensor: the application
//! reads [`Server::sensors`](super::Server::sensors) after each request and
//! recalibrates its drivers when it changed.
//!
//! What the site's parts fix and a technician does not measure stays the build's: the
//! HX711's channel and gain, the probes' range and linearity (their data sheet).

/// A node's sampling period and its sensors' calibration as the map holds them. The
/// load cell: `P = (raw - load_zero_counts) * load_newtons_per_count`, valid on
/// `-load_capacity_n ..= load_capacity_n`; each probe `d = (raw - zero) * scale`;
/// `phi = atan2(d1 - d2 - probe_zero_offset_m, probe_span_m)`; the tachometer
/// `V = 2 pi r pulses / (pulses_per_rev dt)`, at most `tacho_max_speed_m_s`.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct SensorSettings {
    /// The sampling period (ms).
    pub sample_period_ms: u32,
    /// The load cell's raw code at zero load (counts).
    pub load_zero_counts: f32,
    /// The load cell's scale (N per count; negative for a bridge wired the other way).
    pub load_newtons_per_count: f32,
    /// The load cell's rated capacity (N): the calibrated range is +- it.
    pub load_capacity_n: f32,
    /// Probe 1's raw code at displacement 0 (counts).
    pub probe1_zero_counts: f32,
    /// Probe 1's scale (m per count).
    pub probe1_metres_per_count: f32,
    /// Probe 2's raw code at displacement 0 (counts).
    pub probe2_zero_counts: f32,
    /// Probe 2's scale (m per count).
    pub probe2_metres_per_count: f32,
    /// The probes' axial span (m).
    pub probe_span_m: f32,
    /// `d1 - d2` in the known-aligned state (m).
    pub probe_zero_offset_m: f32,
    /// The tachometer's pulses per revolution of the roller it sees.
    pub tacho_pulses_per_rev: u32,
    /// That roller's surface radius (m).
    pub tacho_radius_m: f32,
    /// The highest plausible surface speed (m/s).
    pub tacho_max_speed_m_s: f32,
}

impl SensorSettings {
    /// The reference node's (docs/pico.md), from its parts' data sheets until a
    /// technician's own replace them: 10 samples a second; a 2 mV/V, 20 kN cell on the
    /// HX711's channel A at gain 128 (full capacity `2e-3 * 2 * 128 * 2^23` counts,
    /// zero at code 0); probes of 4-20 mA over 0-2 mm through 150 Ohm read at +-4.096 V
    /// (code 4800 at 0 mm, 24000 at 2 mm), 0.4 m apart, zero offset 0; a 1024-line
    /// encoder on a 50 mm radius roller, 10 m/s at most.
    pub const DEFAULT: SensorSettings = SensorSettings {
        sample_period_ms: 100,
        load_zero_counts: 0.0,
        load_newtons_per_count: 20e3 / (2.0 * 1e-3 * 2.0 * 128.0 * 8_388_608.0),
        load_capacity_n: 20e3,
        probe1_zero_counts: 4800.0,
        probe1_metres_per_count: 2e-3 / (24000.0 - 4800.0),
        probe2_zero_counts: 4800.0,
        probe2_metres_per_count: 2e-3 / (24000.0 - 4800.0),
        probe_span_m: 0.4,
        probe_zero_offset_m: 0.0,
        tacho_pulses_per_rev: 1024,
        tacho_radius_m: 0.05,
        tacho_max_speed_m_s: 10.0,
    };

    /// Whether every value is in its register's domain (docs/modbus.md: each a finite
    /// number, a scale not zero, the sampling period from 10 ms to 60 s).
    pub fn is_valid(&self) -> bool {
        SensorField::ALL.iter().all(|&f| f.takes(self.get(f)))
    }

    /// The value of `f`, as its register's bits.
    pub(crate) fn get(&self, f: SensorField) -> u32 {
        use SensorField as S;
        match f {
            S::SamplePeriod => self.sample_period_ms,
            S::LoadZero => self.load_zero_counts.to_bits(),
            S::LoadScale => self.load_newtons_per_count.to_bits(),
            S::LoadCapacity => self.load_capacity_n.to_bits(),
            S::Probe1Zero => self.probe1_zero_counts.to_bits(),
            S::Probe1Scale => self.probe1_metres_per_count.to_bits(),
            S::Probe2Zero => self.probe2_zero_counts.to_bits(),
            S::Probe2Scale => self.probe2_metres_per_count.to_bits(),
            S::ProbeSpan => self.probe_span_m.to_bits(),
            S::ProbeZeroOffset => self.probe_zero_offset_m.to_bits(),
            S::PulsesPerRev => self.tacho_pulses_per_rev,
            S::Radius => self.tacho_radius_m.to_bits(),
            S::MaxSpeed => self.tacho_max_speed_m_s.to_bits(),
        }
    }

    /// `f` set to the register's bits `v` (unchecked: [`SensorField::takes`] first).
    fn set(&mut self, f: SensorField, v: u32) {
        use SensorField as S;
        let x = f32::from_bits(v);
        match f {
            S::SamplePeriod => self.sample_period_ms = v,
            S::LoadZero => self.load_zero_counts = x,
            S::LoadScale => self.load_newtons_per_count = x,
            S::LoadCapacity => self.load_capacity_n = x,
            S::Probe1Zero => self.probe1_zero_counts = x,
            S::Probe1Scale => self.probe1_metres_per_count = x,
            S::Probe2Zero => self.probe2_zero_counts = x,
            S::Probe2Scale => self.probe2_metres_per_count = x,
            S::ProbeSpan => self.probe_span_m = x,
            S::ProbeZeroOffset => self.probe_zero_offset_m = x,
            S::PulsesPerRev => self.tacho_pulses_per_rev = v,
            S::Radius => self.tacho_radius_m = x,
            S::MaxSpeed => self.tacho_max_speed_m_s = x,
        }
    }

    /// As [`SENSOR_BYTES`] bytes in a committed image: each field's register bits
    /// (u32, little-endian) in [`SensorField::ALL`]'s order.
    pub(crate) fn to_bytes(self) -> [u8; SENSOR_BYTES] {
        let mut b = [0; SENSOR_BYTES];
        for (o, f) in b.chunks_exact_mut(4).zip(SensorField::ALL) {
            o.copy_from_slice(&self.get(f).to_le_bytes());
        }
        b
    }

    /// The settings of [`to_bytes`](Self::to_bytes), if every value is valid.
    pub(crate) fn from_bytes(b: &[u8; SENSOR_BYTES]) -> Option<SensorSettings> {
        let mut s = SensorSettings::DEFAULT;
        for (w, f) in b.chunks_exact(4).zip(SensorField::ALL) {
            let v = u32::from_le_bytes([w[0], w[1], w[2], w[3]]);
            if !f.takes(v) {
                return None;
            }
            s.set(f, v);
        }
        Some(s)
    }

    /// The sensors' calibration of these settings with what the build fixes: the
    /// HX711's `channel` and the probes' `spec` (their range and linearity).
    ///
    /// # Errors
    /// The drivers' check ([`SensorCalibration::validate`](crate::sensors::SensorCalibration::validate)).
    #[cfg(feature = "sensors")]
    pub fn calibration(
        &self,
        channel: crate::sensors::Hx711Channel,
        spec: crate::sensors::ProbeSpec,
    ) -> Result<crate::sensors::SensorCalibration, crate::sensors::CalibrationError> {
        use crate::sensors::{
            LoadCalibration, MisalignmentCalibration, ProbeCalibration, SensorCalibration,
            SpeedCalibration,
        };
        let probe = |zero_counts, metres_per_count| ProbeCalibration {
            zero_counts,
            metres_per_count,
            spec,
        };
        let c = SensorCalibration {
            load: LoadCalibration {
                channel,
                zero_counts: self.load_zero_counts,
                newtons_per_count: self.load_newtons_per_count,
                min_newtons: -self.load_capacity_n,
                max_newtons: self.load_capacity_n,
            },
            misalignment: MisalignmentCalibration {
                probe1: probe(self.probe1_zero_counts, self.probe1_metres_per_count),
                probe2: probe(self.probe2_zero_counts, self.probe2_metres_per_count),
                span_m: self.probe_span_m,
                zero_offset_m: self.probe_zero_offset_m,
            },
            speed: Some(SpeedCalibration {
                pulses_per_rev: self.tacho_pulses_per_rev,
                radius_m: self.tacho_radius_m,
                max_speed_m_s: self.tacho_max_speed_m_s,
            }),
        };
        c.validate()?;
        Ok(c)
    }
}

impl Default for SensorSettings {
    fn default() -> Self {
        SensorSettings::DEFAULT
    }
}

/// Bytes of the sensor settings in a committed image.
pub(crate) const SENSOR_BYTES: usize = 4 * SensorField::ALL.len();

/// The shortest and longest sampling period (ms).
pub const SAMPLE_PERIOD_MS: (u32, u32) = (10, 60_000);

/// One value of the sensor settings' registers.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum SensorField {
    SamplePeriod,
    LoadZero,
    LoadScale,
    LoadCapacity,
    Probe1Zero,
    Probe1Scale,
    Probe2Zero,
    Probe2Scale,
    ProbeSpan,
    ProbeZeroOffset,
    PulsesPerRev,
    Radius,
    MaxSpeed,
}

/// What a field takes: whole numbers, or finite f32 within bounds (a scale also
/// non-zero).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) enum Bounds {
    Whole(u32, u32),
    Finite(f32, f32),
    NonZero(f32),
}

impl SensorField {
    pub(crate) const ALL: [SensorField; 13] = {
        use SensorField as S;
        [
            S::SamplePeriod,
            S::LoadZero,
            S::LoadScale,
            S::LoadCapacity,
            S::Probe1Zero,
            S::Probe1Scale,
            S::Probe2Zero,
            S::Probe2Scale,
            S::ProbeSpan,
            S::ProbeZeroOffset,
            S::PulsesPerRev,
            S::Radius,
            S::MaxSpeed,
        ]
    };

    /// The field's domain.
    pub(crate) const fn bounds(self) -> Bounds {
        use SensorField as S;
        match self {
            S::SamplePeriod => Bounds::Whole(SAMPLE_PERIOD_MS.0, SAMPLE_PERIOD_MS.1),
            // The HX711's 24-bit codes, with room for a tare outside them.
            S::LoadZero => Bounds::Finite(-16_777_216.0, 16_777_216.0),
            S::LoadScale => Bounds::NonZero(1e3),
            S::LoadCapacity => Bounds::Finite(1.0, 1e9),
            // An ADC's codes (the ADS1115's 16 bits and far beyond).
            S::Probe1Zero | S::Probe2Zero => Bounds::Finite(-1e6, 1e6),
            S::Probe1Scale | S::Probe2Scale => Bounds::NonZero(1.0),
            S::ProbeSpan => Bounds::Finite(1e-3, 100.0),
            S::ProbeZeroOffset => Bounds::Finite(-1.0, 1.0),
            S::PulsesPerRev => Bounds::Whole(1, 1_000_000),
            S::Radius => Bounds::Finite(1e-3, 10.0),
            S::MaxSpeed => Bounds::Finite(0.1, 1000.0),
        }
    }

    /// Whether a master may write `v` (the register's bits).
    pub(crate) fn takes(self, v: u32) -> bool {
        let x = f32::from_bits(v);
        match self.bounds() {
            Bounds::Whole(lo, hi) => (lo..=hi).contains(&v),
            Bounds::Finite(lo, hi) => lo <= x && x <= hi,
            Bounds::NonZero(m) => -m <= x && x <= m && x != 0.0,
        }
    }
}

/// The sensor settings' state in a server: in force (and kept), and a staged copy.
#[derive(Debug, Clone)]
pub(crate) struct Sensing {
    active: SensorSettings,
    staged: Option<SensorSettings>,
}

impl Sensing {
    pub(crate) const fn new(settings: SensorSettings) -> Self {
        Sensing {
            active: settings,
            staged: None,
        }
    }

    pub(crate) fn active(&self) -> SensorSettings {
        self.active
    }

    pub(crate) fn staged_value(&self, f: SensorField) -> u32 {
        self.staged.unwrap_or(self.active).get(f)
    }

    /// A write into the staged copy, `v` in the field's domain (checked before).
    pub(crate) fn write_staged(&mut self, f: SensorField, v: u32) {
        let mut s = self.staged.unwrap_or(self.active);
        s.set(f, v);
        self.staged = Some(s);
    }

    pub(crate) fn revert_staged(&mut self) {
        self.staged = None;
    }

    /// The commit: the staged copy in force.
    pub(crate) fn commit(&mut self) {
        if let Some(s) = self.staged.take() {
            self.active = s;
        }
    }

    /// Settings restored from a committed image at boot.
    pub(crate) fn restore(&mut self, settings: SensorSettings) {
        *self = Sensing::new(settings);
    }
}
