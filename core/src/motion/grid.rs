//! The tracker's coarse grid: coordinates cut to cells of 2^[`GRID_BITS`]
//! raw units, where a segment and a box or a sphere are tested in 32-bit
//! steps.
//!
//! Invariant, conservative by construction: a segment's ends are rounded to
//! nearest and a box is rounded outward and widened by a whole cell (more
//! than the rounding of the ends moves any point of the segment), after a
//! widening of [`WIDENING`] raw units, more than a hit point strays from
//! its object plus a shadow ray from its segment (the octree's and the
//! light buffer's bounds). So a segment that does not meet a box on the
//! grid meets nothing in it.

/// log2 of the grid's cell, in raw Q16.16 units (4 normalised units: the
/// scene's range is 2^13 of them each way).
pub(crate) const GRID_BITS: u32 = 18;

/// How far beyond its bounds an object may be met: the octree's filing
/// margin and a shadow ray's straying (the light buffer's margin), and a
/// unit of the end points' own rounding.
pub(crate) const WIDENING: i32 = (crate::accel::FILING_MARGIN + crate::accel::RAY_SLACK) as i32 + 2;

/// A raw coordinate on the grid, rounded to nearest. Raw coordinates are
/// within 2^32 in magnitude (points in the scene's range, or a miss's far
/// end 2^31 beyond), so cells are within 2^14.
#[inline]
pub(crate) fn cell(v: i64) -> i32 {
    ((v + (1 << (GRID_BITS - 1))) >> GRID_BITS) as i32
}

/// [`cell`] of a 32-bit coordinate (an object's place) in 32-bit steps:
/// the floor of `v / 2^GRID_BITS`, plus one when the bit below it is set,
/// is `v + 2^(GRID_BITS − 1)` rounded down, without its overflow. Cells
/// of these are within 2^13.
#[inline]
pub(crate) fn cell_of_i32(v: i32) -> i32 {
    (v >> GRID_BITS) + ((v >> (GRID_BITS - 1)) & 1)
}

/// A raw box on the grid, as a segment's test takes it: widened and
/// rounded outward, then by a whole cell. All zero bits for a `const`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) struct GridBox {
    lo: [i32; 3],
    hi: [i32; 3],
}

impl GridBox {
    /// A placeholder to fill storage with.
    pub(crate) const EMPTY: GridBox = GridBox { lo: [0; 3], hi: [0; 3] };

    /// The raw box `[lo, hi]` on the grid.
    pub(crate) fn around([lo, hi]: [[i32; 3]; 2]) -> GridBox {
        GridBox {
            lo: lo.map(|v| ((v.saturating_sub(WIDENING)) >> GRID_BITS) - 1),
            hi: hi.map(|v| ((v.saturating_add(WIDENING)) >> GRID_BITS) + 2),
        }
    }

    /// The raw box `first` moved by any displacement within `(lo, hi)` on
    /// each axis, on the grid.
    pub(crate) fn displaced(first: [[i32; 3]; 2], (lo, hi): ([i32; 3], [i32; 3])) -> GridBox {
        let [first_lo, first_hi] = first;
        GridBox::around([
            [0, 1, 2].map(|a| first_lo[a].saturating_add(lo[a])),
            [0, 1, 2].map(|a| first_hi[a].saturating_add(hi[a])),
        ])
    }

    /// Its lowest and highest cells.
    #[inline]
    pub(crate) fn corners(&self) -> [[i32; 3]; 2] {
        [self.lo, self.hi]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_32_bit_coordinates_cell_is_the_wide_rounding() {
        let mut next = crate::test_rng::seeded(0xce11_0f32);
        let edges = [i32::MIN, i32::MIN + 1, -(1 << 17) - 1, -(1 << 17), -1, 0, 1, (1 << 17) - 1, 1 << 17, i32::MAX];
        for v in edges.into_iter().chain((0..100_000).map(|_| next() as i32)) {
            assert_eq!(cell_of_i32(v), cell(i64::from(v)), "{v}");
        }
    }
}
