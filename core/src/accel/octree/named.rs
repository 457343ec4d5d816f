//! The thesis's walk (chapter 4.3): from each leaf's exit point, a step of
//! half of Minlen across the faces the ray leaves through, then the leaf
//! holding that point, found from the root by box name through the hash
//! table, one lookup per level.
//!
//! Every parameter is a [`Ratio`] of integers with the per-axis denominator
//! `|d_a|`, so comparing two crossings is two `i64` products and nothing
//! rounds. Which child of a box holds a point on the ray at parameter `t` is
//! decided per axis by comparing `t` with the parameter at which the ray
//! crosses the box's centre plane. (A full Minlen step would land exactly on
//! the far face of a smallest neighbour, which exact arithmetic then skips.)

use super::Octree;
use super::OctreeCapacities;
use crate::capacity::Arena;
use crate::shapes::axis_aligned_box::slab_span_wide;
use crate::shapes::{Ratio, Ray};

/// The leaf the walk stands in.
#[derive(Clone, Copy, Debug)]
struct Leaf {
    node: u32,
    lo: [i64; 3],
    log2: u32,
}

/// The point to locate: the ray at `t`, except on the axes in `faces`, where
/// the coordinate is `face[a]` exactly.
#[derive(Clone, Copy, Debug)]
struct Point {
    t: Ratio,
    faces: u8,
    face: [i64; 3],
}

pub(super) struct NamedWalk {
    o: [i64; 3],
    d: [i64; 3],
    current: Option<Leaf>,
}

impl NamedWalk {
    pub fn new<C: OctreeCapacities, const F: usize>(tree: &Octree<C, F>, ray: &Ray) -> NamedWalk {
        let mut walk = NamedWalk { o: ray.origin.wide(), d: ray.dir.wide(), current: None };
        if tree.nodes.as_slice().is_empty() {
            return walk;
        }
        let hi = tree.root_min.map(|v| v + (1i64 << tree.root_log2));
        let Some(span) = slab_span_wide(walk.o, walk.d, tree.root_min, hi) else { return walk };
        if span.exit.is_none_or(|x| x.num < 0) {
            return walk;
        }
        let t = match span.enter {
            Some(e) if e.num > 0 => e,
            _ => Ratio { num: 0, den: 1 },
        };
        // The first box: the one the ray enters (a point on a plane goes to
        // the side the ray heads into).
        walk.current = walk.locate(tree, Point { t, faces: 0, face: [0; 3] }, true);
        walk
    }

    /// The next leaf and the parameter at which the ray leaves it.
    pub fn next_leaf<C: OctreeCapacities, const F: usize>(&mut self, tree: &Octree<C, F>) -> Option<(u32, Ratio)> {
        let leaf = self.current.take()?;
        let size = 1i64 << leaf.log2;
        // The faces the ray leaves through, and when: tmax of the thesis.
        let mut exit: Option<Ratio> = None;
        let mut faces = 0u8;
        let mut face = [0i64; 3];
        for a in 0..3 {
            if self.d[a] == 0 {
                continue;
            }
            let plane = if self.d[a] > 0 { leaf.lo[a] + size } else { leaf.lo[a] };
            face[a] = plane;
            let r = Ratio { num: (plane - self.o[a]) * self.d[a].signum(), den: self.d[a].abs() };
            match exit {
                Some(e) if e.lt(r) => {}
                Some(e) if !r.lt(e) => faces |= 1 << a,
                _ => {
                    exit = Some(r);
                    faces = 1 << a;
                }
            }
        }
        let exit = exit?;
        let step = (1i64 << tree.min_log2) / 2;
        let moved = [0, 1, 2].map(|a| face[a] + step * self.d[a].signum());
        let root_hi = tree.root_min.map(|v| v + (1i64 << tree.root_log2));
        let inside = (0..3).all(|a| faces >> a & 1 == 0 || (tree.root_min[a] <= moved[a] && moved[a] < root_hi[a]));
        if inside {
            self.current = self.locate(tree, Point { t: exit, faces, face: moved }, false);
        }
        Some((leaf.node, exit))
    }

    /// Whether the point lies in the upper half of a box whose centre plane
    /// on axis `a` is at `c`. With `follow_ray`, a point exactly on the plane
    /// goes to the half the ray is heading into.
    fn upper(&self, p: &Point, a: usize, c: i64, follow_ray: bool) -> bool {
        let d = self.d[a];
        if p.faces >> a & 1 == 1 {
            return p.face[a] >= c;
        }
        if d == 0 {
            return self.o[a] >= c;
        }
        // The parameter at which the ray crosses the plane.
        let tc = Ratio { num: (c - self.o[a]) * d.signum(), den: d.abs() };
        if d > 0 {
            !p.t.lt(tc)
        } else if follow_ray {
            p.t.lt(tc)
        } else {
            !tc.lt(p.t)
        }
    }

    /// The leaf holding `p`, from the root, by name through the hash table.
    fn locate<C: OctreeCapacities, const F: usize>(
        &self,
        tree: &Octree<C, F>,
        p: Point,
        follow_ray: bool,
    ) -> Option<Leaf> {
        let nodes = tree.nodes.as_slice();
        let (mut node, mut name, mut lo, mut log2) = (0u32, 1u64, tree.root_min, tree.root_log2);
        loop {
            if !nodes[node as usize].is_internal() {
                return Some(Leaf { node, lo, log2 });
            }
            let half = 1i64 << (log2 - 1);
            let mut octant = 0;
            for a in 0..3 {
                if self.upper(&p, a, lo[a] + half, follow_ray) {
                    octant |= 1 << a;
                    lo[a] += half;
                }
            }
            let children = tree.lookup(name)?;
            name = name * 10 + 1 + octant as u64;
            node = children + octant;
            log2 -= 1;
        }
    }
}
