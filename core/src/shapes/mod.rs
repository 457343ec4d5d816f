//! The closed set of primitives, one file each, dispatched through [`ShapeRef`]
//! without virtual calls.
//!
//! Every primitive answers three questions, as pbrt splits them: a cheap hit
//! test that returns only the ray parameter ([`ShapeRef::intersect`]), the
//! surface normal at a point found by that test ([`ShapeRef::normal_at`]), and
//! its bounds for the acceleration structures ([`ShapeRef::bounds`]). Each
//! file answers them in its `Shape` implementation; [`ShapeKind`],
//! [`ShapeRef`] and the dispatch are generated from the list of shape kinds
//! (`shape_kinds.rs`), so a kind cannot be missed in one of them.
//!
//! Invariants: a hit test returns `Some(t)` only for `0 < t ≤ t_max`; the
//! object a ray leaves is never hit again at the spot it left
//! ([`Leaving`]); no test divides by zero or overflows for rays whose origin
//! lies in the normalised scene range.

pub(crate) mod axis_aligned_box;
pub mod bspline;
mod polygon;
mod rectangle;
mod smooth_triangle;
mod sphere;
mod superquadric;
mod triangle;

pub use axis_aligned_box::AxisAlignedBox;
pub use bspline::Bspline;
pub use polygon::Polygon;
pub use rectangle::Rectangle;
pub use smooth_triangle::SmoothTriangle;
pub use sphere::Sphere;
pub use superquadric::Superquadric;
pub use triangle::Triangle;

use crate::capacity::{CapacityKind, Counts};
use crate::math::{part_wise_or, Dir, Scalar, Vec3};

/// A ray `origin + t·dir`, `t > 0`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Ray {
    /// Where the ray starts, in normalised space.
    pub origin: Vec3,
    /// Which way it goes.
    pub dir: Dir,
}

impl Ray {
    /// The point at parameter `t`.
    #[inline]
    pub fn at(&self, t: Scalar) -> Vec3 {
        self.origin + self.dir.scale(t)
    }
}

/// How a ray relates to the object it starts on, so that the object is not hit
/// again at the spot the ray leaves (no self-intersection acne, no epsilon).
///
/// Every primitive is convex or flat, so a ray leaving its surface outwards can
/// never meet it again, and one leaving inwards meets it once more, on the far
/// side.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Leaving {
    /// The ray does not start on this object.
    No,
    /// The ray starts on this object and points away from its interior.
    Outward,
    /// The ray starts on this object and points into its interior: only the
    /// far side counts.
    Inward,
}

/// An axis-aligned bounding box in normalised space, inclusive.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Aabb {
    /// The corner with the smallest coordinates.
    pub min: Vec3,
    /// The corner with the largest coordinates.
    pub max: Vec3,
}

impl Aabb {
    /// The smallest box holding two points.
    #[inline]
    pub(crate) fn spanned(a: Vec3, b: Vec3) -> Aabb {
        Aabb {
            min: Vec3 { x: a.x.min(b.x), y: a.y.min(b.y), z: a.z.min(b.z) },
            max: Vec3 { x: a.x.max(b.x), y: a.y.max(b.y), z: a.z.max(b.z) },
        }
    }

    /// The smallest box holding both.
    pub fn union(self, o: Aabb) -> Aabb {
        Aabb {
            min: Vec3 { x: self.min.x.min(o.min.x), y: self.min.y.min(o.min.y), z: self.min.z.min(o.min.z) },
            max: Vec3 { x: self.max.x.max(o.max.x), y: self.max.y.max(o.max.y), z: self.max.z.max(o.max.z) },
        }
    }
}

/// What every primitive answers (the list's dispatch calls these on a
/// known type: no virtual calls). Its file implements it.
pub(crate) trait Shape {
    /// Flat shapes are seen from both sides; the others are closed.
    const FLAT: bool;

    /// The parameter of the nearest hit with `0 < t ≤ t_max`, if any.
    fn intersect(&self, ray: &Ray, t_max: Scalar, leaving: Leaving) -> Option<Scalar>;

    /// The geometric normal at a point on the surface: outward for closed
    /// shapes, the front side (counter-clockwise corners) for flat ones.
    fn normal_at(&self, p: Vec3) -> Dir;

    /// A box holding the whole shape.
    fn bounds(&self) -> Aabb;

    /// The index of its surface in the scene's surface table.
    fn surface(&self) -> u16;

    /// The normal to shade with and the point shadow rays leave from, given
    /// a hit point and its geometric normal turned towards the ray.
    #[inline(always)]
    fn shading(&self, p: Vec3, facing: Dir) -> (Dir, Vec3) {
        (facing, p)
    }
}

/// Declares [`ShapeKind`] and [`ShapeRef`], and dispatches on them, from
/// the list of shape kinds (`crate::shape_kinds`).
macro_rules! shape_kinds {
    (shapes [$($(#[$doc:meta])* $kind:ident($type:ident) in $field:ident: $capacity:ident, $what:literal;)*]) => {
        /// Which primitive an object is.
        #[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
        #[repr(u8)]
        pub enum ShapeKind {
            $($(#[$doc])* $kind,)*
        }

        impl ShapeKind {
            /// Every kind, in the list's order (`kind as usize` indexes it).
            ///
            /// ```
            /// use octrace_core::shapes::ShapeKind;
            ///
            /// assert_eq!(ShapeKind::ALL[ShapeKind::Triangle as usize], ShapeKind::Triangle);
            /// assert!(ShapeKind::ALL.iter().all(|kind| kind.item_bytes() > 0));
            /// assert!(ShapeKind::Rectangle.is_flat() && !ShapeKind::Sphere.is_flat());
            /// ```
            pub const ALL: [ShapeKind; [$(ShapeKind::$kind),*].len()] = [$(ShapeKind::$kind),*];

            /// The capacity objects of this kind count against.
            pub const fn capacity(self) -> CapacityKind {
                match self {
                    $(ShapeKind::$kind => CapacityKind::$capacity,)*
                }
            }

            /// The kind numbered `v` (the last kind for a number past the
            /// list: handles are only made from kinds). Comparisons, not a
            /// table: the compiler folds them into one clamp of `v`.
            const fn from_u8(v: u8) -> ShapeKind {
                $(if v == ShapeKind::$kind as u8 {
                    return ShapeKind::$kind;
                })*
                ShapeKind::ALL[ShapeKind::ALL.len() - 1]
            }

            /// The bytes an object of this kind takes in its arena (the same
            /// on every target: the primitives hold no pointer or `usize`).
            pub const fn item_bytes(self) -> usize {
                match self {
                    $(ShapeKind::$kind => core::mem::size_of::<$type>(),)*
                }
            }

            /// Flat shapes are seen from both sides; the others are closed.
            pub const fn is_flat(self) -> bool {
                match self {
                    $(ShapeKind::$kind => <$type as Shape>::FLAT,)*
                }
            }
        }

        /// A borrowed primitive: the closed set every caller matches on.
        #[derive(Clone, Copy, Debug)]
        pub enum ShapeRef<'a> {
            $($(#[$doc])* $kind(&'a $type),)*
        }

        impl ShapeRef<'_> {
            /// [`ShapeRef::intersect`] for a shape of one of `kinds` (a constant:
            /// the other kinds' tests are not linked; a shape of one of them is
            /// never hit).
            #[inline(always)]
            pub fn intersect_among(&self, kinds: ShapeKinds, ray: &Ray, t_max: Scalar, leaving: Leaving) -> Option<Scalar> {
                match self {
                    $(ShapeRef::$kind(s) if kinds.contains(ShapeKind::$kind) => s.intersect(ray, t_max, leaving),)*
                    _ => None,
                }
            }

            /// [`ShapeRef::normal_at`] for a shape of one of `kinds` (see
            /// [`ShapeRef::intersect_among`]; another kind's is +Y).
            #[inline(always)]
            pub fn normal_at_among(&self, kinds: ShapeKinds, p: Vec3) -> Dir {
                match self {
                    $(ShapeRef::$kind(s) if kinds.contains(ShapeKind::$kind) => s.normal_at(p),)*
                    _ => Dir::Y,
                }
            }

            /// [`ShapeRef::shading`] for a shape of one of `kinds` (see
            /// [`ShapeRef::intersect_among`]).
            #[inline(always)]
            pub fn shading_among(&self, kinds: ShapeKinds, p: Vec3, facing: Dir) -> (Dir, Vec3) {
                match self {
                    $(ShapeRef::$kind(s) if kinds.contains(ShapeKind::$kind) => s.shading(p, facing),)*
                    _ => (facing, p),
                }
            }

            /// A box holding the whole shape (what an octree files it by).
            pub fn bounds(&self) -> Aabb {
                match self {
                    $(ShapeRef::$kind(s) => s.bounds(),)*
                }
            }

            /// The index of its surface in [`SceneView::surfaces`](crate::scene::SceneView::surfaces).
            pub fn surface(&self) -> u16 {
                match self {
                    $(ShapeRef::$kind(s) => s.surface(),)*
                }
            }

            /// Which primitive it is.
            pub fn kind(&self) -> ShapeKind {
                match self {
                    $(ShapeRef::$kind(_) => ShapeKind::$kind,)*
                }
            }
        }
    };
}

crate::__shape_kinds!(shape_kinds! {});

/// The primitive kinds a build can meet: a profile's shapes with room
/// ([`ShapeKinds::with_room`]). Dispatch on a constant set links no code
/// for a kind outside it (a small board's firmware carries only its scene's
/// shapes); an object of such a kind cannot be stored, so none is missed.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ShapeKinds(u8);

impl ShapeKinds {
    /// Every kind.
    pub const ALL: ShapeKinds = ShapeKinds((1 << ShapeKind::ALL.len()) - 1);

    /// The kinds `counts` has room for.
    pub const fn with_room(counts: &Counts) -> ShapeKinds {
        let kinds = ShapeKind::ALL;
        let mut bits = 0;
        let mut i = 0;
        while i < kinds.len() {
            if counts.get(kinds[i].capacity()) > 0 {
                bits |= 1 << kinds[i] as u8;
            }
            i += 1;
        }
        ShapeKinds(bits)
    }

    /// Whether `kind` is in the set.
    #[inline(always)]
    pub const fn contains(self, kind: ShapeKind) -> bool {
        self.0 & (1 << kind as u8) != 0
    }
}

/// An object's primitive kind and its index in that kind's arena, packed in
/// 32 bits (3 for the kind, 29 for the index).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct ShapeHandle(u32);

// The kind's three bits.
const _: () = assert!(ShapeKind::ALL.len() <= 8, "a ShapeHandle has three bits for the kind");

impl ShapeHandle {
    /// Largest index a handle can carry.
    pub const MAX_INDEX: usize = (1 << 29) - 1;

    /// The handle of the `index`th shape of `kind` (indices above
    /// [`ShapeHandle::MAX_INDEX`] wrap: arenas are never that large).
    pub const fn new(kind: ShapeKind, index: usize) -> ShapeHandle {
        ShapeHandle(((kind as u32) << 29) | (index as u32 & Self::MAX_INDEX as u32))
    }

    /// Which arena the shape is in.
    pub const fn kind(self) -> ShapeKind {
        ShapeKind::from_u8((self.0 >> 29) as u8)
    }

    /// Its place in that arena.
    pub const fn index(self) -> usize {
        (self.0 & Self::MAX_INDEX as u32) as usize
    }
}

impl ShapeRef<'_> {
    /// The parameter of the nearest hit with `0 < t ≤ t_max`, if any.
    #[inline]
    pub fn intersect(&self, ray: &Ray, t_max: Scalar, leaving: Leaving) -> Option<Scalar> {
        self.intersect_among(ShapeKinds::ALL, ray, t_max, leaving)
    }

    /// The geometric normal at a point on the surface: outward for closed
    /// shapes, the front side (counter-clockwise corners) for flat ones.
    pub fn normal_at(&self, p: Vec3) -> Dir {
        self.normal_at_among(ShapeKinds::ALL, p)
    }

    /// The normal to shade with and the point shadow rays leave from, given
    /// a hit point and its geometric normal turned towards the ray: the same
    /// for every shape but a B-spline's triangles, which interpolate their
    /// corner normals and lift shadow rays onto the smooth surface.
    #[inline]
    pub fn shading(&self, p: Vec3, facing: Dir) -> (Dir, Vec3) {
        self.shading_among(ShapeKinds::ALL, p, facing)
    }
}

/// A ratio `num / den` with `den > 0`, compared exactly by cross
/// multiplication: the slab tests use it to order crossings without dividing.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Ratio {
    pub num: i64,
    pub den: i64,
}

impl Ratio {
    /// `self < o`; numerators within ±2^32 and denominators within 2^30.
    /// On ARMv6-M from 32-bit products of the operands' top bits when they
    /// decide ([`coarse_ratio_lt`]): the exact products are two library
    /// calls there.
    #[inline]
    pub fn lt(self, o: Ratio) -> bool {
        part_wise_or(|| coarse_ratio_lt(self, o), || self.num * o.den < o.num * self.den)
    }

    /// The ratio of a Q16.16 numerator to a Q2.30 denominator, as Q16.16.
    #[inline]
    pub fn to_scalar(self) -> Scalar {
        Scalar::from_bits(((self.num << 30) / self.den) as i32)
    }

    /// `self.to_scalar() ≤ t` for a non-negative ratio, without dividing.
    /// (Comparing the exact ratio instead would reject a hit whose rounded
    /// parameter equals `t`: a hit test must filter on the value it returns,
    /// or the order in which objects are tested would change the result.)
    #[inline]
    pub fn le_scalar(self, t: Scalar) -> bool {
        (self.num << 30) < (t.to_bits() as i64 + 1) * self.den
    }
}

/// Whether `x < y` (`x.num·y.den < y.num·x.den`) when 32-bit products of
/// their top bits decide it, else `None` (and for a numerator beyond ±2^33
/// or a denominator beyond 2^31, outside what the bounds below cover).
///
/// Why: with `num = h·2^18 + l` (`|h| ≤ 2^15`, `0 ≤ l < 2^18`) and
/// `den = k·2^16 + m` (`k < 2^15`, `0 ≤ m < 2^16`), `num·den` is within
/// `2^15·2^16·2^18 + 2^18·2^15·2^16 + 2^18·2^16 < (2^16 + 1)·2^34` of
/// `h·k·2^34`, so the difference of the two products is within
/// `(2^17 + 2)·2^34` of `H·2^34`, `H` the short products' difference (below
/// 2^31 in magnitude): `H ≤ −(2^17 + 2)` makes it negative, `H ≥ 2^17 + 2`
/// positive.
#[inline(always)]
fn coarse_ratio_lt(x: Ratio, y: Ratio) -> Option<bool> {
    const SURE: i32 = (1 << 17) + 2;
    let fits = |r: Ratio| (r.num >> 33 == 0 || r.num >> 33 == -1) && r.den >> 31 == 0;
    if !fits(x) || !fits(y) {
        return None;
    }
    let short = |n: i64, d: i64| ((n >> 18) as i32) * ((d >> 16) as i32);
    less_when_sure(short(x.num, y.den) - short(y.num, x.den), SURE)
}

/// What the difference `h` of two cross products' short forms says of the
/// ratios' order, when its error bound makes `sure` enough: `Some(true)`
/// (the first is less) for `h ≤ −sure`, `Some(false)` for `h ≥ sure`,
/// else `None` (the exact products decide).
#[inline(always)]
pub(crate) fn less_when_sure(h: i32, sure: i32) -> Option<bool> {
    if h <= -sure {
        Some(true)
    } else if h >= sure {
        Some(false)
    } else {
        None
    }
}

#[cfg(test)]
pub(crate) mod test_util {
    use super::*;

    pub fn s(v: i32) -> Scalar {
        Scalar::from_num(v)
    }

    pub fn p(x: i32, y: i32, z: i32) -> Vec3 {
        Vec3 { x: s(x), y: s(y), z: s(z) }
    }

    pub fn ray(o: Vec3, d: [i64; 3]) -> Ray {
        Ray { origin: o, dir: Dir::normalize(d).unwrap() }
    }

    pub fn far() -> Scalar {
        Scalar::from_num(30000)
    }

    /// `|a − b|` below `tol` raw units on every axis.
    pub fn close(a: Vec3, b: Vec3, tol: i32) -> bool {
        a.bits().iter().zip(b.bits()).all(|(x, y)| (x - y).abs() <= tol)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The short products decide only as the exact cross products do, for
    /// numerators of every scale up to ±2^33 and denominators up to 2^31,
    /// and decide most comparisons of well-separated ratios.
    #[test]
    fn coarse_ratio_comparisons_agree_with_the_exact_ones() {
        let mut next = crate::test_rng::seeded(0x5a7_10c0);
        let (mut decided, mut undecided) = (0, 0);
        for i in 0..1_000_000 {
            let mut ratio = || {
                let r = next();
                let num = match r % 7 {
                    0 => [0, 1, -1, (1 << 33) - 1, -(1 << 33), 1 << 32][(r >> 3) as usize % 6],
                    // Mostly the scene's distances (the coarse test's case).
                    _ => (r as i64 >> 30) >> [0, 1, 2, 3, 4, 8, 16, 30][(r >> 61) as usize],
                };
                let den = ((r >> 34) as i64 & 0x7fff_ffff) >> [0, 0, 1, 2, 3, 6, 12, 24][((r >> 20) % 8) as usize];
                Ratio { num, den: den.max(1) }
            };
            let (x, y) = (ratio(), ratio());
            match coarse_ratio_lt(x, y) {
                Some(lt) => {
                    let exact = (x.num as i128 * y.den as i128) < (y.num as i128 * x.den as i128);
                    assert_eq!(lt, exact, "case {i}: {x:?} {y:?}");
                    decided += 1;
                }
                None => undecided += 1,
            }
        }
        assert!(decided > 500_000 && undecided > 10_000, "{decided} {undecided}");
    }
}
