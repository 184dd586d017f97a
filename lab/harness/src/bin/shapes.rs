//! The table-shape image (`cargo xtask shapes`): instructions per evaluation of every
//! table shape weighed, beside the library's own kernel for the same table, in one run.
//! One line per measurement: `shape table=<t> shape=<id> n=<calls> mean=<x> max=<y>`
//! (`shape=library`: the library's kernel); the host pairs it with the shape's error
//! against the f64 reference and its bytes.
//!
//! The shapes' tables are written by `cargo xtask shapes` and reach this image through
//! `MISALIGN_SHAPES_TABLES` (lab/harness/build.rs copies that file into OUT_DIR); without
//! it the image measures the library's kernels only. The evaluators are
//! `misalign_harness::shapes`, which the host's error measurement compiles too.
//!
//! The f32 core's tables (g(theta), theta(g): octave polynomials) are measured where it
//! runs in hardware, with an FPU (thumbv7em-none-eabihf: Cortex-M4F); the fixed-point
//! core's (log2 g against log2 theta, log2 theta(g) against log2 g: uniform Q8.24) on
//! the targets without one (Cortex-M0 and M3), where it is the core to run. Inputs spread evenly over each table's domain in
//! log2 (every octave alike), the same for every shape of a table.
#![no_std]
#![no_main]

use misalign_harness::support;
use misalign_logger as _;

misalign_harness::log_panics_and_faults!();

mod run {
    use core::hint::black_box;
    use misalign_harness::support::counter::{Counter, Stats};

    /// Inputs per table (a const generic: no allocator).
    const SAMPLES: usize = match option_env!("MISALIGN_SHAPES_SAMPLES") {
        Some(s) => misalign_harness::support::parse_count(s),
        None => 256,
    };

    /// log2(pi/2) in Q8.24: where the fixed-point tables' domains end.
    #[cfg(not(target_abi = "eabihf"))]
    const LOG2_HALF_PI: i32 = 10_930_291;

    /// `f(x)` for every input: mean and maximum instructions, printed as one line.
    /// Never inlined: every measurement is a function of its own, the same but for its
    /// closure, so that the library's kernel and the shape it ships compile alike (in
    /// line, the caller's registers decided which constants were hoisted out of the
    /// counted region: one instruction either way).
    #[inline(never)]
    fn measure<X: Copy, R>(c: &Counter, table: &str, shape: &str, xs: &[X], f: impl Fn(X) -> R) {
        let mut s = Stats::default();
        for &x in xs {
            let x = black_box(x);
            let (r, k) = c.measure(|| f(x));
            black_box(r);
            s.add(k);
        }
        defmt::println!(
            "shape table={=str} shape={=str} n={=u32} mean={=u64} max={=u32}",
            table,
            shape,
            s.n,
            s.mean(),
            s.max
        );
    }

    /// An f32 table's shapes (generated), measured on `xs`.
    #[cfg(target_abi = "eabihf")]
    pub fn measure_f32(
        c: &Counter,
        table: &str,
        shape: &str,
        xs: &[f32],
        f: impl Fn(f32) -> Option<f32>,
    ) {
        measure(c, table, shape, xs, f);
    }

    /// A fixed-point table's shapes (generated), measured on `ys`.
    #[cfg(not(target_abi = "eabihf"))]
    pub fn measure_fixed(
        c: &Counter,
        table: &str,
        shape: &str,
        ys: &[i32],
        f: impl Fn(i32) -> Option<i32>,
    ) {
        measure(c, table, shape, ys, f);
    }

    /// `SAMPLES` f32 from `lo` to `hi`, evenly spaced in their bits: evenly in log2
    /// within a factor of 1 + 2^-23 per octave (no libm on the target needed).
    #[cfg(target_abi = "eabihf")]
    fn f32_inputs(lo: f32, hi: f32) -> [f32; SAMPLES] {
        let (a, b) = (lo.to_bits() as u64, hi.to_bits() as u64);
        core::array::from_fn(|i| {
            f32::from_bits((a + (b - a) * (2 * i as u64 + 1) / (2 * SAMPLES as u64)) as u32)
        })
    }

    /// `SAMPLES` Q8.24 values evenly spaced from `lo` to `hi`.
    #[cfg(not(target_abi = "eabihf"))]
    fn fixed_inputs(lo: i32, hi: i32) -> [i32; SAMPLES] {
        core::array::from_fn(|i| {
            let span = (hi as i64 - lo as i64) * (2 * i as i64 + 1) / (2 * SAMPLES as i64);
            (lo as i64 + span) as i32
        })
    }

    /// The generated shapes (or the stub without them): `f32_shapes` and
    /// `fixed_shapes`, which call [`measure_f32`] and [`measure_fixed`] once per shape.
    mod generated {
        #![allow(unused_imports, clippy::excessive_precision, clippy::approx_constant)]
        use super::*;
        use misalign::fixed::uniform::UniformTable;
        use misalign_harness::shapes::{Linear, Octaves, lookup};
        use misalign_harness::support::counter::Counter;
        include!(concat!(env!("OUT_DIR"), "/shapes.rs"));
    }

    pub fn main(c: Counter) -> i32 {
        #[cfg(target_abi = "eabihf")]
        {
            use misalign::float::{G_OF_THETA, THETA_OF_G};
            let top = core::f32::consts::FRAC_PI_2;
            let g = f32_inputs(G_OF_THETA.lower(), top);
            let theta = f32_inputs(THETA_OF_G.lower(), top);
            // The library's kernels first: the baseline of the same run.
            measure_f32(&c, "g", "library", &g, |x| G_OF_THETA.eval(x));
            // As the core reads it: from g = 1 its top octave's own table.
            measure_f32(&c, "theta_of_g", "library", &theta, |x| {
                if x >= 1.0 {
                    Some(misalign::float::kernels::theta_top::theta_of_g_top(x))
                } else {
                    THETA_OF_G.eval(x)
                }
            });
            generated::f32_shapes(&c, &g, &theta);
        }
        #[cfg(not(target_abi = "eabihf"))]
        {
            use misalign::fixed::tables::{LOG_G_HIGH, LOG_G_LOW, LOG_THETA_HIGH, LOG_THETA_LOW};
            use misalign_harness::shapes::lookup;
            let log_g = fixed_inputs(LOG_G_LOW.start, LOG2_HALF_PI);
            let log_theta = fixed_inputs(LOG_THETA_LOW.start, LOG2_HALF_PI);
            // The fixed-point core's two-table lookup on the library's tables.
            measure_fixed(&c, "log_g", "library", &log_g, |y| {
                lookup(&LOG_G_LOW, &LOG_G_HIGH, y)
            });
            measure_fixed(&c, "log_theta_of_g", "library", &log_theta, |z| {
                lookup(&LOG_THETA_LOW, &LOG_THETA_HIGH, z)
            });
            generated::fixed_shapes(&c, &log_g, &log_theta);
        }
        0
    }
}

#[cortex_m_rt::entry]
fn main() -> ! {
    let Some(peripherals) = cortex_m::Peripherals::take() else {
        support::exit(3)
    };
    let counter = support::counter::Counter::new(peripherals.SYST);
    defmt::println!("shape ticks_per_1000={=u32}", counter.ticks_per_1000());
    support::exit(run::main(counter))
}
