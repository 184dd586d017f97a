//! The row loops of each model: a scene prepared once per run of rows with the same
//! constants, then one estimate per row written into the output slices.

use super::{Column, Counts, Inputs, NONE, OK, Outputs, flags, status_of};
use crate::fixed::{FixedAuto, FixedEllipticScene, exact_lsb};
use crate::float::block::{BLOCK, Block, HotPerSample, hot_of};
use crate::float::{Auto, AutoEstimate, EllipticScene};
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

/// One row's cells: d/b, F, phi0, regime, model, flags, status.
type Cells = (f64, f64, f64, u8, u8, u8, u8);

/// A row's cells, and 1 for a refused row (0 otherwise).
#[inline(always)]
fn cells(row: Result<Row, Error>) -> (usize, Cells) {
    match row {
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
    }
}

/// The main output columns of a core's loop.
type Columns<'o> = (
    &'o mut [f64],
    &'o mut [f64],
    &'o mut [f64],
    &'o mut [u8],
    &'o mut [u8],
    &'o mut [u8],
    &'o mut [u8],
);

/// The main output columns cut to the batch's length `n` (which `rows` checked), so
/// that a loop over them needs no other bound; `None` where one is shorter.
fn columns<'o>(out: &'o mut Outputs<'_>, n: usize) -> Option<Columns<'o>> {
    Some((
        out.slip_ratio.get_mut(..n)?,
        out.axial_force.get_mut(..n)?,
        out.critical_angle.get_mut(..n)?,
        out.regime.get_mut(..n)?,
        out.model.get_mut(..n)?,
        out.flags.get_mut(..n)?,
        out.status.get_mut(..n)?,
    ))
}

/// The reference's further numbers, which the cores do not compute: NaN.
fn no_details(out: &mut Outputs<'_>) {
    if let Some(d) = &mut out.details {
        for slice in d.slices() {
            slice.fill(f64::NAN);
        }
    }
}

/// Writes row `i`; returns 1 for a refused row, 0 otherwise.
#[inline(always)]
fn put(out: &mut Outputs<'_>, i: usize, row: Result<Row, Error>, details: &[f64; 12]) -> usize {
    let (bad, values) = cells(row);
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

/// Rows the reference's fast path takes at a time, in SIMD lanes.
const LANES: usize = 16;

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

/// A row's scene and its fast path (`None` with details: every row the reference's).
type Prepared = (Scene, Option<reference::fast::Prepared>);

/// Row `i` one at a time: its scene prepared (once per run of equal constants), the fast
/// path's answer where it has one, else the reference's.
fn reference_one(
    inputs: &Inputs<'_>,
    out: &mut Outputs<'_>,
    i: usize,
    cache: &mut Cache<Prepared>,
) -> usize {
    let details = out.details.is_some();
    let prepare = |s: &Scene| {
        let fast = if details {
            None
        } else {
            reference::fast::Prepared::new(s, inputs.choice)
        };
        Ok((*s, fast))
    };
    let (load, phi) = (inputs.load.at(i), inputs.phi.at(i));
    let answer = match cache.get(inputs, i, prepare) {
        Ok((scene, fast)) => {
            let answer = fast.and_then(|f| f.estimate(load, phi));
            reference_row(scene, answer, load, phi, inputs.choice)
        }
        Err(e) => Err(*e),
    };
    put_reference(out, i, answer)
}

/// [`reference_one`] out of line: the rows the lanes leave (refused, outside the fast
/// path's domain, line contact).
#[cold]
#[inline(never)]
fn reference_cold(
    inputs: &Inputs<'_>,
    out: &mut Outputs<'_>,
    i: usize,
    cache: &mut Cache<Prepared>,
) -> usize {
    reference_one(inputs, out, i, cache)
}

#[inline(always)]
pub(super) fn reference(inputs: &Inputs<'_>, out: &mut Outputs<'_>, n: usize) -> usize {
    let mut cache = Cache::new();
    if out.details.is_some() || inputs.choice == ModelChoice::Line {
        // Every row the reference's: with its further numbers, or forced line contact
        // (which the fast path never takes).
        return (0..n)
            .map(|i| reference_one(inputs, out, i, &mut cache))
            .sum();
    }
    if !inputs.one_scene_for_all() {
        return reference_lanes(inputs, out, n, &mut cache, PerRowScenes(inputs));
    }
    let fast = inputs
        .scene(0)
        .ok()
        .and_then(|s| reference::fast::Prepared::new(&s, inputs.choice));
    match fast {
        Some(fast) => reference_lanes(inputs, out, n, &mut cache, *fast.constants()),
        // A refused scene, or one outside the fast path: row by row.
        None => (0..n)
            .map(|i| reference_one(inputs, out, i, &mut cache))
            .sum(),
    }
}

/// The scenes of a block of LANES rows from `start` (`lanes` of them in the batch): their
/// constants for the fast path, and which lanes may take it. A method, not a closure,
/// so that it inlines into each build of the batch (a closure is compiled where it is
/// written, without the features of `estimate_avx2`).
trait LaneScenes {
    type Lanes: reference::fast::SceneLanes;
    fn scenes(&mut self, start: usize, lanes: usize) -> (Self::Lanes, [bool; LANES]);
}

/// One scene for every row, prepared once.
impl LaneScenes for reference::fast::Constants {
    type Lanes = reference::fast::Constants;
    #[inline(always)]
    fn scenes(&mut self, _: usize, _: usize) -> (Self::Lanes, [bool; LANES]) {
        (*self, [true; LANES])
    }
}

/// A scene per row ([`per_lane_scenes`]).
struct PerRowScenes<'i, 'a>(&'i Inputs<'a>);

impl LaneScenes for PerRowScenes<'_, '_> {
    type Lanes = reference::fast::PerLane<LANES>;
    #[inline(always)]
    fn scenes(&mut self, start: usize, lanes: usize) -> (Self::Lanes, [bool; LANES]) {
        per_lane_scenes(self.0, start, lanes)
    }
}

/// The fast path's constants of the scenes of rows `start..start + LANES` (as many as
/// there are), and which lanes have a scene that [`Scene::new`] accepts and the fast
/// path takes.
#[inline(always)]
fn per_lane_scenes(
    inputs: &Inputs<'_>,
    start: usize,
    lanes: usize,
) -> (reference::fast::PerLane<LANES>, [bool; LANES]) {
    let [r1, r2, g, nu, mu, length] = scene_lanes::<LANES>(inputs, start);
    let mut k = reference::fast::PerLane {
        c: [0.0; LANES],
        inverse_c: [0.0; LANES],
        friction: [0.0; LANES],
        pressure_per_slip: [0.0; LANES],
        slip_cubed: [0.0; LANES],
        g_cubed_per_load: [0.0; LANES],
        ratio_cubed_per_load: [0.0; LANES],
    };
    let mut valid = [false; LANES];
    let has_length = inputs.length.is_some();
    for i in 0..LANES {
        let l = if has_length { Some(length[i]) } else { None };
        let (c, normal) = reference::fast::Constants::of(r1[i], r2[i], g[i], nu[i], mu[i], l);
        valid[i] =
            normal & (i < lanes) & Scene::accepts_rollers(r1[i], r2[i], g[i], nu[i], mu[i], l);
        k.c[i] = c.c;
        k.inverse_c[i] = c.inverse_c;
        k.friction[i] = c.friction;
        k.pressure_per_slip[i] = c.pressure_per_slip;
        k.slip_cubed[i] = c.slip_cubed;
        k.g_cubed_per_load[i] = c.g_cubed_per_load;
        k.ratio_cubed_per_load[i] = c.ratio_cubed_per_load;
    }
    (k, valid)
}

/// The scene columns R1, R2, G, nu, mu, length of rows `start..start + N` (NaN past the
/// end; the length 0 without one).
#[inline(always)]
fn scene_lanes<const N: usize>(inputs: &Inputs<'_>, start: usize) -> [[f64; N]; 6] {
    let length = inputs.length.unwrap_or(Column::One(0.0));
    // Each column by name, not by `map` over them: a closure would not inline into the
    // AVX2 build (and `map` copies the arrays once more).
    [
        lanes_of(inputs.r1, start),
        lanes_of(inputs.r2, start),
        lanes_of(inputs.shear_modulus, start),
        lanes_of(inputs.poisson_ratio, start),
        lanes_of(inputs.friction, start),
        lanes_of(length, start),
    ]
}

/// Rows `start..start + N` of a column (NaN past its end).
#[inline(always)]
fn lanes_of<const N: usize>(column: Column<'_>, start: usize) -> [f64; N] {
    match column {
        Column::One(x) => [x; N],
        Column::Each(x) => {
            let mut out = [f64::NAN; N];
            for (y, x) in out.iter_mut().zip(x.get(start..).unwrap_or_default()) {
                *y = *x;
            }
            out
        }
    }
}

/// The reference's rows LANES at a time through the fast path ([`reference::fast::rows`]),
/// the scenes of each block from `scenes` (its lanes' constants and which lanes may
/// take the fast path); its elliptic answers written column by column, every other row
/// then one at a time ([`reference_cold`]).
#[inline(always)]
fn reference_lanes(
    inputs: &Inputs<'_>,
    out: &mut Outputs<'_>,
    n: usize,
    cache: &mut Cache<Prepared>,
    mut scenes: impl LaneScenes,
) -> usize {
    let length = inputs.length.is_some();
    let mut bad = 0;
    let mut start = 0;
    while start < n {
        let lanes = LANES.min(n - start);
        let (k, valid) = scenes.scenes(start, lanes);
        let load = lanes_of::<LANES>(inputs.load, start);
        let phi = lanes_of::<LANES>(inputs.phi, start);
        let r = reference::fast::rows(&k, inputs.choice, length, &load, &phi);
        let Some((s, f, c, g, m, fl, t)) = columns(out, n) else {
            return 0; // not reached: `rows` checked every length
        };
        let end = start + lanes;
        let (Some(s), Some(f), Some(c), Some(g), Some(m), Some(fl), Some(t)) = (
            s.get_mut(start..end),
            f.get_mut(start..end),
            c.get_mut(start..end),
            g.get_mut(start..end),
            m.get_mut(start..end),
            fl.get_mut(start..end),
            t.get_mut(start..end),
        ) else {
            return 0; // not reached: end <= n
        };
        // Every row as if answered, a column at a time.
        for (y, x) in s.iter_mut().zip(&r.slip_ratio) {
            *y = *x;
        }
        for (y, x) in f.iter_mut().zip(&r.axial_force) {
            *y = *x;
        }
        for (y, x) in c.iter_mut().zip(&r.critical_angle) {
            *y = *x;
        }
        for (y, x) in g.iter_mut().zip(&r.slip_ratio) {
            *y = u8::from(*x >= 1.0);
        }
        m.fill(model_code(ContactModel::Elliptic));
        t.fill(OK);
        for (j, y) in fl.iter_mut().enumerate() {
            *y = (u8::from(r.large_angle[j]) * flags::LARGE_ANGLE)
                | (u8::from(r.high_pressure[j]) * flags::HIGH_PRESSURE)
                | (u8::from(r.longer_than_rollers[j]) * flags::LONGER_THAN_ROLLERS)
                | (u8::from(r.near_model_switch[j]) * flags::NEAR_MODEL_SWITCH)
                | (u8::from(r.round_ellipse[j]) * flags::ROUND_ELLIPSE);
        }
        // The rows the lanes did not answer, over what was written for them.
        let answered = (0..lanes).fold(true, |all, j| all & valid[j] & r.elliptic[j]);
        if !answered {
            let lanes_answered = valid.iter().zip(&r.elliptic).map(|(&v, &e)| v & e);
            for (j, answered) in lanes_answered.enumerate().take(lanes) {
                if !answered {
                    bad += reference_cold(inputs, out, start + j, cache);
                }
            }
        }
        start = end;
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
    Ok(float_answer(e, phi))
}

/// [`float_row`] out of line: the rows off the ellipse's hot path.
#[cold]
#[inline(never)]
fn float_row_cold(core: &Auto, load: f64, phi: f64) -> Result<Row, Error> {
    float_row(core, load, phi)
}

/// The f32 core's answer as a row (`phi` the row's f64 angle, for the flags).
#[inline(always)]
fn float_answer(e: AutoEstimate, phi: f64) -> Row {
    let est = e.estimate;
    let critical = est.critical_angle.map(f64::from);
    Row {
        slip_ratio: f64::from(est.slip_ratio),
        axial_force: f64::from(est.axial_force),
        critical_angle: critical,
        regime: est.regime,
        model: e.model,
        flags: core_flags(phi, critical, e.near_model_switch),
    }
}

#[inline(always)]
pub(super) fn float(inputs: &Inputs<'_>, out: &mut Outputs<'_>, n: usize) -> usize {
    // A scene per row without a length: the hot path's constants of each row's scene
    // formed in lanes (float::block::hot_of), not a whole preparation a row.
    if !inputs.one_scene_for_all()
        && inputs.length.is_none()
        && inputs.choice != ModelChoice::Line
        && let Ok(tables) = EllipticScene::new(&Scene::DEMO)
    {
        return float_per_row(inputs, out, n, &tables);
    }
    by_scene(inputs, out, n, |s| Auto::with_choice(s, inputs.choice))
}

/// The f32 core's rows with a scene per row and no length, in blocks: each row's hot
/// constants from its scene ([`hot_of`]), the hot path over the block with `tables`'
/// tables ([`EllipticScene::estimate_block_per_sample`]); the rows off it, or whose
/// constants [`hot_of`] is not sure of, through their scene's [`Auto`] as prepared for
/// one row.
#[inline(always)]
fn float_per_row(
    inputs: &Inputs<'_>,
    out: &mut Outputs<'_>,
    n: usize,
    tables: &EllipticScene<'static>,
) -> usize {
    let mut cache = Cache::new();
    let choice = inputs.choice;
    let per_row = PerRowBlocks {
        inputs,
        tables,
        hot: HotPerSample {
            radius_factor: [0.0; BLOCK],
            inv_radius_factor: [0.0; BLOCK],
            friction: [0.0; BLOCK],
            cubed_critical_gain: [0.0; BLOCK],
        },
        sure: [false; BLOCK],
    };
    float_blocks(out, n, inputs.load, inputs.phi, per_row, |i| {
        match cache.get(inputs, i, |s| Auto::with_choice(s, choice)) {
            Ok(core) => float_row_cold(core, inputs.load.at(i), inputs.phi.at(i)),
            Err(e) => Err(*e),
        }
    })
}

/// The hot path of a block of the f32 core's rows ([`float_blocks`]): answers the
/// block's rows from `start` where it can. A method, not a closure, so that it inlines
/// into each build of the batch (a closure is compiled where it is written, without
/// the features of `estimate_avx2`).
trait BlockHotPath {
    fn answer(&mut self, start: usize, b: &mut Block);
}

/// One scene for every row.
impl BlockHotPath for &Auto {
    #[inline(always)]
    fn answer(&mut self, _: usize, b: &mut Block) {
        self.estimate_block(b);
    }
}

/// A scene per row: each row's hot constants from its scene ([`hot_of`]), the tables
/// and risk threshold of `tables`.
struct PerRowBlocks<'i, 'a> {
    inputs: &'i Inputs<'a>,
    tables: &'i EllipticScene<'static>,
    hot: HotPerSample,
    sure: [bool; BLOCK],
}

impl BlockHotPath for PerRowBlocks<'_, '_> {
    #[inline(always)]
    fn answer(&mut self, start: usize, b: &mut Block) {
        let [r1, r2, g, nu, mu, _] = scene_lanes::<BLOCK>(self.inputs, start);
        for i in 0..BLOCK {
            let (h, ok) = hot_of(r1[i], r2[i], g[i], nu[i], mu[i]);
            self.hot.radius_factor[i] = h.radius_factor;
            self.hot.inv_radius_factor[i] = h.inv_radius_factor;
            self.hot.friction[i] = h.friction;
            self.hot.cubed_critical_gain[i] = h.cubed_critical_gain;
            self.sure[i] = ok;
        }
        self.tables
            .estimate_block_per_sample(&self.hot, self.inputs.choice, b);
        for (h, s) in b.hot.iter_mut().zip(&self.sure) {
            *h &= *s;
        }
    }
}

/// A prepared scene of a core, over rows.
trait Core {
    /// One row (f64 inputs as the batch has them).
    fn row(&self, load: f64, phi: f64) -> Result<Row, Error>;
    /// Rows `..n` of the columns into `out`; the number refused.
    fn rows(&self, out: &mut Outputs<'_>, n: usize, load: impl At, phi: impl At) -> usize;
}

impl Core for Auto {
    #[inline(always)]
    fn row(&self, load: f64, phi: f64) -> Result<Row, Error> {
        float_row(self, load, phi)
    }
    fn rows(&self, out: &mut Outputs<'_>, n: usize, load: impl At, phi: impl At) -> usize {
        float_rows(self, out, n, load, phi)
    }
}

/// A core's rows: the scene prepared once for the batch when every scene column is
/// one value (the loop then specialised on whether P and phi are), else once per run
/// of rows with the same constants.
fn by_scene<C: Core>(
    inputs: &Inputs<'_>,
    out: &mut Outputs<'_>,
    n: usize,
    prepare: impl Fn(&Scene) -> Result<C, Error>,
) -> usize {
    if inputs.one_scene_for_all() {
        let core = match inputs.scene(0).and_then(|s| prepare(&s)) {
            Ok(core) => core,
            Err(e) => return refuse_all(out, n, e),
        };
        return match (inputs.load, inputs.phi) {
            (Column::Each(p), Column::Each(a)) => core.rows(out, n, p, a),
            (Column::Each(p), Column::One(a)) => core.rows(out, n, p, Repeat(a)),
            (Column::One(p), Column::Each(a)) => core.rows(out, n, Repeat(p), a),
            (Column::One(p), Column::One(a)) => core.rows(out, n, Repeat(p), Repeat(a)),
        };
    }
    let mut cache = Cache::new();
    let mut bad = 0;
    for i in 0..n {
        let row = match cache.get(inputs, i, &prepare) {
            Ok(c) => c.row(inputs.load.at(i), inputs.phi.at(i)),
            Err(e) => Err(*e),
        };
        bad += put(out, i, row, &NO_DETAILS);
    }
    bad
}

/// Every row refused with the one scene's error.
fn refuse_all(out: &mut Outputs<'_>, n: usize, error: Error) -> usize {
    for i in 0..n {
        put(out, i, Err(error), &NO_DETAILS);
    }
    n
}

/// An input column of a core's loop: one value per row, or one for every row.
trait At: Copy {
    /// Row `i` (NaN beyond the column: not reached, the lengths were checked).
    fn at(self, i: usize) -> f64;
    /// Rows `start..` as f32 into `out`, as many as both hold.
    fn narrow_into(self, start: usize, out: &mut [f32]);
    /// Whether |phi| of rows `start..` is above [`ANGLE_LIMIT`] (f64's), as
    /// [`flags::LARGE_ANGLE`] or 0, into `out`.
    fn large_angle_into(self, start: usize, out: &mut [u8]);
}

/// [`flags::LARGE_ANGLE`] where |phi| is above [`ANGLE_LIMIT`].
#[inline(always)]
fn large_angle(phi: f64) -> u8 {
    u8::from(libm::fabs(phi) > ANGLE_LIMIT) * flags::LARGE_ANGLE
}

impl At for &[f64] {
    #[inline(always)]
    fn at(self, i: usize) -> f64 {
        self.get(i).copied().unwrap_or(f64::NAN)
    }
    #[inline(always)]
    fn narrow_into(self, start: usize, out: &mut [f32]) {
        for (y, x) in out.iter_mut().zip(self.get(start..).unwrap_or_default()) {
            *y = *x as f32;
        }
    }
    #[inline(always)]
    fn large_angle_into(self, start: usize, out: &mut [u8]) {
        for (y, x) in out.iter_mut().zip(self.get(start..).unwrap_or_default()) {
            *y = large_angle(*x);
        }
    }
}

impl At for Column<'_> {
    #[inline(always)]
    fn at(self, i: usize) -> f64 {
        Column::at(&self, i)
    }
    #[inline(always)]
    fn narrow_into(self, start: usize, out: &mut [f32]) {
        match self {
            Column::One(x) => Repeat(x).narrow_into(start, out),
            Column::Each(x) => x.narrow_into(start, out),
        }
    }
    #[inline(always)]
    fn large_angle_into(self, start: usize, out: &mut [u8]) {
        match self {
            Column::One(x) => Repeat(x).large_angle_into(start, out),
            Column::Each(x) => x.large_angle_into(start, out),
        }
    }
}

/// One value for every row.
#[derive(Clone, Copy)]
struct Repeat(f64);

impl At for Repeat {
    #[inline(always)]
    fn at(self, _: usize) -> f64 {
        self.0
    }
    #[inline(always)]
    fn narrow_into(self, _: usize, out: &mut [f32]) {
        out.fill(self.0 as f32);
    }
    #[inline(always)]
    fn large_angle_into(self, _: usize, out: &mut [u8]) {
        out.fill(large_angle(self.0));
    }
}

/// The f32 core's rows of one scene in blocks: the ellipse's hot path over each block
/// ([`Auto::estimate_block`]); the rows off it (refused, zero, asymptotic, line contact)
/// then one by one through [`float_row`].
#[inline(always)]
fn float_rows(core: &Auto, out: &mut Outputs<'_>, n: usize, load: impl At, phi: impl At) -> usize {
    float_blocks(out, n, load, phi, core, |i| {
        float_row_cold(core, load.at(i), phi.at(i))
    })
}

/// The f32 core's rows in blocks: `hot_path.answer(start, block)` answers the block's rows
/// from `start` where it can (P and phi given as f32), its answers written column by
/// column; the rows it leaves, `row(i)` one by one. A row on the hot path took P and
/// phi as f32 without a refusal of [`narrow`] (both finite, not rounded to 0 or inf,
/// |phi| <= 1 < pi/2): it needs no other check, and its flags are [`core_flags`]' with
/// a critical angle.
#[inline(always)]
fn float_blocks(
    out: &mut Outputs<'_>,
    n: usize,
    load: impl At,
    phi: impl At,
    mut hot_path: impl BlockHotPath,
    mut row: impl FnMut(usize) -> Result<Row, Error>,
) -> usize {
    let Some((s, f, c, r, m, g, t)) = columns(out, n) else {
        return 0; // not reached: `rows` checked every length
    };
    let mut bad = 0;
    let mut b = Block::new();
    let mut large = [0u8; BLOCK];
    let blocks = s
        .chunks_mut(BLOCK)
        .zip(f.chunks_mut(BLOCK))
        .zip(c.chunks_mut(BLOCK))
        .zip(r.chunks_mut(BLOCK))
        .zip(m.chunks_mut(BLOCK))
        .zip(g.chunks_mut(BLOCK))
        .zip(t.chunks_mut(BLOCK));
    for (k, ((((((s, f), c), r), m), g), t)) in blocks.enumerate() {
        let start = k * BLOCK;
        load.narrow_into(start, &mut b.load);
        phi.narrow_into(start, &mut b.phi);
        phi.large_angle_into(start, &mut large);
        hot_path.answer(start, &mut b);
        // Every row as if on the hot path, a column at a time.
        for (y, x) in s.iter_mut().zip(&b.slip_ratio) {
            *y = f64::from(*x);
        }
        for (y, x) in f.iter_mut().zip(&b.axial_force) {
            *y = f64::from(*x);
        }
        for ((y, x), (flag, (&large, &near))) in c
            .iter_mut()
            .zip(&b.critical_angle)
            .zip(g.iter_mut().zip(large.iter().zip(&b.near_model_switch)))
        {
            *y = f64::from(*x);
            *flag = large
                | (u8::from(*y > ANGLE_LIMIT) * flags::LARGE_ANGLE)
                | (u8::from(near) * flags::NEAR_MODEL_SWITCH);
        }
        let len = r.len();
        r.copy_from_slice(b.regime.get(..len).unwrap_or_default());
        m.fill(model_code(ContactModel::Elliptic));
        t.fill(OK);
        // The rows off the hot path, over what was written for them.
        // (A fold, not a search: one pass without a branch per row.)
        if b.hot.iter().take(len).fold(true, |all, &hot| all & hot) {
            continue;
        }
        for (j, _) in b.hot.iter().enumerate().take(len).filter(|(_, hot)| !**hot) {
            let (refused, cells) = cells(row(start + j));
            bad += refused;
            let row = (
                s.get_mut(j),
                f.get_mut(j),
                c.get_mut(j),
                r.get_mut(j),
                m.get_mut(j),
                g.get_mut(j),
                t.get_mut(j),
            );
            if let (Some(s), Some(f), Some(c), Some(r), Some(m), Some(g), Some(t)) = row {
                (*s, *f, *c, *r, *m, *g, *t) = cells;
            }
        }
    }
    no_details(out);
    bad
}

/// A fixed-point scene with its LSBs (N and rad per count).
pub(super) struct FixedCore {
    core: FixedAuto,
    load_lsb: f64,
    angle_lsb: f64,
}

/// The ADC's load LSB (N) where none is given: 10 mN, as the nodes.
pub(super) const ADC_LOAD_LSB: f64 = 1e-2;

/// The finest angle LSB (rad) the scene's tables allow, at least 1e-10 rad (where
/// line contact answers, 1e-10 rad).
fn finest_angle_lsb(scene: &Scene, choice: ModelChoice) -> f64 {
    if scene.is_plane() || choice == ModelChoice::Line {
        1e-10
    } else {
        libm::fmax(FixedEllipticScene::min_angle_lsb(scene), 1e-10)
    }
}

pub(super) fn prepare_fixed(
    scene: &Scene,
    choice: ModelChoice,
    load_lsb: f64,
    angle_lsb: Option<f64>,
) -> Result<FixedCore, Error> {
    let angle_lsb = angle_lsb.unwrap_or_else(|| finest_angle_lsb(scene, choice));
    if !(load_lsb.is_finite() && load_lsb > 0.0 && angle_lsb.is_finite() && angle_lsb > 0.0) {
        return Err(Error::OutOfRange);
    }
    Ok(FixedCore {
        core: FixedAuto::with_choice(scene, load_lsb, angle_lsb, choice)?,
        load_lsb,
        angle_lsb,
    })
}

/// The sample's checks, as the reference makes them.
#[inline(always)]
fn fixed_sample(load: f64, phi: f64) -> Result<(), Error> {
    if !(load.is_finite() && load >= 0.0) {
        return Err(Error::Load);
    }
    // As the reference: |phi| up to FRAC_PI_2 (the f64 below the true pi/2).
    if phi.is_nan() || libm::fabs(phi) > core::f64::consts::FRAC_PI_2 {
        return Err(Error::Angle);
    }
    Ok(())
}

#[inline]
fn fixed_row(f: &FixedCore, load: f64, phi: f64) -> Result<Row, Error> {
    fixed_sample(load, phi)?;
    let counts = libm::round(load / f.load_lsb);
    let angle = libm::round(phi / f.angle_lsb);
    if counts > u32::MAX as f64 || libm::fabs(angle) > i32::MAX as f64 {
        return Err(Error::OutOfRange);
    }
    fixed_answer(&f.core, counts as u32, angle as i32, phi)
}

/// The core's answer at `counts` and `angle` counts as a row (`phi` the row's f64
/// angle, for the flags).
#[inline(always)]
fn fixed_answer(core: &FixedAuto, counts: u32, angle: i32, phi: f64) -> Result<Row, Error> {
    let e = core.estimate(counts, angle)?;
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

/// A scene for [`Counts::Exact`]: prepared again for each row's LSBs, as the CSV
/// estimator does.
struct FixedExact {
    scene: Scene,
    choice: ModelChoice,
    /// The finest angle LSB the tables allow (0 where only line contact answers).
    min_angle_lsb: f64,
}

/// Counts up to 2^30 of an LSB that holds the value exactly.
const EXACT_COUNTS: u32 = 1 << 30;

fn prepare_exact(scene: &Scene, choice: ModelChoice) -> Result<FixedExact, Error> {
    let min_angle_lsb = if scene.is_plane() || choice == ModelChoice::Line {
        0.0
    } else {
        FixedEllipticScene::min_angle_lsb(scene)
    };
    Ok(FixedExact {
        scene: *scene,
        choice,
        min_angle_lsb,
    })
}

impl Core for FixedExact {
    fn row(&self, load: f64, phi: f64) -> Result<Row, Error> {
        fixed_sample(load, phi)?;
        let (load_lsb, counts) = exact_lsb(load, EXACT_COUNTS, 0.0);
        let (angle_lsb, angle) = exact_lsb(phi, EXACT_COUNTS, self.min_angle_lsb);
        let angle = i32::try_from(angle).map_err(|_| Error::Angle)?;
        let angle = if phi < 0.0 { -angle } else { angle };
        let core = FixedAuto::with_choice(&self.scene, load_lsb, angle_lsb, self.choice)?;
        fixed_answer(&core, counts, angle, phi)
    }
    fn rows(&self, out: &mut Outputs<'_>, n: usize, load: impl At, phi: impl At) -> usize {
        core_rows(self, out, n, load, phi)
    }
}

pub(super) fn fixed(inputs: &Inputs<'_>, out: &mut Outputs<'_>, n: usize, counts: Counts) -> usize {
    match counts {
        Counts::Exact => by_scene(inputs, out, n, |s| prepare_exact(s, inputs.choice)),
        Counts::Adc {
            load_lsb,
            angle_lsb,
        } => by_scene(inputs, out, n, |s| {
            prepare_fixed(s, inputs.choice, load_lsb, angle_lsb)
        }),
    }
}

impl Core for FixedCore {
    #[inline(always)]
    fn row(&self, load: f64, phi: f64) -> Result<Row, Error> {
        fixed_row(self, load, phi)
    }
    fn rows(&self, out: &mut Outputs<'_>, n: usize, load: impl At, phi: impl At) -> usize {
        core_rows(self, out, n, load, phi)
    }
}

/// A core's rows of one prepared scene, one at a time, written straight into the
/// output columns.
#[inline(always)]
fn core_rows<C: Core>(
    core: &C,
    out: &mut Outputs<'_>,
    n: usize,
    load: impl At,
    phi: impl At,
) -> usize {
    let Some((s, f, c, r, m, g, t)) = columns(out, n) else {
        return 0; // not reached: `rows` checked every length
    };
    let mut bad = 0;
    let rows = s.iter_mut().zip(f).zip(c).zip(r).zip(m).zip(g).zip(t);
    for (i, ((((((s, f), c), r), m), g), t)) in rows.enumerate() {
        let (refused, cells) = cells(core.row(load.at(i), phi.at(i)));
        bad += refused;
        (*s, *f, *c, *r, *m, *g, *t) = cells;
    }
    no_details(out);
    bad
}
