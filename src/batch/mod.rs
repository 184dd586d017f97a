//! Many samples at once, for the PC: the reference, the f32 core or the fixed-point
//! core over slices of inputs, writing slices of outputs, with a status per row.
//!
//! Inputs are [`Column`]s: one value for every row ([`Column::One`]) or one per row
//! ([`Column::Each`]), so a batch has one scene for all rows or a scene per row. A
//! scene is built and prepared once for a run of rows with the same constants (once
//! for the batch when every scene column is [`Column::One`]): a prepared core scene
//! costs far more than one estimate, and a historian's export holds long runs of one
//! installation. Section 9's model choice is made per row, as
//! [`reference::estimate_with`](crate::reference::estimate_with) makes it.
//!
//! A bad row (a refused scene or sample) gets its [`Error`] as a status code
//! ([`status_of`], [`error_of`]), NaN in its numbers and [`NONE`] in its codes; the
//! other rows get their values. No heap, no panic: slices of the wrong length are one
//! [`Mismatch`] for the whole call, before any row is computed.
//!
//! ```
//! use misalign::batch::{self, Column, Inputs, Model, Outputs};
//! use misalign::reference::ModelChoice;
//!
//! let load = [1e3, 2e3, -1.0];
//! let phi = [2e-4, 2e-4, 2e-4];
//! let inputs = Inputs::one_scene(&misalign::Scene::DEMO, Column::Each(&load), Column::Each(&phi));
//! let (mut s, mut f, mut phi0) = ([0.0; 3], [0.0; 3], [0.0; 3]);
//! let (mut regime, mut model, mut flags, mut status) = ([0; 3], [0; 3], [0; 3], [0; 3]);
//! let mut out = Outputs {
//!     slip_ratio: &mut s, axial_force: &mut f, critical_angle: &mut phi0,
//!     regime: &mut regime, model: &mut model, flags: &mut flags, status: &mut status,
//!     details: None,
//! };
//! let bad = batch::estimate(&inputs, &mut out, Model::Reference)?;
//! assert_eq!(bad, 1); // the negative load
//! assert!(s[0] > 0.0 && s[1] < s[0] && s[2].is_nan());
//! assert_eq!(batch::error_of(status[2]), Some(misalign::Error::Load));
//! # Ok::<(), batch::Mismatch>(())
//! ```

mod rows;
#[cfg(feature = "rayon")]
mod threads;

#[cfg(feature = "rayon")]
pub use threads::{par_estimate, par_estimate_with};

use crate::reference::ModelChoice;
use crate::{Error, Scene};

/// One input column: a value for every row, or a value per row.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Column<'a> {
    /// The same value for every row (a scalar that broadcasts).
    One(f64),
    /// One value per row.
    Each(&'a [f64]),
}

impl<'a> Column<'a> {
    /// The value of row `i` (which the caller has checked is in range).
    #[inline(always)]
    fn at(&self, i: usize) -> f64 {
        match self {
            Column::One(x) => *x,
            Column::Each(x) => x.get(i).copied().unwrap_or(f64::NAN),
        }
    }

    /// Its number of rows, if it has one.
    fn rows(&self) -> Option<usize> {
        match self {
            Column::One(_) => None,
            Column::Each(x) => Some(x.len()),
        }
    }

    /// The rows `..mid` and `mid..`.
    pub fn split_at(self, mid: usize) -> (Column<'a>, Column<'a>) {
        match self {
            Column::One(x) => (Column::One(x), Column::One(x)),
            Column::Each(x) => {
                let mid = mid.min(x.len());
                let (a, b) = x.split_at(mid);
                (Column::Each(a), Column::Each(b))
            }
        }
    }
}

/// The inputs of a batch: the scene's constants, the samples and the model choice.
/// Units as [`Scene::new`] and [`reference::estimate`](crate::reference::estimate):
/// R1, R2 (m; R2 = inf is a plane), G (Pa), nu, mu, length (m), P (N; N/m in line
/// contact without a length), phi (rad, signed).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Inputs<'a> {
    /// Radius R1 (m).
    pub r1: Column<'a>,
    /// Radius R2 (m); inf for a plane.
    pub r2: Column<'a>,
    /// Shear modulus G (Pa).
    pub shear_modulus: Column<'a>,
    /// Poisson's ratio nu.
    pub poisson_ratio: Column<'a>,
    /// Friction coefficient mu.
    pub friction: Column<'a>,
    /// The rollers' contact length (m), or none (section 9 then keeps the ellipse).
    pub length: Option<Column<'a>>,
    /// Load P (N).
    pub load: Column<'a>,
    /// Misalignment phi (rad, signed).
    pub phi: Column<'a>,
    /// Section 9 per row, or one model forced.
    pub choice: ModelChoice,
}

impl<'a> Inputs<'a> {
    /// One scene for every row (section 9's choice).
    pub fn one_scene(scene: &Scene, load: Column<'a>, phi: Column<'a>) -> Self {
        Inputs {
            r1: Column::One(scene.r1()),
            r2: Column::One(scene.r2()),
            shear_modulus: Column::One(scene.shear_modulus()),
            poisson_ratio: Column::One(scene.poisson_ratio()),
            friction: Column::One(scene.friction()),
            length: scene.length().map(Column::One),
            load,
            phi,
            choice: ModelChoice::Section9,
        }
    }

    fn columns(&self) -> [Option<Column<'a>>; 8] {
        [
            Some(self.r1),
            Some(self.r2),
            Some(self.shear_modulus),
            Some(self.poisson_ratio),
            Some(self.friction),
            self.length,
            Some(self.load),
            Some(self.phi),
        ]
    }

    /// True when every scene column is one value: one scene for the batch.
    pub fn one_scene_for_all(&self) -> bool {
        self.columns()[..6]
            .iter()
            .all(|c| !matches!(c, Some(Column::Each(_))))
    }

    /// The rows `..mid` and `mid..`.
    pub fn split_at(&self, mid: usize) -> (Inputs<'a>, Inputs<'a>) {
        let split = |c: Column<'a>| c.split_at(mid);
        let (r1, r1b) = split(self.r1);
        let (r2, r2b) = split(self.r2);
        let (g, gb) = split(self.shear_modulus);
        let (nu, nub) = split(self.poisson_ratio);
        let (mu, mub) = split(self.friction);
        let (length, lengthb) = match self.length.map(split) {
            Some((a, b)) => (Some(a), Some(b)),
            None => (None, None),
        };
        let (load, loadb) = split(self.load);
        let (phi, phib) = split(self.phi);
        let head = Inputs {
            r1,
            r2,
            shear_modulus: g,
            poisson_ratio: nu,
            friction: mu,
            length,
            load,
            phi,
            choice: self.choice,
        };
        let tail = Inputs {
            r1: r1b,
            r2: r2b,
            shear_modulus: gb,
            poisson_ratio: nub,
            friction: mub,
            length: lengthb,
            load: loadb,
            phi: phib,
            choice: self.choice,
        };
        (head, tail)
    }

    /// The scene of row `i`.
    #[inline]
    fn scene(&self, i: usize) -> Result<Scene, Error> {
        let scene = Scene::new(
            self.r1.at(i),
            self.r2.at(i),
            self.shear_modulus.at(i),
            self.poisson_ratio.at(i),
            self.friction.at(i),
        )?;
        match self.length {
            Some(l) => scene.with_length(l.at(i)),
            None => Ok(scene),
        }
    }

    /// The scene constants of row `i`, bit for bit (the key of a run of one scene).
    #[inline]
    fn scene_key(&self, i: usize) -> [u64; 6] {
        [
            self.r1.at(i).to_bits(),
            self.r2.at(i).to_bits(),
            self.shear_modulus.at(i).to_bits(),
            self.poisson_ratio.at(i).to_bits(),
            self.friction.at(i).to_bits(),
            self.length.map_or(u64::MAX, |l| l.at(i).to_bits()),
        ]
    }
}

/// Which implementation computes the rows.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Model {
    /// The f64 reference of the whole paper ([`crate::reference`]).
    Reference,
    /// The f32 core ([`crate::float::Auto`]); P and phi rounded to f32.
    F32,
    /// The fixed-point core ([`crate::fixed::FixedAuto`]), its inputs made integer
    /// counts as [`Counts`] says.
    Fixed(Counts),
}

/// How a row's P and phi become the fixed-point core's integer counts.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Counts {
    /// The core: each row in counts of an LSB that holds its P and its phi exactly (up
    /// to 2^30 counts; angles no finer than the scene's tables allow,
    /// [`FixedEllipticScene::min_angle_lsb`](crate::fixed::FixedEllipticScene::min_angle_lsb)),
    /// [`exact_lsb`](crate::fixed::exact_lsb): the answer carries the core's own error
    /// only. The scene is prepared for each row's LSBs.
    Exact,
    /// The node with its ADC: P in counts of `load_lsb` (N), phi in counts of
    /// `angle_lsb` (rad), each rounded to the nearest count; an `angle_lsb` of `None`
    /// takes the finest angle the scene's tables allow, and at least 1e-10 rad. The
    /// answer carries the rounding too.
    Adc {
        /// N per load count.
        load_lsb: f64,
        /// rad per angle count.
        angle_lsb: Option<f64>,
    },
}

/// Which of an ADC's LSBs a scene cannot be prepared with ([`adc_lsb_refused`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum RefusedLsb {
    /// The load LSB.
    Load,
    /// The angle LSB.
    Angle,
    /// Each alone is taken; not the two together.
    Both,
}

/// Whether `scene` is refused by the fixed-point core because of the ADC's LSBs (not
/// because of its own constants): it is prepared with them, then, where that fails,
/// with a load LSB of 10 mN and the finest angle LSB its tables allow in their place.
/// `None` when the LSBs are taken, or when the scene is refused with those too.
pub fn adc_lsb_refused(
    scene: &Scene,
    choice: ModelChoice,
    load_lsb: f64,
    angle_lsb: Option<f64>,
) -> Option<RefusedLsb> {
    let prepares =
        |load: f64, angle: Option<f64>| rows::prepare_fixed(scene, choice, load, angle).is_ok();
    if prepares(load_lsb, angle_lsb) || !prepares(rows::ADC_LOAD_LSB, None) {
        return None;
    }
    match (
        prepares(load_lsb, None),
        prepares(rows::ADC_LOAD_LSB, angle_lsb),
    ) {
        (false, true) => Some(RefusedLsb::Load),
        (true, false) => Some(RefusedLsb::Angle),
        _ => Some(RefusedLsb::Both),
    }
}

/// A code of [`Outputs::regime`] and [`Outputs::model`] for a row without an answer.
pub const NONE: u8 = u8::MAX;
/// [`Outputs::status`] of a row with an answer.
pub const OK: u8 = 0;

/// Bits of [`Outputs::flags`], after [`Validity`](crate::reference::Validity).
pub mod flags {
    /// |phi| or phi0 above [`ANGLE_LIMIT`](crate::reference::ANGLE_LIMIT).
    pub const LARGE_ANGLE: u8 = 1;
    /// p0 / G above [`PRESSURE_LIMIT`](crate::reference::PRESSURE_LIMIT) (reference only).
    pub const HIGH_PRESSURE: u8 = 2;
    /// The ellipse is longer than the rollers.
    pub const LONGER_THAN_ROLLERS: u8 = 4;
    /// 2a / length within [`MODEL_SWITCH_BAND`](crate::reference::MODEL_SWITCH_BAND) of 1.
    pub const NEAR_MODEL_SWITCH: u8 = 8;
    /// a/b below [`SLENDER_LIMIT`](crate::reference::SLENDER_LIMIT) (reference only).
    pub const ROUND_ELLIPSE: u8 = 16;
    /// No theta <= pi/2 reaches d/b = 1: no critical angle.
    pub const NO_CRITICAL_ANGLE: u8 = 32;
}

/// Every error in the order of its status code (1, 2, ...).
const ERRORS: [Error; 12] = [
    Error::Radius,
    Error::ShearModulus,
    Error::PoissonRatio,
    Error::Friction,
    Error::Length,
    Error::Load,
    Error::Angle,
    Error::PlaneHasNoEllipse,
    Error::Unsupported,
    Error::Force,
    Error::OutOfRange,
    Error::LengthTooShort,
];

/// The status code of a refused row: 1 + the error's place in a fixed list; never [`OK`].
pub fn status_of(error: Error) -> u8 {
    let mut code = 0u8;
    while (code as usize) < ERRORS.len() {
        if ERRORS[code as usize] == error {
            return code + 1;
        }
        code += 1;
    }
    u8::MAX // an error added later without a code here
}

/// The error of a status code; `None` for [`OK`] (or a code no error has).
pub fn error_of(status: u8) -> Option<Error> {
    (status as usize)
        .checked_sub(1)
        .and_then(|i| ERRORS.get(i).copied())
}

/// The reference's further numbers per row ([`Model::Reference`] only; the cores leave
/// NaN). Elliptic rows fill all but `radius`; line rows `b, p0, d, pstar, p0star, radius`.
#[derive(Debug)]
pub struct Details<'a> {
    /// Auxiliary angle theta (rad), eq (4).
    pub theta: &'a mut [f64],
    /// k' = b/a, eqs (5)-(6).
    pub kprime: &'a mut [f64],
    /// m (a = m L).
    pub m: &'a mut [f64],
    /// n (b = n L).
    pub n: &'a mut [f64],
    /// Semi-axis a (m).
    pub a: &'a mut [f64],
    /// Semi-axis (half-width for line contact) b (m).
    pub b: &'a mut [f64],
    /// Peak pressure p0 (Pa).
    pub p0: &'a mut [f64],
    /// d (m), capped at b.
    pub d: &'a mut [f64],
    /// Non-dimensional load P* (eqs 17, 24).
    pub pstar: &'a mut [f64],
    /// Critical non-dimensional load P0* (eqs 18, 25).
    pub p0star: &'a mut [f64],
    /// theta0 at the critical angle (rad).
    pub theta0: &'a mut [f64],
    /// The radius of section 8 (m), eq (31).
    pub radius: &'a mut [f64],
}

impl<'a> Details<'a> {
    fn slices(&mut self) -> [&mut [f64]; 12] {
        [
            &mut *self.theta,
            &mut *self.kprime,
            &mut *self.m,
            &mut *self.n,
            &mut *self.a,
            &mut *self.b,
            &mut *self.p0,
            &mut *self.d,
            &mut *self.pstar,
            &mut *self.p0star,
            &mut *self.theta0,
            &mut *self.radius,
        ]
    }

    /// The rows `..mid` and `mid..`.
    pub fn split_at_mut(self, mid: usize) -> (Details<'a>, Details<'a>) {
        let [a0, a1, a2, a3, a4, a5, a6, a7, a8, a9, a10, a11] = [
            self.theta,
            self.kprime,
            self.m,
            self.n,
            self.a,
            self.b,
            self.p0,
            self.d,
            self.pstar,
            self.p0star,
            self.theta0,
            self.radius,
        ]
        .map(|s| {
            let mid = mid.min(s.len());
            s.split_at_mut(mid)
        });
        (
            Details {
                theta: a0.0,
                kprime: a1.0,
                m: a2.0,
                n: a3.0,
                a: a4.0,
                b: a5.0,
                p0: a6.0,
                d: a7.0,
                pstar: a8.0,
                p0star: a9.0,
                theta0: a10.0,
                radius: a11.0,
            },
            Details {
                theta: a0.1,
                kprime: a1.1,
                m: a2.1,
                n: a3.1,
                a: a4.1,
                b: a5.1,
                p0: a6.1,
                d: a7.1,
                pstar: a8.1,
                p0star: a9.1,
                theta0: a10.1,
                radius: a11.1,
            },
        )
    }
}

/// Where a batch writes, one slice per column, all of the batch's length.
#[derive(Debug)]
pub struct Outputs<'a> {
    /// Slip ratio d/b (eqs 16, 23).
    pub slip_ratio: &'a mut [f64],
    /// Axial force F (N; N/m in line contact without a length), signed like phi.
    pub axial_force: &'a mut [f64],
    /// Critical angle phi0 (rad) at the row's load; NaN where none exists (flag
    /// [`flags::NO_CRITICAL_ANGLE`]).
    pub critical_angle: &'a mut [f64],
    /// 0 partial slip, 1 gross slip ([`Regime`](crate::reference::Regime)), [`NONE`].
    pub regime: &'a mut [u8],
    /// 0 elliptic, 1 line ([`ContactModel`](crate::reference::ContactModel)), [`NONE`].
    pub model: &'a mut [u8],
    /// The [`flags`] raised.
    pub flags: &'a mut [u8],
    /// [`OK`], or the row's error ([`error_of`]).
    pub status: &'a mut [u8],
    /// The reference's further numbers, if wanted.
    pub details: Option<Details<'a>>,
}

impl<'a> Outputs<'a> {
    /// The batch's length, or `None` when the columns' lengths differ.
    fn rows(&mut self) -> Option<usize> {
        let n = self.slip_ratio.len();
        let mut same = self.axial_force.len() == n
            && self.critical_angle.len() == n
            && self.regime.len() == n
            && self.model.len() == n
            && self.flags.len() == n
            && self.status.len() == n;
        if let Some(d) = &mut self.details {
            same &= d.slices().iter().all(|s| s.len() == n);
        }
        same.then_some(n)
    }

    /// The rows `..mid` and `mid..`.
    pub fn split_at_mut(self, mid: usize) -> (Outputs<'a>, Outputs<'a>) {
        fn cut<T>(s: &mut [T], mid: usize) -> (&mut [T], &mut [T]) {
            let mid = mid.min(s.len());
            s.split_at_mut(mid)
        }
        let (s0, s1) = cut(self.slip_ratio, mid);
        let (f0, f1) = cut(self.axial_force, mid);
        let (c0, c1) = cut(self.critical_angle, mid);
        let (r0, r1) = cut(self.regime, mid);
        let (m0, m1) = cut(self.model, mid);
        let (g0, g1) = cut(self.flags, mid);
        let (t0, t1) = cut(self.status, mid);
        let (d0, d1) = match self.details.map(|d| d.split_at_mut(mid)) {
            Some((a, b)) => (Some(a), Some(b)),
            None => (None, None),
        };
        (
            Outputs {
                slip_ratio: s0,
                axial_force: f0,
                critical_angle: c0,
                regime: r0,
                model: m0,
                flags: g0,
                status: t0,
                details: d0,
            },
            Outputs {
                slip_ratio: s1,
                axial_force: f1,
                critical_angle: c1,
                regime: r1,
                model: m1,
                flags: g1,
                status: t1,
                details: d1,
            },
        )
    }
}

/// The input columns and the output slices do not all have the batch's length.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Mismatch;

impl core::fmt::Display for Mismatch {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.write_str("batch columns of different lengths")
    }
}

impl core::error::Error for Mismatch {}

/// The batch's length: the outputs' length, which every per-row input column must have.
pub fn rows(inputs: &Inputs<'_>, outputs: &mut Outputs<'_>) -> Result<usize, Mismatch> {
    let n = outputs.rows().ok_or(Mismatch)?;
    let each_fits = inputs
        .columns()
        .iter()
        .flatten()
        .all(|c| c.rows().is_none_or(|r| r == n));
    if each_fits { Ok(n) } else { Err(Mismatch) }
}

/// Computes every row of `inputs` into `outputs` with `model`, on this thread. Returns
/// the number of rows refused (their status says why).
///
/// # Errors
/// [`Mismatch`] when a per-row column or an output slice is not the outputs' length;
/// nothing is written then.
pub fn estimate(
    inputs: &Inputs<'_>,
    outputs: &mut Outputs<'_>,
    model: Model,
) -> Result<usize, Mismatch> {
    estimate_inline(inputs, outputs, model)
}

/// [`estimate`] compiled for x86-64 with AVX2: the reference's SIMD lanes four f64
/// wide instead of SSE2's two, the same numbers bit for bit (no fused multiply-add is
/// enabled, so every operation rounds as in [`estimate`]; tests/batch.rs compares
/// them).
///
/// # Safety
/// The CPU must have AVX2 (`is_x86_feature_detected!("avx2")`): calling it from code
/// compiled without AVX2 takes `unsafe` for that reason alone.
///
/// # Errors
/// As [`estimate`].
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
pub fn estimate_avx2(
    inputs: &Inputs<'_>,
    outputs: &mut Outputs<'_>,
    model: Model,
) -> Result<usize, Mismatch> {
    estimate_inline(inputs, outputs, model)
}

/// [`estimate`]'s body, inlined into each build of it.
#[inline(always)]
fn estimate_inline(
    inputs: &Inputs<'_>,
    outputs: &mut Outputs<'_>,
    model: Model,
) -> Result<usize, Mismatch> {
    let n = rows(inputs, outputs)?;
    Ok(match model {
        Model::Reference => rows::reference(inputs, outputs, n),
        Model::F32 => rows::float(inputs, outputs, n),
        Model::Fixed(counts) => rows::fixed(inputs, outputs, n, counts),
    })
}
