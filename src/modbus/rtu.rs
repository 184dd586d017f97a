//! RTU framing, fed a byte at a time: frame boundaries from the function code's
//! length, the CRC as the judge, resynchronisation by sliding one byte past whatever
//! is not a frame, and the 3.5-character silence where the application reports it.
//!
//! The bytes since the last frame wait in a buffer of one ADU (256 bytes). Once its
//! address and function code wait, and then at each byte that can decide it, the
//! *candidate* (the frame that would start at the oldest waiting byte) is
//! classified from them: a request of a known length for
//! this unit or a broadcast is taken once complete with a valid CRC; a frame for
//! another unit (its request, or another server's response) is skipped once either
//! length has a valid CRC; anything else (an address above 247, an unknown function
//! code, a declared length above 256 bytes, a complete candidate with a wrong CRC)
//! drops its first byte, and the next byte becomes the candidate. Each byte is a
//! candidate's first byte at most once, and a candidate is checked once per length.
//! The server takes two shortcuts that decide as the classification would: a byte that
//! cannot decide the candidate is only appended ([`Framer::push_waiting`]), and a
//! poll's second byte (functions 1 to 6, for this unit or a broadcast) gives its length
//! at once ([`Framer::push_request_head`]), after which its CRC alone decides it.
//!
//! The silence ([`Framer::silence`]) ends whatever waits: the bytes since the last
//! frame, whole, are a frame if their CRC holds (the specification's rule, which also
//! finds requests of function codes whose length this table does not know, to be
//! answered with exception 01); otherwise the candidates are resolved as if no more
//! bytes could come (an incomplete one drops its first byte), and the buffer empties.

use super::crc;
use core::ops::Range;

/// The largest RTU frame (address, PDU of up to 253 bytes, CRC).
pub const ADU_MAX: usize = 256;

/// The highest unicast address; 248 to 255 are reserved.
const ADDRESS_MAX: u8 = 247;

/// Waiting bytes before a new candidate is classified: its address and function code.
/// (A reserved address alone would already drop it; it is dropped when the next byte
/// comes instead, which changes no frame found and saves the first byte of every frame
/// a classification.)
const NEED_MIN: usize = 2;

/// A frame's length from its first bytes.
#[derive(Clone, Copy, PartialEq, Eq, Debug)]
enum Len {
    /// This many bytes, CRC included.
    Known(usize),
    /// The byte that gives it has not arrived yet.
    NeedMore,
    /// Not known for this function code.
    Unknown,
}

/// The length of a request with function code `b[1]`.
fn request_len(b: &[u8]) -> Len {
    let at = |i: usize, base: usize| {
        b.get(i)
            .map_or(Len::NeedMore, |&n| Len::Known(base + usize::from(n)))
    };
    match b[1] {
        1..=6 | 8 => Len::Known(8),
        7 | 11 | 12 | 17 => Len::Known(4),
        15 | 16 => at(6, 9),
        20 | 21 => at(2, 5),
        22 => Len::Known(10),
        23 => at(10, 13),
        24 => Len::Known(6),
        43 => match b.get(2) {
            Some(&0x0E) => Len::Known(7),
            Some(_) => Len::Unknown,
            None => Len::NeedMore,
        },
        _ => Len::Unknown,
    }
}

/// The length of a response with function code `b[1]` (another server's answer on
/// a shared bus).
fn response_len(b: &[u8]) -> Len {
    match b[1] {
        0x80..=0xFF => Len::Known(5),
        1..=4 => b
            .get(2)
            .map_or(Len::NeedMore, |&n| Len::Known(5 + usize::from(n))),
        5 | 6 | 15 | 16 => Len::Known(8),
        _ => Len::Unknown,
    }
}

/// What the candidate at the start of the waiting bytes is.
#[derive(Clone, Copy, PartialEq, Eq, Debug)]
enum Class {
    /// Not decided before this many bytes wait (the candidate's included).
    Need(usize),
    /// Not a frame: drop its first byte.
    Drop,
    /// A request for this unit (or a broadcast) of this length.
    Ours(usize),
    /// A frame for another unit of this length: skip it.
    Other(usize),
}

/// The candidate at the start of `b` for unit `unit`.
/// Out of line: most bytes, and a poll's last, are decided without it
/// ([`Framer::push_waiting`], [`Framer::push_request_head`], a known candidate's CRC),
/// and its set-up would otherwise be theirs.
#[inline(never)]
fn classify(b: &[u8], unit: u8) -> Class {
    let Some(&address) = b.first() else {
        return Class::Need(1);
    };
    if address > ADDRESS_MAX {
        return Class::Drop;
    }
    if b.len() < 2 {
        return Class::Need(2);
    }
    let more = b.len().saturating_add(1);
    let complete_with_crc = |n: usize| n <= b.len() && b.get(..n).is_some_and(crc::valid);
    if address == unit || address == 0 {
        return match request_len(b) {
            Len::NeedMore => Class::Need(more),
            Len::Known(n) if n <= ADU_MAX => {
                if n > b.len() {
                    Class::Need(n)
                } else if complete_with_crc(n) {
                    Class::Ours(n)
                } else {
                    Class::Drop
                }
            }
            Len::Known(_) | Len::Unknown => Class::Drop,
        };
    }
    // Another unit's request or another server's response: whichever length fits.
    // The fewest waiting bytes at which one of them can be decided.
    let mut need = usize::MAX;
    for len in [request_len(b), response_len(b)] {
        match len {
            Len::Known(n) if n <= ADU_MAX => {
                if n > b.len() {
                    need = need.min(n);
                } else if complete_with_crc(n) {
                    return Class::Other(n);
                }
            }
            Len::NeedMore => need = need.min(more),
            Len::Known(_) | Len::Unknown => {}
        }
    }
    if need == usize::MAX {
        Class::Drop
    } else {
        Class::Need(need)
    }
}

/// Counters of the framing.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct FramingCounters {
    /// Frames with a valid CRC, for any unit.
    pub frames: u32,
    /// Bytes dropped: not part of a frame with a valid CRC (garbage, a wrong CRC, a
    /// truncated or oversized frame, a reserved address).
    pub discarded: u32,
}

/// The byte-fed framer. `repr(C)`, the buffer last: the per-byte fields stay within
/// the short load and store offsets of a Cortex-M0.
#[derive(Debug, Clone)]
#[repr(C)]
pub struct Framer {
    len: usize,
    /// The candidate's first byte.
    start: usize,
    /// The end of the last frame found (the silence's whole-span check starts here).
    consumed: usize,
    /// Bytes since the last frame were moved out of the buffer to make room: the span
    /// since the last frame is no longer whole.
    overflowed: bool,
    /// Waiting bytes below which the candidate stays undecided: a byte that does not
    /// reach it costs no classification.
    need: usize,
    /// The candidate is a request for this unit (or a broadcast) of `need` bytes: once
    /// they wait, only its CRC decides it.
    known: bool,
    counters: FramingCounters,
    buf: [u8; ADU_MAX],
}

impl Default for Framer {
    fn default() -> Self {
        Self::new()
    }
}

impl Framer {
    /// An empty framer.
    pub const fn new() -> Self {
        Framer {
            buf: [0; ADU_MAX],
            len: 0,
            start: 0,
            consumed: 0,
            overflowed: false,
            need: NEED_MIN,
            known: false,
            counters: FramingCounters {
                frames: 0,
                discarded: 0,
            },
        }
    }

    /// The counters.
    pub const fn counters(&self) -> FramingCounters {
        self.counters
    }

    /// The bytes of a range [`next`](Self::next) or [`silence`](Self::silence) gave.
    pub fn bytes(&self, range: Range<usize>) -> &[u8] {
        self.buf.get(range).unwrap_or(&[])
    }

    /// Appends one received byte when it cannot decide the candidate (fewer bytes wait
    /// than it needs) and the buffer has room: the usual byte of a frame, at the cost
    /// of a compare and a store. Returns whether it did; if not, call
    /// [`push`](Self::push) and [`next`](Self::next).
    #[inline]
    pub fn push_waiting(&mut self, byte: u8) -> bool {
        let len = self.len;
        let waiting = len.wrapping_sub(self.start).wrapping_add(1);
        match self.buf.get_mut(len) {
            Some(slot) if waiting < self.need => {
                *slot = byte;
                self.len = len + 1;
                true
            }
            _ => false,
        }
    }

    /// Appends the byte after the candidate's address when the two begin a request of
    /// functions 1 to 6 for `unit` or a broadcast: a poll's second byte. Its length (8
    /// bytes) is then known, as the classification finds it, without it. Returns
    /// whether it did; if not, call [`push`](Self::push) and [`next`](Self::next).
    #[inline]
    pub fn push_request_head(&mut self, byte: u8, unit: u8) -> bool {
        const READS_AND_WRITES: core::ops::RangeInclusive<u8> = 1..=6;
        let len = self.len;
        if len.wrapping_sub(self.start) != 1 || !READS_AND_WRITES.contains(&byte) {
            return false;
        }
        let ours = self
            .buf
            .get(self.start)
            .is_some_and(|&a| a == unit || a == 0);
        match self.buf.get_mut(len) {
            Some(slot) if ours => {
                *slot = byte;
                self.len = len + 1;
                self.need = 8;
                self.known = true;
                true
            }
            _ => false,
        }
    }

    /// Appends one received byte. A full buffer first drops the bytes before the
    /// candidate (or the candidate's first byte).
    pub fn push(&mut self, byte: u8) {
        if self.len >= ADU_MAX {
            if self.start == 0 {
                self.drop_one();
            }
            let len = self.len.min(ADU_MAX);
            let start = self.start.min(len);
            self.shift_down(start, len);
            self.overflowed |= self.consumed < start;
            self.len = len - start;
            self.consumed = self.consumed.saturating_sub(start);
            self.start = 0;
        }
        if let Some(slot) = self.buf.get_mut(self.len) {
            *slot = byte;
            self.len = self.len.saturating_add(1);
        }
    }

    /// Moves `buf[start..len]` to the buffer's start, in pieces of at most `start`
    /// bytes, none of which overlaps its destination: a copy (memcpy, which the
    /// image links anyway), not a move (memmove, 1.3 KB more on a Cortex-M0).
    fn shift_down(&mut self, start: usize, len: usize) {
        let mut at: usize = 0;
        while start > 0 && at.saturating_add(start) < len {
            let Some((dest, src)) = self.buf.split_at_mut_checked(at.saturating_add(start)) else {
                return;
            };
            let n = start.min(len.saturating_sub(dest.len()));
            let s = src.get(..n).unwrap_or(&[]);
            if let Some(d) = dest.get_mut(at..).and_then(|d| d.get_mut(..s.len())) {
                d.copy_from_slice(s);
            }
            at = at.saturating_add(n);
        }
    }

    fn drop_one(&mut self) {
        self.start = self.start.saturating_add(1);
        self.need = NEED_MIN;
        self.known = false;
        self.counters.discarded = self.counters.discarded.saturating_add(1);
    }

    /// The next request for `unit` (or a broadcast) among the waiting bytes, as a
    /// range for [`bytes`](Self::bytes); `None` until more bytes come. With `silence`
    /// (no more bytes of this frame will come) an incomplete candidate is dropped.
    pub fn next(&mut self, unit: u8, silence: bool) -> Option<Range<usize>> {
        loop {
            let waiting = self.buf.get(self.start..self.len)?;
            if waiting.is_empty() || (!silence && waiting.len() < self.need) {
                return None;
            }
            if self.known && waiting.len() >= self.need {
                let n = self.need;
                if waiting.get(..n).is_some_and(crc::valid) {
                    return Some(self.take(n));
                }
                self.drop_one();
                continue;
            }
            match classify(waiting, unit) {
                Class::Need(_) if silence => self.drop_one(),
                Class::Need(n) => {
                    self.need = n;
                    return None;
                }
                Class::Drop => self.drop_one(),
                Class::Ours(n) => return Some(self.take(n)),
                Class::Other(n) => {
                    self.take(n);
                }
            }
        }
    }

    fn take(&mut self, n: usize) -> Range<usize> {
        let range = self.start..self.start.saturating_add(n);
        self.start = range.end;
        self.consumed = range.end;
        self.need = NEED_MIN;
        self.known = false;
        self.counters.frames = self.counters.frames.saturating_add(1);
        range
    }

    /// The silence: the bytes since the last frame, whole, if they are a frame for
    /// `unit` with a valid CRC that the length table did not find (an unknown
    /// function code). Call [`next`](Self::next) with `silence` after it until it
    /// answers `None`, then [`clear`](Self::clear).
    pub fn silence(&mut self, unit: u8) -> Option<Range<usize>> {
        let span = self.consumed..self.len;
        let bytes = self.buf.get(span.clone())?;
        let whole = !self.overflowed
            && bytes.len() >= 4
            && (bytes[0] == unit || bytes[0] == 0)
            && crc::valid(bytes);
        if whole {
            // The bytes counted as dropped were a frame after all.
            let n = self.start.saturating_sub(self.consumed) as u32;
            self.counters.discarded = self.counters.discarded.saturating_sub(n);
            self.start = span.start;
            Some(self.take(span.len()))
        } else {
            None
        }
    }

    /// Empties the buffer (after a silence).
    pub fn clear(&mut self) {
        let left = self.len.saturating_sub(self.start) as u32;
        self.counters.discarded = self.counters.discarded.saturating_add(left);
        self.len = 0;
        self.start = 0;
        self.consumed = 0;
        self.overflowed = false;
        self.need = NEED_MIN;
        self.known = false;
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::vec::Vec;

    fn frame(body: &[u8]) -> Vec<u8> {
        let mut f = body.to_vec();
        f.extend_from_slice(&crc::crc16(body).to_le_bytes());
        f
    }

    fn feed(f: &mut Framer, bytes: &[u8], unit: u8) -> Vec<Vec<u8>> {
        let mut out = Vec::new();
        for &b in bytes {
            f.push(b);
            while let Some(r) = f.next(unit, false) {
                out.push(f.bytes(r).to_vec());
            }
        }
        out
    }

    /// As `Server::receive` feeds it: the usual byte and a poll's second byte by
    /// their shortcuts, the others through `push` and `next`.
    fn feed_as_the_server(f: &mut Framer, bytes: &[u8], unit: u8) -> Vec<Vec<u8>> {
        let mut out = Vec::new();
        for &b in bytes {
            if f.push_waiting(b) || f.push_request_head(b, unit) {
                continue;
            }
            f.push(b);
            while let Some(r) = f.next(unit, false) {
                out.push(f.bytes(r).to_vec());
            }
        }
        out
    }

    /// The shortcuts find what classifying every byte finds: the same frames and
    /// counts over streams of polls for this unit, another and all (some with a
    /// wrong CRC or cut short), other functions and garbage.
    #[test]
    fn the_servers_shortcuts_find_what_classifying_finds() {
        let mut seed = 0x2545_F491_u32;
        let mut next = move || {
            seed ^= seed << 13;
            seed ^= seed >> 17;
            seed ^= seed << 5;
            seed
        };
        for _ in 0..2000 {
            let mut stream = Vec::new();
            for _ in 0..next() % 12 {
                let r = next();
                let unit = [0, 1, 1, 2, 247, 250][(r % 6) as usize];
                let function = [1, 3, 4, 6, 7, 16, 43, 0x83][(r >> 8) as usize % 8];
                let mut f = frame(&[unit, function, 0, (r >> 16) as u8, 0, 2]);
                match r >> 24 & 7 {
                    0 => f[4] ^= 1,
                    1 => f.truncate((r >> 12) as usize % f.len()),
                    2 => f.push((r >> 4) as u8),
                    _ => {}
                }
                stream.extend(f);
            }
            let mut plain = Framer::new();
            let mut server = Framer::new();
            assert_eq!(
                feed(&mut plain, &stream, 1),
                feed_as_the_server(&mut server, &stream, 1),
                "{stream:02x?}"
            );
            assert_eq!(plain.counters(), server.counters(), "{stream:02x?}");
        }
    }

    /// The buffer's compaction moves what `copy_within` moves, for every cut.
    #[test]
    fn shifting_down_is_copy_within() {
        for len in [0, 1, 7, 128, 255, ADU_MAX] {
            for start in 0..=len {
                let mut f = Framer::new();
                for (i, b) in f.buf.iter_mut().enumerate() {
                    *b = i as u8 ^ 0x5A;
                }
                let mut expected = f.buf;
                expected.copy_within(start..len, 0);
                f.shift_down(start, len);
                assert_eq!(f.buf, expected, "{start}..{len}");
            }
        }
    }

    #[test]
    fn a_request_after_garbage_and_another_units_traffic() {
        let ours = frame(&[1, 3, 0, 0, 0, 16]);
        let theirs = frame(&[2, 3, 0, 0, 0, 2]);
        let their_answer = frame(&[2, 3, 4, 0, 1, 0, 2]);
        let mut bytes = vec![0xFF, 0x01, 0x10, 0x00];
        bytes.extend(&theirs);
        bytes.extend(&their_answer);
        bytes.extend(&ours);
        let mut f = Framer::new();
        let got = feed(&mut f, &bytes, 1);
        assert_eq!(got, vec![ours]);
        assert_eq!(f.counters().frames, 3);
    }

    #[test]
    fn unknown_function_code_found_at_the_silence() {
        let request = frame(&[1, 0x41, 9, 9, 9]);
        let mut f = Framer::new();
        assert!(feed(&mut f, &request, 1).is_empty());
        let r = f.silence(1).expect("the whole span is a frame");
        assert_eq!(f.bytes(r), &request[..]);
        assert_eq!(f.counters().discarded, 0);
        assert!(f.next(1, true).is_none());
        f.clear();
    }

    #[test]
    fn a_frame_inside_an_incomplete_candidate_is_found_at_the_silence() {
        // A function-16 header declaring 200 data bytes, then a whole request.
        let ours = frame(&[1, 4, 0, 0, 0, 1]);
        let mut bytes = vec![1, 16, 0, 0, 0, 100, 200];
        bytes.extend(&ours);
        let mut f = Framer::new();
        assert!(feed(&mut f, &bytes, 1).is_empty());
        assert!(f.silence(1).is_none());
        let r = f
            .next(1, true)
            .expect("found once the candidate cannot complete");
        assert_eq!(f.bytes(r), &ours[..]);
    }

    #[test]
    fn a_long_stream_of_garbage_overflows_without_harm() {
        let mut f = Framer::new();
        // A function-16 header declaring 246 data bytes holds the buffer full until
        // its candidate fails; reserved addresses are dropped at once.
        let mut garbage = vec![1, 16, 0, 0, 0, 123, 246];
        garbage.extend((0..2000u32).map(|i| if i % 3 == 0 { 0 } else { 0xF8 | i as u8 }));
        assert!(feed(&mut f, &garbage, 1).is_empty());
        assert!(f.counters().discarded > 2000);
        let ours = frame(&[1, 1, 0, 0, 0, 8]);
        assert_eq!(feed(&mut f, &ours, 1), vec![ours]);
    }
}
