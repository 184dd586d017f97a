//! The benchmark image (`cargo xtask bench`): per model and per operation, the
//! instructions per call (mean and maximum over the practical samples of
//! `benches/common/samples.rs`), counted by SysTick under QEMU's `-icount`. One line
//! per measurement: `bench model=<m> op=<op> n=<calls> mean=<x> max=<y>`; the host
//! pairs it with the error of the same code against the reference.
//!
//! Models: the f64 reference (soft float on every Cortex-M here), the f32 core (soft
//! float on the M0 and M3), the fixed-point core and the Hamrock & Brewe baseline.
#![cfg_attr(target_os = "none", no_std)]
#![cfg_attr(target_os = "none", no_main)]

#[cfg(target_os = "none")]
#[path = "../support/mod.rs"]
mod support;

#[cfg(target_os = "none")]
#[path = "../../benches/common/hamrock_brewe.rs"]
mod hamrock_brewe;
#[cfg(target_os = "none")]
#[path = "../../benches/common/samples.rs"]
mod samples;

#[cfg(target_os = "none")]
mod run {
    use super::support::counter::{Counter, SystClkSource};
    use super::{hamrock_brewe::HamrockBrewe, samples};
    use core::hint::black_box;
    use misalign::fixed::logexp::{exp2_fixed, log2_u32};
    use misalign::fixed::{FixedEllipticScene, FixedLineScene};
    use misalign::float::{EllipticScene, LineScene};
    use misalign::kernels::{axial_force::axial_force_ratio, cbrt::cbrt, sqrt::inv_sqrt};
    use misalign::reference;
    use misalign::tables::{G_OF_THETA, LOG_G_HIGH, THETA_OF_G};

    /// Samples per operation (the reference, a thousand times slower, gets an eighth).
    const SAMPLES: usize = match option_env!("MISALIGN_BENCH_SAMPLES") {
        Some(s) => parse(s),
        None => 256,
    };

    const fn parse(s: &str) -> usize {
        let b = s.as_bytes();
        let mut i = 0;
        let mut n = 0;
        while i < b.len() {
            n = n * 10 + (b[i] - b'0') as usize;
            i += 1;
        }
        n
    }

    /// The angle LSB of the fixed-point core in the benchmark (rad per count).
    const ANGLE_LSB: f64 = 1e-8;

    struct Stats {
        n: u32,
        sum: u64,
        max: u32,
    }

    impl Stats {
        fn new() -> Self {
            Stats {
                n: 0,
                sum: 0,
                max: 0,
            }
        }
        fn add(&mut self, x: u32) {
            self.n += 1;
            self.sum += x as u64;
            self.max = self.max.max(x);
        }
        fn print(&self, model: &str, op: &str) {
            let mean = (self.sum + self.n as u64 / 2) / (self.n as u64).max(1);
            defmt::println!(
                "bench model={=str} op={=str} n={=u32} mean={=u64} max={=u32}",
                model,
                op,
                self.n,
                mean,
                self.max
            );
        }
    }

    /// Measures `f(x)` for every x, black-boxing input and output.
    fn each<T: Copy, R>(c: &Counter, xs: impl Iterator<Item = T>, f: impl Fn(T) -> R) -> Stats {
        let mut s = Stats::new();
        for x in xs {
            let x = black_box(x);
            let (r, n) = c.measure(|| f(x));
            black_box(r);
            s.add(n);
        }
        s
    }

    pub fn main(counter: Counter) -> i32 {
        let scene = samples::scene();
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
        let baseline = HamrockBrewe::new(0.05, 0.05, 79.3e9, 0.3, 0.3);
        let f32s = || samples::practical(SAMPLES).map(|(p, phi)| (p as f32, phi as f32));
        let counts = || {
            samples::practical(SAMPLES)
                .map(|(p, phi)| ((p / load_lsb) as u32, (phi / ANGLE_LSB) as i32))
        };
        let c = &counter;

        // The full per-sample estimate (d/b, regime, F, phi0), every model.
        each(c, f32s(), |(p, phi)| core.estimate(p, phi)).print("f32", "estimate");
        each(c, counts(), |(p, a)| fixed.estimate(p, a)).print("fixed", "estimate");
        each(c, f32s(), |(p, phi)| baseline.estimate(p, phi)).print("hamrock-brewe", "estimate");
        // Line contact.
        each(c, f32s(), |(p, phi)| line.estimate(p, phi)).print("f32", "estimate:line");
        each(c, counts(), |(p, a)| fixed_line.estimate(p, a)).print("fixed", "estimate:line");
        // The f32 kernels, on what they see in these estimates.
        let thetas = || f32s().map(|(_, phi)| phi.abs());
        each(c, thetas(), |t| G_OF_THETA.eval(t)).print("f32", "table:g");
        each(c, f32s().map(|(p, _)| 0.93 * libm::cbrtf(p) * 1e-4), |g| {
            THETA_OF_G.eval(g)
        })
        .print("f32", "table:theta_of_g");
        each(c, f32s().map(|(p, _)| p), cbrt).print("f32", "kernel:cbrt");
        each(c, f32s().map(|(p, _)| p), libm::cbrtf).print("f32", "kernel:libm_cbrtf");
        each(c, f32s().map(|(p, _)| p), inv_sqrt).print("f32", "kernel:inv_sqrt");
        each(c, f32s().map(|(p, _)| p), libm::sqrtf).print("f32", "kernel:libm_sqrtf");
        let slips = || (0..SAMPLES).map(|i| (i as f32 + 0.5) / SAMPLES as f32);
        each(c, slips(), axial_force_ratio).print("f32", "kernel:axial_force");
        // The fixed-point kernels.
        each(c, counts().map(|(p, _)| p), log2_u32).print("fixed", "kernel:log2");
        each(c, counts().map(|(p, _)| (p as i32) >> 8), |l| {
            exp2_fixed(-l, 24)
        })
        .print("fixed", "kernel:exp2");
        each(
            c,
            counts().map(|(_, a)| -(a.unsigned_abs() as i32 >> 6)),
            |y| LOG_G_HIGH.eval(y),
        )
        .print("fixed", "table:log_g");

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
        .print("reference", "estimate");
        each(c, samples::practical(few), |(p, phi)| {
            reference::line(&scene, p, phi)
        })
        .print("reference", "estimate:line");
        0
    }
}

#[cfg(target_os = "none")]
#[cortex_m_rt::entry]
fn main() -> ! {
    let Some(peripherals) = cortex_m::Peripherals::take() else {
        support::exit(3)
    };
    let counter = support::counter::Counter::new(peripherals.SYST);
    defmt::println!("bench ticks_per_1000={=u32}", counter.ticks_per_1000());
    support::exit(run::main(counter))
}

#[cfg(not(target_os = "none"))]
fn main() {
    eprintln!("a firmware image: `cargo xtask bench` builds it for Cortex-M and runs it in QEMU");
    std::process::exit(2);
}
