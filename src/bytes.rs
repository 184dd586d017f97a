//! Little-endian fields in byte slices: the one [`Reader`] and [`Writer`] of every
//! byte format of the crate (the prepared scenes of [`crate::prepared`], the
//! checkpoint records of `storage::codec`), and their [`crc32`].
//!
//! Neither reads nor writes past its slice, and neither panics: a field that does not
//! fit is an error. The error is the format's own: `E` is any type that says a
//! [`FieldError`] its way (`From<FieldError>`), so that a checkpoint's payload fails
//! with a `CodecError` and a prepared scene with a
//! [`PreparedError`](crate::prepared::PreparedError), through the same code.
//!
//! Fields: `u8`, `u16`, `u32`, `u64`, `i32` little-endian; `f32` and `f64` as their
//! IEEE bits (restored bit for bit, NaN included: the format refuses what it must);
//! `bool` as one byte, 0 or 1; an optional part as a flag byte and then the part, or
//! as many zero bytes.

use core::fmt;
use core::marker::PhantomData;

/// Why a field could not be read or written.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[non_exhaustive]
pub enum FieldError {
    /// The field goes past the end of the slice.
    Truncated,
    /// The bytes hold no value of the field (a `bool` or flag neither 0 nor 1, a
    /// nonzero byte of an absent optional part).
    InvalidValue,
    /// Bytes were left over after the last field ([`Reader::finish`]).
    TrailingBytes,
}

impl fmt::Display for FieldError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            FieldError::Truncated => "field past the end of the bytes",
            FieldError::InvalidValue => "field holds no valid value",
            FieldError::TrailingBytes => "bytes left over after the last field",
        })
    }
}

impl core::error::Error for FieldError {}

/// CRC-32 (IEEE 802.3, reflected, as zlib's `crc32`), bit by bit: no table in flash.
/// The check of the prepared scenes and of the checkpoint records: one routine in an
/// image for both.
#[must_use]
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

/// Writes little-endian fields into a slice from its start, never past its end.
#[derive(Debug)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Writer<'a, E = FieldError> {
    out: &'a mut [u8],
    at: usize,
    error: PhantomData<fn() -> E>,
}

impl<'a, E: From<FieldError>> Writer<'a, E> {
    /// A writer filling `out` from its start.
    pub fn new(out: &'a mut [u8]) -> Self {
        Writer {
            out,
            at: 0,
            error: PhantomData,
        }
    }

    /// Bytes written so far.
    #[must_use]
    pub fn written(&self) -> usize {
        self.at
    }

    /// Writes raw bytes.
    pub fn bytes(&mut self, bytes: &[u8]) -> Result<(), E> {
        let end = self
            .at
            .checked_add(bytes.len())
            .ok_or(FieldError::Truncated)?;
        let out = self
            .out
            .get_mut(self.at..end)
            .ok_or(FieldError::Truncated)?;
        // (zip, not copy_from_slice: no length check to panic on.)
        for (o, &x) in out.iter_mut().zip(bytes) {
            *o = x;
        }
        self.at = end;
        Ok(())
    }

    /// Writes a `u8`.
    pub fn u8(&mut self, v: u8) -> Result<(), E> {
        self.bytes(&[v])
    }

    /// Writes a `u16`, little-endian.
    pub fn u16(&mut self, v: u16) -> Result<(), E> {
        self.bytes(&v.to_le_bytes())
    }

    /// Writes a `u32`, little-endian.
    pub fn u32(&mut self, v: u32) -> Result<(), E> {
        self.bytes(&v.to_le_bytes())
    }

    /// Writes a `u64`, little-endian.
    pub fn u64(&mut self, v: u64) -> Result<(), E> {
        self.bytes(&v.to_le_bytes())
    }

    /// Writes an `i32`, little-endian.
    pub fn i32(&mut self, v: i32) -> Result<(), E> {
        self.bytes(&v.to_le_bytes())
    }

    /// Writes an `f32` (its IEEE bits), little-endian: restored bit for bit.
    pub fn f32(&mut self, v: f32) -> Result<(), E> {
        self.u32(v.to_bits())
    }

    /// Writes an `f64` (its IEEE bits), little-endian: restored bit for bit.
    pub fn f64(&mut self, v: f64) -> Result<(), E> {
        self.u64(v.to_bits())
    }

    /// Writes a `bool` as one byte, 0 or 1.
    pub fn bool(&mut self, v: bool) -> Result<(), E> {
        self.u8(u8::from(v))
    }

    /// Writes `n` zero bytes.
    pub fn zeros(&mut self, n: usize) -> Result<(), E> {
        (0..n).try_for_each(|_| self.u8(0))
    }

    /// Writes an optional part of `n` bytes: a flag byte ([`Writer::bool`]), then
    /// `part`'s `n` bytes when there is one, else `n` zeros ([`Reader::option`] reads
    /// it back).
    pub fn option<T>(
        &mut self,
        x: Option<&T>,
        n: usize,
        part: impl FnOnce(&mut Self, &T) -> Result<(), E>,
    ) -> Result<(), E> {
        self.bool(x.is_some())?;
        match x {
            Some(x) => part(self, x),
            None => self.zeros(n),
        }
    }

    /// Writes every item of `items` with `field` (e.g. `w.each(&energies, |w, e| w.f64(*e))`).
    pub fn each<T>(
        &mut self,
        items: &[T],
        mut field: impl FnMut(&mut Self, &T) -> Result<(), E>,
    ) -> Result<(), E> {
        items.iter().try_for_each(|item| field(self, item))
    }
}

/// Reads little-endian fields from a slice from its start, never past its end.
#[derive(Debug)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Reader<'a, E = FieldError> {
    bytes: &'a [u8],
    at: usize,
    error: PhantomData<fn() -> E>,
}

impl<'a, E: From<FieldError>> Reader<'a, E> {
    /// A reader of `bytes` from their start.
    #[must_use]
    pub fn new(bytes: &'a [u8]) -> Self {
        Reader {
            bytes,
            at: 0,
            error: PhantomData,
        }
    }

    /// Bytes not read yet.
    #[must_use]
    pub fn remaining(&self) -> usize {
        self.bytes.len().saturating_sub(self.at)
    }

    /// Reads `N` raw bytes.
    pub fn array<const N: usize>(&mut self) -> Result<[u8; N], E> {
        let end = self.at.checked_add(N).ok_or(FieldError::Truncated)?;
        let out = self
            .bytes
            .get(self.at..end)
            .and_then(|b| <[u8; N]>::try_from(b).ok())
            .ok_or(FieldError::Truncated)?;
        self.at = end;
        Ok(out)
    }

    /// Reads a `u8`.
    pub fn u8(&mut self) -> Result<u8, E> {
        self.array::<1>().map(|[b]| b)
    }

    /// Reads a little-endian `u16`.
    pub fn u16(&mut self) -> Result<u16, E> {
        self.array().map(u16::from_le_bytes)
    }

    /// Reads a little-endian `u32`.
    pub fn u32(&mut self) -> Result<u32, E> {
        self.array().map(u32::from_le_bytes)
    }

    /// Reads a little-endian `u64`.
    pub fn u64(&mut self) -> Result<u64, E> {
        self.array().map(u64::from_le_bytes)
    }

    /// Reads a little-endian `i32`.
    pub fn i32(&mut self) -> Result<i32, E> {
        self.array().map(i32::from_le_bytes)
    }

    /// Reads an `f32` from its little-endian IEEE bits (any bits, NaN included: the
    /// format refuses what it must).
    pub fn f32(&mut self) -> Result<f32, E> {
        self.u32().map(f32::from_bits)
    }

    /// Reads an `f64` from its little-endian IEEE bits (any bits, NaN included).
    pub fn f64(&mut self) -> Result<f64, E> {
        self.u64().map(f64::from_bits)
    }

    /// Reads a `bool`: 0 or 1, anything else is [`FieldError::InvalidValue`].
    pub fn bool(&mut self) -> Result<bool, E> {
        match self.u8()? {
            0 => Ok(false),
            1 => Ok(true),
            _ => Err(FieldError::InvalidValue.into()),
        }
    }

    /// Skips `n` bytes, which must be zero ([`FieldError::InvalidValue`] if not).
    pub fn zeros(&mut self, n: usize) -> Result<(), E> {
        for _ in 0..n {
            if self.u8()? != 0 {
                return Err(FieldError::InvalidValue.into());
            }
        }
        Ok(())
    }

    /// Reads an optional part of `n` bytes that [`Writer::option`] wrote: `part`
    /// reads it after a flag of 1; after a flag of 0 its `n` bytes must be zero.
    pub fn option<T>(
        &mut self,
        n: usize,
        part: impl FnOnce(&mut Self) -> Result<T, E>,
    ) -> Result<Option<T>, E> {
        if self.bool()? {
            part(self).map(Some)
        } else {
            self.zeros(n).map(|()| None)
        }
    }

    /// Reads `N` items with `field`, into an array (e.g. `r.array_of(|r| r.f64())`).
    pub fn array_of<T: Copy + Default, const N: usize>(
        &mut self,
        mut field: impl FnMut(&mut Self) -> Result<T, E>,
    ) -> Result<[T; N], E> {
        let mut out = [T::default(); N];
        for item in &mut out {
            *item = field(self)?;
        }
        Ok(out)
    }

    /// Succeeds if every byte was read ([`FieldError::TrailingBytes`] if not).
    pub fn finish(&self) -> Result<(), E> {
        if self.remaining() == 0 {
            Ok(())
        } else {
            Err(FieldError::TrailingBytes.into())
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fields_round_trip_little_endian() {
        let mut buf = [0u8; 4 + 2 + 1 + 4 + 2 + 2];
        let mut w = Writer::<FieldError>::new(&mut buf);
        w.u32(0x0403_0201).unwrap();
        w.u16(0x0605).unwrap();
        w.bool(true).unwrap();
        w.f32(-0.0).unwrap();
        w.option(None::<&u8>, 1, |w, x| w.u8(*x)).unwrap();
        w.option(Some(&7u8), 1, |w, x| w.u8(*x)).unwrap();
        assert_eq!(w.written(), buf.len());
        assert_eq!(buf, [1, 2, 3, 4, 5, 6, 1, 0, 0, 0, 0x80, 0, 0, 1, 7]);

        let mut r = Reader::<FieldError>::new(&buf);
        assert_eq!(r.u32(), Ok(0x0403_0201));
        assert_eq!(r.u16(), Ok(0x0605));
        assert_eq!(r.bool(), Ok(true));
        assert_eq!(r.f32().map(f32::to_bits), Ok((-0.0f32).to_bits()));
        assert_eq!(r.option(1, |r| r.u8()), Ok(None));
        assert_eq!(r.option(1, |r| r.u8()), Ok(Some(7)));
        assert_eq!(r.finish(), Ok(()));
    }

    #[test]
    fn nothing_past_the_end_and_no_invalid_value() {
        let mut buf = [0u8; 3];
        let mut w = Writer::<FieldError>::new(&mut buf);
        assert_eq!(w.u32(1), Err(FieldError::Truncated));
        assert_eq!(w.written(), 0);
        assert_eq!(w.u16(0x0102), Ok(()));
        assert_eq!(w.u16(0), Err(FieldError::Truncated));
        assert_eq!(buf, [2, 1, 0]);

        let mut r = Reader::<FieldError>::new(&[2, 1, 0]);
        assert_eq!(r.u32(), Err(FieldError::Truncated));
        assert_eq!(r.remaining(), 3);
        assert_eq!(r.finish(), Err(FieldError::TrailingBytes));
        assert_eq!(r.bool(), Err(FieldError::InvalidValue));
        assert_eq!(
            Reader::<FieldError>::new(&[0, 0, 9]).option(2, |r| r.u16()),
            Err(FieldError::InvalidValue)
        );
    }
}
