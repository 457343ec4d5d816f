//! Scenes that move: an animation's frames traced with frame-to-frame
//! coherence, each frame re-tracing only the pixels the motion can change,
//! and every frame bit for bit the frame traced whole.
//!
//! A scene with `FRAMES` is an animation; `MOVE` keys displace the
//! statement before them ([`crate::parse::parse_frame`] loads frame k,
//! [`Raytracer::load_frame`](crate::Raytracer::load_frame) on a board).
//! [`Motion`] holds what moves over the whole loop, read once into the
//! caller's storage; [`Coherence`] holds a byte for each tile of the image
//! (the caller's too, [`Coherence::tiles_for`] of them, a `const fn`).
//!
//! # The invariant (`docs/animation.md` has it at length)
//!
//! A pixel's value depends on the camera, on the lights' places if any of
//! its rays hits something, and on the objects that come near a segment of
//! its ray tree: each camera, reflected and transmitted ray from its origin
//! to its hit (or out of the scene), each shadow ray from its point to its
//! light. While a pixel is traced, every segment is checked against each
//! moving object's box in the frames to come (the boxes widened past every
//! rounding the tracer's hits have, on an integer grid rounded outward), and
//! the pixel gets its clean count: how many of the loop's next transitions
//! (after the last frame comes frame 0) keep the camera, the lights and the
//! objects near its segments where they are, and no moving object comes
//! near a segment. If a transition moves nothing near any segment, each ray
//! meets the same objects in the same places, so the tree and its value are
//! the same: skipping the pixel is exact. A tile keeps the smallest count
//! of its pixels, so a frame re-traces the tiles whose count ran out.
//!
//! # Memory
//!
//! One byte a tile: a 240×240 panel in 4×4 tiles is 3,600 bytes. The
//! motion: a [`Track`] (44 bytes) for each `MOVE`, a [`Key`] (8 bytes) for
//! each key, and 12 bytes a frame for each moving object statement
//! ([`Motion::needs`]). Tracing keeps a run of 32 tiles' counts (128 bytes)
//! on the stack.
//!
//! # On two cores
//!
//! [`Coherence::plan`] once a frame on one core; then each core, with a
//! [`Renderer`](crate::render::Renderer) of its own over the frame's scene
//! (`LoadedScene::with_renderer`, `SharedScene::renderer`), takes the next
//! band not yet taken and traces it: [`LoadedScene::draw_bands`](crate::LoadedScene::draw_bands) on the core
//! that drives the display, [`Coherence::trace_band`] on the other, which
//! hands its runs over. The counts are atomics each written by the core
//! that traced the tile.

pub(crate) mod coherence;

#[doc(hidden)]
pub use crate::motion::Dependence;
pub use crate::motion::{Key, Motion, MotionError, MotionNeeds, Track};
pub use coherence::{Coherence, CoherenceError, RunSink};
