//! Division by a constant as a multiply and a shift, for the panels'
//! levels: exact over the ranges it is used on (its test checks each).

/// Division by a constant `d` as a multiply and a shift: a Cortex-M0, which
/// has no divide instruction, would call a routine of some 50 instructions
/// for each pixel. Exact (and without overflow) for `x` up to 4096 with `d`
/// from 255 to 4080 (gray values, level steps in 1/16 gray), and for `x`
/// below 768 with `d` = 3 (the black/white/red projection's third).
#[derive(Clone, Copy, Debug)]
pub(super) struct Divisor {
    /// ceil(2^24 / d): its excess over 2^24 / d is under 1 / x.
    reciprocal: u32,
}

impl Divisor {
    pub(super) const BY_255: Divisor = Divisor::new(255);
    pub(super) const BY_3: Divisor = Divisor::new(3);

    pub(super) const fn new(d: u32) -> Divisor {
        Divisor { reciprocal: (1 << 24) / d + 1 }
    }

    /// `x / d`, rounded down.
    #[inline]
    pub(super) const fn quotient(self, x: u32) -> u32 {
        (x * self.reciprocal) >> 24
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn quotients_are_exact_where_they_are_taken() {
        // Every divisor used, over all it divides: gray values and level
        // steps in 1/16 gray up to 4096, and the projection's sums of three
        // values below 768.
        for (d, below) in [(255, 4097), (16 * 255, 4097), (16 * 85, 4097), (16 * 17, 4097), (3, 768)] {
            for x in 0..below {
                assert_eq!(Divisor::new(d).quotient(x), x / d, "{x} / {d}");
            }
        }
    }
}
