//! The sensors feeding the condition monitor: a fault the sensors'
//! own detection finds becomes the monitor's `SensorFault` state and an event naming
//! the sensor and the reason, counted, never a slip alarm. The node is
//! simulated: an HX711 load cell and two probes on an ADC (`misalign::sensors::sim`)
//! replaying the codes of a steady run, then garbage.

use misalign::monitor::{
    Config, EventKind, FaultCause, Monitor, RiskState, Sample, model_for_range,
};
use misalign::sensors::sim::{SimAdc, SimClock, SimDelay, SimDout, SimHx711, SimSck, TraceEncoder};
use misalign::sensors::{
    FaultKind, Hx711, Hx711Channel, LoadCalibration, LoadCell, Misalignment, Rails, RawLimits,
    SensorFault, SensorId, SensorSample, Timeout,
};
use misalign::{Scene, float::Auto};

/// 100 ms conversions (10 samples/s).
const PERIOD_NS: u64 = 100_000_000;
/// The steady run: 2 kN, 0.1 mrad (d/b well below the warning on the demo scene).
const LOAD_N: f32 = 2000.0;
const PHI_RAD: f32 = 1e-4;

#[path = "common/probes.rs"]
mod probes;
use probes::probe_calibration;

type Cell<'c> = LoadCell<Hx711<SimDout<'c, 'c>, SimSck<'c, 'c>, SimDelay<'c>>>;

/// The node: its sensors, the encoder of the steady run and the monitor, one sample a
/// second.
struct Node<'c> {
    chip: &'c SimHx711<'c>,
    cell: Cell<'c>,
    probes: Misalignment<SimAdc<'c, 2>>,
    encoder: TraceEncoder<Hx711Channel>,
    monitor: Monitor<Auto>,
    time_ms: u32,
    /// The sensor faults the node's sensors reported, per sensor (what the monitor
    /// must have counted).
    reported: [u32; 4],
}

impl<'c> Node<'c> {
    fn new(chip: &'c SimHx711<'c>, clock: &'c SimClock) -> Self {
        let adc = Hx711::new(chip.dout(), chip.sck(), clock.delay(), Timeout::HX711_10SPS).unwrap();
        let nominal = LoadCalibration::from_rated_output(Hx711Channel::A128, 2.0, 5000.0).unwrap();
        let cell = LoadCell::new(
            adc,
            nominal,
            RawLimits::new(Rails::signed_bits(24).unwrap()),
        )
        .unwrap();
        let cal = probe_calibration(0.0);
        let adc = SimAdc::new(Rails::signed_bits(16).unwrap(), [&[], &[]]);
        let limits = RawLimits::new(Rails::signed_bits(16).unwrap());
        let probes = Misalignment::new(adc, (0, 1), cal, limits).unwrap();
        let encoder = TraceEncoder::new(cell.calibration(), cal, 1e-3, 3);
        let scene = Scene::new(0.05, 0.05, 79.3e9, 0.3, 0.3).unwrap();
        let core = Auto::with_choice(&scene, model_for_range(&scene, 5e3, 1e-5).unwrap()).unwrap();
        Node {
            chip,
            cell,
            probes,
            encoder,
            monitor: Monitor::new(core, Config::default()).unwrap(),
            time_ms: 0,
            reported: [0; 4],
        }
    }

    /// One sample: the steady run's codes fed to every sensor but `garbage`, which
    /// reads whatever its trace holds; read, handed to the monitor. Returns the
    /// sensors' sample and the state after it.
    fn step(&mut self, garbage: Option<SensorId>) -> (SensorSample, RiskState) {
        let codes = self.encoder.codes(LOAD_N, PHI_RAD);
        if garbage != Some(SensorId::Load) {
            self.chip.feed(codes.load);
        }
        if garbage != Some(SensorId::Probe1) {
            self.probes.adc_mut().feed(0, codes.probe1);
        }
        if garbage != Some(SensorId::Probe2) {
            self.probes.adc_mut().feed(1, codes.probe2);
        }
        let load = self.cell.read();
        let phi = self.probes.read().map(|r| r.phi_rad);
        let sample = SensorSample::new(load, phi, None);
        if let Some(f) = sample.fault {
            self.reported[f.sensor.index()] += 1;
        }
        self.time_ms += 1000;
        let state = self
            .monitor
            .process(Sample::from_sensors(self.time_ms, &sample));
        assert!(
            !matches!(state, RiskState::Microslip | RiskState::GrossSlip),
            "a slip state from the sensors' garbage at {} ms",
            self.time_ms
        );
        (sample, state)
    }

    /// Every pending event; none may be a slip state.
    fn events(&mut self) -> Vec<EventKind> {
        let mut out = Vec::new();
        while let Some(e) = self.monitor.pop_event() {
            if let EventKind::StateChange { to, .. } = e.kind {
                assert!(!matches!(to, RiskState::Microslip | RiskState::GrossSlip));
            }
            out.push(e.kind);
        }
        out
    }

    /// Steady samples until the monitor has been `Normal` again for a while.
    fn recover(&mut self) {
        for _ in 0..60 {
            self.step(None);
        }
        assert_eq!(self.monitor.state(), RiskState::Normal);
        self.events();
    }

    /// Garbage until the monitor reports a sensor fault (at most `limit` samples);
    /// checks that the event names the sensor and the reason the sensors gave.
    fn garbage_until_fault(&mut self, limit: usize, sensor: SensorId) -> SensorFault {
        let mut first = None;
        for _ in 0..limit {
            let (sample, state) = self.step(Some(sensor));
            first = first.or(sample.fault);
            if state == RiskState::SensorFault {
                let events = self.events();
                let Some(EventKind::StateChange {
                    to: RiskState::SensorFault,
                    fault: Some(FaultCause::Sensor(named)),
                    ..
                }) = events.last().copied()
                else {
                    panic!("no sensor-fault event naming the sensor: {events:?}");
                };
                // The fault default delay is 0: the event names the fault of the
                // sample that raised it, the first the sensors reported.
                assert_eq!(Some(named), first);
                assert_eq!(named.sensor, sensor);
                assert!(!FaultCause::Sensor(named).to_string().is_empty());
                return named;
            }
        }
        panic!("{sensor:?}: no sensor fault within {limit} samples of garbage");
    }
}

#[test]
fn garbage_from_every_sensor_is_a_counted_fault_naming_it_never_slip() {
    let clock = SimClock::new();
    let chip = SimHx711::new(&clock, PERIOD_NS, &[]);
    let mut node = Node::new(&chip, &clock);
    node.recover();
    assert_eq!(node.monitor.statistics().faults().total(), 0);

    // The load cell. All zeros (DOUT shorted to ground): stuck once the detector has
    // seen enough identical codes.
    chip.force_dout(Some(false));
    let f = node.garbage_until_fault(20, SensorId::Load);
    assert_eq!(f.kind, FaultKind::Stuck);
    chip.force_dout(None);
    node.recover();
    // All ones (0xFFFFFF, -1 in two's complement): stuck too.
    let ones = [-1];
    chip.set_trace(&ones);
    let f = node.garbage_until_fault(20, SensorId::Load);
    assert_eq!(f.kind, FaultKind::Stuck);
    node.recover();
    // Alternating rails: saturated at once.
    let rails = [(1 << 23) - 1, -(1 << 23)];
    chip.set_trace(&rails);
    let f = node.garbage_until_fault(1, SensorId::Load);
    assert_eq!(f.kind, FaultKind::Saturated);
    node.recover();
    // A value that jumps by most of the full scale and back (from the 2 kN reading,
    // 1.7 M counts, to -7 M is more than the half scale a signal can move).
    let jumps = [-7_000_000, 7_000_000];
    chip.set_trace(&jumps);
    let f = node.garbage_until_fault(1, SensorId::Load);
    assert_eq!(f.kind, FaultKind::Jump);
    node.recover();
    // Unplugged (DOUT held high): disconnected after the bounded wait.
    chip.force_dout(Some(true));
    let f = node.garbage_until_fault(1, SensorId::Load);
    assert_eq!(f.kind, FaultKind::Disconnected);
    chip.force_dout(None);
    node.recover();

    // Probe 1 reads all ones (-1 on a 16-bit ADC): below its range.
    let ones = [-1];
    node.probes.adc_mut().set_trace(0, &ones);
    let f = node.garbage_until_fault(1, SensorId::Probe1);
    assert_eq!(f.kind, FaultKind::OutOfRange);
    node.recover();
    // Probe 2 alternates between the rails.
    let rails = [i32::from(i16::MAX), i32::from(i16::MIN)];
    node.probes.adc_mut().set_trace(1, &rails);
    let f = node.garbage_until_fault(1, SensorId::Probe2);
    assert_eq!(f.kind, FaultKind::Saturated);
    node.recover();
    // Probe 2 reads all zeros: stuck (0 counts is 0.05 mm, inside its range).
    let zeros = [0];
    node.probes.adc_mut().set_trace(1, &zeros);
    let f = node.garbage_until_fault(20, SensorId::Probe2);
    assert_eq!(f.kind, FaultKind::Stuck);
    node.recover();

    // Every fault the sensors reported is counted, under its sensor, and nothing else.
    let counts = node.monitor.statistics().faults();
    assert_eq!(counts.sensor, node.reported.iter().sum::<u32>());
    assert_eq!(
        counts.total(),
        node.reported.iter().map(|&c| u64::from(c)).sum()
    );
    assert!(node.reported[SensorId::Load.index()] >= 5);
    assert!(node.reported[SensorId::Probe1.index()] >= 1);
    assert!(node.reported[SensorId::Probe2.index()] >= 2);
    let stats = node.monitor.statistics();
    assert_eq!(stats.time_in_state_ms(RiskState::Microslip), 0);
    assert_eq!(stats.time_in_state_ms(RiskState::GrossSlip), 0);
}

#[test]
fn a_sensor_fault_wins_over_values_that_would_be_gross_slip() {
    let scene = Scene::new(0.05, 0.05, 79.3e9, 0.3, 0.3).unwrap();
    let core = Auto::with_choice(&scene, model_for_range(&scene, 5e3, 1e-5).unwrap()).unwrap();
    let config = Config {
        inhibit_ms: 0,
        ..Config::default()
    };
    let mut monitor = Monitor::new(core, config).unwrap();
    let fault = SensorFault {
        sensor: SensorId::Probe1,
        kind: FaultKind::Jump,
    };
    // 10 mrad at 2 kN is far beyond the critical angle: gross slip, were it measured.
    for i in 0..20u32 {
        let s = Sample::new(i * 1000, 2000.0 + i as f32, 1e-2).with_sensor_fault(fault);
        assert_eq!(monitor.process(s), RiskState::SensorFault);
    }
    let e = monitor.pop_event().unwrap();
    assert_eq!(
        e.kind,
        EventKind::StateChange {
            from: RiskState::Stopped,
            to: RiskState::SensorFault,
            fault: Some(FaultCause::Sensor(fault)),
        }
    );
    assert_eq!(monitor.pop_event(), None);
    assert_eq!(monitor.statistics().faults().sensor, 20);
    assert_eq!(monitor.statistics().max_slip_ratio(), 0.0);
    assert_eq!(
        FaultCause::Sensor(fault).to_string(),
        "probe1: jump: raw value moved by more than a signal can"
    );
}

#[test]
fn a_sensor_sample_maps_field_by_field() {
    let good = SensorSample::new(Ok(1500.0), Ok(2e-4), Some(Ok(1.5)));
    let s = Sample::from_sensors(42, &good);
    assert_eq!(
        s,
        Sample::new(42, 1500.0, 2e-4).with_speed(1.5),
        "a good sample carries no fault"
    );
    let speed = SensorFault {
        sensor: SensorId::Speed,
        kind: FaultKind::Disconnected,
    };
    let bad = SensorSample::new(Ok(1500.0), Ok(2e-4), Some(Err(speed)));
    let s = Sample::from_sensors(43, &bad);
    assert_eq!(s.sensor_fault, Some(speed));
    assert_eq!(s.speed, Some(0.0));
}
