//! The sensors on the host: conversions, calibration, timeouts and every fault, with
//! embedded-hal-mock where the pin or bus traffic is short enough to list, and the
//! simulated chips of `misalign::sensors::sim` where it is not.

use embedded_hal_mock::eh1::MockError;
use embedded_hal_mock::eh1::delay::{CheckedDelay, NoopDelay, Transaction as DelayTx};
use embedded_hal_mock::eh1::digital::{Mock as PinMock, State, Transaction as PinTx};
use misalign::sensors::sim::{SimAdc, SimClock, SimHx711};
use misalign::sensors::{
    Adc, AdcError, CalibrationError, FaultKind, Hx711, Hx711Channel, LoadCalibration, LoadCell,
    Misalignment, ProbeCalibration, Rails, RawLimits, STANDARD_GRAVITY, SensorFault, SensorId,
    SensorSample, SpeedCalibration, Tachometer, Timeout, weight_newtons,
};
use proptest::prelude::*;

const HX711_RAILS: Rails = Rails {
    min: -(1 << 23),
    max: (1 << 23) - 1,
};

/// DOUT and PD_SCK traffic of one HX711 read of the 24-bit `word`, with `extra` gain
/// pulses.
fn hx711_read(word: u32, extra: u8, dout: &mut Vec<PinTx>, sck: &mut Vec<PinTx>) {
    dout.push(PinTx::get(State::Low));
    for bit in (0..24).rev() {
        sck.push(PinTx::set(State::High));
        let level = if word >> bit & 1 == 1 {
            State::High
        } else {
            State::Low
        };
        dout.push(PinTx::get(level));
        sck.push(PinTx::set(State::Low));
    }
    for _ in 0..extra {
        sck.push(PinTx::set(State::High));
        dout.push(PinTx::get(State::High));
        sck.push(PinTx::set(State::Low));
    }
}

#[test]
fn hx711_reads_msb_first_and_sign_extends() {
    let (mut dout, mut sck) = (Vec::new(), vec![PinTx::set(State::Low)]);
    let words = [0x00_0123, 0xFF_FFFF, 0x80_0000, 0x7F_FFFF, 0x12_3456];
    for w in words {
        hx711_read(w, 1, &mut dout, &mut sck);
    }
    let (dout_pin, sck_pin) = (PinMock::new(&dout), PinMock::new(&sck));
    let mut adc = Hx711::new(dout_pin, sck_pin, NoopDelay::new(), Timeout::HX711_10SPS).unwrap();
    let got: Vec<i32> = (0..words.len())
        .map(|_| adc.read(Hx711Channel::A128).unwrap())
        .collect();
    assert_eq!(got, [0x123, -1, -(1 << 23), (1 << 23) - 1, 0x12_3456]);
    let (mut dout_pin, mut sck_pin, _) = adc.release();
    dout_pin.done();
    sck_pin.done();
}

#[test]
fn hx711_channel_change_discards_the_conversion_made_with_the_old_gain() {
    // Channel B: the first conversion still has gain 128 and is discarded; both are
    // followed by 26 pulses, so the second is channel B's and is returned.
    let (mut dout, mut sck) = (Vec::new(), vec![PinTx::set(State::Low)]);
    hx711_read(0x00_1000, 2, &mut dout, &mut sck);
    hx711_read(0x00_0042, 2, &mut dout, &mut sck);
    // 1 us before the first edge, 1 us high and 1 us low for each of 26 pulses.
    let bits = || std::iter::repeat_n(DelayTx::delay_us(1), 1 + 2 * 26);
    let delays = bits()
        .chain([DelayTx::delay_us(700)])
        .chain(bits())
        .collect::<Vec<_>>();
    let timeout = Timeout {
        polls: 3,
        interval_us: 700,
    };
    let mut delay = CheckedDelay::new(&delays);
    let mut adc = Hx711::new(PinMock::new(&dout), PinMock::new(&sck), &mut delay, timeout).unwrap();
    assert_eq!(adc.read(Hx711Channel::B32), Ok(0x42));
    let (mut d, mut s, _) = adc.release();
    d.done();
    s.done();
    delay.done();
}

#[test]
fn hx711_never_ready_is_a_timeout_after_the_bounded_wait() {
    let timeout = Timeout {
        polls: 4,
        interval_us: 250,
    };
    let dout = vec![PinTx::get(State::High); 4];
    let mut delay = CheckedDelay::new(&vec![DelayTx::delay_us(250); 4]);
    let sck = [PinTx::set(State::Low)];
    let adc = Hx711::new(PinMock::new(&dout), PinMock::new(&sck), &mut delay, timeout).unwrap();
    let cal = LoadCalibration::two_point(Hx711Channel::A128, 0.0, 1e4, 100.0, 1e3).unwrap();
    let mut cell = LoadCell::new(adc, cal, RawLimits::new(HX711_RAILS)).unwrap();
    assert_eq!(
        cell.read(),
        Err(SensorFault {
            sensor: SensorId::Load,
            kind: FaultKind::Disconnected
        })
    );
    assert_eq!(cell.detector().counts().disconnected, 1);
    let (mut d, mut s, _) = cell.release().release();
    d.done();
    s.done();
    delay.done();
}

#[test]
fn hx711_pin_errors_are_bus_faults() {
    let io = MockError::Io(std::io::ErrorKind::Other);
    let dout = [PinTx::get(State::Low).with_error(io.clone())];
    let sck = [PinTx::set(State::Low)];
    let adc = Hx711::new(
        PinMock::new(&dout),
        PinMock::new(&sck),
        NoopDelay::new(),
        Timeout::HX711_10SPS,
    )
    .unwrap();
    let cal = LoadCalibration::two_point(Hx711Channel::A128, 0.0, 1e4, 100.0, 1e3).unwrap();
    let mut cell = LoadCell::new(adc, cal, RawLimits::new(HX711_RAILS)).unwrap();
    assert_eq!(cell.read().unwrap_err().kind, FaultKind::Bus);
    let (mut d, mut s, _) = cell.release().release();
    d.done();
    s.done();
    // A failing PD_SCK on construction is an error, not a panic.
    let sck = [PinTx::set(State::Low).with_error(io)];
    let mut sck_pin = PinMock::new(&sck);
    let mut dout_pin = PinMock::new(&[]);
    assert!(
        Hx711::new(
            dout_pin.clone(),
            sck_pin.clone(),
            NoopDelay::new(),
            Timeout::HX711_10SPS
        )
        .is_err()
    );
    dout_pin.done();
    sck_pin.done();
}

#[test]
fn hx711_pin_error_mid_word_power_cycles_the_chip_before_the_next_read() {
    let io = MockError::Io(std::io::ErrorKind::Other);
    // Ready, first clock pulse, DOUT fails: a bus error, PD_SCK brought low again.
    let mut dout = vec![
        PinTx::get(State::Low),
        PinTx::get(State::Low).with_error(io),
    ];
    let mut sck = vec![
        PinTx::set(State::Low),
        PinTx::set(State::High),
        PinTx::set(State::Low),
    ];
    // The next read powers the chip down and up, then reads a whole word.
    sck.extend([PinTx::set(State::High), PinTx::set(State::Low)]);
    hx711_read(0x00_0321, 1, &mut dout, &mut sck);
    let mut adc = Hx711::new(
        PinMock::new(&dout),
        PinMock::new(&sck),
        NoopDelay::new(),
        Timeout::HX711_10SPS,
    )
    .unwrap();
    assert!(matches!(
        adc.read(Hx711Channel::A128),
        Err(AdcError::Bus(_))
    ));
    assert_eq!(adc.read(Hx711Channel::A128), Ok(0x321));
    let (mut d, mut s, _) = adc.release();
    d.done();
    s.done();
}

/// 100 ms conversions (10 samples/s).
const PERIOD_NS: u64 = 100_000_000;

/// A noisy trace around `centre` (+-3 counts, never 8 equal in a row).
fn noisy(centre: i32) -> [i32; 7] {
    [0, 2, -1, 3, -3, 1, -2].map(|n| centre + n)
}

fn sim_cell<'c>(
    chip: &'c SimHx711<'c>,
    clock: &'c SimClock,
) -> LoadCell<
    Hx711<
        misalign::sensors::sim::SimDout<'c, 'c>,
        misalign::sensors::sim::SimSck<'c, 'c>,
        misalign::sensors::sim::SimDelay<'c>,
    >,
> {
    let adc = Hx711::new(chip.dout(), chip.sck(), clock.delay(), Timeout::HX711_10SPS).unwrap();
    // From the data sheet of a 2 mV/V, 5 kN cell until the technician calibrates it.
    let nominal = LoadCalibration::from_rated_output(Hx711Channel::A128, 2.0, 5000.0).unwrap();
    LoadCell::new(adc, nominal, RawLimits::new(adc_rails())).unwrap()
}

fn adc_rails() -> Rails {
    Rails::signed_bits(24).unwrap()
}

#[test]
fn tare_and_two_point_calibration_with_a_known_weight() {
    let clock = SimClock::new();
    let unloaded = noisy(-12_000);
    // A 50 kg test mass gives 440_000 counts more than unloaded (the cell's true scale
    // is 50 * g / 440000 N per count).
    let loaded = noisy(-12_000 + 440_000);
    let chip = SimHx711::new(&clock, PERIOD_NS, &unloaded);
    let mut cell = sim_cell(&chip, &clock);

    let zero = cell.mean_raw(7).unwrap();
    assert!((zero - -12_000.0).abs() < 0.01, "{zero}");
    chip.set_trace(&loaded);
    let weight = weight_newtons(50.0, STANDARD_GRAVITY).unwrap();
    let cal = cell.calibrate(zero, weight, 5000.0, 7).unwrap();
    let scale = weight / 440_000.0;
    assert!((cal.newtons_per_count / scale - 1.0).abs() < 1e-5);
    assert_eq!(cal.channel, Hx711Channel::A128);

    // A 1 kN load, within a count's worth of force.
    let at_1kn = cal.counts_for(1000.0);
    let trace = noisy(at_1kn);
    chip.set_trace(&trace);
    for _ in 0..20 {
        let p = cell.read().unwrap();
        assert!((p - 1000.0).abs() <= 4.0 * scale, "{p}");
    }
    // The zero drifts by 500 counts; a tare takes it out and keeps the scale.
    let drifted = noisy(-11_500);
    chip.set_trace(&drifted);
    let tared = cell.tare(7).unwrap();
    assert!((tared.zero_counts - -11_500.0).abs() < 0.01);
    assert_eq!(tared.newtons_per_count, cal.newtons_per_count);
    assert!(cell.read().unwrap().abs() <= 3.0 * scale);
    assert_eq!(cell.detector().counts().total(), 0);
    // Each read waited for one conversion of 100 ms, no more.
    assert_eq!(chip.conversions(), 7 + 7 + 20 + 7 + 1);
}

#[test]
fn a_degenerate_calibration_keeps_the_old_one() {
    let clock = SimClock::new();
    let trace = noisy(1000);
    let chip = SimHx711::new(&clock, PERIOD_NS, &trace);
    let mut cell = sim_cell(&chip, &clock);
    let before = cell.calibration();
    let zero = cell.mean_raw(7).unwrap();
    // The "known weight" was never put on: the same mean, no scale.
    assert_eq!(
        cell.calibrate(zero, 100.0, 5000.0, 7),
        Err(CalibrationError::Degenerate)
    );
    assert_eq!(cell.calibration(), before);
    assert_eq!(cell.mean_raw(0), Err(CalibrationError::NoReadings));
    let bad = LoadCalibration {
        newtons_per_count: f32::NAN,
        ..before
    };
    assert_eq!(cell.set_calibration(bad), Err(CalibrationError::Scale));
}

#[test]
fn sim_hx711_switches_channel_and_gain() {
    let clock = SimClock::new();
    let trace = noisy(77);
    let chip = SimHx711::new(&clock, PERIOD_NS, &trace);
    let mut adc = Hx711::new(chip.dout(), chip.sck(), clock.delay(), Timeout::HX711_10SPS).unwrap();
    assert_eq!(adc.read(Hx711Channel::A128), Ok(77));
    assert_eq!(chip.last_gain(), Some(Hx711Channel::A128));
    // Two conversions for the first read on channel B: one discarded.
    let before = chip.conversions();
    assert_eq!(adc.read(Hx711Channel::B32), Ok(77 - 1));
    assert_eq!(chip.conversions(), before + 2);
    assert_eq!(chip.last_gain(), Some(Hx711Channel::B32));
    assert_eq!(
        adc.read(Hx711Channel::A64).map(|_| chip.last_gain()),
        Ok(Some(Hx711Channel::A64))
    );
    assert_eq!(chip.gain(), Hx711Channel::A64);
    // Powered down and up, the chip is back on A128, and the driver knows it.
    adc.power_down().unwrap();
    adc.power_up().unwrap();
    assert_eq!(chip.gain(), Hx711Channel::A128);
    let before = chip.conversions();
    adc.read(Hx711Channel::A128).unwrap();
    assert_eq!(chip.conversions(), before + 1);
}

#[test]
fn the_80_sps_timeout_covers_a_channel_change() {
    let clock = SimClock::new();
    let trace = noisy(-5);
    let chip = SimHx711::new(&clock, 12_500_000, &trace);
    let mut adc = Hx711::new(chip.dout(), chip.sck(), clock.delay(), Timeout::HX711_80SPS).unwrap();
    assert_eq!(adc.read(Hx711Channel::B32), Ok(-5 + 2));
    assert!(clock.now_ns() <= 50_000_000);
    // At 10 samples/s the same wait is too short: a timeout, not a hang.
    let slow = SimHx711::new(&clock, 100_000_000, &trace);
    let mut adc = Hx711::new(slow.dout(), slow.sck(), clock.delay(), Timeout::HX711_80SPS).unwrap();
    assert_eq!(adc.read(Hx711Channel::A128), Err(AdcError::Timeout));
}

#[test]
fn disconnected_hx711_times_out_in_bounded_simulated_time() {
    let clock = SimClock::new();
    let trace = noisy(0);
    let chip = SimHx711::new(&clock, PERIOD_NS, &trace);
    let mut cell = sim_cell(&chip, &clock);
    chip.force_dout(Some(true));
    let t0 = clock.now_ns();
    for _ in 0..3 {
        assert_eq!(cell.read().unwrap_err().kind, FaultKind::Disconnected);
    }
    let waited = clock.now_ns() - t0;
    // 500 polls 1 ms apart per read.
    assert_eq!(waited, 3 * 500 * 1_000_000);
    assert_eq!(cell.detector().counts().disconnected, 3);
    // Plugged back in, it reads again.
    chip.force_dout(None);
    assert!(cell.read().is_ok());
    chip.set_pin_error(true);
    assert_eq!(cell.read().unwrap_err().kind, FaultKind::Bus);
}

/// Reads `n` times and returns the faults' kinds (None for a good reading).
fn kinds(
    cell: &mut LoadCell<impl Adc<Channel = Hx711Channel>>,
    n: usize,
) -> Vec<Option<FaultKind>> {
    (0..n).map(|_| cell.read().err().map(|f| f.kind)).collect()
}

#[test]
fn garbage_from_the_load_cell_ends_as_counted_faults() {
    let clock = SimClock::new();
    let start = noisy(100);
    let chip = SimHx711::new(&clock, PERIOD_NS, &start);
    let mut cell = sim_cell(&chip, &clock);
    assert!(cell.read().is_ok());

    // DOUT shorted to ground: always "ready", all zeros. Stuck from the 8th on.
    chip.force_dout(Some(false));
    let k = kinds(&mut cell, 10);
    assert!(k[..7].iter().all(Option::is_none), "{k:?}");
    assert_eq!(k[7..], [Some(FaultKind::Stuck); 3]);
    chip.force_dout(None);

    // All ones (0xFFFFFF = -1): stuck too.
    let ones = [-1];
    chip.set_trace(&ones);
    let k = kinds(&mut cell, 9);
    assert!(k[..7].iter().all(Option::is_none), "{k:?}");
    assert_eq!(k[7..], [Some(FaultKind::Stuck); 2]);

    // Alternating rails: every reading saturated.
    let rails = [HX711_RAILS.max, HX711_RAILS.min];
    chip.set_trace(&rails);
    assert_eq!(kinds(&mut cell, 6), [Some(FaultKind::Saturated); 6]);

    // A jump by the full scale (and back): jumps.
    let jumps = [-4_200_000, 4_200_000];
    chip.set_trace(&jumps);
    let k = kinds(&mut cell, 4);
    assert_eq!(k[1..], [Some(FaultKind::Jump); 3]);

    // Beyond the 5 kN capacity: out of range.
    let over = noisy(cell.calibration().counts_for(6000.0));
    chip.set_trace(&over);
    assert_eq!(kinds(&mut cell, 3), [Some(FaultKind::OutOfRange); 3]);

    let c = cell.detector().counts();
    assert_eq!((c.stuck, c.saturated, c.out_of_range), (5, 6, 3));
    assert!(c.jump >= 3);
    assert_eq!(c.total(), c.stuck + c.saturated + c.jump + c.out_of_range);
}

#[path = "common/probes.rs"]
mod probes;
use probes::{PROBE, probe_calibration};

/// An ADS1115-like ADC with two probes; probe 1 reads 1e-7 m per count from 800 counts
/// at 0 m, probe 2 1.25e-7 m per count from -400 counts.
fn probe1_counts(m: f32) -> i32 {
    800 + (m / 1e-7).round() as i32
}
fn probe2_counts(m: f32) -> i32 {
    -400 + (m / 1.25e-7).round() as i32
}

fn calibrated_probes<'a>(adc: SimAdc<'a, 2>) -> Misalignment<SimAdc<'a, 2>> {
    let limits = RawLimits::new(Rails::signed_bits(16).unwrap());
    Misalignment::new(adc, (0, 1), probe_calibration(0.0), limits).unwrap()
}

fn noisy_at(counts: i32) -> Vec<i32> {
    noisy(counts).to_vec()
}

#[test]
fn probes_two_point_linearity_zero_and_angle() {
    // On-site probe calibration: gauge blocks at 0.2 mm and 1.8 mm, a check at 1.0 mm.
    let at = |m: f32| (noisy_at(probe1_counts(m)), noisy_at(probe2_counts(m)));
    let (lo1, lo2) = at(0.2e-3);
    let mut adc = SimAdc::new(Rails::signed_bits(16).unwrap(), [&lo1, &lo2]);
    let mut probes = calibrated_probes(adc.clone());
    let (r1_lo, r2_lo) = probes.mean_raw(7).unwrap();
    let (hi1, hi2) = at(1.8e-3);
    probes.adc_mut().set_trace(0, &hi1);
    probes.adc_mut().set_trace(1, &hi2);
    let (r1_hi, r2_hi) = probes.mean_raw(7).unwrap();
    let p1 = ProbeCalibration::two_point((r1_lo, 0.2e-3), (r1_hi, 1.8e-3), PROBE).unwrap();
    let p2 = ProbeCalibration::two_point((r2_lo, 0.2e-3), (r2_hi, 1.8e-3), PROBE).unwrap();
    assert!((p1.metres_per_count - 1e-7).abs() < 1e-11);
    assert!((p2.metres_per_count - 1.25e-7).abs() < 1e-11);
    // The mid check point is on the line; one 10 um off is refused.
    let mid = (probe1_counts(1.0e-3) as f32, 1.0e-3);
    assert!(p1.check_linearity(&[mid]).unwrap() < 1e-6);
    assert_eq!(
        p1.check_linearity(&[(mid.0 + 100.0, mid.1)]),
        Err(CalibrationError::Nonlinear)
    );

    // Mounted on the roller: 1.00 mm and 1.03 mm in a known-aligned state (the probes'
    // mounts differ by 30 um): the zero offset takes that out.
    let mut cal = probes.calibration();
    cal.probe1 = p1;
    cal.probe2 = p2;
    probes.set_calibration(cal).unwrap();
    let (a1, a2) = (
        noisy_at(probe1_counts(1.00e-3)),
        noisy_at(probe2_counts(1.03e-3)),
    );
    probes.adc_mut().set_trace(0, &a1);
    probes.adc_mut().set_trace(1, &a2);
    let zeroed = probes.zero(14).unwrap();
    assert!(
        (zeroed.zero_offset_m - -30e-6).abs() < 0.3e-6,
        "{}",
        zeroed.zero_offset_m
    );
    // Misaligned: probe 1 moved out by 80 um: phi = atan2(80e-6, 0.4) = 2e-4 rad.
    let (m1, m2) = (
        noisy_at(probe1_counts(1.08e-3)),
        noisy_at(probe2_counts(1.03e-3)),
    );
    probes.adc_mut().set_trace(0, &m1);
    probes.adc_mut().set_trace(1, &m2);
    for _ in 0..14 {
        let r = probes.read().unwrap();
        // Noise of +-3 counts on each probe: +-0.7 um over 0.4 m.
        assert!((r.phi_rad - 2e-4).abs() < 2.5e-6, "{}", r.phi_rad);
        assert!((r.d1_m - 1.08e-3).abs() < 0.5e-6);
    }
    // The other way round gives the opposite sign.
    probes.adc_mut().set_trace(0, &a1);
    let back = noisy_at(probe2_counts(1.11e-3));
    probes.adc_mut().set_trace(1, &back);
    assert!(probes.read().unwrap().phi_rad < -1e-4);
    adc.set_timeout(true);
    assert!(adc.read(0).is_err());
}

#[test]
fn probe_faults_name_the_probe() {
    let ok1 = noisy_at(probe1_counts(1e-3));
    let ok2 = noisy_at(probe2_counts(1e-3));
    let mut probes = calibrated_probes(SimAdc::new(Rails::signed_bits(16).unwrap(), [&ok1, &ok2]));
    assert!(probes.read().is_ok());

    // Probe 2's wire broken: its input at the rail.
    let rail = [i32::from(i16::MAX)];
    probes.adc_mut().set_trace(1, &rail);
    assert_eq!(
        probes.read(),
        Err(SensorFault {
            sensor: SensorId::Probe2,
            kind: FaultKind::Saturated
        })
    );
    // Probe 1 beyond its 2 mm range (and probe 2 still saturated: both counted, the
    // first reported).
    let far = noisy_at(probe1_counts(2.5e-3));
    probes.adc_mut().set_trace(0, &far);
    assert_eq!(
        probes.read(),
        Err(SensorFault {
            sensor: SensorId::Probe1,
            kind: FaultKind::OutOfRange
        })
    );
    let (d1, d2) = probes.detectors();
    assert_eq!((d1.counts().out_of_range, d2.counts().saturated), (1, 2));
    // Zeroing refuses a faulty probe.
    assert!(matches!(
        probes.zero(4),
        Err(CalibrationError::Sensor(SensorFault {
            sensor: SensorId::Probe1,
            ..
        }))
    ));
    // The ADC stops answering: both probes disconnected.
    probes.adc_mut().set_timeout(true);
    assert_eq!(probes.read().unwrap_err().kind, FaultKind::Disconnected);
    let (d1, d2) = probes.detectors();
    assert_eq!(d2.counts().disconnected, 1);
    assert!(d1.counts().disconnected >= 1);
    probes.adc_mut().set_timeout(false);
    probes.adc_mut().set_bus_error(true);
    assert_eq!(probes.read().unwrap_err().kind, FaultKind::Bus);
}

#[test]
fn tachometer_speed_wraps_and_refuses_a_backward_counter() {
    let cal = SpeedCalibration {
        pulses_per_rev: 60,
        radius_m: 0.25,
        max_speed_m_s: 30.0,
    };
    let mut tach = Tachometer::new(cal).unwrap();
    // 3 rev/s at r = 0.25 m: V = 1.5 pi m/s. Counter and clock both wrap in between.
    let (p0, t0) = (u32::MAX - 50, u32::MAX - 200_000);
    assert_eq!(tach.update(p0, t0), Ok(None));
    let v = tach
        .update(p0.wrapping_add(180), t0.wrapping_add(1_000_000))
        .unwrap()
        .unwrap();
    assert!((v - 1.5 * std::f32::consts::PI).abs() < 1e-5, "{v}");
    // No time passed: no new speed.
    assert_eq!(
        tach.update(p0.wrapping_add(181), t0.wrapping_add(1_000_000)),
        Ok(None)
    );
    // The counter ran backwards by one pulse: 2^32 - 1 pulses in 1 ms.
    let fault = tach
        .update(p0.wrapping_add(179), t0.wrapping_add(1_001_000))
        .unwrap_err();
    assert_eq!(
        (fault.sensor, fault.kind),
        (SensorId::Speed, FaultKind::OutOfRange)
    );
    assert_eq!(tach.counts().out_of_range, 1);
    // Stopped: zero speed is a measurement.
    assert_eq!(
        tach.update(p0.wrapping_add(179), t0.wrapping_add(2_001_000)),
        Ok(Some(0.0))
    );
}

#[test]
fn a_sample_carries_the_first_fault_and_no_made_up_value() {
    let probe = SensorFault {
        sensor: SensorId::Probe2,
        kind: FaultKind::Stuck,
    };
    let speed = SensorFault {
        sensor: SensorId::Speed,
        kind: FaultKind::OutOfRange,
    };
    let s = SensorSample::new(Ok(1200.0), Err(probe), Some(Err(speed)));
    assert_eq!(s.fault, Some(probe));
    assert_eq!((s.load_n, s.phi_rad, s.speed_m_s), (1200.0, 0.0, Some(0.0)));
    assert!(!s.is_valid());
    let good = SensorSample::new(Ok(1200.0), Ok(2e-4), None);
    assert!(good.is_valid());
    assert_eq!((good.phi_rad, good.speed_m_s), (2e-4, None));
    assert_eq!(
        format!("{probe}"),
        "probe2: stuck: identical raw values where noise is expected"
    );
}

#[test]
fn sim_adc_out_of_its_channels_is_an_error_not_a_panic() {
    let t = [5];
    let mut adc = SimAdc::new(Rails::signed_bits(12).unwrap(), [&t[..]]);
    assert_eq!(
        adc.read(3),
        Err(AdcError::Bus(misalign::sensors::sim::SimError))
    );
    adc.feed(0, 1 << 20);
    assert_eq!(adc.read(0), Ok(2047));
    assert_eq!(adc.read(0), Ok(5));
}

#[test]
fn a_scenario_replayed_through_the_simulated_chips_reads_back() {
    use misalign::sensors::sim::TraceEncoder;
    let clock = SimClock::new();
    let chip = SimHx711::new(&clock, PERIOD_NS, &[]);
    let mut load = sim_cell(&chip, &clock);
    let mut probes = calibrated_probes(SimAdc::new(Rails::signed_bits(16).unwrap(), [&[], &[]]));
    let mut cal = probes.calibration();
    cal.zero_offset_m = 20e-6;
    probes.set_calibration(cal).unwrap();
    let mut encoder = TraceEncoder::new(load.calibration(), cal, 1e-3, 2);
    let lsb_p = load.calibration().newtons_per_count;
    // A steady load and angle for 40 samples, then a drift: no fault, values within the
    // dither (2 counts) plus rounding.
    for i in 0..80 {
        let (p, phi) = if i < 40 {
            (1500.0, 1e-4)
        } else {
            (1500.0 + 10.0 * i as f32, 1e-4 + 2e-6 * i as f32)
        };
        let codes = encoder.codes(p, phi);
        chip.feed(codes.load);
        probes.adc_mut().feed(0, codes.probe1);
        probes.adc_mut().feed(1, codes.probe2);
        let got_p = load.read().unwrap();
        let got_phi = probes.read().unwrap().phi_rad;
        assert!((got_p - p).abs() <= 3.0 * lsb_p, "{i}: {got_p} vs {p}");
        // Probe 1: 1e-7 m a count, probe 2: 1.25e-7; 0.4 m span.
        assert!(
            (got_phi - phi).abs() <= (3.0 * 1e-7 + 3.0 * 1.25e-7) / 0.4,
            "{i}: {got_phi} vs {phi}"
        );
    }
    assert_eq!(load.detector().counts().total(), 0);
    let exact = TraceEncoder::new(load.calibration(), cal, 1e-3, 0).codes(0.0, 0.0);
    assert_eq!(exact.probe1, probe1_counts(1.02e-3));
    assert_eq!(exact.probe2, probe2_counts(1e-3));
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]

    /// Any codes at all on both probes: every reading is an angle in (-pi/2, pi/2) or
    /// a counted fault, never a panic or a NaN.
    #[test]
    fn any_probe_codes_give_an_angle_or_a_counted_fault(
        t1 in prop::collection::vec(any::<i32>(), 1..40),
        t2 in prop::collection::vec(any::<i32>(), 1..40),
    ) {
        let mut probes = calibrated_probes(SimAdc::new(Rails::signed_bits(16).unwrap(), [&t1, &t2]));
        let mut faults = 0u32;
        for _ in 0..60 {
            match probes.read() {
                Ok(r) => prop_assert!(r.phi_rad.abs() < std::f32::consts::FRAC_PI_2),
                Err(_) => faults += 1,
            }
        }
        let (d1, d2) = probes.detectors();
        // Both probes are read every time: a faulty reading has one or two faults.
        prop_assert!(d1.counts().total() + d2.counts().total() >= faults);
        prop_assert!(d1.counts().total() <= 60 && d2.counts().total() <= 60);
    }

    /// Any 24-bit codes through the simulated HX711's pins: a load inside the
    /// calibrated range or a counted fault.
    #[test]
    fn any_hx711_codes_give_a_load_in_range_or_a_counted_fault(
        trace in prop::collection::vec(-(1i32 << 23)..(1 << 23), 1..30),
    ) {
        let clock = SimClock::new();
        let chip = SimHx711::new(&clock, PERIOD_NS, &trace);
        let mut cell = sim_cell(&chip, &clock);
        let mut faults = 0;
        for _ in 0..40 {
            match cell.read() {
                Ok(p) => prop_assert!(p.abs() <= 5000.0),
                Err(f) => {
                    prop_assert_eq!(f.sensor, SensorId::Load);
                    faults += 1;
                }
            }
        }
        prop_assert_eq!(cell.detector().counts().total(), faults);
    }
}

/// The ADS1115 through the `ads1x1x` crate, its I2C traffic listed.
#[cfg(feature = "ads1x1x")]
mod ads1115 {
    use super::*;
    use ads1x1x::{Ads1x1x, TargetAddr};
    use embedded_hal::i2c::ErrorKind;
    use embedded_hal_mock::eh1::i2c::{Mock as I2cMock, Transaction as I2cTx};
    use misalign::sensors::ads1x1x::{Ads1115, Ads1115Channel};

    const ADDR: u8 = 0x48;
    /// The config register: default 0x8583, AIN0 against GND (MUX = 100).
    const CONFIG_A0: [u8; 2] = [0xC5, 0x83];
    /// The same while converting (OS = 0).
    const BUSY_A0: [u8; 2] = [0x45, 0x83];

    /// Start a conversion on AIN0: idle config read, config written with OS set.
    fn start() -> [I2cTx; 2] {
        [
            I2cTx::write_read(ADDR, vec![0x01], vec![0x85, 0x83]),
            I2cTx::write(ADDR, vec![0x01, CONFIG_A0[0], CONFIG_A0[1]]),
        ]
    }

    fn adapter(i2c: &I2cMock, timeout: Timeout) -> Ads1115<I2cMock, NoopDelay> {
        Ads1115::new(
            Ads1x1x::new_ads1115(i2c.clone(), TargetAddr::default()),
            NoopDelay::new(),
            timeout,
        )
    }

    #[test]
    fn one_shot_read_polls_until_the_conversion_is_done() {
        let mut tx = start().to_vec();
        tx.push(I2cTx::write_read(ADDR, vec![0x01], BUSY_A0.to_vec()));
        tx.push(I2cTx::write_read(ADDR, vec![0x01], CONFIG_A0.to_vec()));
        tx.push(I2cTx::write_read(ADDR, vec![0x00], vec![0xF0, 0x0D]));
        let mut i2c = I2cMock::new(&tx);
        let mut adc = adapter(&i2c, Timeout::ADS1115_128SPS);
        assert_eq!(
            adc.read(Ads1115Channel::A0).ok(),
            Some(0xF00Du16 as i16 as i32)
        );
        assert_eq!(adc.rails(), Rails::signed_bits(16).unwrap());
        i2c.done();
    }

    #[test]
    fn a_conversion_that_never_finishes_is_a_timeout() {
        let mut tx = start().to_vec();
        tx.extend((0..3).map(|_| I2cTx::write_read(ADDR, vec![0x01], BUSY_A0.to_vec())));
        let mut i2c = I2cMock::new(&tx);
        let timeout = Timeout {
            polls: 4,
            interval_us: 500,
        };
        let mut adc = adapter(&i2c, timeout);
        assert!(matches!(
            adc.read(Ads1115Channel::A0),
            Err(AdcError::Timeout)
        ));
        i2c.done();
    }

    #[test]
    fn a_bus_that_reads_all_ones_is_out_of_range_then_stuck() {
        // Every register reads 0xFFFF: "conversion done" and a code of -1 on both
        // channels (AIN0, then AIN1 with MUX = 101).
        let ones = || I2cTx::write_read(ADDR, vec![0x01], vec![0xFF, 0xFF]);
        let mut tx = Vec::new();
        for _ in 0..8 {
            for config in [[0xC5, 0x83], [0xD5, 0x83]] {
                tx.push(ones());
                tx.push(I2cTx::write(ADDR, vec![0x01, config[0], config[1]]));
                tx.push(ones());
                tx.push(I2cTx::write_read(ADDR, vec![0x00], vec![0xFF, 0xFF]));
            }
        }
        let mut i2c = I2cMock::new(&tx);
        let adc = adapter(&i2c, Timeout::ADS1115_128SPS);
        let cal = calibrated_probes(SimAdc::new(Rails::signed_bits(16).unwrap(), [&[], &[]]))
            .calibration();
        let limits = RawLimits::new(adc.rails());
        let channels = (Ads1115Channel::A0, Ads1115Channel::A1);
        let mut probes = Misalignment::new(adc, channels, cal, limits).unwrap();
        // -1 count is 80 um below probe 1's range: out of range, until the eighth equal
        // code in a row makes it stuck.
        let kinds: Vec<_> = (0..8).map(|_| probes.read().unwrap_err()).collect();
        let out = SensorFault {
            sensor: SensorId::Probe1,
            kind: FaultKind::OutOfRange,
        };
        assert_eq!(kinds[..7], [out; 7]);
        assert_eq!(kinds[7].kind, FaultKind::Stuck);
        let (d1, d2) = probes.detectors();
        assert_eq!((d1.counts().out_of_range, d1.counts().stuck), (7, 1));
        // Probe 2 reads 0 m at -400 counts: -1 is a plausible 50 um, caught as stuck.
        assert_eq!((d2.counts().out_of_range, d2.counts().stuck), (0, 1));
        i2c.done();
    }

    #[test]
    fn an_unanswered_address_is_a_bus_fault_of_the_probe() {
        let nack = || I2cTx::write_read(ADDR, vec![0x01], vec![0, 0]).with_error(ErrorKind::Other);
        let tx = [nack(), nack()];
        let mut i2c = I2cMock::new(&tx);
        let adc = adapter(&i2c, Timeout::ADS1115_128SPS);
        let cal = calibrated_probes(SimAdc::new(Rails::signed_bits(16).unwrap(), [&[], &[]]))
            .calibration();
        let limits = RawLimits::new(adc.rails());
        let mut probes =
            Misalignment::new(adc, (Ads1115Channel::A0, Ads1115Channel::A1), cal, limits).unwrap();
        // Both probes' reads fail on the bus; the first is reported, both are counted.
        let fault = probes.read();
        assert_eq!(
            fault,
            Err(SensorFault {
                sensor: SensorId::Probe1,
                kind: FaultKind::Bus
            })
        );
        let (d1, d2) = probes.detectors();
        assert_eq!((d1.counts().bus, d2.counts().bus), (1, 1));
        i2c.done();
    }
}
