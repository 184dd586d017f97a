//! The no-panic proof (`cargo xtask nopanic`): an image with every public entry point a
//! firmware calls, fed from volatile reads so that nothing is known at compile time:
//! the f32 core (`EllipticScene` with the full and with narrowed tables, `LineScene`,
//! the inverses, the model choice `Auto` per sample, the risk-threshold setters,
//! `load_range`), the
//! fixed-point core (`FixedEllipticScene::estimate`, `details`, `FixedLineScene`, their
//! risk setters), the f64 reference (`reference::elliptic`, `line`, `estimate`,
//! `critical_angle`, traction, stick zones, pressure) and the scene (`Scene::new`,
//! `with_length`, the exact theta relation) and the condition monitor on both cores
//! (`Monitor` over `float::Auto` and over `fixed::FixedAuto`: the configuration's
//! validation, construction, `process` per sample with every optional channel, the
//! event queue, the statistics, `snapshot` and `restore`, `model_for_range`), the
//! sensors' conversions (load cell, probes, phi, rolling speed) with a calibration
//! decoded from a stored record, and the checkpoint codec (`storage::codec::decode`
//! and `encode` of `SensorCalibration`), and the Modbus server's request path
//! (`modbus::Server` over the f32 monitor: every byte of a stream as unknown as the
//! bus's through `receive`, the silence through `idle`, `response` and `sent`, the
//! node's own samples through `process`: framing, every function, the register map,
//! identification, the event window, acknowledgement, external samples). Its panic handler is panic-never's, which
//! refers to a symbol that does not exist: the image links only if the optimiser
//! (profile `nopanic`: release, fat LTO, overflow checks on) removed every path to a
//! panic, an integer overflow included. It also runs: in QEMU it exits with 0.
#![no_std]
#![no_main]

use panic_never as _;

use misalign::monitor::{Channel, Sample};
use misalign_harness::io;

/// What the scene and the cores are configured with besides the demo scene: a contact
/// length (m), the d/b risk threshold and
/// a point of the contact (m), as a configuration block would hold them.
static SETTINGS: [f64; 4] = [0.02, 0.8, 1e-4, 2e-5];
/// Whether the scene uses the exact theta relation (the reference only).
static EXACT_THETA: bool = false;

/// The monitor's samples: timestamps across the u32 wrap, a repeated and a
/// backwards one, a measured speed and axial force, a driver's fault, a stop.
static SAMPLES: [Sample; 6] = [
    Sample::new(u32::MAX - 500, 1000.0, 2e-4).with_speed(2.0),
    Sample::new(500, 1010.0, 2.1e-4).with_axial_force(30.0),
    Sample::new(500, 1010.0, 2.1e-4),
    Sample::new(1500, 990.0, -2e-4).with_speed(2.0),
    Sample {
        driver_fault: Some(Channel::Load),
        ..Sample::new(100, 1000.0, 2e-4)
    },
    Sample::new(2500, 10.0, 0.0).with_speed(0.0),
];

/// What a Modbus master sends: a read of the map's first 16 input registers, a
/// function-16 write of external samples, an identification request, coil writes and
/// garbage. Read through volatile reads, so each byte is as unknown as the bus's.
static MODBUS_STREAM: [u8; 64] = [
    0x01, 0x04, 0x00, 0x00, 0x00, 0x10, 0xF1, 0xC6, 0xFF, 0x00, 0x01, 0x2B, 0x0E, 0x02, 0x00, 0x00,
    0x00, 0x01, 0x10, 0x00, 0x05, 0x00, 0x06, 0x0C, 0x00, 0x00, 0x03, 0xE8, 0x44, 0x7A, 0x00, 0x00,
    0x38, 0xD1, 0xB7, 0x17, 0x00, 0x00, 0x01, 0x0F, 0x00, 0x00, 0x00, 0x06, 0x01, 0x3F, 0x00, 0x00,
    0x01, 0x03, 0x00, 0x00, 0x00, 0x02, 0x00, 0x00, 0x00, 0x01, 0x05, 0x00, 0x05, 0xFF, 0x00, 0x00,
];

/// A checkpoint record of the sensors' calibration as flash would hold it (its bytes are
/// as unknown to the optimiser as a damaged record's).
static CALIBRATION_RECORD: [u8; RECORD_LEN] = [0; RECORD_LEN];
const RECORD_LEN: usize = misalign::storage::codec::record_len(
    <misalign::storage::SensorCalibration as misalign::storage::Checkpoint>::SIZE,
);

/// Which paths run.
mod paths {
    use misalign::fixed::FixedAuto;
    use misalign::fixed::{FixedEllipticScene, FixedLineScene};
    use misalign::float::octave::{OctaveTable, Row, WIDE, narrow_rows};
    use misalign::float::{Auto, EllipticScene, LineScene, Tables};
    use misalign::float::{G_OF_THETA_ROWS, THETA_OF_G_ROWS};
    use misalign::monitor::{Config, Monitor, Sample, model_for_range};
    use misalign::{Error, Estimator, Scene, ThetaRelation, reference};
    use misalign_harness::io;

    // Narrowed tables (theta from 2^-20 to 2^-6), as in tests/narrow_tables.rs.
    static G_ROWS: [Row<WIDE>; 14] = narrow_rows(&G_OF_THETA_ROWS, 12);
    static THETA_ROWS: [Row<WIDE>; 10] = narrow_rows(&THETA_OF_G_ROWS, 13);
    const NARROW: Tables<'static> = Tables {
        g: OctaveTable::new(-20, &G_ROWS),
        theta_of_g: OctaveTable::new(-14, &THETA_ROWS),
    };

    pub fn fixed_core(scene: &Scene, load: u32, angle: i32, risk: f32) -> Result<(), Error> {
        let (lsb_p, lsb_a) = (io::LOAD_LSB, io::ANGLE_LSB);
        let elliptic = FixedEllipticScene::new(scene, lsb_p, lsb_a)?.with_risk_slip_ratio(risk)?;
        let line = FixedLineScene::new(scene, lsb_p, lsb_a)?.with_risk_slip_ratio(risk)?;
        io::emit(elliptic.input_range());
        io::emit(elliptic.estimate(load, angle));
        io::emit(elliptic.details(load, angle));
        io::emit(line.estimate(load, angle));
        Ok(())
    }

    pub fn f32_core(scene: &Scene, load: f32, phi: f32, risk: f32) -> Result<(), Error> {
        let elliptic = EllipticScene::new(scene)?.with_risk_slip_ratio(risk)?;
        let narrow = EllipticScene::with_tables(scene, NARROW)?;
        let line = LineScene::new(scene)?.with_risk_slip_ratio(risk)?;
        io::emit(elliptic.estimate(load, phi));
        io::emit(elliptic.details(load, phi));
        io::emit(narrow.estimate(load, phi));
        io::emit(line.load_range());
        io::emit(line.estimate(load, phi));
        // The inverses, with a force as unknown as the sample.
        let force = load * phi;
        io::emit(elliptic.friction_from_axial_force(load, phi, force));
        io::emit(elliptic.angle_from_axial_force(load, force));
        io::emit(line.friction_from_axial_force(load, phi, force));
        io::emit(line.angle_from_axial_force(load, force));
        Ok(())
    }

    /// Section 9's model choice per sample, in both cores, and the f32 inverses
    /// through it.
    pub fn model_choice(
        scene: &Scene,
        sample: (f32, f32),
        counts: (u32, i32),
        risk: f32,
    ) -> Result<(), Error> {
        let (load, phi) = sample;
        let (lsb_p, lsb_a) = (io::LOAD_LSB, io::ANGLE_LSB);
        let auto = Auto::new(scene)?.with_risk_slip_ratio(risk)?;
        io::emit(auto.estimate(load, phi));
        io::emit(auto.details(load, phi));
        io::emit(auto.friction_from_axial_force(load, phi, load * phi));
        io::emit(auto.angle_from_axial_force(load, load * phi));
        let fixed = FixedAuto::new(scene, lsb_p, lsb_a)?.with_risk_slip_ratio(risk)?;
        io::emit(fixed.estimate(counts.0, counts.1));
        io::emit(fixed.details(counts.0, counts.1));
        Ok(())
    }

    /// The condition monitor over `estimator`: validation and construction, every
    /// sample, the events, the statistics, the state taken out and put back.
    fn monitor<E: Estimator + Copy>(estimator: E, config: Config, samples: &[Sample]) {
        io::emit(config.validate());
        let Ok(mut m) = Monitor::new(estimator, config) else {
            return;
        };
        for s in samples {
            io::emit(m.process(io::read(s)));
        }
        io::emit(m.pop_event());
        io::emit((m.pending_events(), m.reading(), m.time_to_critical()));
        io::emit((
            m.statistics().total_energy(),
            m.statistics().faults().total(),
        ));
        let state = io::read(&m.snapshot());
        if let Ok(mut r) = Monitor::restore(estimator, config, &state) {
            for s in samples {
                io::emit(r.process(io::read(s)));
            }
            io::emit(r.pop_event());
        }
    }

    /// The monitor on both cores, with the model chosen for the operating range.
    pub fn monitors(scene: &Scene, samples: &[Sample], load_max: f64) -> Result<(), Error> {
        let choice = model_for_range(scene, load_max, 1e-5)?;
        let config = io::read(&Config::default());
        let f32_core = Auto::with_choice(scene, choice)?;
        monitor(f32_core, config, samples);
        let (lsb_p, lsb_a) = (io::LOAD_LSB, io::ANGLE_LSB);
        let fixed = FixedAuto::with_choice(scene, lsb_p, lsb_a, choice)?;
        monitor(fixed, config, samples);
        Ok(())
    }

    /// The sensors' conversions with a calibration decoded from a stored record, and
    /// the record encoded again: what a node does at start-up and per reading.
    pub fn sensors_and_storage(record: &[u8], raw: i32, pulses: u32) {
        use misalign::sensors::rolling_speed;
        use misalign::storage::{SensorCalibration, codec};
        io::emit(rolling_speed(pulses, 64, 0.05, 0.1));
        let Ok(decoded) = codec::decode::<SensorCalibration>(record) else {
            return;
        };
        let cal = decoded.value;
        io::emit((cal.load.validate(), cal.misalignment.validate()));
        let newtons = cal.load.newtons(raw);
        io::emit((newtons, cal.load.counts_for(newtons)));
        let m = &cal.misalignment;
        let (d1, d2) = (m.probe1.metres(raw), m.probe2.metres(raw / 2));
        io::emit((m.phi(d1, d2), m.probe1.counts_for(d1)));
        if let Some(speed) = cal.speed {
            io::emit((
                speed.validate(),
                rolling_speed(pulses, speed.pulses_per_rev, speed.radius_m, 0.1),
            ));
        }
        let mut out = [0u8; super::RECORD_LEN];
        io::emit(codec::encode(
            &cal,
            decoded.sequence.wrapping_add(1),
            &mut out,
        ));
        io::emit(out);
    }

    /// The Modbus server over the f32 monitor: every byte of `stream` received (the
    /// silence after each eighth), the answers taken, the node's samples processed.
    pub fn modbus(scene: &Scene, samples: &[Sample], stream: &[u8]) -> Result<(), Error> {
        use misalign::modbus::{Server, ServerConfig};
        let core = Auto::with_choice(scene, model_for_range(scene, 5e3, 1e-5)?)?;
        let Ok(monitor) = Monitor::new(core, io::read(&Config::default())) else {
            return Ok(());
        };
        let config = ServerConfig {
            external_samples: io::read(&true),
            ..ServerConfig::default()
        };
        let Ok(mut server) = Server::new(monitor, config) else {
            return Ok(());
        };
        for s in samples {
            io::emit(server.process(io::read(s)));
        }
        for (i, byte) in stream.iter().enumerate() {
            server.receive(io::read(byte));
            if i % 8 == 7 {
                server.idle();
            }
            if let Some(answer) = server.response() {
                io::emit(answer);
                server.sent();
            }
        }
        io::emit(server.counters());
        Ok(())
    }

    /// The f64 reference, with the scene's length and theta relation as configured.
    pub fn reference(
        scene: &Scene,
        length: f64,
        exact: bool,
        sample: (f64, f64),
        point: (f64, f64),
    ) -> Result<(), Error> {
        let (load, phi) = sample;
        let (x, y) = point;
        let relation = if exact {
            ThetaRelation::Exact
        } else {
            ThetaRelation::SmallAngle
        };
        let scene = scene.with_length(length)?.with_theta_relation(relation);
        let e = reference::elliptic(&scene, load, phi)?;
        io::emit((e.pressure(x, y), e.traction(&scene, x, y), e.stick_zone(x)));
        io::emit((e.rolling_resistance(), e.dissipated_power(phi)));
        let l = reference::line(&scene, load, phi)?;
        io::emit((l.traction(&scene, y), l.stick_zone()));
        io::emit(reference::estimate(&scene, load, phi)?.axial_force(&scene));
        io::emit(reference::critical_angle(&scene, load));
        Ok(())
    }
}

#[cortex_m_rt::entry]
fn main() -> ! {
    let (r1, r2, g, nu, mu) = io::scene();
    let (load, phi) = io::sample();
    let (load_counts, angle_counts) = io::counts();
    let [length, risk, x, y] = io::read(&SETTINGS);
    let exact = io::read(&EXACT_THETA);
    let result = misalign::Scene::new(r1, r2, g, nu, mu).and_then(|scene| {
        paths::f32_core(&scene, load, phi, risk as f32)?;
        paths::fixed_core(&scene, load_counts, angle_counts, risk as f32)?;
        let with_length = scene.with_length(length)?;
        paths::model_choice(
            &with_length,
            (load, phi),
            (load_counts, angle_counts),
            risk as f32,
        )?;
        paths::monitors(&with_length, &SAMPLES, 5e3)?;
        paths::modbus(&with_length, &SAMPLES, &io::read(&MODBUS_STREAM))?;
        paths::sensors_and_storage(&io::read(&CALIBRATION_RECORD), angle_counts, load_counts);
        paths::reference(&scene, length, exact, (load as f64, phi as f64), (x, y))
    });
    semihosting::process::exit(if result.is_ok() { 0 } else { 1 })
}
