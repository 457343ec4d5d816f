//! octrace on the desktop: load a scene file, render it with the same core
//! code a board runs, write an image file. The binary is a thin wrapper
//! around [`cli::run`], so tests drive exactly what a user runs.
//!
//! Invariants: any number of threads and any partition give the same bits;
//! a streamed render ([`render_streamed`]) holds a few bands of rows, never
//! the image, and hands every row to its sink once, in order.

pub mod animation;
mod arguments;
pub mod board;
pub mod cli;
mod convert;
pub mod exit;
mod merge;
mod options;
pub mod output;
pub mod parts;
mod render;
mod rows;
mod scene;
pub mod signals;
pub mod studio;
mod terminal;
mod threaded;

pub use octrace_core::AccelMode;
pub use octrace_images::{RgbImage, NO_OBJECT};
pub use options::{all_cores, Partition, RenderOptions, OCTREE, TILE_SIDE};
pub use render::{build_octree, render, render_streamed, render_with_progress, Rendered, Streamed};
pub use rows::{RowSink, StreamError};
pub use scene::{load_bytes, load_file, load_frame_bytes, new_scene, HostScene, LoadError, Loaded};
