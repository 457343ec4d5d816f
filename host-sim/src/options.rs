//! How host-sim renders (its options: size, acceleration, threads and
//! their partition, the light buffer, a stop) and where a streamed render's
//! rows go: what the renders and their threads share.

use octrace_core::accel::OctreeConfig;
use octrace_core::profile::Host;
use octrace_core::scene::CameraError;
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
    /// Cells a face side of the shadow rays' light buffer (0: none); the
    /// naive mode asked for by name never has one (the thesis's test of
    /// every object).
    pub light_buffer: u32,
    /// Once set (host-sim's Ctrl-C), a streamed render ([`render_streamed`](crate::render_streamed))
    /// stops before its next ray, inside the pixels it traces, with
    /// [`StreamError::Stopped`]. The renders into memory ([`render`](crate::render) and
    /// the others) never stop.
    pub stop: Option<&'static AtomicBool>,
}

impl Default for RenderOptions {
    fn default() -> Self {
        RenderOptions {
            size: None,
            accel: AccelMode::Auto,
            octree: OCTREE,
            threads: 1,
            partition: Partition::Tiles,
            light_buffer: LIGHT_BUFFER,
            stop: None,
        }
    }
}

/// Cells a face side of host-sim's light buffers (the finest the core
/// builds): chosen by measurement, see BENCHMARKS.md.
pub const LIGHT_BUFFER: u32 = octrace_core::accel::MAX_CELLS_A_SIDE;

/// Every core of this machine (1 if that cannot be told).
/// How host-sim builds octrees unless told otherwise: the host profile's
/// config (shadow shafts on).
pub const OCTREE: OctreeConfig = <Host as octrace_core::profile::Profile>::OCTREE;

/// Receives a streamed render's rows, each once, in order from top to bottom.
pub trait RowSink {
    /// Row `y` (counted in the whole image): RGB triples, and the object
    /// seen through each pixel ([`NO_OBJECT`](octrace_images::NO_OBJECT) for background).
    fn row(&mut self, y: u32, colors: &[u8], objects: &[u32]) -> std::io::Result<()>;
}

/// Why a streamed render stopped.
#[derive(Debug)]
pub enum StreamError {
    /// The camera cannot be set up for the size asked (nothing rendered).
    Camera(CameraError),
    /// The sink refused a row; the render stopped there.
    Sink(std::io::Error),
    /// The render's stop was set ([`RenderOptions::stop`]): it stopped
    /// inside the pixels it traced.
    Stopped,
}

impl std::fmt::Display for StreamError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            StreamError::Camera(e) => write!(f, "cannot set up the camera: {e}"),
            StreamError::Sink(e) => write!(f, "{e}"),
            StreamError::Stopped => f.write_str("the render was stopped"),
        }
    }
}

impl std::error::Error for StreamError {}
