//! What moves in an animation, for the whole loop at once: each `MOVE`
//! read again from the scene text and placed with a loaded frame's
//! objects, so that the tracker can tell, for any frame, when a moving
//! object will next come near a ray.
//!
//! Invariants: a track's table holds, for every frame, its displacement
//! relative to frame 0 in normalised raw units, computed exactly as the
//! parser places the statement (so the object at frame f is the object at
//! frame 0 moved by `table[f]`, to the bit); `first` is the objects' box
//! at frame 0; a key's `changes` says whether its displacement differs
//! from the key before it (the first key: from the last, the loop's jump).

use super::sweep::{Key, Sweep};
use crate::parse::{for_each_move, Mover};
use crate::scene::{displacement_at, Frames, ObjectId, SceneView};
use core::fmt;

/// A clean count that never runs out: nothing that moves can change the
/// value.
pub(crate) const NEVER: u32 = u32::MAX;

/// What a track moves.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Target {
    /// Objects (a statement's: one, or a patch's triangles), in a box.
    Objects,
    /// A light: every point it shades depends on it.
    Light,
    /// The eye or the point looked at: every pixel depends on them.
    Camera,
}

/// One moving statement of an animation: storage for [`Motion::read`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Track {
    target: Target,
    /// Its keys in the motion's keys.
    keys: (u32, u32),
    /// Objects: where its displacements start in the motion's table.
    table: u32,
    /// Objects: their box at frame 0 (normalised raw units).
    first: [[i32; 3]; 2],
    /// Objects: a single sphere (tested as one, not as its box).
    sphere: bool,
    /// Objects: the box holding them in every frame.
    swept: [[i32; 3]; 2],
}

impl Track {
    /// A placeholder to fill storage with.
    pub const EMPTY: Track =
        Track { target: Target::Camera, keys: (0, 0), table: 0, first: [[0; 3]; 2], sphere: false, swept: [[0; 3]; 2] };
}

/// How much storage [`Motion::read`] needs for a scene: see
/// [`Motion::needs`].
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct MotionNeeds {
    /// Tracks: one for each `MOVE`.
    pub tracks: usize,
    /// Keys of all the `MOVE`s.
    pub keys: usize,
    /// Displacements: the frames once for each moving object statement.
    pub displacements: usize,
}

/// Why [`Motion::read`] could not read an animation's motion.
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum MotionError {
    /// The storage given holds less than the scene needs: what ran out
    /// (`"tracks"`, `"keys"` or `"displacements"`) and how many it needs.
    NoRoom {
        /// The storage that ran out.
        what: &'static str,
        /// How many the scene needs.
        needed: usize,
    },
    /// The scene loaded is not the text's (a MOVE names an object or a
    /// light it does not have).
    NotTheScene,
}

impl fmt::Display for MotionError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            MotionError::NoRoom { what, needed } => {
                write!(f, "no room for the animation's motion: it needs {needed} {what}")
            }
            MotionError::NotTheScene => f.write_str("the scene loaded is not the one whose motion was read"),
        }
    }
}

impl core::error::Error for MotionError {}

/// Everything that moves in an animation, over the whole loop: read once
/// ([`Motion::read`]) into the caller's storage, shared read-only by every
/// core that renders frames.
///
/// ```
/// use octrace_core::animation::{Key, Motion, MotionNeeds, Track};
/// use octrace_core::{profile::Board16K, Raytracer};
///
/// let text = "FRAMES 8\nSURFACE 1 .1 .1 .1 .7 .2 .2 0 0 0 1 0 0\nLIGHT 10 5 5 5\n\
///             SPHERE 1 1 0 0 0 MOVE 0 -2 0 0  4 2 0 0  7 0 1 0\n";
/// let needs = Motion::needs(text);
/// assert_eq!(needs, MotionNeeds { tracks: 1, keys: 3, displacements: 8 });
/// let (mut tracks, mut keys, mut displacements) = ([Track::EMPTY; 1], [Key::default(); 3], [[0; 3]; 8]);
/// let mut raytracer = Raytracer::<Board16K>::new();
/// let scene = raytracer.load(text)?;
/// let frames = scene.frames().unwrap();
/// let motion = Motion::read(text, frames, &scene.view(), 0, &mut tracks, &mut keys, &mut displacements)?;
/// assert_eq!(motion.frames().count, 8);
/// # Ok::<(), Box<dyn core::error::Error>>(())
/// ```
#[derive(Clone, Copy, Debug)]
pub struct Motion<'s> {
    frames: Frames,
    tracks: &'s [Track],
    keys: &'s [Key],
    table: &'s [[i32; 3]],
}

impl<'s> Motion<'s> {
    /// What [`Motion::read`] needs to hold `text`'s motion.
    pub fn needs(text: &str) -> MotionNeeds {
        let frames = crate::parse::frames_of(text).map_or(0, |f| f.count as usize);
        let mut needs = MotionNeeds::default();
        for_each_move(text, |m| {
            needs.tracks += 1;
            needs.keys += m.keys.iter().count();
            if m.mover == Mover::Object {
                needs.displacements += frames;
            }
        });
        needs
    }

    /// Reads the motion of `text`, an animation of `frames` whose frame
    /// `frame` is loaded as `view` (the same text, parsed at that frame),
    /// into the storage given ([`Motion::needs`] says how much).
    pub fn read(
        text: &str,
        frames: Frames,
        view: &SceneView<'_>,
        frame: u32,
        tracks: &'s mut [Track],
        keys: &'s mut [Key],
        table: &'s mut [[i32; 3]],
    ) -> Result<Motion<'s>, MotionError> {
        let needs = Motion::needs(text);
        let room = |what, have: usize, needed| match have >= needed {
            true => Ok(()),
            false => Err(MotionError::NoRoom { what, needed }),
        };
        room("tracks", tracks.len(), needs.tracks)?;
        room("keys", keys.len(), needs.keys)?;
        room("displacements", table.len(), needs.displacements)?;
        let norm = view.normalization;
        let mut written = WrittenObjects { view, next: 0, seen: 0 };
        let (mut track_count, mut key_count, mut table_len) = (0usize, 0usize, 0usize);
        let mut failed = false;
        for_each_move(text, |m| {
            if failed {
                return;
            }
            let target = match m.mover {
                Mover::Object => Target::Objects,
                Mover::Light => Target::Light,
                Mover::Eye | Mover::LookAt => Target::Camera,
            };
            // The camera moves in world units, the rest in normalised ones
            // (as the parser places them).
            let normalised = target != Target::Camera;
            let key_first = key_count;
            let keys_of = m.keys;
            let values = || {
                keys_of.offsets().map(move |(f, d)| (f, if normalised { d.map(|v| norm.length_wide(v)) } else { d }))
            };
            let last = values().last().map_or([0; 3], |(_, d)| d);
            let mut before = last;
            for (at, value) in values() {
                keys[key_count] = Key::new(at, value != before);
                before = value;
                key_count += 1;
            }
            let mut track = Track { target, keys: (key_first as u32, (key_count - key_first) as u32), ..Track::EMPTY };
            if target == Target::Objects {
                let Some(objects) = written.nth(m.ordinal) else {
                    failed = true;
                    return;
                };
                let start = displacement_at(values(), 0);
                let slice = &mut table[table_len..table_len + frames.count as usize];
                for (f, entry) in slice.iter_mut().enumerate() {
                    let d = displacement_at(values(), f as u32);
                    // Two places of the objects in range: the difference
                    // fits.
                    *entry = [0, 1, 2].map(|a| (d[a] - start[a]) as i32);
                }
                let now = slice.get(frame as usize).copied().unwrap_or([0; 3]);
                let [mut lo, mut hi] = [[i32::MAX; 3], [i32::MIN; 3]];
                for id in objects.clone() {
                    let bounds = view.shape(ObjectId(id)).bounds();
                    let (min, max) = (bounds.min.bits(), bounds.max.bits());
                    for a in 0..3 {
                        lo[a] = lo[a].min(min[a].saturating_sub(now[a]));
                        hi[a] = hi[a].max(max[a].saturating_sub(now[a]));
                    }
                }
                let mut swept = [lo, hi];
                for entry in slice.iter() {
                    for a in 0..3 {
                        swept[0][a] = swept[0][a].min(lo[a].saturating_add(entry[a]));
                        swept[1][a] = swept[1][a].max(hi[a].saturating_add(entry[a]));
                    }
                }
                track.sphere = objects.len() == 1
                    && view.shape(ObjectId(objects.start)).kind() == crate::shapes::ShapeKind::Sphere;
                track.table = table_len as u32;
                track.first = [lo, hi];
                track.swept = swept;
                table_len += frames.count as usize;
            } else if target == Target::Light && m.ordinal as usize >= view.lights.len() {
                failed = true;
                return;
            }
            tracks[track_count] = track;
            track_count += 1;
        });
        if failed {
            return Err(MotionError::NotTheScene);
        }
        Ok(Motion { frames, tracks: &tracks[..track_count], keys: &keys[..key_count], table: &table[..table_len] })
    }

    /// The animation's frames.
    pub fn frames(&self) -> Frames {
        self.frames
    }

    /// Whether nothing moves at all: every frame is frame 0.
    pub fn is_still(&self) -> bool {
        self.tracks.iter().all(|t| self.next_change(t, 0) == NEVER)
    }

    /// The tracks of `target`.
    pub(crate) fn tracks_of(&self, target: Target) -> impl Iterator<Item = &Track> + '_ {
        self.tracks.iter().filter(move |t| t.target == target)
    }

    /// How many transitions after frame `frame` (in the loop's order, the
    /// one out of `frame` counting 0) pass before `track` first changes;
    /// [`NEVER`] if it never does.
    pub(crate) fn next_change(&self, track: &Track, frame: u32) -> u32 {
        let n = self.frames.count;
        let keys = &self.keys[track.keys.0 as usize..(track.keys.0 + track.keys.1) as usize];
        let mut best = NEVER;
        let mut consider = |first: u32, last: u32| {
            // Transitions first..=last change; the nearest from `frame`.
            let d = if frame <= last { first.max(frame) - frame } else { first + n - frame };
            best = best.min(d);
        };
        if keys.first().is_some_and(|k| k.changes) && n > 1 {
            consider(n - 1, n - 1);
        }
        for pair in keys.windows(2) {
            if pair[1].changes {
                consider(pair[0].frame, pair[1].frame - 1);
            }
        }
        best
    }

    /// The first change among the tracks of `target` after `frame`.
    pub(crate) fn next_change_of(&self, target: Target, frame: u32) -> u32 {
        self.tracks_of(target).map(|t| self.next_change(t, frame)).min().unwrap_or(NEVER)
    }

    /// How the objects of `track` sweep through the loop, for the tracker.
    pub(crate) fn sweep<'m>(&'m self, track: &'m Track) -> Sweep<'m> {
        let keys = &self.keys[track.keys.0 as usize..(track.keys.0 + track.keys.1) as usize];
        let table = &self.table[track.table as usize..track.table as usize + self.frames.count as usize];
        Sweep { first: track.first, sphere: track.sphere, swept: track.swept, table, keys }
    }
}

/// The objects of a scene as its statements wrote them, in file order: a
/// patch's triangles together.
struct WrittenObjects<'v, 'a> {
    view: &'v SceneView<'a>,
    /// The next object id to look at.
    next: u32,
    /// Written objects passed so far.
    seen: u32,
}

impl WrittenObjects<'_, '_> {
    /// The object ids of written object `ordinal` (at or after those asked
    /// for before).
    fn nth(&mut self, ordinal: u32) -> Option<core::ops::Range<u32>> {
        let count = self.view.object_count() as u32;
        let starts = |id: u32| self.view.written_object(ObjectId(id)).0 == id;
        loop {
            if self.next >= count {
                return None;
            }
            let start = self.next;
            let mut end = start + 1;
            while end < count && !starts(end) {
                end += 1;
            }
            self.next = end;
            self.seen += 1;
            if self.seen - 1 == ordinal {
                return Some(start..end);
            }
        }
    }
}
