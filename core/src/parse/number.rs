//! Scene-file numbers, read exactly as decimals and converted to Q32.32 with
//! correct rounding: no float is involved, so every target reads the same
//! bits.
//!
//! Grammar: optional sign, digits, optional fraction, optional exponent
//! (`3`, `-0.5`, `.25`, `1e-3`, `+2.5E2`, `3.`). `nan`, `inf` and
//! hexadecimal are not numbers. Integers are written without fraction or
//! exponent.

/// `±mantissa · 10^exponent`, with up to 19 significant digits kept.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Decimal {
    pub negative: bool,
    pub mantissa: u64,
    pub exponent: i32,
}

/// The largest magnitude the format accepts.
pub const LIMIT: u64 = 1_000_000;

const POW10: [u64; 20] = {
    let mut t = [1u64; 20];
    let mut i = 1;
    while i < 20 {
        t[i] = t[i - 1] * 10;
        i += 1;
    }
    t
};

impl Decimal {
    /// Parses `text` per the grammar above; `None` if it is not a number.
    pub fn parse(text: &str) -> Option<Decimal> {
        let b = text.as_bytes();
        let mut i = 0;
        let negative = match b.first() {
            Some(b'-') => {
                i += 1;
                true
            }
            Some(b'+') => {
                i += 1;
                false
            }
            _ => false,
        };
        let mut mantissa: u64 = 0;
        let mut exponent: i32 = 0;
        let mut digits = 0;
        let push = |d: u8, fraction: bool, mantissa: &mut u64, exponent: &mut i32| {
            if *mantissa < POW10[18] {
                *mantissa = *mantissa * 10 + d as u64;
                if fraction {
                    *exponent -= 1;
                }
            } else if !fraction {
                // A dropped integer digit still scales the value.
                *exponent = exponent.saturating_add(1);
            }
        };
        while i < b.len() && b[i].is_ascii_digit() {
            push(b[i] - b'0', false, &mut mantissa, &mut exponent);
            digits += 1;
            i += 1;
        }
        if i < b.len() && b[i] == b'.' {
            i += 1;
            while i < b.len() && b[i].is_ascii_digit() {
                push(b[i] - b'0', true, &mut mantissa, &mut exponent);
                digits += 1;
                i += 1;
            }
        }
        if digits == 0 {
            return None;
        }
        if i < b.len() && (b[i] == b'e' || b[i] == b'E') {
            i += 1;
            let exp_negative = match b.get(i) {
                Some(b'-') => {
                    i += 1;
                    true
                }
                Some(b'+') => {
                    i += 1;
                    false
                }
                _ => false,
            };
            let start = i;
            let mut e: i32 = 0;
            while i < b.len() && b[i].is_ascii_digit() {
                e = e.saturating_mul(10).saturating_add((b[i] - b'0') as i32).min(1_000_000);
                i += 1;
            }
            if i == start {
                return None;
            }
            exponent = exponent.saturating_add(if exp_negative { -e } else { e });
        }
        (i == b.len()).then_some(Decimal { negative, mantissa, exponent })
    }

    pub fn is_zero(&self) -> bool {
        self.mantissa == 0
    }

    /// Whether the magnitude exceeds 10^6.
    pub fn out_of_range(&self) -> bool {
        if self.mantissa == 0 {
            return false;
        }
        let digits = 20 - POW10.iter().rev().position(|&p| self.mantissa >= p).unwrap_or(19) as i32;
        let magnitude = digits + self.exponent; // value in [10^(m−1), 10^m)
        if magnitude <= 6 {
            false
        } else if magnitude > 7 {
            true
        } else if self.exponent >= 0 {
            self.mantissa * POW10[self.exponent as usize] > LIMIT
        } else {
            self.mantissa > POW10[(6 - self.exponent) as usize]
        }
    }

    /// The value in Q32.32, rounded to nearest (ties away from zero). The
    /// magnitude must be within 10^6 ([`Decimal::out_of_range`] false).
    // Not inlined: its 128-bit division (for long numbers) is long code on
    // a 32-bit core, and the parser reads numbers in many places.
    #[inline(never)]
    pub fn to_q32(self) -> i64 {
        let magnitude: u128 = if self.exponent >= 0 {
            let e = self.exponent.min(19) as usize;
            ((self.mantissa as u128) * POW10[e] as u128).min(LIMIT as u128) << 32
        } else if self.exponent < -38 {
            0
        } else {
            // From the table while it holds the power: `pow` multiplies
            // in 128 bits, long code on a 32-bit core.
            let div = match POW10.get((-self.exponent) as usize) {
                Some(&power) => power as u128,
                None => 10u128.pow((-self.exponent) as u32),
            };
            let numerator = ((self.mantissa as u128) << 32) + div / 2;
            // A number of a few digits fits 64 bits: one 64-bit division
            // instead of the 128-bit one, long code on a 32-bit core
            // (fig5_3's 1,922 numbers took 10 M cycles on a Pico). The
            // same quotient.
            match (u64::try_from(numerator), u64::try_from(div)) {
                (Ok(numerator), Ok(div)) => (numerator / div) as u128,
                _ => numerator / div,
            }
        };
        let m = magnitude.min(i64::MAX as u128) as i64;
        if self.negative {
            -m
        } else {
            m
        }
    }
}

/// An integer as the format writes it (optional sign and digits); `None` if
/// the text is something else. Saturates far beyond any valid value.
pub fn parse_integer(text: &str) -> Option<i64> {
    // Bytes, not a sliced `str`: no char-boundary check to panic.
    let (negative, digits) = match text.as_bytes() {
        [b'-', digits @ ..] => (true, digits),
        [b'+', digits @ ..] => (false, digits),
        digits => (false, digits),
    };
    if digits.is_empty() || !digits.iter().all(|c| c.is_ascii_digit()) {
        return None;
    }
    let v = digits.iter().fold(0i64, |v, &c| v.saturating_mul(10).saturating_add((c - b'0') as i64));
    Some(if negative { -v } else { v })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn q(text: &str) -> i64 {
        Decimal::parse(text).unwrap().to_q32()
    }

    #[test]
    fn the_grammar() {
        for ok in ["3", "-0.5", ".25", "1e-3", "+2.5E2", "3.", "-0", "0.000", "1E+2"] {
            assert!(Decimal::parse(ok).is_some(), "{ok}");
        }
        for bad in ["", "+", "-", ".", "e5", "1e", "1e+", "nan", "inf", "-inf", "0x10", "1.2.3", "1,5", "2f", "--1"] {
            assert!(Decimal::parse(bad).is_none(), "{bad}");
        }
    }

    #[test]
    fn exact_values() {
        assert_eq!(q("3"), 3 << 32);
        assert_eq!(q("-0.5"), -(1 << 31));
        assert_eq!(q(".25"), 1 << 30);
        assert_eq!(q("+2.5E2"), 250 << 32);
        assert_eq!(q("-0"), 0);
        assert_eq!(q("1e-3"), 4_294_967); // 0.001 · 2^32 = 4294967.296
        assert_eq!(q("0.1"), 429_496_730); // 429496729.6 rounds up
        assert_eq!(q("1e6"), 1_000_000 << 32);
        assert_eq!(q("1e-50"), 0);
        assert_eq!(q("123456789012345678901234e-18"), q("123456.789012345678901234"));
    }

    #[test]
    fn the_64_bit_quotient_is_the_128_bit_one() {
        // Every fraction a number can have, at the edges of the 64-bit path
        // and at random: the quotient by the 128-bit formula alone.
        extern crate std;
        let mut next = crate::test_rng::seeded(0xd1_91_75);
        let mut cases: std::vec::Vec<(u64, i32)> = std::vec::Vec::new();
        for exponent in -38..0 {
            for mantissa in [0, 1, 5, 9, (1 << 31) - 1, 1 << 31, (1 << 32) - 1, 1 << 32, u64::MAX >> 1, u64::MAX] {
                cases.push((mantissa, exponent));
            }
        }
        for _ in 0..20_000 {
            let bits = next() % 65;
            let mantissa = if bits == 64 { next() } else { next() & ((1u64 << bits) - 1) };
            cases.push((mantissa, -((next() % 38) as i32) - 1));
        }
        for (mantissa, exponent) in cases {
            let d = Decimal { negative: false, mantissa, exponent };
            let div = 10u128.pow((-exponent) as u32);
            let wide = ((((mantissa as u128) << 32) + div / 2) / div).min(i64::MAX as u128) as i64;
            assert_eq!(d.to_q32(), wide, "{mantissa}e{exponent}");
        }
    }

    #[test]
    fn range_is_one_million_exactly() {
        for inside in ["1000000", "-1e6", "999999.9999", "0.1e7", "1e-400", "0"] {
            assert!(!Decimal::parse(inside).unwrap().out_of_range(), "{inside}");
        }
        for outside in ["1000000.0001", "1e400", "-1e7", "10000000", "1000001", &"9".repeat(200)] {
            assert!(Decimal::parse(outside).unwrap().out_of_range(), "{outside}");
        }
    }

    #[test]
    fn integers() {
        assert_eq!(parse_integer("42"), Some(42));
        assert_eq!(parse_integer("-7"), Some(-7));
        assert_eq!(parse_integer("+0"), Some(0));
        assert_eq!(parse_integer("3.0"), None);
        assert_eq!(parse_integer("1e3"), None);
        assert_eq!(parse_integer(&"9".repeat(200)), Some(i64::MAX));
    }
}
