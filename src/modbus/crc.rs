//! CRC-16/MODBUS (polynomial 0xA001 reflected, initial value 0xFFFF, no final XOR),
//! sent low byte first. Two 512-byte tables: a byte costs a shift, an XOR and a load
//! instead of eight conditional shifts (about ten instructions on a Cortex-M0
//! against about seventy), and two bytes at once (a register's word) two loads and
//! XORs ("slicing by 2").

/// The CRC of each byte value.
static TABLE: [u16; 256] = table();
/// The CRC of each byte value followed by a zero byte: `crc` advanced over two bytes
/// is `TABLE2[low byte of crc ^ first] ^ TABLE[high byte of crc ^ second]`.
static TABLE2: [u16; 256] = table2();

const fn table() -> [u16; 256] {
    let mut t = [0u16; 256];
    let mut i = 0;
    while i < 256 {
        let mut c = i as u16;
        let mut bit = 0;
        while bit < 8 {
            c = if c & 1 != 0 {
                (c >> 1) ^ 0xA001
            } else {
                c >> 1
            };
            bit += 1;
        }
        t[i] = c;
        i += 1;
    }
    t
}

const fn table2() -> [u16; 256] {
    let one = table();
    let mut t = [0u16; 256];
    let mut i = 0;
    while i < 256 {
        t[i] = (one[i] >> 8) ^ one[(one[i] & 0xFF) as usize];
        i += 1;
    }
    t
}

/// The CRC's initial value.
pub(crate) const INIT: u16 = 0xFFFF;

/// `crc` advanced over one byte.
#[inline(always)]
pub(crate) fn step(crc: u16, byte: u8) -> u16 {
    (crc >> 8) ^ TABLE[usize::from((crc as u8) ^ byte)]
}

/// `crc` advanced over the two bytes of a register's word, high byte first (as it
/// goes on the wire).
#[inline(always)]
#[cfg(test)]
pub(crate) fn word(crc: u16, word: u16) -> u16 {
    // The first byte in the low half, as the reflected CRC takes it.
    let x = crc ^ word.swap_bytes();
    TABLE2[usize::from(x as u8)] ^ TABLE[usize::from(x >> 8)]
}

/// The CRC of `bytes`.
pub fn crc16(bytes: &[u8]) -> u16 {
    // Four bytes a turn (two pairs), then what is left.
    let (quads, rest) = bytes.as_chunks::<4>();
    // In a u32 whose high half stays 0: no masking of the CRC to 16 bits per pair.
    let mut c = u32::from(INIT);
    for &[a, b, x, y] in quads {
        c = pair(pair(c, a, b), x, y);
    }
    let (pairs, rest) = rest.as_chunks::<2>();
    for &[a, b] in pairs {
        c = pair(c, a, b);
    }
    rest.iter().fold(c as u16, |c, &b| step(c, b))
}

/// `crc` (below 2^16) advanced over two bytes.
#[inline(always)]
fn pair(crc: u32, first: u8, second: u8) -> u32 {
    let lo = (crc ^ u32::from(first)) & 0xFF;
    let hi = ((crc >> 8) ^ u32::from(second)) & 0xFF;
    u32::from(TABLE2[lo as usize]) ^ u32::from(TABLE[hi as usize])
}

/// Whether `frame` (at least the two CRC bytes) ends with the CRC of what precedes
/// them, low byte first.
pub(crate) fn valid(frame: &[u8]) -> bool {
    match frame.split_last_chunk::<2>() {
        Some((body, crc)) => crc16(body) == u16::from_le_bytes(*crc),
        None => false,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A bit at a time, as the specification's appendix describes it.
    fn bitwise(bytes: &[u8]) -> u16 {
        let mut crc = 0xFFFFu16;
        for &b in bytes {
            crc ^= u16::from(b);
            for _ in 0..8 {
                crc = if crc & 1 != 0 {
                    (crc >> 1) ^ 0xA001
                } else {
                    crc >> 1
                };
            }
        }
        crc
    }

    #[test]
    fn check_value_and_known_frame() {
        // The catalogue's check value of CRC-16/MODBUS over "123456789".
        assert_eq!(crc16(b"123456789"), 0x4B37);
        // Read holding registers 0x006B, 3 of them, unit 0x11: CRC bytes 76 87.
        assert_eq!(
            crc16(&[0x11, 0x03, 0x00, 0x6B, 0x00, 0x03]).to_le_bytes(),
            [0x76, 0x87]
        );
        assert!(valid(&[0x11, 0x03, 0x00, 0x6B, 0x00, 0x03, 0x76, 0x87]));
        assert!(!valid(&[0x11, 0x03, 0x00, 0x6B, 0x00, 0x03, 0x87, 0x76]));
        assert!(!valid(&[0x11]));
    }

    #[test]
    fn table_matches_bitwise() {
        let data: std::vec::Vec<u8> = (0..=255u8).chain((0..=255u8).rev()).collect();
        for n in 0..data.len() {
            assert_eq!(crc16(&data[..n]), bitwise(&data[..n]), "length {n}");
        }
    }

    #[test]
    fn a_word_is_its_two_bytes() {
        for (c, w) in [
            (INIT, 0u16),
            (0x1234, 0xABCD),
            (0xFFFF, 0xFFFF),
            (0, 0x00FF),
        ] {
            let [hi, lo] = w.to_be_bytes();
            assert_eq!(word(c, w), step(step(c, hi), lo), "{c:#x} {w:#x}");
        }
    }
}
