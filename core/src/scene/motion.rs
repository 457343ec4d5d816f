//! Motion in the scene format: how many frames an animation has
//! ([`Frames`], the `FRAMES` statement) and a statement's displacement at
//! each frame from its `MOVE` keys ([`displacement_at`]).
//!
//! Invariants: keys are sorted by frame, strictly increasing (the parser
//! refuses others); between two keys the displacement is linear, rounded
//! down (floor) in integers, so frame k has the same bits on every target;
//! before the first key it is the first key's, after the last the last's.
//! Within two neighbouring keys each coordinate is monotone in the frame,
//! so the displacements of a range of frames between two keys lie within
//! those at the range's ends (what the coherence tracker's sweeps rely on).

/// `FRAMES count [rate]`: an animation of `count` frames, numbered 0 to
/// `count − 1`, shown at `rate` frames a second.
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct Frames {
    /// Frames in the animation, at least 1.
    pub count: u32,
    /// Frames a second, from 1 to [`Frames::MAX_RATE`].
    pub rate: u32,
}

impl Frames {
    /// The rate when `FRAMES` gives none.
    pub const DEFAULT_RATE: u32 = 24;
    /// The fastest rate the format accepts.
    pub const MAX_RATE: u32 = 1000;
    /// The most frames an animation has.
    pub const MAX_COUNT: u32 = 1_000_000;

    /// Every frame, in order (`0..count`).
    pub fn all(&self) -> core::ops::Range<u32> {
        0..self.count
    }

    /// The frame after `frame` when the animation loops: after the last
    /// one, frame 0 again.
    pub fn after(&self, frame: u32) -> u32 {
        if frame + 1 >= self.count {
            0
        } else {
            frame + 1
        }
    }
}

/// The displacement at `frame` given by `keys`, `(frame, displacement)`
/// sorted by frame: linear between two keys (rounded down), the first key's
/// before it, the last key's after it; zero without keys.
///
/// ```
/// use octrace_core::scene::displacement_at;
///
/// let keys = [(0, [0, 0, 0]), (4, [10, -10, 3])];
/// assert_eq!(displacement_at(keys.into_iter(), 2), [5, -5, 1]);
/// assert_eq!(displacement_at(keys.into_iter(), 1), [2, -3, 0]); // rounded down
/// assert_eq!(displacement_at(keys.into_iter(), 9), [10, -10, 3]);
/// ```
pub fn displacement_at(keys: impl Iterator<Item = (u32, [i64; 3])>, frame: u32) -> [i64; 3] {
    KeyWalk::new(keys).at(frame)
}

/// The displacements given by `keys` at frames taken in increasing order,
/// each key read once: [`displacement_at`] for every frame of a loop in
/// time linear in the frames and keys together.
pub(crate) struct KeyWalk<I> {
    keys: I,
    /// The last key before the frame asked for last.
    before: Option<(u32, [i64; 3])>,
    /// The first key at or after it.
    after: Option<(u32, [i64; 3])>,
}

impl<I: Iterator<Item = (u32, [i64; 3])>> KeyWalk<I> {
    pub(crate) fn new(mut keys: I) -> Self {
        let after = keys.next();
        KeyWalk { keys, before: None, after }
    }

    /// The displacement at `frame`, not before the frame asked for last.
    pub(crate) fn at(&mut self, frame: u32) -> [i64; 3] {
        while let Some(key) = self.after.filter(|&(at, _)| at < frame) {
            self.before = Some(key);
            self.after = self.keys.next();
        }
        match (self.before, self.after) {
            (Some(from), Some(to)) if to.0 > frame => between(from, to, frame),
            (_, Some((_, value))) | (Some((_, value)), None) => value,
            (None, None) => [0; 3],
        }
    }
}

/// The displacement at `frame`, strictly between the keys `from` and `to`.
/// Not inlined: one copy of its 128-bit arithmetic whatever the keys'
/// iterator (a board links it once).
#[inline(never)]
fn between(from: (u32, [i64; 3]), to: (u32, [i64; 3]), frame: u32) -> [i64; 3] {
    let ((from, start), (at, value)) = (from, to);
    [0, 1, 2].map(|a| {
        let span = i128::from(at - from);
        let step = (i128::from(value[a]) - i128::from(start[a])) * i128::from(frame - from);
        // Between the two values, so it fits an i64.
        (i128::from(start[a]) + step.div_euclid(span)) as i64
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_walk_over_the_frames_gives_each_frame_s_displacement() {
        let keys = [(2, [0, 100, -7]), (6, [8, 100, 1]), (7, [0, 0, 0]), (11, [-9, 3, 5])];
        let mut walk = KeyWalk::new(keys.into_iter());
        for frame in 0..14 {
            assert_eq!(walk.at(frame), displacement_at(keys.into_iter(), frame), "frame {frame}");
        }
        let mut none = KeyWalk::new(core::iter::empty());
        assert_eq!([none.at(0), none.at(5)], [[0; 3]; 2]);
    }

    #[test]
    fn between_before_and_after_the_keys() {
        let keys = [(2, [0, 100, -7]), (6, [8, 100, 1]), (7, [0, 0, 0])];
        let at = |f| displacement_at(keys.into_iter(), f);
        assert_eq!(at(0), [0, 100, -7]);
        assert_eq!(at(2), [0, 100, -7]);
        assert_eq!(at(3), [2, 100, -5]);
        assert_eq!(at(6), [8, 100, 1]);
        assert_eq!(at(7), [0, 0, 0]);
        assert_eq!(at(1000), [0, 0, 0]);
        assert_eq!(displacement_at(core::iter::empty(), 3), [0; 3]);
    }

    #[test]
    fn monotone_and_within_the_keys_at_the_extremes() {
        let big = 1_000_000i64 << 32;
        let keys = [(0, [-big, big, 3]), (999_999, [big, -big, -3])];
        let mut last = displacement_at(keys.into_iter(), 0);
        for f in (0..1_000_000).step_by(997).chain([999_998, 999_999]) {
            let d = displacement_at(keys.into_iter(), f);
            assert!(d[0] >= last[0] && d[1] <= last[1] && d[2] <= last[2], "{f}");
            assert!(d.iter().all(|v| v.abs() <= big));
            last = d;
        }
        assert_eq!(last, [big, -big, -3]);
    }

    #[test]
    fn the_loop_comes_back_to_frame_zero() {
        let frames = Frames { count: 3, rate: 24 };
        assert_eq!([0, 1, 2].map(|f| frames.after(f)), [1, 2, 0]);
        assert_eq!(Frames { count: 1, rate: 24 }.after(0), 0);
    }
}
