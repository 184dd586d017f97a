//! The benchmark image (`cargo xtask bench`): per model and per operation, the
//! instructions per call (mean and maximum over the practical samples of
//! `misalign_workload::samples`), counted by SysTick under QEMU's `-icount`. One line
//! per measurement: `bench model=<m> op=<op> n=<calls> mean=<x> max=<y>`; the host
//! pairs it with the error of the same code against the reference.
//!
//! Models: the f64 reference (soft float on every Cortex-M here), the f32 core (soft
//! float on the M0 and M3), the fixed-point core and the Hamrock & Brewe baseline.
#![no_std]
#![no_main]

use misalign_harness::support;
use misalign_logger as _;

misalign_harness::log_panics_and_faults!();

mod run {
    use core::hint::black_box;
    use misalign::fixed::logexp::{exp2_fixed, log2_u32};
    use misalign::fixed::tables::LOG_G_HIGH;
    use misalign::fixed::{FixedAuto, FixedEllipticScene, FixedLineScene};
    use misalign::float::kernels::{axial_force::axial_force_ratio, cbrt::cbrt, sqrt::inv_sqrt};
    use misalign::float::{Auto, EllipticScene, G_OF_THETA, LineScene, THETA_OF_G};
    use misalign::monitor::{Config, Monitor, scenario};
    use misalign::{Estimator, Scene, reference};
    use misalign_harness::support::counter::{Counter, Stats, SystClkSource};
    use misalign_harness::support::parse_count;
    use misalign_workload::{Model, Operation, hamrock_brewe::HamrockBrewe, samples};

    /// Samples per operation (the reference, a thousand times slower, gets an eighth).
    const SAMPLES: usize = match option_env!("MISALIGN_BENCH_SAMPLES") {
        Some(s) => parse_count(s),
        None => 256,
    };

    /// Samples of the built-in scenario that the monitor processes: its first
    /// `16 * SAMPLES` seconds (4096 s in the full run: the start, the start-up inhibit,
    /// the load's cycles and two spikes).
    const MONITOR_SAMPLES: usize = 16 * SAMPLES;

    /// The angle LSB of the fixed-point core in the benchmark (rad per count).
    const ANGLE_LSB: f64 = 1e-8;

    /// One line for the host: `bench model=<m> op=<op> n=<calls> mean=<x> max=<y>`.
    trait Print {
        fn print(&self, model: Model, op: Operation);
    }

    impl Print for Stats {
        fn print(&self, model: Model, op: Operation) {
            defmt::println!(
                "bench model={=str} op={=str} n={=u32} mean={=u64} max={=u32}",
                model.name(),
                op.name(),
                self.n,
                self.mean(),
                self.max
            );
        }
    }

    /// Measures `f(x)` for every x, black-boxing input and output.
    fn each<T: Copy, R>(c: &Counter, xs: impl Iterator<Item = T>, f: impl Fn(T) -> R) -> Stats {
        let mut s = Stats::default();
        for x in xs {
            let x = black_box(x);
            let (r, n) = c.measure(|| f(x));
            black_box(r);
            s.add(n);
        }
        s
    }

    /// The monitor's per-sample pipeline (`Monitor::process`) over the scenario's
    /// first samples, each generated outside the measured call, in order: the monitor
    /// is the stream's, its state carried from sample to sample. Out of line, so that
    /// the monitor's code does not share a function (and its registers) with the other
    /// measurements.
    #[inline(never)]
    fn monitor<E: Estimator>(c: &Counter, estimator: E, op: Operation) -> Stats {
        let mut s = Stats::default();
        let mut config = Config::default();
        // The profile: the same stream with stages off.
        if matches!(op, Operation::MonitorNoSpikes | Operation::MonitorBare) {
            config.spikes = None;
        }
        if matches!(op, Operation::MonitorNoSmoothing | Operation::MonitorBare) {
            config.smoothing_tau_s = 0.0;
        }
        if matches!(op, Operation::MonitorNoTrend | Operation::MonitorBare) {
            config.trend = None;
        }
        if op == Operation::MonitorBare {
            (config.stuck_ms, config.gap_ms) = (0, 0);
        }
        let Ok(mut monitor) = Monitor::new(estimator, black_box(config)) else {
            return s;
        };
        for sample in scenario::Scenario::new().take(MONITOR_SAMPLES) {
            let sample = black_box(sample);
            let (state, n) = c.measure(|| monitor.process(sample));
            black_box(state);
            s.add(n);
        }
        // What the consumer would drain, out of the measurement.
        while black_box(monitor.pop_event()).is_some() {}
        s
    }

    pub fn main(counter: Counter) -> i32 {
        // Opaque to the optimiser, as a scene read from a configuration block: nothing
        // of it is folded into the per-sample code.
        let scene = black_box(Scene::DEMO);
        let (Ok(core), Ok(line)) = (EllipticScene::new(&scene), LineScene::new(&scene)) else {
            return 2;
        };
        let load_lsb = samples::LOAD_MAX / (1u64 << 30) as f64;
        let (Ok(fixed), Ok(fixed_line)) = (
            FixedEllipticScene::new(&scene, load_lsb, ANGLE_LSB),
            FixedLineScene::new(&scene, load_lsb, ANGLE_LSB),
        ) else {
            return 2;
        };
        let baseline = HamrockBrewe::of(&scene);
        let f32s = || samples::practical(SAMPLES).map(|(p, phi)| (p as f32, phi as f32));
        let counts = || {
            samples::practical(SAMPLES)
                .map(|(p, phi)| ((p / load_lsb) as u32, (phi / ANGLE_LSB) as i32))
        };
        let c = &counter;

        // The full per-sample estimate (d/b, regime, F, phi0), every model.
        each(c, f32s(), |(p, phi)| core.estimate(p, phi)).print(Model::F32, Operation::Estimate);
        each(c, counts(), |(p, a)| fixed.estimate(p, a)).print(Model::Fixed, Operation::Estimate);
        each(c, f32s(), |(p, phi)| baseline.estimate(p, phi))
            .print(Model::HamrockBrewe, Operation::Estimate);
        // Line contact.
        each(c, f32s(), |(p, phi)| line.estimate(p, phi))
            .print(Model::F32, Operation::EstimateLine);
        each(c, counts(), |(p, a)| fixed_line.estimate(p, a))
            .print(Model::Fixed, Operation::EstimateLine);
        // The inverses: mu from (P, phi, F) and phi from (P, F), with F from
        // the forward estimate (computed outside the measured call).
        let with_force =
            |(p, phi): (f32, f32)| (p, phi, core.estimate(p, phi).map_or(0.0, |e| e.axial_force));
        each(c, f32s().map(with_force), |(p, phi, f)| {
            core.friction_from_axial_force(p, phi, f)
        })
        .print(Model::F32, Operation::InverseMu);
        each(c, f32s().map(with_force), |(p, _, f)| {
            core.angle_from_axial_force(p, f)
        })
        .print(Model::F32, Operation::InversePhi);
        let with_line_force =
            |(p, phi): (f32, f32)| (p, phi, line.estimate(p, phi).map_or(0.0, |e| e.axial_force));
        each(c, f32s().map(with_line_force), |(p, phi, f)| {
            line.friction_from_axial_force(p, phi, f)
        })
        .print(Model::F32, Operation::InverseMuLine);
        each(c, f32s().map(with_line_force), |(p, _, f)| {
            line.angle_from_axial_force(p, f)
        })
        .print(Model::F32, Operation::InversePhiLine);
        // The monitor's whole per-sample pipeline over the built-in scenario, on both
        // cores: the scenario's estimator (`scenario::estimator`, as the node and
        // `cargo run --example monitor` build it), on the scene made opaque.
        let Ok(shift) = scenario::scene() else {
            return 2;
        };
        let shift = black_box(shift);
        let (Ok(f32_core), Ok(fixed_core)) = (
            scenario::estimator_for::<Auto>(&shift, scenario::LOAD_MAX),
            scenario::estimator_for::<FixedAuto>(&shift, scenario::LOAD_MAX),
        ) else {
            return 2;
        };
        for op in Operation::ALL.into_iter().filter(|o| o.is_monitor()) {
            monitor(c, f32_core, op).print(Model::F32, op);
            monitor(c, fixed_core, op).print(Model::Fixed, op);
        }
        // The f32 kernels, on what they see in these estimates.
        let thetas = || f32s().map(|(_, phi)| phi.abs());
        each(c, thetas(), |t| G_OF_THETA.eval(t)).print(Model::F32, Operation::TableG);
        each(c, f32s().map(|(p, _)| 0.93 * libm::cbrtf(p) * 1e-4), |g| {
            THETA_OF_G.eval(g)
        })
        .print(Model::F32, Operation::TableThetaOfG);
        each(c, f32s().map(|(p, _)| p), cbrt).print(Model::F32, Operation::KernelCbrt);
        each(c, f32s().map(|(p, _)| p), libm::cbrtf).print(Model::F32, Operation::KernelLibmCbrtf);
        each(c, f32s().map(|(p, _)| p), inv_sqrt).print(Model::F32, Operation::KernelInvSqrt);
        each(c, f32s().map(|(p, _)| p), libm::sqrtf).print(Model::F32, Operation::KernelLibmSqrtf);
        let slips = || (0..SAMPLES).map(|i| (i as f32 + 0.5) / SAMPLES as f32);
        each(c, slips(), axial_force_ratio).print(Model::F32, Operation::KernelAxialForce);
        // The fixed-point kernels.
        each(c, counts().map(|(p, _)| p), log2_u32).print(Model::Fixed, Operation::KernelLog2);
        each(c, counts().map(|(p, _)| (p as i32) >> 8), |l| {
            exp2_fixed(-l, 24)
        })
        .print(Model::Fixed, Operation::KernelExp2);
        each(
            c,
            counts().map(|(_, a)| -(a.unsigned_abs() as i32 >> 6)),
            |y| LOG_G_HIGH.eval(y),
        )
        .print(Model::Fixed, Operation::TableLogG);

        // The f64 reference, a thousand times slower: on SysTick's reference clock,
        // whose 24 bits last long enough (the core clock's would wrap on a Cortex-M0).
        let slow = Counter::with_clock(counter.release(), SystClkSource::External, 1 << 20);
        defmt::println!(
            "bench reference_clock_ticks_per_1000={=u32}",
            slow.ticks_per_1000()
        );
        let c = if slow.ticks_per_1000() > 0 {
            &slow
        } else {
            return 0;
        };
        let few = (SAMPLES / 8).max(4);
        each(c, samples::practical(few), |(p, phi)| {
            reference::elliptic(&scene, p, phi)
        })
        .print(Model::Reference, Operation::Estimate);
        each(c, samples::practical(few), |(p, phi)| {
            reference::line(&scene, p, phi)
        })
        .print(Model::Reference, Operation::EstimateLine);
        let with_ref_force = |(p, phi): (f64, f64)| {
            let f = reference::elliptic(&scene, p, phi).map_or(0.0, |e| e.axial_force);
            (p, phi, f)
        };
        each(
            c,
            samples::practical(few).map(with_ref_force),
            |(p, phi, f)| reference::inverse::friction_elliptic(&scene, p, phi, f),
        )
        .print(Model::Reference, Operation::InverseMu);
        each(
            c,
            samples::practical(few).map(with_ref_force),
            |(p, _, f)| reference::inverse::angle_elliptic(&scene, p, f),
        )
        .print(Model::Reference, Operation::InversePhi);
        0
    }
}

#[cortex_m_rt::entry]
fn main() -> ! {
    let Some(peripherals) = cortex_m::Peripherals::take() else {
        support::exit(3)
    };
    let counter = support::counter::Counter::new(peripherals.SYST);
    defmt::println!("bench ticks_per_1000={=u32}", counter.ticks_per_1000());
    support::exit(run::main(counter))
}
