//! Divisions without a division routine: a node without a hardware divider (the
//! Cortex-M0) links none for the server's few divisions (the seconds of a millisecond
//! count, the record of an address in a block).

/// `x / 1000` for every u32, by a multiplication: `x` times 2^41 / 1000 rounded up
/// (2199023256, 448 / 1000 above it: less than 2^(41 - 32) / 1000, so exact for every
/// 32-bit `x`, Granlund and Montgomery's bound), shifted down 41 bits. No division
/// routine is linked into a node without a divider (the Cortex-M0).
pub(crate) fn div1000(x: u32) -> u32 {
    ((u64::from(x) * 2_199_023_256) >> 41) as u32
}

/// `n / d` and `n % d` (`None` for `d` 0) by shifts and subtractions, 16 steps: no
/// division routine linked into a node without a divider (the Cortex-M0), for the few
/// divisions by a block's stride, none of them on a poll's path. Out of line: one
/// copy for its three callers.
#[inline(never)]
pub(crate) fn div_rem(n: u16, d: u16) -> Option<(u16, u16)> {
    if d == 0 {
        return None;
    }
    let (mut q, mut r) = (0u16, 0u32);
    for i in (0..16).rev() {
        r = r << 1 | u32::from(n >> i & 1);
        q <<= 1;
        if r >= u32::from(d) {
            r -= u32::from(d);
            q |= 1;
        }
    }
    Some((q, r as u16))
}

#[cfg(test)]
mod tests {
    use super::{div_rem, div1000};

    /// Every u32 near a multiple of 1000 (where a quotient changes), the extremes and
    /// a spread of others.
    #[test]
    fn div1000_is_division() {
        let near = (0..=4_294_967u32).flat_map(|k| {
            let m = k.wrapping_mul(1000);
            [m, m.wrapping_sub(1), m.wrapping_add(999)]
        });
        let mut x = 0x2545_F491u32;
        let spread = (0..1_000_000).map(|_| {
            x ^= x << 13;
            x ^= x >> 17;
            x ^= x << 5;
            x
        });
        for v in near.chain(spread).chain([u32::MAX, u32::MAX - 1, 1 << 31]) {
            assert_eq!(div1000(v), v / 1000, "{v}");
        }
    }

    #[test]
    fn div_rem_is_division() {
        for n in 0..=u16::MAX {
            for d in [
                0,
                1,
                2,
                3,
                6,
                7,
                11,
                25,
                255,
                256,
                1000,
                0x7FFF,
                0x8000,
                u16::MAX,
            ] {
                let expected = n.checked_div(d).zip(n.checked_rem(d));
                assert_eq!(div_rem(n, d), expected, "{n} {d}");
            }
        }
    }
}
