//! octrace's core: a ray tracer in fixed-point arithmetic for small
//! microcontrollers, `no_std` and allocation-free. A scene is parsed from
//! text ([`parse`]) into fixed-capacity arenas ([`scene`], sized by a
//! [`profile`](mod@profile)), optionally indexed by an octree ([`accel`]),
//! and rendered pixel by pixel ([`render`]) into any embedded-graphics
//! `DrawTarget`, in truecolour, through a 256-colour [`palette`], or
//! dithered onto a [`panel`] of few levels (a one-bit OLED, gray OLEDs,
//! e-paper).
//!
//! # From scene text to a display
//!
//! One [`Raytracer`] holds a scene, its octree and a mailbox. On a board it
//! lives in a `static` cell (all zero bits: it costs RAM in `.bss`, no
//! flash), [`Raytracer::load`] parses and indexes a scene, and the loaded
//! scene draws as an embedded-graphics image as large as the display, in the
//! display's colour. Here the display is embedded-graphics' `MockDisplay`
//! (64×64 pixels):
//!
//! ```
//! use embedded_graphics::{image::Image, mock_display::MockDisplay, pixelcolor::Rgb888, prelude::*};
//! use octrace_core::{profile::Board16K, ConstStaticCell, Raytracer};
//!
//! const SCENE_TEXT: &str = "
//!     VIEWPOINT 0 0 5
//!     ORIGIN 0 0 0
//!     UPVECTOR 0 1 0
//!     BACKGROUND 0 0 1
//!     LIGHT 10  5 5 5
//!     SPHERE 1  1.5  0 0 0
//!     SURFACE 1  .1 .1 .1  .8 .2 .2  0 0 0  1  0 0
//! ";
//! let mut display = MockDisplay::<Rgb888>::new();
//!
//! static RAYTRACER: ConstStaticCell<Raytracer<Board16K>> = ConstStaticCell::new(Raytracer::new());
//! let scene = RAYTRACER.take().load(SCENE_TEXT)?;
//! Image::new(&scene.image_for(&display), Point::zero()).draw(&mut display)?;
//!
//! // The corner sees the blue background; the centre, the lit red sphere.
//! assert_eq!(display.get_pixel(Point::new(0, 0)), Some(Rgb888::BLUE));
//! let centre = display.get_pixel(Point::new(32, 32)).unwrap();
//! assert!(centre.r() > centre.g() && centre.r() > centre.b(), "{centre:?}");
//! # Ok::<(), Box<dyn core::error::Error>>(())
//! ```
//!
//! A scene with errors gives a [`LoadError`] (its first error with line and
//! column, and how many there are); [`Raytracer::load_with`] hands over
//! every error and chooses the accelerator. On a host, where there is no
//! `static` to spare, box the raytracer (`Box::new(Raytracer::<Host>::new())`
//! with the feature `alloc`).
//!
//! # Capacities
//!
//! A [`profile`](mod@profile) says how many of each thing a build holds, so the linker
//! checks the board's RAM: [`profile::Board16K`] and [`profile::Board64K`]
//! are ready-made, and [`profile!`] defines one for your own scenes from
//! counts ([`parse::count`] tells what a scene needs; a scene that needs
//! more is a [`capacity::CapacityError`] naming the count that ran out):
//!
//! ```
//! octrace_core::profile! {
//!     /// Up to 8 spheres, 2 triangles and an octree of 64 boxes.
//!     pub struct MyBoard {
//!         spheres: 8, triangles: 2, surfaces: 4, lights: 2,
//!         octree_boxes: 64, octree_references: 256,
//!     }
//! }
//! let mut raytracer = octrace_core::Raytracer::<MyBoard>::new();
//! let scene = raytracer.load("SURFACE 1 .1 .1 .1 .7 .2 .2 0 0 0 1 0 0\nSPHERE 1 1 0 0 0\n").unwrap();
//! assert_eq!(scene.view().object_count(), 1);
//! ```
//!
//! # Modes
//!
//! [`AccelMode`] chooses how rays find objects: `Naive` tests every object,
//! `Octree` and `Dda` walk an octree (the thesis's way, or by integer
//! 3DDDA), and `Auto` (what [`Raytracer::load`] uses) picks `Naive` for up
//! to [`AccelMode::AUTO_NAIVE_UP_TO`] objects and `Dda` above. Every mode
//! gives the same image, bit for bit.
//!
//! # Features
//!
//! - `static-cell` (default): re-exports
//!   [`ConstStaticCell`](https://docs.rs/static_cell/2/static_cell/struct.ConstStaticCell.html),
//!   the cell a board keeps its [`Raytracer`] in.
//! - `alloc`: the heap-backed `profile::Host` profile, for desktops.
//! - `defmt`: every error type implements `defmt::Format`, so a board can
//!   log why a scene did not load or draw.
//!
//! # No-panic contract
//!
//! For any input text, however malformed or hostile, and any scene the
//! parser accepted:
//!
//! - [`parse::parse`] and [`parse::parse_bytes`] return; they never panic,
//!   never loop, and take time linear in the text's length (plus the
//!   evaluation of `BSPLINE` patches, linear in their generated points). A
//!   scene with errors is left empty.
//! - Building an octree ([`accel::Octree::build`]) returns for any scene; an
//!   arena that runs out leaves boxes unsplit (slower, same image), never a
//!   panic.
//! - Rendering ([`render::Renderer`]) never panics, divides by zero or
//!   overflows silently: fixed-point products are exact in 64 bits, or
//!   saturate where a value can grow (colours, attenuation). The only errors
//!   it returns are the `DrawTarget`'s own.
//! - The API panics only when handed values it did not make: an
//!   [`scene::ObjectId`] from another scene, say.
//!
//! The test suite runs with overflow checks on, so a silent wrap fails it,
//! and the parser and renderer are fuzzed (`fuzz/`).
//!
//! # Worst-case time per pixel
//!
//! Each of the `SAMPLES²` primary rays spawns a ray tree bounded by
//! [`shade::MAX_RAYS_PER_SAMPLE`] rays (4096), however large RDEPTH is; each
//! ray that hits sends one shadow ray per light. So a pixel costs at most
//! `SAMPLES² × 4096 × (1 + lights)` ray queries, and a query at most one
//! intersection test per object (the naive mode; the octree's walk, given a
//! mailbox, tests each object at most once per ray too) plus, with an
//! octree, one step per box crossed. With
//! RDEPTH d and no transparency the tree is a chain: `SAMPLES² × (d + 1) ×
//! (1 + lights)` queries.

#![no_std]
#![warn(missing_docs, missing_debug_implementations)]
#![forbid(unsafe_code)]
// Per-axis loops index several arrays at once; iterators would obscure them.
#![allow(clippy::needless_range_loop)]

#[cfg(feature = "alloc")]
extern crate alloc;

pub mod accel;
pub mod animation;
pub mod capacity;
pub mod math;
mod motion;
pub mod palette;
pub mod panel;
pub mod parse;
pub mod profile;
mod raytracer;
pub mod render;
pub mod scene;
pub mod shade;
mod shape_kinds;
pub mod shapes;
mod sort;
#[cfg(test)]
mod test_rng;

pub use accel::{AccelMode, SceneAccelerator};
pub use raytracer::picture;
pub use raytracer::{
    AnimationError, DrawError, Frame, LoadError, LoadedScene, Raytracer, RendererRoom, SharedScene, TracedImage,
};
#[cfg(feature = "static-cell")]
pub use static_cell::ConstStaticCell;
