//! Leading zeros and 64-bit shifts by a variable amount, in 32-bit steps:
//! ARMv6-M has no count of leading zeros, and a variable 64-bit shift is a
//! library call on a 32-bit core. The same bits on every target.

use super::super::ARMV6M;

/// The number of leading zero bits of `x` (64 for zero).
#[inline(always)]
pub fn leading_zeros(x: u64) -> u32 {
    if ARMV6M {
        leading_zeros_by_search(x)
    } else {
        x.leading_zeros()
    }
}

/// The number of leading zero bits of a 32-bit `x` (32 for zero).
#[inline(always)]
pub fn leading_zeros_u32(x: u32) -> u32 {
    if ARMV6M {
        leading_zeros_of_word(x, 0)
    } else {
        x.leading_zeros()
    }
}

/// Leading zeros of each byte value (8 for zero).
static BYTE_LEADING_ZEROS: [u8; 256] = {
    let mut t = [0u8; 256];
    let mut i = 0;
    while i < 256 {
        t[i] = (i as u8).leading_zeros() as u8;
        i += 1;
    }
    t
};

/// Two halvings of one 32-bit word, then a table of the top byte: about ten
/// instructions (the library routine costs about 35 on a Cortex-M0, a
/// five-step binary search about 25).
#[inline(always)]
fn leading_zeros_by_search(x: u64) -> u32 {
    let (high, low) = ((x >> 32) as u32, x as u32);
    if high != 0 {
        leading_zeros_of_word(high, 0)
    } else {
        leading_zeros_of_word(low, 32)
    }
}

/// `base` plus the leading zeros of `w` (8 more than the table's for zero).
#[inline(always)]
fn leading_zeros_of_word(mut w: u32, base: u32) -> u32 {
    let mut n = base;
    if w >> 16 == 0 {
        n += 16;
        w <<= 16;
    }
    if w >> 24 == 0 {
        n += 8;
        w <<= 8;
    }
    n + BYTE_LEADING_ZEROS[(w >> 24) as usize] as u32
}

/// `x >> shift` for a shift in 0 ..= 63 whose result fits 32 bits: on a
/// 32-bit core, a 64-bit shift by a variable amount is a library call.
#[inline(always)]
pub(crate) fn shr_to_u32(x: u64, shift: u32) -> u32 {
    let (high, low) = ((x >> 32) as u32, x as u32);
    if shift >= 32 {
        high >> (shift - 32)
    } else if shift == 0 {
        low
    } else {
        (low >> shift) | (high << (32 - shift))
    }
}

/// `x >> shift` for a shift in −31 ..= 63 whose result fits 32 bits, a
/// negative shift moving the low word left: a value brought to a chosen
/// scale, whichever side of it the value is.
#[inline(always)]
pub(crate) fn shr_signed_to_u32(x: u64, shift: i32) -> u32 {
    // A zero shift takes the cheaper arm: the low word, as the result fits.
    if shift > 0 {
        shr_to_u32(x, shift as u32)
    } else {
        (x as u32) << -shift
    }
}

/// `min(x >> shift, u32::MAX)` for a shift in 1 ..= 63, in 32-bit steps
/// (a 64-bit shift by a variable amount is a library call on a 32-bit core).
#[inline(always)]
pub(crate) fn shr_saturating_u32(x: u64, shift: u32) -> u32 {
    let (high, low) = ((x >> 32) as u32, x as u32);
    if shift >= 32 {
        high >> (shift - 32)
    } else if high >> shift != 0 {
        u32::MAX
    } else {
        (low >> shift) | (high << (32 - shift))
    }
}

/// `x >> shift` for a shift in 0 ..= 63, in 32-bit halves (a variable
/// 64-bit shift is a library call on a 32-bit core).
#[inline(always)]
pub(crate) fn shr_u64(x: u64, shift: u32) -> u64 {
    let (high, low) = ((x >> 32) as u32, x as u32);
    if shift >= 32 {
        (high >> (shift - 32)) as u64
    } else if shift == 0 {
        x
    } else {
        (((high >> shift) as u64) << 32) | ((low >> shift) | (high << (32 - shift))) as u64
    }
}

/// `x << shift` for a shift in 0 ..= 31 whose result fits 64 bits, in
/// 32-bit halves (a variable 64-bit shift is a library call on a 32-bit
/// core).
#[inline(always)]
pub(crate) fn shl_u64(x: u64, shift: u32) -> u64 {
    if shift == 0 {
        return x;
    }
    let (high, low) = ((x >> 32) as u32, x as u32);
    ((((high << shift) | (low >> (32 - shift))) as u64) << 32) | (low << shift) as u64
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::wide::tests::spread;

    #[test]
    fn part_wise_forms_match_the_native_operations() {
        for v in spread(20_000).chain([0, 1, u64::MAX, 1 << 32, (1 << 32) - 1, 1 << 63]) {
            assert_eq!(leading_zeros_by_search(v), v.leading_zeros(), "{v}");
            assert_eq!(leading_zeros_of_word(v as u32, 0), (v as u32).leading_zeros(), "{v}");
        }
        for v in spread(5_000).chain([u64::MAX, 1 << 63, (1 << 32) - 1, 1]) {
            for shift in 0..64 {
                assert_eq!(shr_u64(v, shift), v >> shift, "{v} >> {shift}");
            }
            for shift in 0..32 {
                if v.leading_zeros() >= shift {
                    assert_eq!(shl_u64(v, shift), v << shift, "{v} << {shift}");
                }
            }
        }
        for v in spread(5_000).chain([u64::MAX, 1 << 63, (1 << 32) - 1]) {
            for shift in 1..64 {
                assert_eq!(shr_saturating_u32(v, shift), (v >> shift).min(u32::MAX as u64) as u32, "{v} >> {shift}");
            }
        }
        for v in spread(5_000) {
            for shift in 0..64 {
                if v >> shift <= u32::MAX as u64 {
                    assert_eq!(shr_to_u32(v, shift), (v >> shift) as u32, "{v} >> {shift}");
                    assert_eq!(shr_signed_to_u32(v, shift as i32), (v >> shift) as u32, "{v} >> {shift}");
                }
            }
            for shift in 1..32 {
                if v.leading_zeros() >= 32 + shift {
                    assert_eq!(shr_signed_to_u32(v, -(shift as i32)), (v << shift) as u32, "{v} << {shift}");
                }
            }
        }
    }
}
