//! The power-on self-test (Cortex-M only): the estimator of this target against the
//! f64 reference's answers on the built-in trace (`trace.rs`), before the node starts.
//!
//! Every core is reached through the library's estimator contract,
//! [`misalign::Estimator`]: the f32 core where there is an FPU (Cortex-M4F, M7), the
//! fixed-point core where there is none (Cortex-M0, M3). The trace, the check against
//! the reference, the stack and instruction measurements are the same for both; the
//! `result` lines feed the estimator rows of `cargo xtask firmware`'s size table.

use crate::trace::{self, Answer};
use misalign::fixed::{FixedEllipticScene, FixedLineScene};
use misalign::float::{EllipticScene, LineScene};
use misalign::reference::Regime;
use misalign::{Error, Estimate, Estimator, Scene};
use misalign_harness::support::{counter::Counter, stack};

/// The fixed-point core's LSBs in the firmware: 1 mN and 10 prad per count.
const LOAD_LSB: f64 = 1e-3;
const ANGLE_LSB: f64 = 1e-11;

/// The core this target's self-test runs, as the log and `cargo xtask firmware` name
/// it: the f32 core with an FPU, the fixed-point core without one (thumbv6m, thumbv7m).
const CORE: &str = if cfg!(target_abi = "eabihf") {
    "f32"
} else {
    "fixed"
};

/// How the firmware runs one prepared core: its name in the log and in `cargo xtask
/// firmware`'s table, and what it is held to.
struct Run<'a, E> {
    core: &'a E,
    /// Contact model ("elliptic", "line").
    model: &'static str,
    /// Number format ("f32", "fixed").
    number: &'static str,
    /// Relative tolerance against the reference: the core's bound on the reference
    /// data (f32 2e-6, fixed point 1e-4).
    tolerance: f32,
    /// The fixed-point core's `(load, angle)` LSBs: a sample is estimated only if its
    /// counts hold it to 1e-5 (else it is skipped and said so); `None` for f32.
    lsb: Option<(f64, f64)>,
}

/// The f32 core's run of `core`.
fn f32_run<'a, E>(core: &'a E, model: &'static str) -> Run<'a, E> {
    Run {
        core,
        model,
        number: "f32",
        tolerance: 2e-6,
        lsb: None,
    }
}

/// The fixed-point core's run of `core`.
fn fixed_run<'a, E>(core: &'a E, model: &'static str) -> Run<'a, E> {
    Run {
        core,
        model,
        number: "fixed",
        tolerance: 1e-4,
        lsb: Some((LOAD_LSB, ANGLE_LSB)),
    }
}

/// Whether `x` is 0 or holds at least 1e5 counts of `lsb` (quantised to 5e-6 at most).
fn representable(x: f32, lsb: f64) -> bool {
    x == 0.0 || libm::fabs(x as f64) / lsb >= 1e5 - 0.5
}

fn answer(e: &Estimate) -> Answer {
    Answer {
        slip_ratio: e.slip_ratio,
        axial_force: e.axial_force,
        critical_angle: e.critical_angle,
        margin: e.margin,
        gross: e.regime == Regime::Gross,
        risk: e.microslip_risk,
    }
}

/// The per-sample call whose stack and instructions are measured: the estimator and
/// nothing else (it is inlined here).
#[inline(never)]
fn call<E: Estimator>(core: &E, load: E::Load, phi: E::Angle) -> Result<E::Output, Error> {
    core.estimate(load, phi)
}

/// The self-test: the core of this target over the built-in trace, every answer
/// against the reference's. Returns the number of mismatches, or the error of a scene
/// the core refused.
///
/// Out of line in the node with flash: inlined, its locals (about 1.9 KiB on the
/// Cortex-M0) stay in `main`'s frame under the node, which the micro:bit's 16 KiB of
/// RAM do not hold beside the node's storage.
#[cfg_attr(feature = "modbus-flash", inline(never))]
pub fn run_all(counter: &Counter) -> Result<usize, Error> {
    defmt::println!(
        "self-test: demo scene, {=usize} elliptic and {=usize} line samples, {=str} core; SysTick ticks per 1000 instructions {=u32}",
        trace::ELLIPTIC.len(),
        trace::LINE.len(),
        CORE,
        counter.ticks_per_1000()
    );
    let scene = Scene::DEMO;
    let failures = if cfg!(target_abi = "eabihf") {
        // With an FPU: the f32 core.
        let (elliptic, line) = prepared(EllipticScene::new(&scene), LineScene::new(&scene))?;
        run(
            f32_run(&elliptic, "elliptic"),
            &trace::ELLIPTIC,
            &trace::ELLIPTIC_EXPECTED,
            counter,
        ) + run(
            f32_run(&line, "line"),
            &trace::LINE,
            &trace::LINE_EXPECTED,
            counter,
        )
    } else {
        // Without one: the fixed-point core.
        let (elliptic, line) = prepared(
            FixedEllipticScene::new(&scene, LOAD_LSB, ANGLE_LSB),
            FixedLineScene::new(&scene, LOAD_LSB, ANGLE_LSB),
        )?;
        run(
            fixed_run(&elliptic, "elliptic"),
            &trace::ELLIPTIC,
            &trace::ELLIPTIC_EXPECTED,
            counter,
        ) + run(
            fixed_run(&line, "line"),
            &trace::LINE,
            &trace::LINE_EXPECTED,
            counter,
        )
    };
    if failures == 0 {
        defmt::println!("self-test: all answers within the core's tolerance of the reference");
    } else {
        defmt::error!(
            "self-test: {=usize} answers differ from the reference",
            failures
        );
    }
    Ok(failures)
}

/// Both prepared scenes, or the first error.
fn prepared<A, B>(elliptic: Result<A, Error>, line: Result<B, Error>) -> Result<(A, B), Error> {
    Ok((elliptic?, line?))
}

/// Runs the core over `trace`: first every sample once on a painted stack (the deepest
/// stack use of [`call`]), then every sample under the instruction counter, then the
/// check of every answer. Returns the number of mismatches.
fn run<E: Estimator, const N: usize>(
    run: Run<'_, E>,
    trace: &[(f32, f32); N],
    expected: &[Answer; N],
    counter: &Counter,
) -> usize {
    let core = run.core;
    let samples = trace.map(|(load, phi)| {
        let fits = run
            .lsb
            .is_none_or(|(p, a)| representable(load, p) && representable(phi, a));
        fits.then(|| core.input(load, phi).ok()).flatten()
    });
    let mut outputs = [None; N];
    let sp = stack::paint();
    for (out, sample) in outputs.iter_mut().zip(&samples) {
        *out = sample.map(|(load, phi)| call(core, load, phi));
    }
    let stack_bytes = stack::used(sp);

    let (mut max, mut sum, mut measured) = (0u32, 0u32, 0u32);
    for &(load, phi) in samples.iter().flatten() {
        let (_, n) = counter.measure(|| core::hint::black_box(call(core, load, phi)));
        max = max.max(n);
        sum += n;
        measured += 1;
    }

    let mut failures = 0;
    let mut worst = 0.0f32;
    for ((&(load, phi), out), want) in trace.iter().zip(&outputs).zip(expected) {
        let Some(out) = out else {
            defmt::info!(
                "{=str} P={=f32} phi={=f32}: outside the {=str} core's input range, skipped",
                run.model,
                load,
                phi,
                run.number
            );
            continue;
        };
        let got = out
            .as_ref()
            .map(|o| answer(&core.to_estimate(o)))
            .map_err(|e| *e);
        let ok = check(&run, (load, phi), got, want);
        if let Ok(got) = got {
            worst = worst.max(worst_error(&got, want));
        }
        failures += usize::from(!ok);
    }
    defmt::println!(
        "result model={=str} core={=str} samples={=u32} failures={=usize} worst_relative_error={=f32} stack_bytes={=usize} instructions_max={=u32} instructions_mean={=u32}",
        run.model,
        run.number,
        measured,
        failures,
        worst,
        stack_bytes,
        max,
        sum / measured.max(1)
    );
    failures
}

/// Logs one answer against the reference's and says whether it matches.
fn check<E>(
    run: &Run<'_, E>,
    (load, phi): (f32, f32),
    got: Result<Answer, Error>,
    want: &Answer,
) -> bool {
    match got {
        Ok(got) if matches(&got, want, phi, run.tolerance) => {
            defmt::info!(
                "{=str} P={=f32} phi={=f32}: d/b={=f32} F={=f32} phi0={} margin={} gross={=bool} risk={=bool}",
                run.model,
                load,
                phi,
                got.slip_ratio,
                got.axial_force,
                got.critical_angle,
                got.margin,
                got.gross,
                got.risk
            );
            true
        }
        Ok(got) => {
            defmt::error!(
                "{=str} P={=f32} phi={=f32}: got {} want {}",
                run.model,
                load,
                phi,
                got,
                want
            );
            false
        }
        Err(e) => {
            defmt::error!(
                "{=str} P={=f32} phi={=f32}: error {} (want {})",
                run.model,
                load,
                phi,
                defmt::Debug2Format(&e),
                want
            );
            false
        }
    }
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

/// Within `tolerance` (the core's, [`Run::tolerance`]) of the reference, or, below
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
