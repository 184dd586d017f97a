//! The row loops of each model: a scene prepared once per run of rows with the same
//! constants, then one estimate per row written into the output slices.

use super::{Inputs, NONE, OK, Outputs, flags, status_of};
use crate::fixed::{FixedAuto, FixedEllipticScene};
use crate::float::Auto;
use crate::reference::{self, ANGLE_LIMIT, ContactModel, ModelChoice, Regime, Validity};
use crate::{Error, Scene};

/// One row's answer.
struct Row {
    slip_ratio: f64,
    axial_force: f64,
    critical_angle: Option<f64>,
    regime: Regime,
    model: ContactModel,
    flags: u8,
}

/// No further numbers (the cores).
const NO_DETAILS: [f64; 12] = [f64::NAN; 12];

fn regime_code(r: Regime) -> u8 {
    match r {
        Regime::Partial => 0,
        Regime::Gross => 1,
    }
}

fn model_code(m: ContactModel) -> u8 {
    match m {
        ContactModel::Elliptic => 0,
        ContactModel::Line => 1,
    }
}

/// Writes row `i`; returns 1 for a refused row, 0 otherwise.
#[inline(always)]
fn put(out: &mut Outputs<'_>, i: usize, row: Result<Row, Error>, details: &[f64; 12]) -> usize {
    let (bad, values) = match row {
        Ok(r) => (
            0,
            (
                r.slip_ratio,
                r.axial_force,
                r.critical_angle.unwrap_or(f64::NAN),
                regime_code(r.regime),
                model_code(r.model),
                r.flags,
                OK,
            ),
        ),
        Err(e) => (
            1,
            (f64::NAN, f64::NAN, f64::NAN, NONE, NONE, 0, status_of(e)),
        ),
    };
    // The lengths were checked by `rows`: `get_mut` never misses.
    fn set<T>(slice: &mut [T], i: usize, x: T) {
        if let Some(v) = slice.get_mut(i) {
            *v = x;
        }
    }
    set(out.slip_ratio, i, values.0);
    set(out.axial_force, i, values.1);
    set(out.critical_angle, i, values.2);
    set(out.regime, i, values.3);
    set(out.model, i, values.4);
    set(out.flags, i, values.5);
    set(out.status, i, values.6);
    if let Some(d) = &mut out.details {
        let values = if bad == 0 { details } else { &NO_DETAILS };
        for (slice, x) in d.slices().into_iter().zip(values) {
            if let Some(v) = slice.get_mut(i) {
                *v = *x;
            }
        }
    }
    bad
}

/// A prepared scene of the current run of rows, rebuilt when the constants change.
struct Cache<T> {
    key: Option<[u64; 6]>,
    value: Result<T, Error>,
}

impl<T> Cache<T> {
    fn new() -> Self {
        Cache {
            key: None,
            value: Err(Error::OutOfRange),
        }
    }

    #[inline]
    fn get(
        &mut self,
        inputs: &Inputs<'_>,
        i: usize,
        prepare: impl FnOnce(&Scene) -> Result<T, Error>,
    ) -> &Result<T, Error> {
        let key = inputs.scene_key(i);
        if self.key != Some(key) {
            self.key = Some(key);
            self.value = inputs.scene(i).and_then(|s| prepare(&s));
        }
        &self.value
    }
}

/// The flags of a validity, and whether the row has no critical angle.
fn flag_bits(v: &Validity, no_critical_angle: bool) -> u8 {
    let mut bits = 0;
    for (raised, bit) in [
        (v.large_angle, flags::LARGE_ANGLE),
        (v.high_pressure, flags::HIGH_PRESSURE),
        (v.longer_than_rollers, flags::LONGER_THAN_ROLLERS),
        (v.near_model_switch, flags::NEAR_MODEL_SWITCH),
        (v.round_ellipse, flags::ROUND_ELLIPSE),
        (no_critical_angle, flags::NO_CRITICAL_ANGLE),
    ] {
        if raised {
            bits |= bit;
        }
    }
    bits
}

/// The flags a core can say from its own answer: large angle, near the switch, no
/// critical angle.
fn core_flags(phi: f64, critical_angle: Option<f64>, near_model_switch: bool) -> u8 {
    let mut bits = 0;
    if libm::fabs(phi) > ANGLE_LIMIT || critical_angle.is_none_or(|c| c > ANGLE_LIMIT) {
        bits |= flags::LARGE_ANGLE;
    }
    if near_model_switch {
        bits |= flags::NEAR_MODEL_SWITCH;
    }
    if critical_angle.is_none() {
        bits |= flags::NO_CRITICAL_ANGLE;
    }
    bits
}

/// The fast path's elliptic answer as a row.
#[inline(always)]
fn fast_row(e: &reference::fast::Elliptic) -> Row {
    Row {
        slip_ratio: e.slip_ratio,
        axial_force: e.axial_force,
        critical_angle: Some(e.critical_angle),
        regime: e.regime,
        model: ContactModel::Elliptic,
        flags: flag_bits(&e.validity, false),
    }
}

/// A row the fast path left to the reference (or answered with line contact), out of
/// the eight-row loop.
#[cold]
#[inline(never)]
fn other_row(
    out: &mut Outputs<'_>,
    i: usize,
    scene: &Scene,
    answer: Option<reference::fast::Answer>,
    load: f64,
    phi: f64,
    choice: ModelChoice,
) -> usize {
    put_reference(out, i, reference_row(scene, answer, load, phi, choice))
}

/// The reference's answer for one row, and its further numbers: the fast path's
/// `answer` where it has one, else the reference's.
#[inline]
fn reference_row(
    scene: &Scene,
    answer: Option<reference::fast::Answer>,
    load: f64,
    phi: f64,
    choice: ModelChoice,
) -> Result<(Row, [f64; 12]), Error> {
    use reference::fast::Answer;
    let est = match answer {
        Some(Answer::Elliptic(e)) => return Ok((fast_row(&e), NO_DETAILS)),
        Some(Answer::Line(l)) => reference::Solution::Line(l),
        None => reference::estimate_with(scene, load, phi, choice)?,
    };
    let force = est.axial_force(scene);
    Ok(match est {
        reference::Solution::Elliptic(e) => (
            Row {
                slip_ratio: e.slip_ratio,
                axial_force: force,
                critical_angle: e.critical_angle,
                regime: e.regime,
                model: ContactModel::Elliptic,
                flags: flag_bits(&e.validity, e.critical_angle.is_none()),
            },
            [
                e.shape.theta,
                e.shape.kprime,
                e.shape.m,
                e.shape.n,
                e.a,
                e.b,
                e.p0,
                e.d,
                e.pstar,
                e.p0star,
                e.critical_theta.unwrap_or(f64::NAN),
                f64::NAN,
            ],
        ),
        reference::Solution::Line(l) => (
            Row {
                slip_ratio: l.slip_ratio,
                axial_force: force,
                critical_angle: l.critical_angle,
                regime: l.regime,
                model: ContactModel::Line,
                flags: flag_bits(&l.validity, l.critical_angle.is_none()),
            },
            [
                f64::NAN,
                f64::NAN,
                f64::NAN,
                f64::NAN,
                f64::NAN,
                l.b,
                l.p0,
                l.d,
                l.pstar,
                l.p0star,
                f64::NAN,
                l.radius,
            ],
        ),
    })
}

/// Rows the reference's fast path takes at a time (their latency chains side by side).
const LANES: usize = 8;

/// Writes a reference row; returns 1 for a refused row.
fn put_reference(
    out: &mut Outputs<'_>,
    i: usize,
    answer: Result<(Row, [f64; 12]), Error>,
) -> usize {
    match answer {
        Ok((row, details)) => put(out, i, Ok(row), &details),
        Err(e) => put(out, i, Err(e), &NO_DETAILS),
    }
}

pub(super) fn reference(inputs: &Inputs<'_>, out: &mut Outputs<'_>, n: usize) -> usize {
    let details = out.details.is_some();
    let prepare = |s: &Scene| Ok((*s, reference::fast::Prepared::new(s, inputs.choice)));
    let mut cache = Cache::new();
    let mut bad = 0;
    let mut start = 0;
    // One scene for every row and no details: the fast path LANES rows at a time.
    if !details
        && inputs.one_scene_for_all()
        && let Ok((scene, Some(fast))) = cache.get(inputs, 0, prepare)
    {
        let (scene, fast) = (*scene, *fast);
        while start + LANES <= n {
            let load: [f64; LANES] = core::array::from_fn(|k| inputs.load.at(start + k));
            let phi: [f64; LANES] = core::array::from_fn(|k| inputs.phi.at(start + k));
            let answers = fast.estimate_rows(&load, &phi);
            for (k, answer) in answers.into_iter().enumerate() {
                bad += match answer {
                    // The ellipse's rows (most) straight into the columns.
                    Some(reference::fast::Answer::Elliptic(e)) => {
                        put(out, start + k, Ok(fast_row(&e)), &NO_DETAILS)
                    }
                    _ => other_row(
                        out,
                        start + k,
                        &scene,
                        answer,
                        load[k],
                        phi[k],
                        inputs.choice,
                    ),
                };
            }
            start += LANES;
        }
    }
    for i in start..n {
        let (load, phi) = (inputs.load.at(i), inputs.phi.at(i));
        let answer = match cache.get(inputs, i, prepare) {
            Ok((scene, fast)) => {
                let answer = fast
                    .filter(|_| !details)
                    .and_then(|f| f.estimate(load, phi));
                reference_row(scene, answer, load, phi, inputs.choice)
            }
            Err(e) => Err(*e),
        };
        bad += put_reference(out, i, answer);
    }
    bad
}

/// An f64 input as the f32 core takes it: NaN and infinities pass (the core's typed
/// errors name them); a finite value outside f32's range, or one that rounds to 0, is
/// out of range.
#[inline(always)]
fn narrow(x: f64, error: Error) -> Result<f32, Error> {
    let y = x as f32;
    if x.is_finite() && (y.is_infinite() || (y == 0.0 && x != 0.0)) {
        return Err(error);
    }
    Ok(y)
}

#[inline(always)]
fn float_row(core: &Auto, load: f64, phi: f64) -> Result<Row, Error> {
    // As the reference: |phi| up to f64's FRAC_PI_2; above it, refused before f32's
    // rounding would carry it down onto f32's FRAC_PI_2, which the core accepts.
    if libm::fabs(phi) > core::f64::consts::FRAC_PI_2 {
        return Err(Error::Angle);
    }
    let e = core.estimate(narrow(load, Error::Load)?, narrow(phi, Error::Angle)?)?;
    let est = e.estimate;
    let critical = est.critical_angle.map(f64::from);
    Ok(Row {
        slip_ratio: f64::from(est.slip_ratio),
        axial_force: f64::from(est.axial_force),
        critical_angle: critical,
        regime: est.regime,
        model: e.model,
        flags: core_flags(phi, critical, e.near_model_switch),
    })
}

pub(super) fn float(inputs: &Inputs<'_>, out: &mut Outputs<'_>, n: usize) -> usize {
    let prepare = |s: &Scene| Auto::with_choice(s, inputs.choice);
    let mut bad = 0;
    if inputs.one_scene_for_all() {
        let core = inputs.scene(0).and_then(|s| prepare(&s));
        for i in 0..n {
            let row = match &core {
                Ok(c) => float_row(c, inputs.load.at(i), inputs.phi.at(i)),
                Err(e) => Err(*e),
            };
            bad += put(out, i, row, &NO_DETAILS);
        }
    } else {
        let mut cache = Cache::new();
        for i in 0..n {
            let row = match cache.get(inputs, i, prepare) {
                Ok(c) => float_row(c, inputs.load.at(i), inputs.phi.at(i)),
                Err(e) => Err(*e),
            };
            bad += put(out, i, row, &NO_DETAILS);
        }
    }
    bad
}

/// A fixed-point scene with its LSBs (N and rad per count).
struct FixedCore {
    core: FixedAuto,
    load_lsb: f64,
    angle_lsb: f64,
}

fn prepare_fixed(
    scene: &Scene,
    choice: ModelChoice,
    load_lsb: f64,
    angle_lsb: Option<f64>,
) -> Result<FixedCore, Error> {
    let angle_lsb = angle_lsb.unwrap_or_else(|| {
        if scene.is_plane() || choice == ModelChoice::Line {
            1e-10
        } else {
            libm::fmax(FixedEllipticScene::min_angle_lsb(scene), 1e-10)
        }
    });
    if !(load_lsb.is_finite() && load_lsb > 0.0 && angle_lsb.is_finite() && angle_lsb > 0.0) {
        return Err(Error::OutOfRange);
    }
    Ok(FixedCore {
        core: FixedAuto::with_choice(scene, load_lsb, angle_lsb, choice)?,
        load_lsb,
        angle_lsb,
    })
}

#[inline]
fn fixed_row(f: &FixedCore, load: f64, phi: f64) -> Result<Row, Error> {
    if !(load.is_finite() && load >= 0.0) {
        return Err(Error::Load);
    }
    // As the reference: |phi| up to FRAC_PI_2 (the f64 below the true pi/2).
    if phi.is_nan() || libm::fabs(phi) > core::f64::consts::FRAC_PI_2 {
        return Err(Error::Angle);
    }
    let counts = libm::round(load / f.load_lsb);
    let angle = libm::round(phi / f.angle_lsb);
    if counts > u32::MAX as f64 || libm::fabs(angle) > i32::MAX as f64 {
        return Err(Error::OutOfRange);
    }
    let e = f.core.estimate(counts as u32, angle as i32)?;
    let est = e.estimate;
    let critical = est.critical_angle.map(|c| c.to_f64());
    let force = est.axial_force.to_f64();
    Ok(Row {
        slip_ratio: est.slip_ratio.to_f64(),
        axial_force: if est.axial_force_negative {
            -force
        } else {
            force
        },
        critical_angle: critical,
        regime: est.regime,
        model: e.model,
        flags: core_flags(phi, critical, e.near_model_switch),
    })
}

pub(super) fn fixed(
    inputs: &Inputs<'_>,
    out: &mut Outputs<'_>,
    n: usize,
    load_lsb: f64,
    angle_lsb: Option<f64>,
) -> usize {
    let prepare = |s: &Scene| prepare_fixed(s, inputs.choice, load_lsb, angle_lsb);
    let mut cache = Cache::new();
    let mut bad = 0;
    for i in 0..n {
        let row = match cache.get(inputs, i, prepare) {
            Ok(c) => fixed_row(c, inputs.load.at(i), inputs.phi.at(i)),
            Err(e) => Err(*e),
        };
        bad += put(out, i, row, &NO_DETAILS);
    }
    bad
}
