//! The record format: a fixed header, the payload a [`Checkpoint`] type writes, and a
//! CRC-32 over both. Pure functions on byte slices; no flash here.
//!
//! | bytes | field | value |
//! | --- | --- | --- |
//! | 0..4 | magic | `b"MSLG"` |
//! | 4 | kind | [`Checkpoint::KIND`] |
//! | 5 | framing | [`FRAMING`] (this table's version) |
//! | 6..8 | format version | [`Checkpoint::VERSION`] of the writer, u16 LE |
//! | 8..10 | payload length | bytes, u16 LE |
//! | 10..12 | reserved | 0 |
//! | 12..16 | sequence | checkpoint number, u32 LE |
//! | 16..16+n | payload | [`Checkpoint::encode`] |
//! | 16+n..20+n | CRC-32 | IEEE (zlib's), over bytes 0..16+n, u32 LE |

use core::fmt;

use super::Checkpoint;
use crate::bytes::FieldError;

/// The magic bytes at the start of every record: a record of another program fails here.
pub const MAGIC: [u8; 4] = *b"MSLG";
/// The version of the framing (the header layout above), not of any payload.
pub const FRAMING: u8 = 1;
/// Header bytes before the payload.
pub const HEADER_LEN: usize = 16;
/// Bytes a record adds to its payload: the header and the CRC.
pub const OVERHEAD: usize = HEADER_LEN + 4;

/// Bytes of the record of a payload of `payload` bytes.
#[must_use]
pub const fn record_len(payload: usize) -> usize {
    payload + OVERHEAD
}

/// Why bytes could not be encoded or decoded as a record.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[non_exhaustive]
pub enum CodecError {
    /// The output buffer is shorter than the record (`needed` bytes).
    BufferTooSmall {
        /// Bytes the record needs.
        needed: usize,
    },
    /// A read or write went past the end of the payload.
    Truncated,
    /// The payload had bytes left over after decoding, or `encode` wrote fewer bytes
    /// than [`Checkpoint::SIZE`].
    TrailingBytes,
    /// The bytes do not start with [`MAGIC`] and this framing: not one of our records.
    Foreign,
    /// A record of ours, of another kind (another [`Checkpoint`] type).
    WrongKind {
        /// The kind found.
        found: u8,
    },
    /// The CRC does not match: the record is damaged.
    Checksum,
    /// The header's length disagrees with the record's size, or the payload is longer
    /// than a record can say (65 535 bytes).
    Length,
    /// A format version this firmware cannot read (newer, or older without a
    /// [`Checkpoint::migrate`] arm for it).
    UnsupportedVersion {
        /// The version found.
        version: u16,
    },
    /// The payload decoded, but a field holds a value the type refuses.
    InvalidValue,
    /// Every field holds a value of its type, but together they hold a state no writer
    /// reaches: a time after the state's own clock, a count above what it counts.
    Inconsistent,
}

impl fmt::Display for CodecError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            CodecError::BufferTooSmall { needed } => {
                write!(f, "buffer too small for the record ({needed} bytes)")
            }
            CodecError::Truncated => f.write_str("read or write past the end of the payload"),
            CodecError::TrailingBytes => f.write_str("payload size differs from the type's"),
            CodecError::Foreign => f.write_str("not a misalign record (magic or framing)"),
            CodecError::WrongKind { found } => write!(f, "record of another kind ({found})"),
            CodecError::Checksum => f.write_str("record checksum mismatch"),
            CodecError::Length => f.write_str("record length field mismatch"),
            CodecError::UnsupportedVersion { version } => {
                write!(f, "unsupported format version {version}")
            }
            CodecError::InvalidValue => f.write_str("a field holds a value the type refuses"),
            CodecError::Inconsistent => f.write_str("the fields contradict each other"),
        }
    }
}

impl core::error::Error for CodecError {}

impl From<FieldError> for CodecError {
    fn from(e: FieldError) -> Self {
        match e {
            FieldError::Truncated => CodecError::Truncated,
            FieldError::InvalidValue => CodecError::InvalidValue,
            FieldError::TrailingBytes => CodecError::TrailingBytes,
        }
    }
}

/// CRC-32 of the records: the prepared scenes' own (IEEE 802.3, reflected, as
/// zlib's `crc32`), one routine in the image for both.
pub use crate::bytes::crc32;

/// Writes little-endian fields into a payload, never past its end: the crate's one
/// byte writer ([`crate::bytes::Writer`]), failing with a [`CodecError`].
pub type Writer<'a> = crate::bytes::Writer<'a, CodecError>;

/// Reads little-endian fields from a payload, never past its end: the crate's one
/// byte reader ([`crate::bytes::Reader`]), failing with a [`CodecError`].
pub type Reader<'a> = crate::bytes::Reader<'a, CodecError>;

/// A record decoded: the value, its checkpoint number and the format version it was
/// stored in (older than [`Checkpoint::VERSION`] when it was migrated).
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Decoded<T> {
    /// The value, in the current version's type.
    pub value: T,
    /// The checkpoint number the record was written with.
    pub sequence: u32,
    /// The format version the record was written in.
    pub version: u16,
}

/// Encodes `value` as a record numbered `sequence` into the start of `out`; returns the
/// record's length, [`record_len`]`(T::SIZE)`.
pub fn encode<T: Checkpoint>(
    value: &T,
    sequence: u32,
    out: &mut [u8],
) -> Result<usize, CodecError> {
    let len = record_len(T::SIZE);
    let payload_len = u16::try_from(T::SIZE).map_err(|_| CodecError::Length)?;
    let out = out
        .get_mut(..len)
        .ok_or(CodecError::BufferTooSmall { needed: len })?;
    let (body, crc_bytes) = out
        .split_at_mut_checked(len - 4)
        .ok_or(CodecError::Length)?;
    let (header, payload) = body
        .split_at_mut_checked(HEADER_LEN)
        .ok_or(CodecError::Length)?;
    let mut w = Writer::new(header);
    w.bytes(&MAGIC)?;
    w.u8(T::KIND)?;
    w.u8(FRAMING)?;
    w.u16(T::VERSION)?;
    w.u16(payload_len)?;
    w.u16(0)?;
    w.u32(sequence)?;
    let mut w = Writer::new(payload);
    value.encode(&mut w)?;
    if w.written() != T::SIZE {
        return Err(CodecError::TrailingBytes);
    }
    Writer::new(crc_bytes).u32(crc32(body))?;
    Ok(len)
}

/// Decodes a record of `T` (or of an older version of it, through
/// [`Checkpoint::migrate`]). Every check comes before the payload is read: a damaged,
/// foreign or unknown record is an error, never a value.
pub fn decode<T: Checkpoint>(record: &[u8]) -> Result<Decoded<T>, CodecError> {
    let (mut r, header) = payload::<T>(record)?;
    let value = if header.version == T::VERSION {
        T::decode(&mut r)?
    } else {
        T::migrate(header.version, &mut r)?
    };
    r.finish()?;
    Ok(Decoded {
        value,
        sequence: header.sequence,
        version: header.version,
    })
}

/// [`decode`] into `value` in place ([`Checkpoint::decode_into`]; an older version
/// through [`Checkpoint::migrate`]): the same checks and errors, and no second value
/// on the stack. Returns the record's number and version. On an error from the
/// payload `value` may hold part of it: start afresh.
pub fn decode_into<T: Checkpoint>(record: &[u8], value: &mut T) -> Result<Decoded<()>, CodecError> {
    let (mut r, header) = payload::<T>(record)?;
    if header.version == T::VERSION {
        value.decode_into(&mut r)?;
    } else {
        *value = T::migrate(header.version, &mut r)?;
    }
    r.finish()?;
    Ok(header)
}

/// The checks of a record of `T` before its payload is read: a reader over the
/// payload, and the record's number and version (a version `T` reads).
fn payload<T: Checkpoint>(record: &[u8]) -> Result<(Reader<'_>, Decoded<()>), CodecError> {
    let mut r = Reader::new(record);
    if r.array::<4>().map_err(|_| CodecError::Foreign)? != MAGIC {
        return Err(CodecError::Foreign);
    }
    // The magic matched: from here on the header is ours.
    let kind = r.u8()?;
    let framing = r.u8()?;
    if framing != FRAMING {
        return Err(CodecError::Foreign);
    }
    let version = r.u16()?;
    let payload_len = usize::from(r.u16()?);
    let _reserved = r.u16()?;
    let sequence = r.u32()?;
    if record.len() != record_len(payload_len) {
        return Err(CodecError::Length);
    }
    let (body, crc_bytes) = record
        .split_at_checked(record.len().saturating_sub(4))
        .ok_or(CodecError::Length)?;
    let mut crc = Reader::new(crc_bytes);
    if crc.u32()? != crc32(body) {
        return Err(CodecError::Checksum);
    }
    if kind != T::KIND {
        return Err(CodecError::WrongKind { found: kind });
    }
    if version > T::VERSION {
        return Err(CodecError::UnsupportedVersion { version });
    }
    if version == T::VERSION && payload_len != T::SIZE {
        return Err(CodecError::Length);
    }
    let payload = body.get(HEADER_LEN..).ok_or(CodecError::Length)?;
    let header = Decoded {
        value: (),
        sequence,
        version,
    };
    Ok((Reader::new(payload), header))
}
