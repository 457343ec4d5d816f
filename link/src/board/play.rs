//! What a board checks before it plays an animation: that the scene's
//! animation fits the [`Animation`](octrace_core::animation::Animation) a
//! firmware gives its [`Link`](super::Link) (each capacity that runs out
//! named, as the parser's are), and which scenes are animations to play.
//!
//! Invariants: a scene whose animation does not fit is rejected with one
//! `scene-error` for each capacity that runs out, before any `drawing`;
//! the room is the firmware's, never allocated.

use crate::message::{CapacityNeed, Panel};
use embedded_graphics_core::geometry::Size;
use octrace_core::animation::{AnimationNeeds, NoRoom};
use octrace_core::profile::Profile;
use octrace_core::scene::Frames;
use octrace_core::LoadedScene;

/// The panel's size, as an animation's image.
pub(crate) fn size_of(panel: Panel) -> Size {
    Size::new(panel.width.into(), panel.height.into())
}

/// What `text`'s animation needs on `panel` (nothing for text that is not
/// UTF-8: the loader refuses it first).
pub(crate) fn needs(text: &[u8], panel: Panel) -> AnimationNeeds {
    core::str::from_utf8(text).map(|text| AnimationNeeds::of(text, size_of(panel))).unwrap_or_default()
}

/// Each capacity of `room` that `text`'s animation, played on `panel`,
/// needs more of.
pub(crate) fn short_of(room: &AnimationNeeds, text: &[u8], panel: Panel) -> [Option<NoRoom>; 3] {
    needs(text, panel).beyond(room)
}

/// A capacity a scene needs more of, as the protocol names it.
pub(crate) fn capacity(short: &NoRoom) -> CapacityNeed<'static> {
    CapacityNeed { name: short.what.name(), needed: Some(saturate(short.needed)), holds: saturate(short.holds) }
}

/// Where in `text` a scene goes past the room (`NoRoom::position_in`), as
/// the protocol's line and column: (0, 0), an error of the whole scene,
/// where no statement does.
pub(crate) fn position(short: &NoRoom, text: &[u8]) -> (u32, u32) {
    let at = core::str::from_utf8(text).ok().and_then(|text| short.position_in(text));
    at.map_or((0, 0), |pos| (pos.line, pos.column))
}

/// The frames of `scene`, if it is an animation to play (more than one
/// frame).
pub(crate) fn animated<P: Profile>(scene: &LoadedScene<'_, P>) -> Option<Frames> {
    scene.frames().filter(|frames| frames.count > 1)
}

pub(crate) fn saturate(n: usize) -> u32 {
    u32::try_from(n).unwrap_or(u32::MAX)
}
