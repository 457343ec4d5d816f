//! Where a moving statement stands at any frame, from its keys alone: the
//! parser's linear interpolation rounded down, in exact integers, with no
//! table of frames (an animation of a million frames costs what its keys
//! do).
//!
//! Invariants: a key's `at` is the statement's displacement at the key's
//! frame from its displacement at frame 0, in normalised raw units (the
//! parser places its objects by whole bits, so an object at frame f is the
//! object at frame 0 moved by [`Path::at`]`(f)`, to the bit); towards the
//! next key, `span` frames on, the displacement grows by `step · t +
//! ⌊rest · t / span⌋` after `t` frames (`step` and `rest` the floor
//! division of the difference by `span`, `0 ≤ rest < span`), which is the
//! parser's `⌊(next − at) · t / span⌋`; the last key has `span` 0. Every
//! displacement is between two places of objects in the scene's range, so
//! within ±2^30, and so is every partial sum here, in an `i32`.

use super::grid::GridBox;

/// Spans shorter than this divide by a multiplication: `⌊y / span⌋ =
/// (y · ⌈2^24 / span⌉) >> 24` for every `y < span²` (the error `y · e /
/// 2^24`, `e < span`, stays below `1 / span`; and the product below 2^32).
const RECIPROCAL_SPANS: u32 = 256;

/// A key of a moving statement: where it is at a frame, and how it moves
/// to the next key. Held in an animation's room
/// ([`AnimationRoom`](crate::animation::AnimationRoom), all zero bits).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) struct Key {
    pub(super) frame: u32,
    /// Whether the displacement differs from the key before (the first
    /// key: from the last, the loop's jump back).
    pub(super) changes: bool,
    /// Objects: the displacement here from frame 0's.
    at: [i32; 3],
    /// Objects: towards the next key, the whole part of each frame's step
    /// and the remainder over the span.
    step: [i32; 3],
    rest: [u32; 3],
    /// Frames to the next key; 0 for the last.
    span: u32,
    /// `⌈2^24 / span⌉` for a span shorter than [`RECIPROCAL_SPANS`], else 0.
    reciprocal: u32,
    /// Objects: the box they are in over the span to the next key, on the
    /// tracker's grid ([`reach_keys`]); a search over the whole stretch
    /// tests it first.
    reach: GridBox,
}

impl Key {
    /// A placeholder to fill storage with (a `const`, for a `static`).
    pub(crate) const EMPTY: Key = Key {
        frame: 0,
        changes: false,
        at: [0; 3],
        step: [0; 3],
        rest: [0; 3],
        span: 0,
        reciprocal: 0,
        reach: GridBox::EMPTY,
    };

    /// A key at `frame` whose displacement `at` (from frame 0's) moves to
    /// `next`, `span` frames on (`span` 0: the last key).
    pub(super) fn new(frame: u32, changes: bool, at: [i32; 3], next: [i32; 3], span: u32) -> Key {
        let (mut step, mut rest) = ([0; 3], [0; 3]);
        if span > 0 {
            for a in 0..3 {
                // Both within ±2^30: the difference fits an i64 and its
                // floor quotient an i32.
                let difference = i64::from(next[a]) - i64::from(at[a]);
                step[a] = difference.div_euclid(i64::from(span)) as i32;
                rest[a] = difference.rem_euclid(i64::from(span)) as u32;
            }
        }
        let reciprocal = if span > 0 && span < RECIPROCAL_SPANS { (1u32 << 24).div_ceil(span) } else { 0 };
        Key { frame, changes, at, step, rest, span, reciprocal, reach: GridBox::EMPTY }
    }

    /// The objects' box over the span to the next key, on the grid, when
    /// `ta..=tb` steps after the key are the whole span.
    #[inline]
    pub(super) fn reach_over(&self, ta: u32, tb: u32) -> Option<&GridBox> {
        (ta == 0 && tb == self.span).then_some(&self.reach)
    }

    /// Frame `frame` as steps after the key: 0 before it, its span after
    /// the next key (a stretch before the first key, or after the last,
    /// stands still).
    #[inline]
    pub(super) fn steps_to(&self, frame: u32) -> u32 {
        frame.saturating_sub(self.frame).min(self.span)
    }

    /// The displacement `t` frames after the key (`t` at most its span).
    #[inline(always)]
    pub(super) fn after(&self, t: u32) -> [i32; 3] {
        if t == 0 {
            return self.at;
        }
        let fraction = |rest: u32| -> i32 {
            // rest · t < span² (both below the span).
            if self.reciprocal != 0 {
                ((rest * t * self.reciprocal) >> 24) as i32
            } else if let Some(y) = rest.checked_mul(t) {
                (y / self.span) as i32
            } else {
                (u64::from(rest) * u64::from(t) / u64::from(self.span)) as i32
            }
        };
        // |step · t| ≤ |difference| + t, and each partial sum is within a
        // frame's step of the displacement: all fit an i32. A loop rather
        // than an array's `map`, which the tracker's hot paths on a
        // Cortex-M0+ would call out of line.
        let mut at = self.at;
        for (a, at) in at.iter_mut().enumerate() {
            *at += self.step[a] * t as i32 + fraction(self.rest[a]);
        }
        at
    }

    /// Bounds on the displacement over `ta..=tb` frames after the key (at
    /// most its span), per axis: below by dropping the remainders, above by
    /// counting each as a whole unit a frame. Wider than the exact
    /// extremes by at most `tb` raw units; what a search that narrows a
    /// range of frames needs, without a division.
    #[inline]
    pub(super) fn within(&self, ta: u32, tb: u32) -> ([i32; 3], [i32; 3]) {
        let (ta, tb) = (ta as i32, tb as i32);
        let (mut lo, mut hi) = ([0; 3], [0; 3]);
        for a in 0..3 {
            let (step, up) = (self.step[a], self.step[a] + i32::from(self.rest[a] != 0));
            // Monotone: increasing for a step of 0 or more, else decreasing.
            (lo[a], hi[a]) = match step >= 0 {
                true => (self.at[a] + step * ta, self.at[a] + up * tb),
                false => (self.at[a] + step * tb, self.at[a] + up * ta),
            };
        }
        (lo, hi)
    }
}

/// A moving statement's displacements over the loop: its keys, the
/// animation's frame count, and its displacement at one frame kept (the
/// frame being traced, asked most).
#[derive(Clone, Copy, Debug)]
pub(crate) struct Path<'m> {
    pub keys: &'m [Key],
    pub frames: u32,
    /// The frame whose displacement is kept, and it.
    pub kept: (u32, [i32; 3]),
}

impl<'m> Path<'m> {
    /// Over `keys` of an animation of `frames` frames, no frame kept.
    pub(crate) fn unkept(keys: &'m [Key], frames: u32) -> Path<'m> {
        Path { keys, frames, kept: (u32::MAX, [0; 3]) }
    }

    /// The displacement at `frame`, from frame 0's.
    #[inline(always)]
    pub(crate) fn at(&self, frame: u32) -> [i32; 3] {
        // The kept frame, asked most, without a call.
        match frame == self.kept.0 {
            true => self.kept.1,
            false => self.searched(frame),
        }
    }

    /// The displacement at `frame`, from its key.
    #[inline(never)]
    fn searched(&self, frame: u32) -> [i32; 3] {
        match self.keys.partition_point(|k| k.frame <= frame).checked_sub(1) {
            Some(k) => self.keys[k].after((frame - self.keys[k].frame).min(self.keys[k].span)),
            // Before the first key: its displacement.
            None => self.keys.first().map_or([0; 3], |k| k.at),
        }
    }

    /// The frames of the loop cut where the displacement stops being
    /// monotone, each with the key it follows from: frame 0 to the first
    /// key (standing at it), from each key to the next, the last key to
    /// the last frame (standing).
    pub(crate) fn stretches(&self) -> impl Iterator<Item = Stretch> + '_ {
        let last = self.frames.saturating_sub(1);
        let first = self.keys.first().map(|k| Stretch { from: 0, to: k.frame.min(last), key: 0 });
        let rest = self.keys.iter().enumerate().map(move |(i, k)| {
            let to = self.keys.get(i + 1).map_or(last, |next| next.frame);
            Stretch { from: k.frame, to: to.min(last), key: i }
        });
        first.into_iter().chain(rest).filter(|s| s.from <= s.to)
    }

    /// The key `stretch` follows.
    #[inline]
    pub(crate) fn key(&self, stretch: &Stretch) -> &Key {
        &self.keys[stretch.key]
    }
}

/// Frames `from..=to` over which a path is monotone, following key `key`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) struct Stretch {
    pub from: u32,
    pub to: u32,
    pub key: usize,
}

/// Sets each of `keys`' reach: the objects whose box is `first` at frame 0,
/// over the span to the next key, on the grid, as a search would make it
/// for the whole span ([`Key::within`]).
pub(crate) fn reach_keys(keys: &mut [Key], first: [[i32; 3]; 2]) {
    for key in keys {
        key.reach = GridBox::displaced(first, key.within(0, key.span));
    }
}

/// Writes the keys of a statement moved by `values()` (`(frame,
/// displacement)`, frames increasing, as the parser reads them) into
/// `keys`, as many as fit; returns how many there are. With `placed`
/// (objects: displacements in normalised raw units, as the parser places
/// them) each key holds its displacement from frame 0's and how it moves;
/// without, only its frame and whether it changes anything.
pub(crate) fn write_keys<I>(values: impl Fn() -> I, placed: bool, keys: &mut [Key]) -> usize
where
    I: Iterator<Item = (u32, [i64; 3])>,
{
    let start = crate::scene::displacement_at(values(), 0);
    // Two places of the objects in range: the difference fits.
    let relative = |d: [i64; 3]| match placed {
        true => [0, 1, 2].map(|a| (d[a] - start[a]) as i32),
        false => [0; 3],
    };
    let mut before = values().last().map_or([0; 3], |(_, d)| d);
    let mut next = values().skip(1);
    let mut count = 0;
    for (frame, value) in values() {
        let (span, to) = match next.next() {
            Some((next_frame, to)) => (next_frame - frame, to),
            None => (0, value),
        };
        if let Some(key) = keys.get_mut(count) {
            *key = Key::new(frame, value != before, relative(value), relative(to), span);
        }
        before = value;
        count += 1;
    }
    count
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::displacement_at;

    /// The keys of `values`, displacements placed.
    fn path_of(values: &[(u32, [i64; 3])], keys: &mut [Key]) {
        assert_eq!(write_keys(|| values.iter().copied(), true, keys), values.len());
    }

    #[test]
    fn every_frame_is_the_parsers_displacement_from_frame_zero() {
        let mut next = crate::test_rng::seeded(0x9a74);
        for round in 0..400 {
            let frames = 1 + (next() % if round % 4 == 0 { 3000 } else { 60 }) as u32;
            let count = 1 + (next() % 5) as usize;
            let mut at: [u32; 5] = core::array::from_fn(|_| (next() % u64::from(frames)) as u32);
            at[..count].sort_unstable();
            let mut values = [(0u32, [0i64; 3]); 5];
            let mut n = 0;
            for &frame in &at[..count] {
                if n > 0 && values[n - 1].0 == frame {
                    continue;
                }
                let mut v = || ((next() >> 33) as i64 % (1 << 29)) - (1 << 28);
                values[n] = (frame, [v(), v(), v() >> (next() % 20)]);
                n += 1;
            }
            let values = &values[..n];
            let mut keys = [Key::EMPTY; 5];
            path_of(values, &mut keys);
            let path = Path::unkept(&keys[..n], frames);
            let start = displacement_at(values.iter().copied(), 0);
            for f in 0..frames {
                let d = displacement_at(values.iter().copied(), f);
                let expected = [0, 1, 2].map(|a| (d[a] - start[a]) as i32);
                assert_eq!(path.at(f), expected, "frame {f} of {frames}, keys {values:?}");
            }
            // Every stretch's bounds hold its frames; the stretches cover
            // the loop in order (meeting at the keys' frames).
            let mut covered = 0;
            for stretch in path.stretches() {
                assert!(stretch.from <= covered && stretch.from + 1 >= covered, "{stretch:?} after {covered}");
                covered = stretch.to + 1;
                let (a, b) = (stretch.from, stretch.to);
                let key = path.key(&stretch);
                let (lo, hi) = key.within(key.steps_to(a), key.steps_to(b));
                for f in a..=b {
                    let d = path.at(f);
                    assert!((0..3).all(|x| lo[x] <= d[x] && d[x] <= hi[x]), "{f}: {lo:?} {d:?} {hi:?}");
                    assert!((0..3).all(|x| hi[x] - lo[x] <= (path.at(a)[x] - path.at(b)[x]).abs() + b as i32));
                }
            }
            assert_eq!(covered, frames, "{values:?}");
        }
    }

    #[test]
    fn long_spans_divide_and_the_kept_frame_is_answered_as_kept() {
        let values = [(3, [0, 0, 0]), (999_999, [(1 << 30) - 7, -(1 << 30) + 3, 12_345])];
        let mut keys = [Key::EMPTY; 2];
        path_of(&values, &mut keys);
        let path = Path { keys: &keys, frames: 1_000_000, kept: (7, [1, 2, 3]) };
        for f in (0..1_000_000).step_by(4999).chain([999_998, 999_999]) {
            let d = displacement_at(values.into_iter(), f);
            if f != 7 {
                assert_eq!(path.at(f), d.map(|v| v as i32), "{f}");
            }
        }
        assert_eq!(path.at(7), [1, 2, 3]);
    }
}
