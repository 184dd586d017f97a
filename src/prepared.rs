//! Prepared scenes as bytes: a scene prepared once on a host (at build time, or by a
//! PC tool for a node configured in the field) and loaded on the node with integer
//! checks only, no floating-point preparation and no libm.
//!
//! Every prepared scene of both cores has `to_bytes()` (a fixed-size array, its
//! length the type's `BYTES`) and `from_bytes()`; the loaded scene is the prepared one
//! field for field, so it answers bit for bit as preparing on the node does
//! (`tests/prepared.rs` holds that over many scenes and samples).
//!
//! The format (little-endian), version [`FORMAT_VERSION`]:
//!
//! | bytes | what |
//! |---|---|
//! | 0..2 | magic `b"MS"` |
//! | 2 | [`Kind`]: which scene type |
//! | 3 | format version |
//! | 4..n-4 | the scene's constants: i32, u32 and f32 (as bits) little-endian; a flag byte (0 or 1) before an optional part, whose bytes are zero when absent; a model choice as one byte (0 section 9, 1 elliptic, 2 line) |
//! | n-4..n | CRC-32 (IEEE, as zlib's `crc32`) of bytes 0..n-4 |
//!
//! `from_bytes` refuses, with a [`PreparedError`] and never a panic: a wrong length,
//! magic, kind or version, a checksum that does not match, and constants outside what
//! the type's `new` can produce (a Q8.24 constant beyond +-100, an f32 constant that is
//! not a positive normal number, an input range or per-sample sum that `new` would
//! refuse). The f32 elliptic scene's bytes hold no table: it loads with the full
//! tables, or with narrowed ones chosen at compile time.

use core::fmt;

use crate::bytes::FieldError;

/// The format version that `to_bytes` writes and `from_bytes` accepts.
pub const FORMAT_VERSION: u8 = 1;
/// The first two bytes of every prepared scene.
pub const MAGIC: [u8; 2] = *b"MS";
/// Bytes around the constants: magic, kind and version before, CRC-32 after.
pub const OVERHEAD: usize = 8;

/// Which scene type the bytes hold (byte 2).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[repr(u8)]
pub enum Kind {
    /// [`crate::fixed::FixedEllipticScene`].
    FixedElliptic = 1,
    /// [`crate::fixed::FixedLineScene`].
    FixedLine = 2,
    /// [`crate::fixed::FixedAuto`].
    FixedAuto = 3,
    /// [`crate::float::EllipticScene`] (its constants; not its tables).
    Elliptic = 4,
    /// [`crate::float::LineScene`].
    Line = 5,
    /// [`crate::float::Auto`].
    Auto = 6,
}

/// Why prepared-scene bytes were refused.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[non_exhaustive]
pub enum PreparedError {
    /// Not the length of the type's bytes.
    Length,
    /// Not a prepared scene (the first two bytes).
    Magic,
    /// Another scene type's bytes.
    Kind,
    /// Another format version.
    Version,
    /// The CRC-32 does not match: the bytes are damaged.
    Checksum,
    /// A constant outside what preparing a scene produces.
    Value,
}

impl fmt::Display for PreparedError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            PreparedError::Length => "prepared scene: wrong length",
            PreparedError::Magic => "prepared scene: not a prepared scene (magic)",
            PreparedError::Kind => "prepared scene: another scene type",
            PreparedError::Version => "prepared scene: unsupported format version",
            PreparedError::Checksum => "prepared scene: checksum mismatch",
            PreparedError::Value => "prepared scene: a constant out of range",
        })
    }
}

impl core::error::Error for PreparedError {}

impl From<FieldError> for PreparedError {
    fn from(e: FieldError) -> Self {
        match e {
            FieldError::InvalidValue => PreparedError::Value,
            FieldError::Truncated | FieldError::TrailingBytes => PreparedError::Length,
        }
    }
}

/// CRC-32 of the scenes (the checkpoint records' too).
pub use crate::bytes::crc32;

/// Writes one scene's constants, in order.
pub(crate) type Writer<'a> = crate::bytes::Writer<'a, PreparedError>;

/// Reads one scene's constants, after [`Reader::open`] checked the frame.
pub(crate) type Reader<'a> = crate::bytes::Reader<'a, PreparedError>;

/// A scene's bytes: the header, what `write` writes, the CRC-32. Should `write` fail
/// or not fill the bytes (the lengths are constants, held by the tests), every byte is
/// zero, which `from_bytes` refuses ([`PreparedError::Magic`]): never a scene that
/// loads wrong.
pub(crate) fn seal<const N: usize>(
    kind: Kind,
    write: impl FnOnce(&mut Writer<'_>) -> Result<(), PreparedError>,
) -> [u8; N] {
    let mut out = [0; N];
    if seal_into(&mut out, kind, write).is_err() {
        out = [0; N];
    }
    out
}

fn seal_into(
    out: &mut [u8],
    kind: Kind,
    write: impl FnOnce(&mut Writer<'_>) -> Result<(), PreparedError>,
) -> Result<(), PreparedError> {
    let n = out.len().checked_sub(4).ok_or(PreparedError::Length)?;
    let (body, crc) = out.split_at_mut_checked(n).ok_or(PreparedError::Length)?;
    let mut w = Writer::new(body);
    w.bytes(&MAGIC)?;
    w.u8(kind as u8)?;
    w.u8(FORMAT_VERSION)?;
    write(&mut w)?;
    if w.written() != body.len() {
        return Err(PreparedError::Length);
    }
    Writer::new(crc).u32(crc32(body))
}

impl<'a> Reader<'a> {
    /// Checks length, magic, kind, version and checksum of `bytes`, which must be
    /// `len` long; the reader is then at the first constant.
    pub(crate) fn open(bytes: &'a [u8], kind: Kind, len: usize) -> Result<Self, PreparedError> {
        if bytes.len() != len || len < OVERHEAD {
            return Err(PreparedError::Length);
        }
        let (body, crc) = bytes
            .split_at_checked(len - 4)
            .ok_or(PreparedError::Length)?;
        let mut r = Reader::new(body);
        if r.array::<2>()? != MAGIC {
            return Err(PreparedError::Magic);
        }
        if r.u8()? != kind as u8 {
            return Err(PreparedError::Kind);
        }
        if r.u8()? != FORMAT_VERSION {
            return Err(PreparedError::Version);
        }
        if crc32(body).to_le_bytes() != crc {
            return Err(PreparedError::Checksum);
        }
        Ok(r)
    }
}

/// `x` a positive normal f32, checked on its bits (no soft-float call).
pub(crate) fn positive_normal(x: f32) -> Result<f32, PreparedError> {
    let exponent = (x.to_bits() >> 23) & 0xff;
    if x.to_bits() >> 31 == 0 && exponent != 0 && exponent != 0xff {
        Ok(x)
    } else {
        Err(PreparedError::Value)
    }
}

/// `x` positive and finite (a risk threshold), checked on its bits.
pub(crate) fn positive_finite(x: f32) -> Result<f32, PreparedError> {
    let bits = x.to_bits();
    if bits != 0 && bits < f32::INFINITY.to_bits() {
        Ok(x)
    } else {
        Err(PreparedError::Value)
    }
}

/// `Ok` when `ok`, else [`PreparedError::Value`].
pub(crate) fn value(ok: bool) -> Result<(), PreparedError> {
    if ok {
        Ok(())
    } else {
        Err(PreparedError::Value)
    }
}

/// A model choice as one byte.
pub(crate) fn choice_byte(choice: crate::reference::ModelChoice) -> u8 {
    use crate::reference::ModelChoice;
    match choice {
        ModelChoice::Section9 => 0,
        ModelChoice::Elliptic => 1,
        ModelChoice::Line => 2,
    }
}

/// The model choice of one byte.
pub(crate) fn read_choice(
    r: &mut Reader<'_>,
) -> Result<crate::reference::ModelChoice, PreparedError> {
    use crate::reference::ModelChoice;
    match r.u8()? {
        0 => Ok(ModelChoice::Section9),
        1 => Ok(ModelChoice::Elliptic),
        2 => Ok(ModelChoice::Line),
        _ => Err(PreparedError::Value),
    }
}

/// The model a choice forces is there, and some model is (an `Auto` scene's parts).
pub(crate) fn models_present(
    choice: crate::reference::ModelChoice,
    elliptic: bool,
    line: bool,
) -> Result<(), PreparedError> {
    use crate::reference::ModelChoice;
    value(match choice {
        ModelChoice::Elliptic => elliptic,
        ModelChoice::Line => line,
        ModelChoice::Section9 => elliptic || line,
    })
}
