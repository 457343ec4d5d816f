//! The seam between the tracer and the acceleration structures: a nearest-hit
//! query and an any-hit query for shadow rays.
//!
//! Contract every accelerator keeps, so that all modes give the same bits:
//! - [`Accelerator::nearest`] returns the hit with the smallest `t`, and among
//!   equal `t` the smallest [`ObjectId`] (the format's tie rule);
//! - [`Accelerator::occluded`] answers whether any object is hit with
//!   `0 < t ≤ t_max`, and may stop at the first one;
//!   [`Accelerator::occluded_toward`] gives the same answer for a shadow ray
//!   towards one of the scene's lights (which a [`LightBuffered`]
//!   accelerator answers from its light buffer's cells);
//! - the object a ray starts on is treated as [`RayStart`] says;
//! - camera rays may be answered by the renderer's screen-space lists
//!   instead, where the scene's accelerator allows it (its octree, if
//!   any, walked by 3DDDA): the same hits;
//! - an object is tested at most once per query when the caller provides a
//!   [`Mailbox`] large enough for the scene (one bit per object).

mod choice;
mod light_buffer;
pub(crate) mod linked;
pub(crate) mod naive;
mod octree;

pub use choice::{prepare, Indexing, Prepared};
pub use light_buffer::{
    LightBuffer, LightBufferError, LightBufferReport, LightBufferStore, LightBuffered, MAX_CELLS_A_SIDE,
};
pub(crate) use light_buffer::{ShadowLinks, RAY_SLACK};
pub(crate) use linked::uses_mailbox;
pub(crate) use linked::Linked;
pub use linked::SceneAccelerator;
pub use naive::Naive;
pub(crate) use octree::FILING_MARGIN;
pub use octree::{
    BuildReport, HashEntry, Index, Octree, OctreeCapacities, OctreeConfig, OctreeNode, OctreeStore, ShadowShaft,
    Traversal, MAX_DEPTH,
};

use crate::math::Scalar;
use crate::scene::{ObjectId, SceneView};
use crate::shapes::{Leaving, Ray};

/// How a scene's rays find their objects: the choice a user makes (host-sim's
/// `--accel`, the firmware's `OCTRACE_ACCEL`). Every mode gives the same
/// image; they differ in speed and memory.
///
/// ```
/// use octrace_core::AccelMode;
///
/// assert_eq!(AccelMode::from_name("DDA"), Some(AccelMode::Dda));
/// assert_eq!(AccelMode::Auto.resolve(3), AccelMode::Naive);
/// assert_eq!(AccelMode::Auto.resolve(500), AccelMode::Dda);
/// assert_eq!(AccelMode::Octree.resolve(3), AccelMode::Octree);
/// ```
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum AccelMode {
    /// [`AccelMode::Naive`] for a handful of objects, else [`AccelMode::Dda`].
    #[default]
    Auto,
    /// Every object tested for every ray (the thesis's first version).
    Naive,
    /// The octree walked the thesis's way ([`Traversal::Named`]).
    Octree,
    /// The octree walked by integer 3DDDA ([`Traversal::Dda`]).
    Dda,
}

impl AccelMode {
    /// Every mode, in the order of their names in messages.
    pub const ALL: [AccelMode; 4] = [AccelMode::Auto, AccelMode::Naive, AccelMode::Octree, AccelMode::Dda];

    /// Up to this many objects, [`AccelMode::Auto`] tests them all: below it
    /// an octree's walk costs more than it saves.
    pub const AUTO_NAIVE_UP_TO: usize = 16;

    /// The mode's name: `auto`, `naive`, `octree`, `dda`.
    pub const fn name(self) -> &'static str {
        match self {
            AccelMode::Auto => "auto",
            AccelMode::Naive => "naive",
            AccelMode::Octree => "octree",
            AccelMode::Dda => "dda",
        }
    }

    /// The mode its name stands for (case-insensitive).
    pub fn from_name(name: &str) -> Option<AccelMode> {
        AccelMode::ALL.into_iter().find(|m| m.name().eq_ignore_ascii_case(name))
    }

    /// The mode used for a scene of `objects` objects: never `Auto`.
    pub const fn resolve(self, objects: usize) -> AccelMode {
        match self {
            AccelMode::Auto if objects <= AccelMode::AUTO_NAIVE_UP_TO => AccelMode::Naive,
            AccelMode::Auto => AccelMode::Dda,
            mode => mode,
        }
    }

    /// The octree walk this mode uses, `None` for the naive mode (and for
    /// `Auto`, which must be resolved first).
    pub const fn traversal(self) -> Option<Traversal> {
        match self {
            AccelMode::Octree => Some(Traversal::Named),
            AccelMode::Dda => Some(Traversal::Dda),
            AccelMode::Auto | AccelMode::Naive => None,
        }
    }
}

impl core::fmt::Display for AccelMode {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.write_str(self.name())
    }
}

/// The nearest intersection: the cheap part of a hit (pbrt's split); the
/// surface data is computed only for the hit that wins.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Hit {
    /// Where along the ray, in normalised units.
    pub t: Scalar,
    /// The object hit.
    pub object: ObjectId,
}

impl Hit {
    /// No hit yet: the farthest parameter and no object (a hit at
    /// `Scalar::MAX` still wins, by the earlier-object rule).
    pub(crate) const NONE: Hit = Hit { t: Scalar::MAX, object: ObjectId(u32::MAX) };

    /// Whether this hit wins over `other`: nearer, or as near and on an
    /// earlier object (the format's tie rule).
    #[inline]
    pub(crate) fn beats(&self, other: &Hit) -> bool {
        self.t < other.t || (self.t == other.t && self.object < other.object)
    }

    /// The hit, unless it is [`Hit::NONE`].
    #[inline]
    pub(crate) fn found(self) -> Option<Hit> {
        (self.object != Hit::NONE.object).then_some(self)
    }
}

/// The object a secondary ray leaves, and how it leaves it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct RayStart {
    /// The object the ray starts on.
    pub object: ObjectId,
    /// Which way it leaves that object.
    pub leaving: Leaving,
}

impl RayStart {
    /// How the ray relates to `object`.
    #[inline]
    pub fn leaving(start: Option<RayStart>, object: ObjectId) -> Leaving {
        match start {
            Some(s) if s.object == object => s.leaving,
            _ => Leaving::No,
        }
    }
}

/// Remembers which objects a query has tested, so that an object filed in
/// several cells is tested once. One bit per object in caller-owned words;
/// clearing zeroes the words when they are few (up to 256 objects), else
/// only the bits that were set (up to 32, else all the words). Words too
/// few for an object just disable the check for it.
pub struct Mailbox<'m> {
    words: &'m mut [u32],
    touched: heapless::Vec<u32, 32>,
    overflowed: bool,
    /// Cells (leaves) visited, for the benchmarks.
    pub cells: u64,
    /// The object that answered the last `occluded` query with true
    /// (`u32::MAX`: none), so the tracer can try it first next time.
    pub(crate) blocker: u32,
}

impl core::fmt::Debug for Mailbox<'_> {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.debug_struct("Mailbox")
            .field("objects", &(self.words.len() * 32))
            .field("cells", &self.cells)
            .finish_non_exhaustive()
    }
}

impl<'m> Mailbox<'m> {
    /// Up to this many words, clearing zeroes them all: cheaper than
    /// listing the bits as they are set.
    const ZERO_ALL_UP_TO: usize = 8;

    /// A mailbox over `words`, for up to `32 · words.len()` objects.
    pub fn new(words: &'m mut [u32]) -> Mailbox<'m> {
        words.fill(0);
        Mailbox { words, touched: heapless::Vec::new(), overflowed: false, cells: 0, blocker: u32::MAX }
    }

    /// No mailbox: every candidate is tested.
    pub fn none() -> Mailbox<'static> {
        Mailbox { words: &mut [], touched: heapless::Vec::new(), overflowed: false, cells: 0, blocker: u32::MAX }
    }

    /// Words needed for `objects` objects.
    pub const fn words_for(objects: usize) -> usize {
        objects.div_ceil(32)
    }

    /// True the first time `object` is seen in this query.
    #[inline]
    pub fn first_visit(&mut self, object: u32) -> bool {
        let (w, bit) = ((object / 32) as usize, 1u32 << (object % 32));
        let Some(word) = self.words.get_mut(w) else { return true };
        if *word & bit != 0 {
            return false;
        }
        *word |= bit;
        if self.words.len() > Self::ZERO_ALL_UP_TO && self.touched.push(object).is_err() {
            self.overflowed = true;
        }
        true
    }

    /// Forgets every visit (call between queries).
    #[inline]
    pub fn clear(&mut self) {
        if self.words.len() <= Self::ZERO_ALL_UP_TO {
            zero_few(self.words);
        } else if self.overflowed {
            self.words.fill(0);
            self.overflowed = false;
        } else {
            for &o in &self.touched {
                if let Some(w) = self.words.get_mut((o / 32) as usize) {
                    *w = 0;
                }
            }
        }
        self.touched.clear();
    }
}

/// Zeroes up to [`Mailbox::ZERO_ALL_UP_TO`] words with a store each: a
/// slice's `fill` of unknown length is a library call on a Cortex-M0,
/// dearer than the few words a small scene's mailbox has.
#[inline(always)]
fn zero_few(words: &mut [u32]) {
    macro_rules! lengths {
        ($($n:literal)*) => {
            match words.len() {
                $($n => if let Ok(words) = <&mut [u32; $n]>::try_from(&mut *words) {
                    *words = [0; $n];
                },)*
                _ => words.fill(0),
            }
        };
    }
    const _: () = assert!(Mailbox::ZERO_ALL_UP_TO == 8);
    lengths!(1 2 3 4 5 6 7 8)
}

/// An intersection strategy over a scene: the nearest hit, and any hit for
/// shadow rays. What a build links around it (the shape kinds, the
/// mailbox, the screen lists, coherence) is its profile's ([`Linked`]).
pub trait Accelerator {
    /// The nearest hit along `ray` (`t > 0`), ties to the earlier object.
    fn nearest(
        &self,
        scene: &SceneView<'_>,
        ray: &Ray,
        start: Option<RayStart>,
        mailbox: &mut Mailbox<'_>,
    ) -> Option<Hit>;

    /// Whether anything is hit with `0 < t ≤ t_max`; when so, the object
    /// found is left in the mailbox's `blocker`.
    fn occluded(
        &self,
        scene: &SceneView<'_>,
        ray: &Ray,
        t_max: Scalar,
        start: Option<RayStart>,
        mailbox: &mut Mailbox<'_>,
    ) -> bool;

    /// [`Accelerator::occluded`] for a shadow ray from its origin towards
    /// the scene's light `light`, aimed as the tracer aims it (its direction
    /// [`Vec3::direction_and_length_estimate`](crate::math::Vec3::direction_and_length_estimate)'s
    /// of the vector to the light, or exactly rounded, and `t_max` at most
    /// that length): the same answer, and an accelerator may use what it
    /// knows of that light (the octree's shadow shafts, a
    /// [`LightBuffered`]'s cells).
    fn occluded_toward(
        &self,
        scene: &SceneView<'_>,
        ray: &Ray,
        t_max: Scalar,
        light: usize,
        start: Option<RayStart>,
        mailbox: &mut Mailbox<'_>,
    ) -> bool {
        let _ = light;
        self.occluded(scene, ray, t_max, start, mailbox)
    }
}

/// A reference to an accelerator answers as it does.
impl<A: Accelerator + ?Sized> Accelerator for &A {
    #[inline]
    fn nearest(
        &self,
        scene: &SceneView<'_>,
        ray: &Ray,
        start: Option<RayStart>,
        mailbox: &mut Mailbox<'_>,
    ) -> Option<Hit> {
        (**self).nearest(scene, ray, start, mailbox)
    }

    #[inline]
    fn occluded(
        &self,
        scene: &SceneView<'_>,
        ray: &Ray,
        t_max: Scalar,
        start: Option<RayStart>,
        mailbox: &mut Mailbox<'_>,
    ) -> bool {
        (**self).occluded(scene, ray, t_max, start, mailbox)
    }

    #[inline]
    fn occluded_toward(
        &self,
        scene: &SceneView<'_>,
        ray: &Ray,
        t_max: Scalar,
        light: usize,
        start: Option<RayStart>,
        mailbox: &mut Mailbox<'_>,
    ) -> bool {
        (**self).occluded_toward(scene, ray, t_max, light, start, mailbox)
    }
}

#[cfg(test)]
mod tests {
    extern crate std;
    use super::*;

    #[test]
    fn auto_picks_naive_for_few_objects_and_dda_above() {
        assert_eq!(AccelMode::Auto.resolve(16), AccelMode::Naive);
        assert_eq!(AccelMode::Auto.resolve(17), AccelMode::Dda);
        assert_eq!(AccelMode::Octree.resolve(1), AccelMode::Octree);
        for mode in AccelMode::ALL {
            assert_eq!(AccelMode::from_name(mode.name()), Some(mode));
        }
        assert_eq!(AccelMode::from_name("DDA"), Some(AccelMode::Dda));
        assert_eq!(AccelMode::from_name("fast"), None);
    }

    #[test]
    fn mailbox_sees_each_object_once_per_query() {
        // Few words (zeroed whole) and many (cleared bit by bit, or whole
        // once more than 32 bits were set).
        for count in [4, 16] {
            let mut words = std::vec![0u32; count];
            let mut m = Mailbox::new(&mut words);
            assert!(m.first_visit(5));
            assert!(!m.first_visit(5));
            assert!(m.first_visit(127));
            assert!(m.first_visit(1000), "beyond the words: always tested");
            assert!(m.first_visit(1000));
            m.clear();
            assert!(m.first_visit(5) && m.first_visit(127), "{count} words");
            m.clear();
            for i in 0..100 {
                m.first_visit(i);
            }
            m.clear();
            assert!((0..128).all(|i| m.first_visit(i)), "cleared after overflow too, {count} words");
        }
    }
}
