//! How host-sim renders: the size, the mode, the octree's criterion, the
//! threads and how the image is cut between them.
//!
//! Invariants: any options give the same bits but for the size; the
//! default is the host profile's octree on one thread.

use octrace_core::accel::{Indexing, OctreeConfig};
use octrace_core::profile::{Host, Profile};
use octrace_core::AccelMode;
use std::sync::atomic::AtomicBool;

/// How the image is cut between threads.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum Partition {
    /// Tiles of 32×32 pixels handed out one at a time from a shared
    /// counter: a thread that finishes early takes the next, so all stay
    /// busy to the end.
    Tiles,
    /// The thesis's parallel mode: four equal rectangles (the image's
    /// quarters), quarter `i` to thread `i mod threads`.
    Equal4,
}

/// The side of a tile in [`Partition::Tiles`]: small enough to balance 2 to
/// 64 threads on a 160×128 image, large enough that handing one out costs
/// nothing next to tracing it.
pub const TILE_SIDE: u32 = 32;

/// How to render.
#[derive(Clone, Copy, Debug)]
pub struct RenderOptions {
    /// Overrides RASTER.
    pub size: Option<(u32, u32)>,
    pub accel: AccelMode,
    /// Subdivision criterion (the traversal follows `accel`).
    pub octree: OctreeConfig,
    /// Threads to render on (at least 1). The image is the same for any
    /// number.
    pub threads: usize,
    pub partition: Partition,
    /// Once set (host-sim's Ctrl-C), a streamed render ([`render_streamed`](crate::render_streamed))
    /// stops before its next ray, inside the pixels it traces, with
    /// [`StreamError::Stopped`](crate::StreamError::Stopped). The renders into memory ([`render`](crate::render) and
    /// the others) never stop.
    pub stop: Option<&'static AtomicBool>,
}

impl Default for RenderOptions {
    fn default() -> Self {
        RenderOptions {
            size: None,
            accel: AccelMode::default(),
            octree: OCTREE,
            threads: 1,
            partition: Partition::Tiles,
            stop: None,
        }
    }
}

impl RenderOptions {
    /// How the scene is indexed: the mode, and the octree's criterion.
    pub fn indexing(&self) -> Indexing {
        Indexing { mode: self.accel, octree: Some(self.octree) }
    }
}

/// Every core of this machine (1 if that cannot be told).
pub fn all_cores() -> usize {
    std::thread::available_parallelism().map_or(1, |n| n.get())
}

/// How host-sim builds octrees unless told otherwise: the host profile's
/// config (shadow shafts on).
pub const OCTREE: OctreeConfig = <Host as Profile>::OCTREE;
