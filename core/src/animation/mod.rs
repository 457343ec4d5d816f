//! Scenes that move: an animation's frames traced with frame-to-frame
//! coherence, each frame re-tracing only the pixels the motion can change,
//! and every frame bit for bit the frame traced whole.
//!
//! A scene with `FRAMES` is an animation; `MOVE` keys displace the
//! statement before them ([`crate::parse::parse_frame`] reads frame k). An
//! [`Animation`] holds what moves over the whole loop and a byte for each
//! tile of the image ([`Coherence`]), in storage the caller owns
//! ([`AnimationRoom`], sized by [`AnimationNeeds`] of the scene: it grows
//! with the scene's `MOVE`s and keys, not with its frames).
//! [`Animation::load`] loads a frame (recording the motion as the loader
//! places a scene it has not seen, and checking every frame's camera
//! then), and the [`Frame`](crate::Frame) draws as a still does, tracing
//! only the tiles that can have changed.
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
//! One byte a tile: a 240×240 panel in tiles of [`TILE`] is 3,600 bytes.
//! The motion: a track (88 bytes) for each `MOVE` and a key (76 bytes) for
//! each of its keys ([`AnimationNeeds::bytes`]), whatever the number of
//! frames. Tracing keeps a run of 32 tiles' counts (128 bytes) on the
//! stack.
//!
//! # On two cores
//!
//! A frame is loaded on one core; then each core, with a renderer of its
//! own over the frame (the loading core's room, or
//! [`SharedScene::image`](crate::SharedScene::image) with a
//! [`RendererRoom`](crate::RendererRoom)), takes the next band of tiles not
//! yet taken and draws it ([`TracedImage::bands`](crate::TracedImage::bands)).
//! The counts are atomics each written by the core that traced the tile.

pub(crate) mod coherence;
mod needs;
mod player;
mod room;

pub use crate::motion::Dependence;
pub use coherence::Coherence;
pub use needs::{AnimationCapacity, AnimationNeeds, NoRoom};
pub use player::Animation;
pub(crate) use player::Playing;
pub use room::AnimationRoom;
#[cfg(feature = "alloc")]
pub use room::HostAnimationRoom;

/// The side of the square tiles an animation's image is traced in, in
/// pixels: chosen by measurement (BENCHMARKS.md, "Animation").
pub const TILE: u32 = 4;
