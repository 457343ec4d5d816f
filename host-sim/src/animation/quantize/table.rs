//! A colour table for a set of weighted colours, and the nearest entry to
//! any colour: the colours cut in boxes by least squares (each cut the one
//! that most lowers the sum of squared distances to the boxes' means, the
//! box to cut the one with the largest such sum), then refined by k-means
//! (Lloyd's iterations) over the same colours.
//!
//! Invariants: integers only (sums in `u128`, means rounded to nearest),
//! every order total (ties broken by the colour's value), so the same
//! colours give the same table on every machine; a set of at most
//! `entries` colours gets each of them exactly.

/// A colour and how much it counts (pixels times frames shown).
pub type Weighted = ([u8; 3], u64);

/// The squared distance between two colours.
pub fn distance(a: [u8; 3], b: [u8; 3]) -> u32 {
    (0..3).map(|c| (i32::from(a[c]) - i32::from(b[c])).pow(2) as u32).sum()
}

/// A colour table of at most `entries` colours for `colours` (distinct,
/// any order), in a fixed order (by value).
pub fn table_for(colours: &[Weighted], entries: usize) -> Vec<[u8; 3]> {
    let mut colours: Vec<Weighted> = colours.iter().copied().filter(|&(_, w)| w > 0).collect();
    colours.sort_unstable();
    if colours.len() <= entries {
        return colours.iter().map(|&(c, _)| c).collect();
    }
    let mut table = cut(&mut colours, entries);
    refine(&colours, &mut table);
    table.sort_unstable();
    table.dedup();
    table
}

/// Sums over a box of colours: weight, weighted colour, weighted squares.
#[derive(Clone, Copy, Default)]
struct Sums {
    weight: u128,
    linear: [u128; 3],
    squares: u128,
}

impl Sums {
    fn add(&mut self, (c, w): Weighted) {
        let w = u128::from(w);
        self.weight += w;
        for (l, &v) in self.linear.iter_mut().zip(&c) {
            *l += w * u128::from(v);
        }
        self.squares += w * c.iter().map(|&v| u128::from(v) * u128::from(v)).sum::<u128>();
    }

    fn plus(self, other: Sums) -> Sums {
        Sums {
            weight: self.weight + other.weight,
            linear: [0, 1, 2].map(|c| self.linear[c] + other.linear[c]),
            squares: self.squares + other.squares,
        }
    }

    fn minus(self, other: Sums) -> Sums {
        Sums {
            weight: self.weight - other.weight,
            linear: [0, 1, 2].map(|c| self.linear[c] - other.linear[c]),
            squares: self.squares - other.squares,
        }
    }

    /// The sum of weighted squared distances to the mean, times the
    /// weight (exact: no division).
    fn scaled_error(self) -> u128 {
        let spread: u128 = self.linear.iter().map(|l| l * l).sum();
        self.squares * self.weight - spread
    }

    /// The sum of weighted squared distances to the mean (rounded down).
    fn error(self) -> u128 {
        self.scaled_error().checked_div(self.weight).unwrap_or(0)
    }

    /// The mean colour, rounded to nearest.
    fn mean(self) -> [u8; 3] {
        let w = self.weight.max(1);
        self.linear.map(|l| ((2 * l + w) / (2 * w)).min(255) as u8)
    }

    fn of(colours: &[Weighted]) -> Sums {
        let mut sums = Sums::default();
        colours.iter().for_each(|&c| sums.add(c));
        sums
    }
}

/// A box: a range of the colours, and its error.
struct Cell {
    start: usize,
    end: usize,
    error: u128,
}

/// Cuts `colours` into `entries` boxes (or as many as have more than one
/// colour), each cut where it most lowers the error; their means.
fn cut(colours: &mut [Weighted], entries: usize) -> Vec<[u8; 3]> {
    let mut cells = vec![Cell { start: 0, end: colours.len(), error: Sums::of(colours).error() }];
    while cells.len() < entries {
        // The box of largest error (the first of equals) with two colours.
        let Some((at, _)) = cells
            .iter()
            .enumerate()
            .filter(|(_, c)| c.end - c.start > 1)
            .max_by(|(i, a), (j, b)| a.error.cmp(&b.error).then(j.cmp(i)))
        else {
            break;
        };
        let (start, end) = (cells[at].start, cells[at].end);
        let split = start + cut_box(&mut colours[start..end]);
        cells[at] = Cell { start, end: split, error: Sums::of(&colours[start..split]).error() };
        cells.push(Cell { start: split, end, error: Sums::of(&colours[split..end]).error() });
    }
    cells.iter().map(|c| Sums::of(&colours[c.start..c.end]).mean()).collect()
}

/// Cuts `colours` (at least two distinct) in two where that most lowers
/// the error, along one axis between two of its 256 values: the colours
/// below the cut are moved before the others (each side keeping its
/// order); returns how many there are.
fn cut_box(colours: &mut [Weighted]) -> usize {
    let total = Sums::of(colours);
    let mut best: Option<(u128, usize, u8)> = None;
    for axis in 0..3 {
        let mut bins = [Sums::default(); 256];
        colours.iter().for_each(|&c| bins[usize::from(c.0[axis])].add(c));
        let mut left = Sums::default();
        for value in 0..255usize {
            left = left.plus(bins[value]);
            if left.weight == 0 || left.weight == total.weight || bins[value + 1].weight == 0 {
                continue;
            }
            let error = left.error() + total.minus(left).error();
            if best.is_none_or(|(e, _, _)| error < e) {
                best = Some((error, axis, value as u8 + 1));
            }
        }
    }
    let Some((_, axis, threshold)) = best else { return colours.len() / 2 };
    let (below, above): (Vec<Weighted>, Vec<Weighted>) = colours.iter().partition(|c| c.0[axis] < threshold);
    colours[..below.len()].copy_from_slice(&below);
    colours[below.len()..].copy_from_slice(&above);
    below.len()
}

/// Lloyd's iterations: each colour to its nearest entry, each entry to its
/// colours' mean, until nothing moves (at most a few rounds).
fn refine(colours: &[Weighted], table: &mut [[u8; 3]]) {
    for _ in 0..8 {
        let nearest = Nearest::new(table);
        let mut sums = vec![Sums::default(); table.len()];
        for &colour in colours {
            sums[nearest.index(colour.0) as usize].add(colour);
        }
        let mut moved = false;
        for (entry, sums) in table.iter_mut().zip(&sums) {
            if sums.weight > 0 && *entry != sums.mean() {
                *entry = sums.mean();
                moved = true;
            }
        }
        if !moved {
            break;
        }
    }
}

/// The nearest entry of a table to a colour, found by scanning the
/// entries sorted by green outward from the colour's green.
pub struct Nearest {
    /// (green, entry index), by green then index.
    by_green: Vec<(u8, u8)>,
    table: Vec<[u8; 3]>,
}

impl Nearest {
    /// The search over `table` (at most 256 entries).
    pub fn new(table: &[[u8; 3]]) -> Nearest {
        let mut by_green: Vec<(u8, u8)> = table.iter().enumerate().map(|(i, c)| (c[1], i as u8)).collect();
        by_green.sort_unstable();
        Nearest { by_green, table: table.to_vec() }
    }

    /// The index of the entry nearest `colour` (of equals, the lowest).
    pub fn index(&self, colour: [u8; 3]) -> u8 {
        let start = self.by_green.partition_point(|&(g, _)| g < colour[1]);
        let mut best = (u32::MAX, u8::MAX);
        let mut consider = |at: usize| -> bool {
            let (g, i) = self.by_green[at];
            let dg = (i32::from(g) - i32::from(colour[1])).pow(2) as u32;
            if dg > best.0 {
                return false;
            }
            let d = distance(self.table[i as usize], colour);
            if (d, i) < best {
                best = (d, i);
            }
            true
        };
        for at in start..self.by_green.len() {
            if !consider(at) {
                break;
            }
        }
        for at in (0..start).rev() {
            if !consider(at) {
                break;
            }
        }
        best.1
    }

    /// The table.
    pub fn table(&self) -> &[[u8; 3]] {
        &self.table
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn few_colours_are_kept_exactly() {
        let colours = [([1, 2, 3], 5), ([200, 0, 9], 1), ([1, 2, 3], 0)];
        assert_eq!(table_for(&colours[..2], 255), [[1, 2, 3], [200, 0, 9]]);
    }

    #[test]
    fn a_gradient_is_cut_evenly_and_nearest_is_exhaustive_search() {
        let colours: Vec<Weighted> = (0..=255u8).flat_map(|r| (0..4u8).map(move |b| ([r, r / 2, 60 * b], 3))).collect();
        let table = table_for(&colours, 64);
        assert!(table.len() <= 64 && table.len() > 48, "{}", table.len());
        let nearest = Nearest::new(&table);
        let mut worst = 0;
        for &(c, _) in &colours {
            let i = nearest.index(c) as usize;
            let exhaustive = table.iter().map(|&t| distance(t, c)).min().unwrap();
            assert_eq!(distance(table[i], c), exhaustive, "{c:?}");
            worst = worst.max(exhaustive);
        }
        // 1024 colours in 64 entries: none far from its entry.
        assert!(worst <= 3 * 16 * 16, "{worst}");
        // The same colours in another order: the same table.
        let mut shuffled = colours.clone();
        shuffled.reverse();
        assert_eq!(table_for(&shuffled, 64), table);
    }
}
