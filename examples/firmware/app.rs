//! The firmware proper (Cortex-M only).
//!
//! Every estimator is reached through [`Core`]: the f32 core where there is an FPU
//! (Cortex-M4F, M7), the fixed-point core where there is none (Cortex-M0, M3). The
//! trace, the check against the reference, the stack and instruction measurements are
//! the same for both.

use crate::support::{self, counter::Counter, stack};
use crate::trace;
use misalign::fixed::{FixedEllipticScene, FixedEstimate, FixedLineScene};
use misalign::float::{EllipticScene, Estimate, LineScene};
use misalign::reference::Regime;
use misalign::{Error, Scene};

/// The fixed-point core's LSBs in the firmware: 1 mN and 10 prad per count.
const LOAD_LSB: f64 = 1e-3;
const ANGLE_LSB: f64 = 1e-11;

/// One answer in f32, whatever the core: what is checked against the reference.
#[derive(Clone, Copy, defmt::Format)]
pub struct Answer {
    slip_ratio: f32,
    axial_force: f32,
    critical_angle: Option<f32>,
    margin: Option<f32>,
    gross: bool,
    risk: bool,
}

// `ELLIPTIC_EXPECTED`, `LINE_EXPECTED`: the reference's answers for `trace`.
include!(concat!(env!("OUT_DIR"), "/firmware_expected.rs"));

/// An estimator as the firmware drives it: prepared once, then one call per sample.
trait Core {
    /// Contact model, for the log and `cargo xtask firmware`.
    const NAME: &'static str;
    /// Number format ("f32", "f32-soft", "fixed").
    const NUMBER: &'static str;
    /// Relative tolerance against the reference: the core's bound on the reference data
    /// (f32 2e-6, fixed point 1e-4).
    const TOLERANCE: f32;
    /// A sample in the core's own units (f32 SI here; counts for a fixed-point core).
    type Sample: Copy;
    /// The core's own answer.
    type Output: Copy;
    /// The sample in the core's units; `None` when its input range cannot hold it to
    /// 1e-5 (then it is skipped and said so).
    fn sample(load: f32, phi: f32) -> Option<Self::Sample>;
    fn estimate(&self, sample: Self::Sample) -> Result<Self::Output, Error>;
    /// The answer in f32 SI units.
    fn answer(output: &Self::Output) -> Answer;
}

fn f32_answer(e: &Estimate) -> Answer {
    Answer {
        slip_ratio: e.slip_ratio,
        axial_force: e.axial_force,
        critical_angle: e.critical_angle,
        margin: e.margin,
        gross: e.regime == Regime::Gross,
        risk: e.microslip_risk,
    }
}

/// "f32" with an FPU, "f32-soft" without (thumbv6m, thumbv7m: soft float).
const F32: &str = if cfg!(target_abi = "eabihf") {
    "f32"
} else {
    "f32-soft"
};

impl Core for EllipticScene<'static> {
    const NAME: &'static str = "elliptic";
    const NUMBER: &'static str = F32;
    const TOLERANCE: f32 = 2e-6;
    type Sample = (f32, f32);
    type Output = Estimate;
    fn sample(load: f32, phi: f32) -> Option<(f32, f32)> {
        Some((load, phi))
    }
    #[inline(always)]
    fn estimate(&self, (load, phi): (f32, f32)) -> Result<Estimate, Error> {
        EllipticScene::estimate(self, load, phi)
    }
    fn answer(e: &Estimate) -> Answer {
        f32_answer(e)
    }
}

impl Core for LineScene {
    const NAME: &'static str = "line";
    const NUMBER: &'static str = F32;
    const TOLERANCE: f32 = 2e-6;
    type Sample = (f32, f32);
    type Output = Estimate;
    fn sample(load: f32, phi: f32) -> Option<(f32, f32)> {
        Some((load, phi))
    }
    #[inline(always)]
    fn estimate(&self, (load, phi): (f32, f32)) -> Result<Estimate, Error> {
        LineScene::estimate(self, load, phi)
    }
    fn answer(e: &Estimate) -> Answer {
        f32_answer(e)
    }
}

/// A value as counts of `lsb`, if it is 0 or holds at least 1e5 counts (quantised to
/// 5e-6 at most) and fits.
fn counts(x: f32, lsb: f64, max: f64) -> Option<f64> {
    let c = libm::round(libm::fabs(x as f64) / lsb);
    ((x == 0.0 || c >= 1e5) && c <= max).then_some(c)
}

fn fixed_sample(load: f32, phi: f32) -> Option<(u32, i32)> {
    let p = counts(load, LOAD_LSB, u32::MAX as f64)?;
    let a = counts(phi, ANGLE_LSB, i32::MAX as f64)?;
    Some((p as u32, if phi < 0.0 { -(a as i32) } else { a as i32 }))
}

fn fixed_answer(e: &FixedEstimate) -> Answer {
    let force = e.axial_force.to_f64() as f32;
    Answer {
        slip_ratio: e.slip_ratio.to_f64() as f32,
        axial_force: if e.axial_force_negative {
            -force
        } else {
            force
        },
        critical_angle: e.critical_angle.map(|c| c.to_f64() as f32),
        margin: e.margin.map(|m| (m as f64 * ANGLE_LSB) as f32),
        gross: e.regime == Regime::Gross,
        risk: e.microslip_risk,
    }
}

impl Core for FixedEllipticScene {
    const NAME: &'static str = "elliptic";
    const NUMBER: &'static str = "fixed";
    const TOLERANCE: f32 = 1e-4;
    type Sample = (u32, i32);
    type Output = FixedEstimate;
    fn sample(load: f32, phi: f32) -> Option<(u32, i32)> {
        fixed_sample(load, phi)
    }
    #[inline(always)]
    fn estimate(&self, (load, angle): (u32, i32)) -> Result<FixedEstimate, Error> {
        FixedEllipticScene::estimate(self, load, angle)
    }
    fn answer(e: &FixedEstimate) -> Answer {
        fixed_answer(e)
    }
}

impl Core for FixedLineScene {
    const NAME: &'static str = "line";
    const NUMBER: &'static str = "fixed";
    const TOLERANCE: f32 = 1e-4;
    type Sample = (u32, i32);
    type Output = FixedEstimate;
    fn sample(load: f32, phi: f32) -> Option<(u32, i32)> {
        fixed_sample(load, phi)
    }
    #[inline(always)]
    fn estimate(&self, (load, angle): (u32, i32)) -> Result<FixedEstimate, Error> {
        FixedLineScene::estimate(self, load, angle)
    }
    fn answer(e: &FixedEstimate) -> Answer {
        fixed_answer(e)
    }
}

/// The per-sample call whose stack and instructions are measured: the estimator and
/// nothing else (it is inlined here).
#[inline(never)]
fn call<C: Core>(core: &C, sample: C::Sample) -> Result<C::Output, Error> {
    core.estimate(sample)
}

#[cortex_m_rt::entry]
fn main() -> ! {
    let peripherals = cortex_m::Peripherals::take().expect("first and only take");
    let counter = Counter::new(peripherals.SYST);
    defmt::println!(
        "misalign firmware: demo scene, {=usize} elliptic and {=usize} line samples, {=str} core; SysTick ticks per 1000 instructions {=u32}",
        trace::ELLIPTIC.len(),
        trace::LINE.len(),
        F32,
        counter.ticks_per_1000()
    );
    let (r1, r2, g, nu, mu) = trace::SCENE;
    let Ok(scene) = Scene::new(r1, r2, g, nu, mu) else {
        support::exit(2)
    };
    let failures = if cfg!(target_abi = "eabihf") {
        // With an FPU: the f32 core.
        let prepared = EllipticScene::new(&scene).and_then(|e| Ok((e, LineScene::new(&scene)?)));
        let Ok((elliptic, line)) = prepared else {
            defmt::error!(
                "cannot prepare the demo scene: {}",
                defmt::Debug2Format(&prepared.err())
            );
            support::exit(2)
        };
        run(&elliptic, &trace::ELLIPTIC, &ELLIPTIC_EXPECTED, &counter)
            + run(&line, &trace::LINE, &LINE_EXPECTED, &counter)
    } else {
        // Without one: the fixed-point core.
        let prepared = FixedEllipticScene::new(&scene, LOAD_LSB, ANGLE_LSB)
            .and_then(|e| Ok((e, FixedLineScene::new(&scene, LOAD_LSB, ANGLE_LSB)?)));
        let Ok((elliptic, line)) = prepared else {
            defmt::error!(
                "cannot prepare the demo scene: {}",
                defmt::Debug2Format(&prepared.err())
            );
            support::exit(2)
        };
        run(&elliptic, &trace::ELLIPTIC, &ELLIPTIC_EXPECTED, &counter)
            + run(&line, &trace::LINE, &LINE_EXPECTED, &counter)
    };
    if failures == 0 {
        defmt::println!("all answers within the core's tolerance of the reference");
        support::exit(0)
    }
    defmt::error!("{=usize} answers differ from the reference", failures);
    support::exit(1)
}

/// Runs `core` over `trace`: first every sample once on a painted stack (the deepest
/// stack use of [`call`]), then every sample under the instruction counter, then the
/// check of every answer. Returns the number of mismatches.
fn run<C: Core, const N: usize>(
    core: &C,
    trace: &[(f32, f32); N],
    expected: &[Answer; N],
    counter: &Counter,
) -> usize {
    let samples = trace.map(|(load, phi)| C::sample(load, phi));
    let mut outputs = [None; N];
    let sp = stack::paint();
    for (out, sample) in outputs.iter_mut().zip(&samples) {
        *out = sample.map(|s| call(core, s));
    }
    let stack_bytes = stack::used(sp);

    let (mut max, mut sum, mut measured) = (0u32, 0u32, 0u32);
    for &sample in samples.iter().flatten() {
        let (_, n) = counter.measure(|| core::hint::black_box(call(core, sample)));
        max = max.max(n);
        sum += n;
        measured += 1;
    }

    let (mut failures, mut worst) = (0, 0.0f32);
    for ((&(load, phi), out), want) in trace.iter().zip(&outputs).zip(expected) {
        let Some(out) = out else {
            defmt::info!(
                "{=str} P={=f32} phi={=f32}: outside the {=str} core's input range, skipped",
                C::NAME,
                load,
                phi,
                C::NUMBER
            );
            continue;
        };
        match out {
            Ok(o) => {
                let got = C::answer(o);
                let ok = matches(&got, want, phi, C::TOLERANCE);
                worst = worst.max(worst_error(&got, want));
                failures += usize::from(!ok);
                if ok {
                    defmt::info!(
                        "{=str} P={=f32} phi={=f32}: d/b={=f32} F={=f32} phi0={} margin={} gross={=bool} risk={=bool}",
                        C::NAME,
                        load,
                        phi,
                        got.slip_ratio,
                        got.axial_force,
                        got.critical_angle,
                        got.margin,
                        got.gross,
                        got.risk
                    );
                } else {
                    defmt::error!(
                        "{=str} P={=f32} phi={=f32}: got {} want {}",
                        C::NAME,
                        load,
                        phi,
                        got,
                        want
                    );
                }
            }
            Err(e) => {
                failures += 1;
                defmt::error!(
                    "{=str} P={=f32} phi={=f32}: error {} (want {})",
                    C::NAME,
                    load,
                    phi,
                    defmt::Debug2Format(e),
                    want
                );
            }
        }
    }
    defmt::println!(
        "result model={=str} core={=str} samples={=u32} failures={=usize} worst_relative_error={=f32} stack_bytes={=usize} instructions_max={=u32} instructions_mean={=u32}",
        C::NAME,
        C::NUMBER,
        measured,
        failures,
        worst,
        stack_bytes,
        max,
        sum / measured.max(1)
    );
    failures
}

/// The largest relative error of d/b, F and phi0 (against the reference rounded to
/// f32; exact agreement, zeros and infinities included, counts as 0, and so do
/// subnormal values, which f32 holds to an absolute 2^-149 only).
fn worst_error(got: &Answer, want: &Answer) -> f32 {
    let rel = |g: f32, w: f32| {
        if g == w || w.abs() < f32::MIN_POSITIVE {
            0.0
        } else {
            ((g - w) / w).abs()
        }
    };
    let critical = match (got.critical_angle, want.critical_angle) {
        (Some(g), Some(w)) => rel(g, w),
        _ => 0.0,
    };
    rel(got.slip_ratio, want.slip_ratio)
        .max(rel(got.axial_force, want.axial_force))
        .max(critical)
}

/// Within `tolerance` (the core's, [`Core::TOLERANCE`]) of the reference, or, below
/// f32's normal range (F of a subnormal load), within two steps of 2^-149 (the
/// reference's rounding to f32 and the core's); the regime and the risk flag may differ
/// only within that tolerance of their thresholds (d/b = 1 and 0.8).
fn matches(got: &Answer, want: &Answer, phi: f32, tolerance: f32) -> bool {
    let tiny = 2.0 * f32::from_bits(1);
    let close =
        |g: f32, w: f32| g == w || (g - w).abs() <= tolerance * w.abs() || (g - w).abs() <= tiny;
    let near = |threshold: f32| (want.slip_ratio - threshold).abs() <= tolerance * threshold;
    let critical = match (got.critical_angle, want.critical_angle) {
        (Some(g), Some(w)) => close(g, w),
        (None, None) => true,
        _ => false,
    };
    // The margin phi0 - |phi| cancels: hold it to the error of the larger term.
    let margin = match (got.margin, want.margin, want.critical_angle) {
        (Some(g), Some(w), Some(phi0)) => {
            g == w || (g - w).abs() <= tolerance * phi0.max(phi.abs())
        }
        (None, None, _) => true,
        _ => false,
    };
    close(got.slip_ratio, want.slip_ratio)
        && close(got.axial_force, want.axial_force)
        && critical
        && margin
        && (got.gross == want.gross || near(1.0))
        && (got.risk == want.risk || near(0.8))
}
