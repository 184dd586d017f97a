//! The node's sensors, simulated (feature `sim-sensors`): QEMU has no load cell, so the
//! scenario's samples are turned into the raw codes a calibrated load cell on an HX711,
//! two displacement probes on a 16-bit ADC and a tachometer would give
//! (`misalign::sensors::sim`), and the node reads them back through the same drivers
//! and embedded-hal traits as on a real board: `LoadCell<Hx711<..>>` over the simulated
//! DOUT and PD_SCK pins and a delay, `Misalignment<SimAdc>`, `Tachometer`. What the
//! monitor then gets is the sensors' reading, quantised, dithered and fault-checked,
//! not the scenario's numbers.
//!
//! This file is shared, as source, with `cargo xtask firmware` (`lab/xtask/src/node.rs`
//! includes it), so that the host replay the node is compared with goes through
//! exactly these sensors. It uses nothing of the target: `no_std`, no heap, no defmt.
//!
//! Two things the scenario does are the simulated world's to model here:
//! - a stuck sensor: where the scenario repeats a value bit for bit (its stuck angle
//!   sensor), the simulated chip repeats its codes, as a frozen ADC does; the probes'
//!   fault detector then reports `Stuck` after 8 identical codes (the monitor's own
//!   stuck check, on values, waits 2 minutes);
//! - the speed: the roller's surface turns pulses of a 1024-line encoder on a roller of
//!   50 mm radius, counted by a free-running u32 counter that the tachometer reads each
//!   sample.
//!
//! A sensor fault becomes the sample's sensor fault (`Sample::from_sensors`): the
//! monitor reports a sensor fault naming the sensor and the reason, never slip.

use misalign::monitor::Sample;
use misalign::sensors::sim::{
    SampleCodes, SimAdc, SimClock, SimDelay, SimDout, SimHx711, SimSck, TraceEncoder,
};
use misalign::sensors::{
    CalibrationError, Hx711, Hx711Channel, LoadCalibration, LoadCell, Misalignment,
    MisalignmentCalibration, ProbeCalibration, ProbeSpec, Rails, RawLimits, SensorSample,
    SpeedCalibration, Tachometer, Timeout,
};

/// The HX711's conversion period: 10 samples/s.
pub const HX711_PERIOD_NS: u64 = 100_000_000;
/// Each probe's linear range (0 to 2 mm) and linearity.
const PROBE: ProbeSpec = ProbeSpec {
    min_m: 0.0,
    max_m: 2e-3,
    linearity_m: 4e-6,
};
/// The probes' axial span (m).
const SPAN_M: f32 = 0.4;
/// Probe 2's displacement (m): probe 1 reads it plus `SPAN_M * tan(phi)`.
const D2_M: f32 = 0.5e-3;
/// The dither of every code (counts): enough that a steady probe does not repeat one
/// code 8 times by chance (about 2e-7 a sample at 9 values).
const DITHER: u32 = 4;
/// A 1024-line encoder on a roller of 50 mm radius.
const SPEED: SpeedCalibration = SpeedCalibration {
    pulses_per_rev: 1024,
    radius_m: 0.05,
    max_speed_m_s: 10.0,
};

/// The load cell on the simulated HX711's pins.
pub type Cell<'c> = LoadCell<Hx711<SimDout<'c, 'c>, SimSck<'c, 'c>, SimDelay<'c>>>;

/// The node's simulated sensors and what the simulated world remembers.
pub struct Sensors<'c> {
    clock: &'c SimClock,
    chip: &'c SimHx711<'c>,
    cell: Cell<'c>,
    probes: Misalignment<SimAdc<'c, 2>>,
    tachometer: Tachometer,
    encoder: TraceEncoder<Hx711Channel>,
    /// The previous sample's time (ms), values and codes.
    last: Option<(u32, f32, f32, SampleCodes)>,
    /// The encoder's pulse counter (wraps) and the fraction of a pulse turned so far.
    pulses: u32,
    pulse_fraction: f32,
    /// The tachometer's time base (µs, wraps).
    now_us: u32,
}

impl<'c> Sensors<'c> {
    /// The sensors on `chip` (an HX711 made on `clock` with [`HX711_PERIOD_NS`] and an
    /// empty trace), calibrated: the load cell from its data sheet (2 mV/V, 20 kN: the
    /// scenario's load spikes stay inside its range), the probes from two points each.
    pub fn new(clock: &'c SimClock, chip: &'c SimHx711<'c>) -> Result<Self, CalibrationError> {
        let hx711 = Hx711::new(chip.dout(), chip.sck(), clock.delay(), Timeout::HX711_10SPS)
            .map_err(|_| CalibrationError::Value)?;
        let load = LoadCalibration::from_rated_output(Hx711Channel::A128, 2.0, 20e3)?;
        let cell = LoadCell::new(hx711, load, RawLimits::new(rails(24)))?;
        let probes = MisalignmentCalibration {
            probe1: ProbeCalibration::two_point((800.0, 0.0), (20_800.0, 2e-3), PROBE)?,
            probe2: ProbeCalibration::two_point((-400.0, 0.0), (15_600.0, 2e-3), PROBE)?,
            span_m: SPAN_M,
            zero_offset_m: 0.0,
        };
        let adc = SimAdc::new(rails(16), [&[], &[]]);
        let probes_driver = Misalignment::new(adc, (0, 1), probes, RawLimits::new(rails(16)))?;
        Ok(Sensors {
            clock,
            chip,
            cell,
            probes: probes_driver,
            tachometer: Tachometer::new(SPEED)?,
            encoder: TraceEncoder::new(load, probes, D2_M, DITHER),
            last: None,
            pulses: 0,
            pulse_fraction: 0.0,
            now_us: 0,
        })
    }

    /// The scenario's sample `world` as the node's sensors read it: the codes of its
    /// load, angle and speed put into the simulated chips, the simulated time moved on
    /// to it, and the chips read through their drivers.
    pub fn read(&mut self, world: Sample) -> Sample {
        // The first sample comes a second after power-up.
        let dt_ms = self
            .last
            .map_or(1000, |(t, ..)| world.time_ms.wrapping_sub(t));
        self.clock.advance(u64::from(dt_ms) * 1_000_000);
        self.now_us = self.now_us.wrapping_add(dt_ms.wrapping_mul(1000));

        let mut codes = self.encoder.codes(world.load, world.phi);
        if let Some((_, load, phi, last)) = self.last {
            // A sensor that repeats its value bit for bit is frozen: so are its codes.
            if world.load.to_bits() == load.to_bits() {
                codes.load = last.load;
            }
            if world.phi.to_bits() == phi.to_bits() {
                (codes.probe1, codes.probe2) = (last.probe1, last.probe2);
            }
        }
        self.last = Some((world.time_ms, world.load, world.phi, codes));
        self.chip.feed(codes.load);
        self.probes.adc_mut().feed(0, codes.probe1);
        self.probes.adc_mut().feed(1, codes.probe2);

        let speed = world.speed.map(|v| {
            let turned = v * (dt_ms as f32 * 1e-3) * SPEED.pulses_per_rev as f32
                / (core::f32::consts::TAU * SPEED.radius_m)
                + self.pulse_fraction;
            let whole = turned as u32;
            self.pulse_fraction = turned - whole as f32;
            self.pulses = self.pulses.wrapping_add(whole);
            self.tachometer.update(self.pulses, self.now_us)
        });
        let reading = SensorSample::new(
            self.cell.read(),
            self.probes.read().map(|r| r.phi_rad),
            speed.and_then(Result::transpose),
        );
        to_monitor(world.time_ms, &reading)
    }
}

/// The monitor's sample from the sensors': a fault names its sensor (its value, 0,
/// is never estimated).
pub fn to_monitor(time_ms: u32, reading: &SensorSample) -> Sample {
    Sample::from_sensors(time_ms, reading)
}

/// A two's-complement ADC's rails (`bits` in 2..=32).
fn rails(bits: u32) -> Rails {
    Rails::signed_bits(bits).unwrap_or(Rails { min: 0, max: 0 })
}
