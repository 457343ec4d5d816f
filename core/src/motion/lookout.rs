//! The tracer's lookout: while a pixel is traced, every segment of its ray
//! tree is checked against what moves in the frames to come, and the pixel
//! gets its *clean count*: how many of the loop's next transitions surely
//! leave its value as it is.
//!
//! Invariant (see `docs/animation.md`): a pixel's value depends only on the
//! camera, the lights' places, and for each segment of its ray tree
//! (camera, reflected and transmitted rays up to their hit or out of the
//! scene, shadow rays up to their light) the objects that come near it.
//! So the value stays while the camera and, for a pixel that hits
//! anything, the lights stay, and no moving object's box comes near a
//! segment (or, if it is near one now, moves).

use super::sweep::Segment;
use super::track::{Motion, Target, NEVER};
use crate::math::{mul_wide, Scalar, Vec3};
use crate::shapes::Ray;

/// One kind of dependence of a pixel on what moves. The tracker follows
/// them all; a test drops one ([`crate::animation::Animation::ignoring`])
/// to see its check of exactness fail.
#[doc(hidden)]
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Dependence {
    /// On the eye and the point looked at.
    Camera,
    /// On the lights' places (every pixel that hits something).
    Lights,
    /// Of camera rays on the objects along them.
    Primary,
    /// Of reflected rays on the objects along them.
    Reflected,
    /// Of transmitted rays on the objects along them.
    Transmitted,
    /// Of shadow rays on the objects between a point and its light.
    Shadows,
}

impl Dependence {
    const fn bit(self) -> u8 {
        1 << self as u8
    }
}

/// What a traced ray is, for the lookout.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum RayKind {
    Primary,
    Reflected,
    Transmitted,
}

/// A renderer's lookout over one frame of an animation.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Lookout<'m> {
    motion: Motion<'m>,
    frame: u32,
    /// Transitions before the camera next moves, and a light.
    camera: u32,
    lights: u32,
    /// Dependences dropped ([`Dependence::bit`]), by a test only.
    ignored: u8,
    /// The pixel's clean count so far: the smallest of its segments'.
    pub clean: u32,
}

impl<'m> Lookout<'m> {
    /// The lookout over frame `frame` of `motion`.
    pub(crate) fn new(motion: Motion<'m>, frame: u32, ignored: u8) -> Lookout<'m> {
        let camera = motion.next_change_of(Target::Camera, frame);
        let lights = motion.next_change_of(Target::Light, frame);
        Lookout { motion, frame, camera, lights, ignored, clean: NEVER }
    }

    /// Whether the camera moves before the next frame: then every pixel is
    /// traced again, and watching this frame's rays would only cost.
    pub(crate) fn is_idle(&self) -> bool {
        self.camera == 0 && self.follows(Dependence::Camera)
    }

    fn follows(&self, dependence: Dependence) -> bool {
        self.ignored & dependence.bit() == 0
    }

    /// Starts a pixel whose clean count matters only below `bound`.
    pub(crate) fn start(&mut self, bound: u32) {
        self.clean = match self.follows(Dependence::Camera) {
            true => bound.min(self.camera),
            false => bound,
        };
    }

    /// A ray of the tree, with the parameter of its hit (`None`: it left
    /// the scene).
    #[inline]
    pub(crate) fn ray(&mut self, ray: &Ray, hit: Option<Scalar>, kind: RayKind) {
        if self.clean == 0 {
            return;
        }
        if hit.is_some() && self.follows(Dependence::Lights) {
            self.clean = self.clean.min(self.lights);
        }
        let dependence = match kind {
            RayKind::Primary => Dependence::Primary,
            RayKind::Reflected => Dependence::Reflected,
            RayKind::Transmitted => Dependence::Transmitted,
        };
        if !self.follows(dependence) {
            return;
        }
        let o = ray.origin.wide();
        let d = ray.dir.wide();
        // To the hit, or 2^31 raw units on: beyond the scene's range
        // (2^30 across, its diagonal below 2^31) from any point in it.
        let end = match hit {
            Some(t) => [0, 1, 2].map(|a| o[a] + (mul_wide(d[a] as i32, t.to_bits()) >> 30)),
            None => [0, 1, 2].map(|a| o[a] + 2 * d[a]),
        };
        self.segment(&Segment::new(o, end), false);
    }

    /// A shadow ray from `from` to a light at `light`.
    #[inline]
    pub(crate) fn shadow(&mut self, from: Vec3, light: Vec3) {
        if self.clean == 0 || !self.follows(Dependence::Shadows) {
            return;
        }
        self.segment(&Segment::new(from.wide(), light.wide()), true);
    }

    /// Lowers the clean count for the moving objects `segment` comes near
    /// now or in the frames to come (`shadow`: a shadow ray's, whose answer
    /// stays while a moving sphere surely blocks it).
    fn segment(&mut self, segment: &Segment, shadow: bool) {
        for track in self.motion.tracks_of(Target::Objects) {
            let Some(sweep) = self.motion.sweep_near(track, segment) else {
                continue;
            };
            let clean = if shadow && sweep.blocks_at(segment, self.frame) {
                // Blocked now, surely: blocked, whatever else moves, until
                // the first frame the sphere may let it through.
                match sweep.first_unblocked(segment, self.frame, self.clean) {
                    Some(e) => e - 1,
                    None => self.clean,
                }
            } else if sweep.meets_at(segment, self.frame) {
                // Near it now: the value stands until the objects move.
                self.motion.next_change(track, self.frame)
            } else {
                // Until the transition into the first frame they come near
                // it (only one before the present bound matters).
                match sweep.first_meeting(segment, self.frame, self.clean) {
                    Some(e) => e - 1,
                    None => NEVER,
                }
            };
            self.clean = self.clean.min(clean);
            if self.clean == 0 {
                return;
            }
        }
    }
}
