//! An in-place heap sort for the few lists the core orders (surfaces by
//! number, objects by their nearest hit): O(n log n), no allocation, and a
//! few hundred bytes of code where `sort_unstable` links several KiB of a
//! board's flash per use.
//!
//! Invariant: the order is by `key` alone; equal keys may land in any order
//! (every caller's keys are unique).

/// Sorts `items` by `key`, ascending.
pub(crate) fn sort_by_key<T, K: Ord>(items: &mut [T], key: impl Fn(&T) -> K) {
    // Heapify, then move the largest to the end, one by one.
    for root in (0..items.len() / 2).rev() {
        sift_down(items, root, &key);
    }
    for end in (1..items.len()).rev() {
        swap_apart(items, 0, end);
        sift_down(&mut items[..end], 0, &key);
    }
}

/// Swaps `items[i]` and `items[j]`, `i < j`. `slice::swap` allows the two
/// to be one, which the compiler keeps by a copy that may overlap: a
/// board then links `memmove` (1.3 KiB of flash) for it.
fn swap_apart<T>(items: &mut [T], i: usize, j: usize) {
    let (head, tail) = items.split_at_mut(j);
    core::mem::swap(&mut head[i], &mut tail[0]);
}

/// Moves `items[root]` down until neither child's key is larger.
fn sift_down<T, K: Ord>(items: &mut [T], mut root: usize, key: &impl Fn(&T) -> K) {
    loop {
        let mut child = 2 * root + 1;
        if child >= items.len() {
            return;
        }
        if child + 1 < items.len() && key(&items[child]) < key(&items[child + 1]) {
            child += 1;
        }
        if key(&items[root]) >= key(&items[child]) {
            return;
        }
        swap_apart(items, root, child);
        root = child;
    }
}

#[cfg(test)]
mod tests {
    extern crate std;
    use super::*;

    #[test]
    fn sorts_like_the_standard_sort() {
        let seed = 0x50_e7_u64;
        std::println!("seed {seed:#x}");
        let mut next = crate::test_rng::seeded(seed);
        for len in 0..200 {
            let mut items: std::vec::Vec<(u32, u32)> = (0..len).map(|i| ((next() % 17) as u32, i)).collect();
            let mut expected = items.clone();
            expected.sort();
            sort_by_key(&mut items, |&item| item);
            assert_eq!(items, expected, "length {len}");
        }
    }
}
