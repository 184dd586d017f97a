//! The crate's one error type: every refused input gets a variant saying which.

use core::fmt;

/// Why a scene or a sample was refused. Input that is merely outside the
/// theory's comfort zone is not refused; it is flagged in the result's
/// [`Validity`](crate::reference::Validity).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[non_exhaustive]
pub enum Error {
    /// Radius R1 not finite and positive, or R2 not positive (R2 may be +infinity: a plane).
    Radius,
    /// Shear modulus G not finite and positive.
    ShearModulus,
    /// Poisson's ratio not in [0, 0.5].
    PoissonRatio,
    /// Friction coefficient mu not finite and positive.
    Friction,
    /// Roller contact length not finite and positive.
    Length,
    /// Roller contact length below [`Scene::shortest_length`](crate::Scene::shortest_length):
    /// the contact strip would be wider than the rollers are long at every working
    /// load (beyond a peak pressure of [`crate::SHORT_ROLLER_PRESSURE`] G), where the
    /// paper's model of the contact means nothing; often a length in the wrong unit.
    LengthTooShort,
    /// Load P is NaN, infinite or negative.
    Load,
    /// Misalignment angle phi is NaN or infinite, or |phi| above pi/2 (rad) as the
    /// input's precision rounds it: the angle between two axes is at most a right
    /// angle, and eq (4) maps it to theta <= pi/2, where m(theta), n(theta) are defined
    /// (theta = pi/2: m = n = 1, crossed cylinders). f64 input: every |phi| up to
    /// `f64::consts::FRAC_PI_2` (just below the true pi/2); f32 input: up to
    /// `f32::consts::FRAC_PI_2` (just above it, standing for pi/2); fixed-point input:
    /// angle counts whose product with the LSB is at most `f64::consts::FRAC_PI_2`.
    Angle,
    /// The elliptic solution was asked for a plane (R2 = infinity): its contact is a
    /// strip for every phi (section 8); use the line-contact model.
    PlaneHasNoEllipse,
    /// The f32 and fixed-point cores implement eq (4); the exact theta relation is in
    /// the reference only.
    Unsupported,
    /// Measured axial force F is NaN or infinite.
    Force,
    /// A value outside what a prepared scene accepts: a scene constant that does not
    /// fit the core's number format, or an input outside the declared range.
    OutOfRange,
}

impl fmt::Display for Error {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Error::Radius => "radius must be finite and positive (R2 may be inf)",
            Error::ShearModulus => "shear modulus G must be finite and positive",
            Error::PoissonRatio => "Poisson's ratio nu must be in [0, 0.5]",
            Error::Friction => "friction coefficient mu must be finite and positive",
            Error::Length => "contact length must be finite and positive",
            Error::LengthTooShort => {
                "contact length too short for the radii: below 2 (1 - nu) R x 1e-5 (R = R1 R2 / \
                 (R1 + R2)) the contact is wider than the rollers are long at any working \
                 load; is the length in m?"
            }
            Error::Load => "load P must be finite and >= 0",
            Error::Angle => {
                "misalignment phi must be finite with |phi| <= pi/2 rad (pi/2 as the input's \
                 float type rounds it)"
            }
            Error::PlaneHasNoEllipse => {
                "a plane (R2 = inf) has no contact ellipse: use line contact"
            }
            Error::Unsupported => {
                "the cores implement eq (4) only; use the reference for the exact relation"
            }
            Error::Force => "axial force F must be finite",
            Error::OutOfRange => "value outside the range the prepared scene accepts",
        })
    }
}

// `core::error::Error` (Rust 1.81): an `Error` is a `std::error::Error` on the host,
// with no feature, as is every error type of the crate (held at compile time in lib.rs).
impl core::error::Error for Error {}
