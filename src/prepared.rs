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

/// CRC-32 (IEEE 802.3, reflected, as zlib's `crc32`), bit by bit: no table in flash.
pub fn crc32(bytes: &[u8]) -> u32 {
    let mut crc = !0u32;
    for &byte in bytes {
        crc ^= u32::from(byte);
        for _ in 0..8 {
            let mask = (crc & 1).wrapping_neg();
            crc = (crc >> 1) ^ (0xEDB8_8320 & mask);
        }
    }
    !crc
}

/// Writes one scene's bytes: the header on creation, the constants in order, the
/// CRC-32 on [`Writer::finish`]. Writes past the end are dropped (the lengths are
/// constants, held by the tests).
pub(crate) struct Writer<'a> {
    buf: &'a mut [u8],
    at: usize,
}

impl<'a> Writer<'a> {
    pub(crate) fn new(buf: &'a mut [u8], kind: Kind) -> Self {
        let mut w = Writer { buf, at: 0 };
        w.bytes(&[MAGIC[0], MAGIC[1], kind as u8, FORMAT_VERSION]);
        w
    }

    fn bytes(&mut self, b: &[u8]) {
        let end = self.at.saturating_add(b.len());
        if let Some(out) = self.buf.get_mut(self.at..end) {
            // (zip, not copy_from_slice: no length check to panic on.)
            for (o, &x) in out.iter_mut().zip(b) {
                *o = x;
            }
        }
        self.at = end;
    }

    pub(crate) fn u8(&mut self, x: u8) {
        self.bytes(&[x]);
    }
    pub(crate) fn u32(&mut self, x: u32) {
        self.bytes(&x.to_le_bytes());
    }
    pub(crate) fn i32(&mut self, x: i32) {
        self.bytes(&x.to_le_bytes());
    }
    pub(crate) fn f32(&mut self, x: f32) {
        self.u32(x.to_bits());
    }
    /// `n` zero bytes: an absent optional part.
    pub(crate) fn zeros(&mut self, n: usize) {
        for _ in 0..n {
            self.u8(0);
        }
    }

    /// An optional part: a flag byte, then `write`'s `n` bytes, or `n` zeros.
    pub(crate) fn option<T>(&mut self, x: Option<&T>, n: usize, write: impl FnOnce(&T, &mut Self)) {
        self.u8(x.is_some() as u8);
        match x {
            Some(x) => write(x, self),
            None => self.zeros(n),
        }
    }

    /// Writes the CRC-32 of everything before it into the last four bytes.
    pub(crate) fn finish(self) {
        let n = self.buf.len().saturating_sub(4);
        let (body, tail) = self.buf.split_at_mut(n);
        let crc = crc32(body).to_le_bytes();
        for (o, &x) in tail.iter_mut().zip(&crc) {
            *o = x;
        }
    }
}

/// A scene's bytes: the header, what `write` writes, the CRC-32.
pub(crate) fn seal<const N: usize>(kind: Kind, write: impl FnOnce(&mut Writer<'_>)) -> [u8; N] {
    let mut out = [0; N];
    let mut w = Writer::new(&mut out, kind);
    write(&mut w);
    w.finish();
    out
}

/// Reads one scene's constants after [`Reader::open`] checked the frame. Reads past
/// the end give 0 (not reached: the length is checked first).
pub(crate) struct Reader<'a> {
    bytes: &'a [u8],
    at: usize,
}

impl<'a> Reader<'a> {
    /// Checks length, magic, kind, version and checksum of `bytes`, which must be
    /// `len` long.
    pub(crate) fn open(bytes: &'a [u8], kind: Kind, len: usize) -> Result<Self, PreparedError> {
        if bytes.len() != len || len < OVERHEAD {
            return Err(PreparedError::Length);
        }
        let (body, crc) = bytes.split_at(len - 4);
        match body {
            [m0, m1, ..] if [*m0, *m1] != MAGIC => return Err(PreparedError::Magic),
            [_, _, k, ..] if *k != kind as u8 => return Err(PreparedError::Kind),
            [_, _, _, v, ..] if *v != FORMAT_VERSION => return Err(PreparedError::Version),
            _ => {}
        }
        if crc32(body).to_le_bytes() != crc {
            return Err(PreparedError::Checksum);
        }
        Ok(Reader { bytes: body, at: 4 })
    }

    fn array<const N: usize>(&mut self) -> [u8; N] {
        let end = self.at.saturating_add(N);
        let out = self
            .bytes
            .get(self.at..end)
            .and_then(|b| b.try_into().ok())
            .unwrap_or([0; N]);
        self.at = end;
        out
    }

    pub(crate) fn u8(&mut self) -> u8 {
        self.array::<1>()[0]
    }
    pub(crate) fn u32(&mut self) -> u32 {
        u32::from_le_bytes(self.array())
    }
    pub(crate) fn i32(&mut self) -> i32 {
        i32::from_le_bytes(self.array())
    }
    /// An f32 by its bits (checked by the caller, e.g. [`positive_normal`]).
    pub(crate) fn f32(&mut self) -> f32 {
        f32::from_bits(self.u32())
    }
    /// A flag byte: 0 or 1.
    pub(crate) fn flag(&mut self) -> Result<bool, PreparedError> {
        match self.u8() {
            0 => Ok(false),
            1 => Ok(true),
            _ => Err(PreparedError::Value),
        }
    }
    /// An optional part that [`Writer::option`] wrote.
    pub(crate) fn option<T>(
        &mut self,
        n: usize,
        read: impl FnOnce(&mut Self) -> Result<T, PreparedError>,
    ) -> Result<Option<T>, PreparedError> {
        if self.flag()? {
            read(self).map(Some)
        } else {
            self.zeros(n).map(|()| None)
        }
    }

    /// Skips `n` bytes, which must be zero (an absent optional part).
    pub(crate) fn zeros(&mut self, n: usize) -> Result<(), PreparedError> {
        for _ in 0..n {
            if self.u8() != 0 {
                return Err(PreparedError::Value);
            }
        }
        Ok(())
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
    match r.u8() {
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
