//! What moves in an animation and what it can change, for the tracer: the
//! moving statements over the whole loop ([`Motion`], read from the scene
//! text), where a ray segment meets a moving object's box (`sweep.rs`), and
//! the lookout that gives each traced pixel its clean count (`lookout.rs`).
//! The public face is [`crate::animation`], which re-exports these types
//! beside the tiles' coherence; this module sits below the tracer so that
//! `shade` and `render` can call the lookout.

mod lookout;
mod sweep;
mod track;

pub use lookout::Dependence;
pub(crate) use lookout::{Lookout, RayKind};
pub use sweep::Key;
pub(crate) use track::NEVER;
pub use track::{Motion, MotionError, MotionNeeds, Track};
