//! Structured fuzz inputs: numbers drawn from the corners of f64, f32 and u32 rather
//! than from uniform bits, where libFuzzer seldom lands (subnormals, the largest finite
//! values, powers of two and ten, values next to the models' thresholds). Each value is
//! one selector byte and eight payload bytes (little-endian), so that a seed input is
//! easy to write by hand (lab/fuzz/seeds/make.py writes the seeds).
#![allow(dead_code)]

use arbitrary::{Arbitrary, Result, Unstructured};

/// Where f64 ends and where the models change path: the smallest subnormals and normal,
/// the f32 limits, the cores' table and load thresholds (2^-40, 2^-27, 2^+-120), the
/// Q8.24 range (2^+-127), nu's bound 0.5, d/b = 1, pi/2, the f32 core's friction limit
/// 128, realistic steel values, and the largest finite values, inf and NaN.
pub const F64_CORNERS: [f64; 44] = [
    0.0,
    5e-324,
    1e-323,
    1e-310,
    2.2250738585072014e-308,
    1e-300,
    1e-100,
    7.888609052210118e-31, // 2^-100
    1e-38,
    1.1754943508222875e-38, // f32::MIN_POSITIVE
    1.401298464324817e-45,  // smallest f32 subnormal
    5.877471754111438e-39,  // 2^-127
    7.52316384526264e-37,   // 2^-120
    9.094947017729282e-13,  // 2^-40
    7.450580596923828e-9,   // 2^-27
    f64::EPSILON,
    1e-6,
    1e-3,
    0.05,
    0.1,
    0.3,
    0.49999999999999994,
    0.5,
    0.8,
    1.0,
    core::f64::consts::FRAC_PI_2,
    2.0,
    128.0,
    1000.0,
    79.3e9,
    1e10,
    1e24,
    1e30,
    7.922816251426434e28,  // 2^96
    1.329227995784916e36,  // 2^120
    1.7014118346046923e38, // 2^127
    3.4028234663852886e38, // f32::MAX
    1e38,
    1e100,
    1e300,
    1e308,
    f64::MAX,
    f64::INFINITY,
    f64::NAN,
];

/// The f64 for a selector and a payload. Bit 7 of the selector gives the sign (except
/// for raw bits, which carry their own); bits 0-2 the kind of value.
pub fn f64_from(pick: u8, payload: u64) -> f64 {
    let corner = F64_CORNERS[(payload % F64_CORNERS.len() as u64) as usize];
    let high = (payload >> 32) as u32;
    let x = match pick & 7 {
        0 => return f64::from_bits(payload), // any bits, as a plain f64 field would be
        1 => corner,
        // Every power of two from the smallest subnormal to 2^1023.
        2 => pow2_f64((payload % 2098) as i32 - 1074),
        // Subnormal (or 0).
        3 => f64::from_bits(payload & ((1 << 52) - 1)),
        // Up to four ulps either side of a corner.
        4 => {
            let mut y = corner;
            for _ in 0..high % 5 {
                y = if high & 8 == 0 {
                    y.next_up()
                } else {
                    y.next_down()
                };
            }
            y
        }
        // Powers of ten, 1e-323 to 1e308.
        5 => format!("1e{}", (payload % 632) as i64 - 323)
            .parse()
            .unwrap_or(1.0),
        // A realistic reading: 1 to 999 times a power of ten from 1e-20 to 1e20.
        6 => format!("{}e{}", payload % 999 + 1, (high % 41) as i64 - 20)
            .parse()
            .unwrap_or(1.0),
        // The f32 corners, as f64.
        _ => f32_from(1, payload) as f64,
    };
    if pick & 0x80 != 0 { -x } else { x }
}

/// 2^k for k in -1074 ..= 1023, exactly (subnormals included).
fn pow2_f64(k: i32) -> f64 {
    if k >= -1022 {
        f64::from_bits(((k + 1023) as u64) << 52)
    } else {
        f64::from_bits(1 << (k + 1074))
    }
}

/// 2^k for k in -149 ..= 127, exactly.
fn pow2_f32(k: i32) -> f32 {
    if k >= -126 {
        f32::from_bits(((k + 127) as u32) << 23)
    } else {
        f32::from_bits(1 << (k + 149))
    }
}

/// Where f32 ends and where the f32 core changes path.
pub const F32_CORNERS: [f32; 24] = [
    0.0,
    1.0e-45,
    1.1754942e-38, // largest subnormal
    f32::MIN_POSITIVE,
    7.888609e-31,  // 2^-100
    7.523_164e-37, // 2^-120
    9.094947e-13,  // 2^-40
    7.450581e-9,   // 2^-27
    f32::EPSILON,
    1e-6,
    2e-4,
    0.5,
    1.0,
    core::f32::consts::FRAC_PI_2,
    1.5707964, // pi/2 rounded up
    128.0,
    1000.0,
    1.329228e36,  // 2^120
    1.7014118e38, // 2^127
    1e38,
    f32::MAX,
    f32::INFINITY,
    f32::NAN,
    -0.0,
];

/// The f32 for a selector and a payload, like [`f64_from`].
pub fn f32_from(pick: u8, payload: u64) -> f32 {
    let corner = F32_CORNERS[(payload % F32_CORNERS.len() as u64) as usize];
    let high = (payload >> 32) as u32;
    let x = match pick & 7 {
        0 => return f32::from_bits(payload as u32),
        1 => corner,
        2 => pow2_f32((payload % 277) as i32 - 149),
        3 => f32::from_bits(payload as u32 & ((1 << 23) - 1)),
        4 => {
            let mut y = corner;
            for _ in 0..high % 5 {
                y = if high & 8 == 0 {
                    y.next_up()
                } else {
                    y.next_down()
                };
            }
            y
        }
        5 => format!("1e{}", (payload % 84) as i64 - 45)
            .parse()
            .unwrap_or(1.0),
        6 => format!("{}e{}", payload % 999 + 1, (high % 41) as i64 - 20)
            .parse()
            .unwrap_or(1.0),
        _ => f64_from(1, payload) as f32,
    };
    if pick & 0x80 != 0 { -x } else { x }
}

/// A count for the fixed-point core: the u32 and i32 limits, powers of two and their
/// neighbours, or any bits.
pub fn u32_from(pick: u8, payload: u64) -> u32 {
    const CORNERS: [u32; 12] = [
        0,
        1,
        2,
        3,
        1000,
        1_000_000,
        1 << 30,
        i32::MAX as u32,
        1 << 31,
        u32::MAX - 1,
        u32::MAX,
        65535,
    ];
    let k = (payload % 32) as u32;
    match pick & 3 {
        0 => payload as u32,
        1 => CORNERS[(payload % CORNERS.len() as u64) as usize],
        2 => 1 << k,
        _ => (1u32 << k).wrapping_add(if payload & (1 << 40) == 0 {
            1
        } else {
            u32::MAX
        }),
    }
}

macro_rules! structured {
    ($name:ident, $ty:ty, $from:ident) => {
        /// A structured value (one selector byte, eight payload bytes).
        #[derive(Debug, Clone, Copy)]
        pub struct $name(pub $ty);

        impl<'a> Arbitrary<'a> for $name {
            fn arbitrary(u: &mut Unstructured<'a>) -> Result<Self> {
                let pick = u8::arbitrary(u)?;
                let payload = u64::arbitrary(u)?;
                Ok($name($from(pick, payload)))
            }

            fn size_hint(_depth: usize) -> (usize, Option<usize>) {
                (9, Some(9))
            }
        }
    };
}

structured!(X64, f64, f64_from);
structured!(X32, f32, f32_from);
structured!(Count, u32, u32_from);

/// A signed angle count: a [`Count`] with the selector's bit 7 as its sign.
#[derive(Debug, Clone, Copy)]
pub struct Angle(pub i32);

impl<'a> Arbitrary<'a> for Angle {
    fn arbitrary(u: &mut Unstructured<'a>) -> Result<Self> {
        let pick = u8::arbitrary(u)?;
        let payload = u64::arbitrary(u)?;
        let magnitude = u32_from(pick, payload) as i32;
        Ok(Angle(if pick & 0x80 != 0 {
            magnitude.wrapping_neg()
        } else {
            magnitude
        }))
    }

    fn size_hint(_depth: usize) -> (usize, Option<usize>) {
        (9, Some(9))
    }
}
