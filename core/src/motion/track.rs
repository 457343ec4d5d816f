//! What moves in an animation, for the whole loop at once: each moving
//! statement (a track) and its keys, recorded by the loader as it places
//! the statement ([`Recorder`]), so that the tracker can tell, for any
//! frame, when a moving object will next come near a ray.
//!
//! Invariants: a track's keys say where its objects stand at every frame
//! relative to frame 0, exactly as the parser places them ([`Path`]);
//! `first` is the objects' box at frame 0 and `swept` the box holding them
//! in every frame (on the tracker's grid); `now` is their displacement at
//! the frame the motion was last set to ([`Motion::at_frame`]); a key's
//! `changes` says whether its displacement differs from the key before it
//! (the first key: from the last, the loop's jump).

use super::grid::GridBox;
use super::path::{reach_keys, write_keys, Key, Path};
use super::sweep::{sphere_in, Segment, Sweep};
use crate::parse::{MotionSink, Moved, Mover};
use crate::scene::Frames;

/// A clean count that never runs out: nothing that moves can change the
/// value.
pub(crate) const NEVER: u32 = u32::MAX;

/// What a track moves.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Target {
    /// The eye or the point looked at: every pixel depends on them. First,
    /// so that [`Track::EMPTY`] is all zero bits (a board's room in `.bss`,
    /// not copied from flash).
    Camera,
    /// Objects (a statement's: one, or a patch's triangles), in a box.
    Objects,
    /// A light: every point it shades depends on it.
    Light,
}

/// One moving statement of an animation, held in its room
/// ([`AnimationRoom`](crate::animation::AnimationRoom), all zero bits).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) struct Track {
    target: Target,
    /// Its keys in the motion's keys: the first, and how many.
    keys: (u32, u32),
    /// Objects: their box at frame 0 (normalised raw units).
    first: [[i32; 3]; 2],
    /// Objects: a single sphere's centre at frame 0 and its radius (as
    /// [`sphere_in`] makes them from `first`), tested as one, not as its
    /// box; a radius of 0: not a sphere (a sphere's is at least 1).
    center: [i32; 3],
    radius: i32,
    /// Objects: the box holding them in every frame, on the tracker's grid
    /// (made once: every segment of every traced pixel is tested on it).
    swept: GridBox,
    /// Objects: their displacement at the motion's frame.
    now: [i32; 3],
}

impl Track {
    /// Its keys among the motion's `keys`.
    fn keys_in<'k>(&self, keys: &'k [Key]) -> &'k [Key] {
        &keys[self.keys.0 as usize..(self.keys.0 + self.keys.1) as usize]
    }

    /// A placeholder to fill storage with (a `const`, for a `static`).
    pub(crate) const EMPTY: Track = Track {
        target: Target::Camera,
        keys: (0, 0),
        first: [[0; 3]; 2],
        center: [0; 3],
        radius: 0,
        swept: GridBox::EMPTY,
        now: [0; 3],
    };
}

/// What an animation's motion takes: a track for each `MOVE`, and their
/// keys; and the loop's length (FRAMES' count, 1 without).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub(crate) struct MotionNeeds {
    pub tracks: usize,
    pub keys: usize,
    pub frames: u32,
}

impl MotionNeeds {
    /// What `text`'s motion takes (a scene with errors: what its valid
    /// `MOVE`s take). Not inlined: a pass of its own over the statements,
    /// kept out of the player that asks it once a scene.
    #[inline(never)]
    pub(crate) fn of(text: &str) -> MotionNeeds {
        let mut needs = MotionNeeds::default();
        let frames = crate::parse::for_each_move(text, |_, keys| {
            needs.tracks += 1;
            needs.keys += keys.iter().count();
        });
        MotionNeeds { frames: frames.map_or(1, |(_, f)| f.count.max(1)), ..needs }
    }
}

/// Everything that moves in an animation, over the whole loop, read-only
/// while frames are traced (by any number of cores).
#[derive(Clone, Copy, Debug)]
pub(crate) struct Motion<'s> {
    frames: Frames,
    tracks: &'s [Track],
    keys: &'s [Key],
    /// The frame whose displacements the tracks keep.
    frame: u32,
}

impl<'s> Motion<'s> {
    /// The motion recorded in `tracks` and `keys` of an animation of
    /// `frames`, at frame `frame` (set by [`Motion::at_frame`]).
    pub(crate) fn new(frames: Frames, tracks: &'s [Track], keys: &'s [Key], frame: u32) -> Motion<'s> {
        Motion { frames, tracks, keys, frame }
    }

    /// Keeps, in each object track, its displacement at frame `frame`: the
    /// frame about to be traced, whose displacements the tracker asks most.
    pub(crate) fn at_frame(tracks: &mut [Track], keys: &[Key], frames: Frames, frame: u32) {
        for track in tracks.iter_mut().filter(|t| t.target == Target::Objects) {
            track.now = Path::unkept(track.keys_in(keys), frames.count).at(frame);
        }
    }

    /// The animation's frames.
    pub(crate) fn frames(&self) -> Frames {
        self.frames
    }

    /// The tracks of `target`.
    pub(crate) fn tracks_of(&self, target: Target) -> impl Iterator<Item = &Track> + '_ {
        self.tracks.iter().filter(move |t| t.target == target)
    }

    fn keys_of(&self, track: &Track) -> &'s [Key] {
        track.keys_in(self.keys)
    }

    /// How many transitions after frame `frame` (in the loop's order, the
    /// one out of `frame` counting 0) pass before `track` first changes;
    /// [`NEVER`] if it never does.
    pub(crate) fn next_change(&self, track: &Track, frame: u32) -> u32 {
        let n = self.frames.count;
        let keys = self.keys_of(track);
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

    /// How the objects of `track` sweep through the loop, for the tracker,
    /// if `segment` comes near them in some frame (`None`: it never does,
    /// told from the box they sweep, the test most segments end at).
    pub(crate) fn sweep_near<'m>(&'m self, track: &'m Track, segment: &Segment) -> Option<Sweep<'m>> {
        if !segment.meets_grid(&track.swept) {
            return None;
        }
        let path = Path { keys: self.keys_of(track), frames: self.frames.count, kept: (self.frame, track.now) };
        let sphere = (track.radius > 0).then_some((track.center, track.radius));
        Some(Sweep { first: track.first, sphere, path })
    }
}

/// Records an animation's motion into the caller's storage as the loader
/// places each moving statement.
pub(crate) struct Recorder<'s> {
    tracks: &'s mut [Track],
    keys: &'s mut [Key],
    /// Tracks and keys recorded (or, past the storage, met).
    pub track_count: usize,
    pub key_count: usize,
}

impl<'s> Recorder<'s> {
    /// A recorder into `tracks` and `keys`, empty.
    pub(crate) fn new(tracks: &'s mut [Track], keys: &'s mut [Key]) -> Recorder<'s> {
        Recorder { tracks, keys, track_count: 0, key_count: 0 }
    }

    /// Whether everything met was recorded.
    pub(crate) fn fits(&self) -> bool {
        self.track_count <= self.tracks.len() && self.key_count <= self.keys.len()
    }
}

impl MotionSink for Recorder<'_> {
    fn moved(&mut self, moved: &Moved<'_>) {
        let target = match moved.mover {
            Mover::Object => Target::Objects,
            Mover::Light => Target::Light,
            Mover::Eye | Mover::LookAt => Target::Camera,
        };
        let first_key = self.key_count;
        let room = self.keys.get_mut(first_key..).unwrap_or(&mut []);
        let count = write_keys(|| moved.values(), target == Target::Objects, room);
        self.key_count += count;
        let mut track = Track { target, keys: (first_key as u32, count as u32), ..Track::EMPTY };
        if let Some(objects) = moved.objects.filter(|_| self.key_count <= self.keys.len()) {
            let keys = &self.keys[first_key..self.key_count];
            // The box where the statement stands, moved back to frame 0.
            let now = Path::unkept(keys, moved.frames.count).at(moved.frame);
            let [lo, hi] = objects.bounds.map(|corner| [0, 1, 2].map(|a| corner[a].saturating_sub(now[a])));
            // Between keys the displacement lies between theirs: the
            // extremes over the loop are at keys.
            let mut swept = [lo, hi];
            for key in keys {
                let at = key.after(0);
                for a in 0..3 {
                    swept[0][a] = swept[0][a].min(lo[a].saturating_add(at[a]));
                    swept[1][a] = swept[1][a].max(hi[a].saturating_add(at[a]));
                }
            }
            (track.first, track.swept) = ([lo, hi], GridBox::around(swept));
            reach_keys(&mut self.keys[first_key..self.key_count], track.first);
            if objects.sphere {
                (track.center, track.radius) = sphere_in(track.first);
            }
        }
        if let Some(slot) = self.tracks.get_mut(self.track_count) {
            *slot = track;
        }
        self.track_count += 1;
    }
}
