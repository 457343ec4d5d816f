//! The seeded generator of the property tests (xorshift64): each test names
//! its seed, and the seed is printed so that a failure can be replayed.

extern crate std;

/// A generator of 64-bit values from `seed` (not 0), after printing it.
pub(crate) fn seeded(seed: u64) -> impl FnMut() -> u64 {
    std::println!("seed {seed:#x}");
    let mut state = seed;
    move || {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        state
    }
}
