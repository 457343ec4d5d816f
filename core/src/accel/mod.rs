//! The seam between the tracer and the acceleration structures: a nearest-hit
//! query and an any-hit query for shadow rays.
//!
//! Contract every accelerator keeps, so that all modes give the same bits:
//! - [`Accelerator::nearest`] returns the hit with the smallest `t`, and among
//!   equal `t` the smallest [`ObjectId`] (the format's tie rule);
//! - [`Accelerator::occluded`] answers whether any object is hit with
//!   `0 < t ≤ t_max`, and may stop at the first one;
//! - the object a ray starts on is treated as [`RayStart`] says;
//! - an object is tested at most once per query when the caller provides a
//!   [`Mailbox`] large enough for the scene (one bit per object).

mod naive;
mod octree;

pub use naive::Naive;
pub use octree::{
    overlaps, BuildReport, Cell, HashEntry, Octree, OctreeConfig, OctreeNode, Traversal, FILING_MARGIN, MAX_DEPTH,
};

use crate::math::Scalar;
use crate::scene::{ObjectId, SceneView};
use crate::shapes::{Leaving, Ray};

/// The nearest intersection: the cheap part of a hit (pbrt's split); the
/// surface data is computed only for the hit that wins.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Hit {
    pub t: Scalar,
    pub object: ObjectId,
}

/// The object a secondary ray leaves, and how it leaves it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct RayStart {
    pub object: ObjectId,
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
/// clearing costs only the bits that were set (up to 32, else the words are
/// zeroed). Words too few for an object just disable the check for it.
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

impl<'m> Mailbox<'m> {
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
        if self.touched.push(object).is_err() {
            self.overflowed = true;
        }
        true
    }

    /// Forgets every visit (call between queries).
    #[inline]
    pub fn clear(&mut self) {
        if self.overflowed {
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

/// An intersection strategy over a scene.
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
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn mailbox_sees_each_object_once_per_query() {
        let mut words = [0u32; 4];
        let mut m = Mailbox::new(&mut words);
        assert!(m.first_visit(5));
        assert!(!m.first_visit(5));
        assert!(m.first_visit(127));
        assert!(m.first_visit(500), "beyond the words: always tested");
        assert!(m.first_visit(500));
        m.clear();
        assert!(m.first_visit(5));
        for i in 0..100 {
            m.first_visit(i);
        }
        m.clear();
        assert!((0..128).all(|i| m.first_visit(i)), "cleared after overflow too");
    }
}
