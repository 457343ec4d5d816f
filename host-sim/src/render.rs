//! Renders of a host scene: into memory ([`render`]) or streamed row by row
//! to a sink ([`render_streamed`]), on threads, through the core's loaded
//! scene as a board draws it.
//!
//! Invariants: any number of threads and any partition give the same bits;
//! a streamed render holds a few bands of rows, never the image.

use crate::options::RenderOptions;
use crate::rows::{Canvas, RowSink, StreamError};
use crate::scene::{HostScene, Indexed};
use crate::threaded::stream_threads;
use octrace_core::accel::{BuildReport, LightBufferReport, OctreeConfig};
use octrace_core::scene::CameraError;
use octrace_core::shade::Stats;
use octrace_core::AccelMode;
use octrace_images::RgbImage;
use std::time::Duration;

/// A finished render.
pub struct Rendered {
    pub image: RgbImage,
    /// The object seen through each pixel (its centre sample), row-major;
    /// [`NO_OBJECT`](crate::NO_OBJECT) for background.
    pub objects: Vec<u32>,
    pub stats: Stats,
    /// The mode actually used (never `Auto`).
    pub accel: AccelMode,
    /// The octree's build report and time, when one was built.
    pub build: Option<(BuildReport, std::time::Duration)>,
    /// The light buffer's report and build time, when one was built.
    pub light_buffer: Option<(LightBufferReport, Duration)>,
    /// Wall-clock time of the render (without building the octree).
    pub wall: Duration,
    /// For each thread, the time it spent rendering; `wall − busy` is the
    /// time it stood idle while others worked.
    pub busy: Vec<Duration>,
}

/// Indexes `scene` as a render in `mode` with the octree `config` does:
/// the octree's build report and the time the build took, when the mode
/// walks one.
pub fn build_octree(scene: &mut HostScene, mode: AccelMode, config: &OctreeConfig) -> Option<(BuildReport, Duration)> {
    let options = RenderOptions { accel: mode, octree: *config, ..RenderOptions::default() };
    scene.index(&options).build
}

/// Renders a loaded scene into a new image, indexed as `options` say.
pub fn render(scene: &mut HostScene, options: &RenderOptions) -> Result<Rendered, CameraError> {
    render_with_progress(scene, options, &|_| {})
}

/// As [`render`], calling `progress(pixels)` (from any thread) each time a
/// piece of the image is done.
pub fn render_with_progress(
    scene: &mut HostScene,
    options: &RenderOptions,
    progress: &(dyn Fn(u64) + Sync),
) -> Result<Rendered, CameraError> {
    let (w, h) = options.size.unwrap_or((scene.view().settings.raster[0], scene.view().settings.raster[1]));
    let mut canvas = Canvas::new(w, h);
    // Never stopped (see `RenderOptions::stop`).
    let options = RenderOptions { stop: None, ..*options };
    let streamed = match render_streamed(scene, &options, 0..h, progress, &mut canvas) {
        Ok(s) => s,
        Err(StreamError::Camera(e)) => return Err(e),
        // The canvas takes every row, and nothing stops the render.
        Err(e @ (StreamError::Sink(_) | StreamError::Stopped)) => unreachable!("a render into memory failed: {e}"),
    };
    let Streamed { stats, accel, build, light_buffer, wall, busy } = streamed;
    Ok(Rendered { image: canvas.image, objects: canvas.objects, stats, accel, build, light_buffer, wall, busy })
}

/// What a streamed render reports; its rows went to a [`RowSink`].
#[derive(Clone, Debug)]
pub struct Streamed {
    pub stats: Stats,
    /// The mode actually used (never `Auto`).
    pub accel: AccelMode,
    /// The octree's build report and time, when one was built.
    pub build: Option<(BuildReport, Duration)>,
    /// The light buffer's report and build time, when one was built.
    pub light_buffer: Option<(LightBufferReport, Duration)>,
    /// Wall-clock time of the render (without building the octree).
    pub wall: Duration,
    /// For each thread, the time it spent tracing.
    pub busy: Vec<Duration>,
}

impl Streamed {
    /// The time spent tracing: building the octree and the light buffer
    /// plus every thread's time rendering pixels, without the encoder's
    /// time or idle waits. With one thread this is what POV-Ray calls its
    /// trace time.
    pub fn tracing(&self) -> Duration {
        self.indexing() + self.busy.iter().sum::<Duration>()
    }

    /// The part of [`Streamed::tracing`] spent building the octree and the
    /// light buffer, before any pixel (most of it for a scene of a million
    /// triangles).
    pub fn indexing(&self) -> Duration {
        self.build.map_or(Duration::ZERO, |(_, built)| built)
            + self.light_buffer.map_or(Duration::ZERO, |(_, built)| built)
    }
}

/// Renders the rows `rows` of the whole image (`options.size`, else RASTER)
/// on `options.threads` threads and hands them to `sink` in order, holding
/// only a few bands of rows at a time: memory follows the width, not the
/// height. Indexes the scene as `options.accel` and `options.octree` ask
/// first (timed apart from the render).
pub fn render_streamed(
    scene: &mut HostScene,
    options: &RenderOptions,
    rows: std::ops::Range<u32>,
    progress: &(dyn Fn(u64) + Sync),
    sink: &mut dyn RowSink,
) -> Result<Streamed, StreamError> {
    let view = scene.view();
    let (w, h) = options.size.unwrap_or((view.settings.raster[0], view.settings.raster[1]));
    // Set-up errors are found once, before anything is built or started.
    view.check_camera(w, h).map_err(StreamError::Camera)?;
    let rows = rows.start.min(h)..rows.end.min(h);
    let Indexed { scene, build, light_buffer } = scene.index(options);
    let (stats, wall, busy) = stream_threads(scene.share(), (w, h), rows, options, progress, sink)?;
    Ok(Streamed { stats, accel: scene.mode(), build, light_buffer, wall, busy })
}
