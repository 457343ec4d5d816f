//! Animations on the desktop: every frame of a scene with `FRAMES` loaded
//! and traced in turn, each after the first re-tracing only the tiles the
//! motion can change (the core's Animation, `frames.rs`) on every thread, then
//! written as an animated GIF (`gif.rs`, its colours from `quantize/`), an
//! APNG (`apng.rs`), both storing only what each frame changed
//! (`changes.rs`), or one image file a frame (`writers.rs`).
//!
//! Invariants: a frame's image is the frame traced whole, bit for bit
//! (the core's coherence is exact; `--no-coherence` traces every pixel);
//! any number of threads gives the same bits; the frames reach the writer
//! in order, each once.

mod apng;
mod changes;
mod command;
mod frames;
mod gif;
mod quantize;
mod writers;

pub use apng::ApngWriter;
pub use changes::Area;
pub use command::{animate, check_frames, is_frame_file, merge_frames, Request};
pub use frames::{render_frames, AnimationError, AnimationOptions, AnimationReport, FrameImage, COHERENCE_TILE};
pub use gif::{gif_delay, GifWriter};
pub use writers::{FrameInfo, FramePattern, Output};
