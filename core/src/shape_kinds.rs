//! The one list of shape kinds: every line octrace writes once per kind is
//! generated from it.
//!
//! [`ShapeKind`](crate::shapes::ShapeKind), [`ShapeRef`](crate::shapes::ShapeRef)
//! and their dispatch, the capacities ([`CapacityKind`](crate::capacity::CapacityKind)
//! and [`Counts`](crate::capacity::Counts)), the scene's arenas and
//! [`SceneView`](crate::scene::SceneView)'s slices, and the arenas
//! [`profile!`](crate::profile!) and the `Host` profile declare all expand
//! it. Adding a kind is a line here, the shape's file in `shapes/` (its
//! `Shape` implementation) and its statement in `parse/`
//! (`docs/architecture.md` walks through one).
//!
//! Invariants: this file uses nothing from the crate; a kind's place in the
//! list is its `ShapeKind` discriminant, and there are at most eight (a
//! `ShapeHandle` keeps the kind in three bits).

/// Hands the list of shape kinds to a macro: `__shape_kinds!(m! { tokens })`
/// expands to `m! { shapes [ list ] tokens }`. Each entry reads
/// `Kind(Type) in field: Capacity, "what";`: the `ShapeKind` and `ShapeRef`
/// variant, the primitive's type, the arena's name (a `Counts` field, a
/// `Scene` and `SceneView` field), its `CapacityKind` variant (and the
/// `SceneCapacities` arena type), and what runs out, in plain words.
/// Not a public API: [`profile!`](crate::profile!) expands it.
#[doc(hidden)]
#[macro_export]
macro_rules! __shape_kinds {
    ($($callback:ident)::+ ! { $($tokens:tt)* }) => {
        $($callback)::+ ! {
            shapes [
                /// A `SPHERE`.
                Sphere(Sphere) in spheres: Spheres, "spheres";
                /// A `BOX`, axis-aligned.
                Box(AxisAlignedBox) in boxes: Boxes, "boxes";
                /// A `SUPERQUADRIC`.
                Superquadric(Superquadric) in superquadrics: Superquadrics, "superquadrics";
                /// A `TRIANGLE`.
                Triangle(Triangle) in triangles: Triangles, "triangles";
                /// A `RECTANGLE`.
                Rectangle(Rectangle) in rectangles: Rectangles, "rectangles";
                /// A triangle of a `BSPLINE` patch (two per cell of its grid).
                SmoothTriangle(SmoothTriangle) in bspline_triangles: BsplineTriangles, "B-spline triangles";
            ]
            $($tokens)*
        }
    };
}
