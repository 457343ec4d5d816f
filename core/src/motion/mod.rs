//! What moves in an animation and what it can change, for the tracer: the
//! moving statements over the whole loop ([`Motion`], recorded by the
//! loader), where each stands at any frame from its keys alone
//! (`path.rs`), the coarse grid the tracker tests on (`grid.rs`), where a
//! ray segment meets a moving object (`sweep.rs`),
//! and the lookout that gives each traced pixel its clean count
//! (`lookout.rs`). The public face is [`crate::animation`], which owns the
//! motion's storage beside the tiles' coherence; this module sits below
//! the tracer so that `shade` and `render` can call the lookout.

mod grid;
mod lookout;
mod path;
mod sweep;
mod track;

pub use lookout::Dependence;
pub(crate) use lookout::{Lookout, RayKind};
pub(crate) use path::Key;
pub(crate) use track::Track;
pub(crate) use track::{Motion, MotionNeeds, Recorder, NEVER};
