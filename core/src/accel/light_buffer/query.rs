//! Shadow rays through a light buffer: a ray's lists, tested nearest the
//! light first, up to the ray's own depth.

use super::build::cell_in;
use super::cells::direction;
use super::{LightBuffer, ShadowLinks, Words, DEPTH_SHIFT, OBJECT_BITS, OBJECT_MASK};
use crate::accel::{Mailbox, RayStart};
use crate::math::Scalar;
use crate::scene::{ObjectId, SceneView};
use crate::shapes::{Leaving, Ray, ShapeKinds};

/// A shadow ray from its origin towards the scene's light `light` as the
/// tracer aims it (see [`RAY_SLACK`](super::RAY_SLACK)), up to `t_max`.
pub(crate) struct ShadowQuery<'q, 'v> {
    pub scene: &'q SceneView<'v>,
    pub ray: &'q Ray,
    pub t_max: Scalar,
    pub light: usize,
    pub start: Option<RayStart>,
}

impl LightBuffer<'_> {
    /// Whether anything blocks the shadow ray `query` asks of; the blocker
    /// is left in the mailbox. `None` when the light is not buffered (in a
    /// build that links a cube): the caller asks its accelerator.
    #[inline]
    pub(crate) fn occluded<S: ShadowLinks>(
        &self,
        query: &ShadowQuery<'_, '_>,
        mailbox: &mut Mailbox<'_>,
    ) -> Option<bool> {
        // A build of cones alone tests every shadow ray here, against its
        // light's cones or, for a light without, every object (the
        // accelerator's answer, with no second loop linked).
        if !S::CUBES || (S::CONES && self.cones) {
            return Some(self.occluded_in_cones::<S>(query, mailbox));
        }
        if self.cones {
            return None;
        }
        let ShadowQuery { scene, ray, t_max, light, start } = *query;
        let ([own, cell], depth) = self.lists(ray.origin.bits(), light)?;
        let shadow = Shadow { scene, kinds: S::KINDS, ray, t_max, start, depth };
        // The light's own list is mostly empty.
        Some((!own.is_empty() && shadow.blocked_by(own, mailbox)) || shadow.blocked_by(cell, mailbox))
    }

    /// The lists a shadow ray from `origin` to light `light` tests (the
    /// light's own and its cell's) and the ray's depth; `None` when the
    /// light is not buffered.
    #[inline(never)]
    pub(super) fn lists(&self, origin: [i32; 3], light: usize) -> Option<([&[u32]; 2], u32)> {
        if light >= self.lights {
            return None;
        }
        let cube = self.words.get(Words::HEADER + Words::CUBE * light..)?.get(..Words::CUBE)?;
        let v = [0, 1, 2].map(|a| origin[a].checked_sub(cube[a] as i32));
        let (face, m, [i, j]) = direction([v[0]?, v[1]?, v[2]?], self.level)?;
        let own = self.list(cube[3] as usize)?;
        let cell = match cell_in(cube[4 + 2 * face] as usize, cube[5 + 2 * face], i, j) {
            Some(cell) => self.list(cell)?,
            None => &[],
        };
        Some(([own, cell], m >> DEPTH_SHIFT))
    }

    /// The list of cell `cell`, if there is one.
    #[inline(always)]
    pub(super) fn list(&self, cell: usize) -> Option<&[u32]> {
        let starts = self.words.get(self.cells + cell..self.cells + cell + 2)?;
        self.words.get(self.entries + starts[0] as usize..self.entries + starts[1] as usize)
    }
}

/// A shadow ray testing lists.
pub(super) struct Shadow<'s, 'r> {
    pub(super) scene: &'s SceneView<'s>,
    pub(super) kinds: ShapeKinds,
    pub(super) ray: &'r Ray,
    pub(super) t_max: Scalar,
    pub(super) start: Option<RayStart>,
    /// The ray's depth: objects beyond it cannot block.
    pub(super) depth: u32,
}

impl Shadow<'_, '_> {
    /// Whether an object of `list` up to the ray's depth blocks it (the
    /// blocker left in the mailbox).
    #[inline(never)]
    pub(super) fn blocked_by(&self, list: &[u32], mailbox: &mut Mailbox<'_>) -> bool {
        for &entry in list {
            if entry >> OBJECT_BITS > self.depth {
                break;
            }
            let object = entry & OBJECT_MASK;
            let leaving = RayStart::leaving(self.start, ObjectId(object));
            // A ray leaving an object outward never meets it again (every
            // shape's test says so first).
            if leaving == Leaving::Outward {
                continue;
            }
            let Some(&handle) = self.scene.objects.get(object as usize) else { continue };
            if self.scene.intersect_handle(self.kinds, handle, self.ray, self.t_max, leaving).is_some() {
                mailbox.blocker = object;
                return true;
            }
        }
        false
    }
}
