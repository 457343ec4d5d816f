//! Pass 1 of the parser, the survey: the surfaces, the world-space extent
//! of objects, eye and lights (which fixes the normalisation), FRAMES, and
//! what the scene needs of each capacity.
//!
//! Invariant: it reports no error (the build pass reports each once); a
//! statement in error counts for nothing but its keyword's `failed` mark.

use super::keyword::KeywordSet;
use super::motion::{for_each_paired, Paired};
use super::statement::{Keys, RoomOf, Statement};
use crate::capacity::Counts;
use crate::scene::{Frames, Normalization, Scene, SceneCapacities, SurfaceEntry, WorldPoint};

/// World bounds of everything that matters for the normalisation.
struct Extent {
    min: WorldPoint,
    max: WorldPoint,
}

impl Extent {
    fn add(&mut self, lo: WorldPoint, hi: WorldPoint) {
        for a in 0..3 {
            self.min[a] = self.min[a].min(lo[a]);
            self.max[a] = self.max[a].max(hi[a]);
        }
    }
}

/// What pass 1 found besides the surfaces and the normalisation it stored.
pub(super) struct Survey {
    /// What the scene needs of each capacity.
    pub needed: Counts,
    /// The scene's FRAMES (its first).
    pub frames: Option<Frames>,
    /// Keywords with a statement in error: what such a statement defines
    /// (a SURFACE, FRAMES) is missing, and an error for its absence
    /// elsewhere would only repeat that statement's.
    pub failed: KeywordSet,
}

/// Pass 1: surfaces (sorted by number), the normalisation and FRAMES. The
/// extent is every frame's: a moved statement's box at each of its keys
/// (between keys it stays within theirs).
pub(super) fn survey<C: SceneCapacities>(text: &str, scene: &mut Scene<C>) -> Survey {
    let mut counts = Counts::ZERO;
    let mut frames = None;
    let mut failed = KeywordSet::default();
    let mut eye: Option<(WorldPoint, Option<Keys<'_>>)> = None;
    let mut extent: Option<Extent> = None;
    let mut add = |lo: WorldPoint, hi: WorldPoint, moved: Option<Keys<'_>>| {
        let mut at = |d: WorldPoint| {
            let (lo, hi) = ([0, 1, 2].map(|a| lo[a] + d[a]), [0, 1, 2].map(|a| hi[a] + d[a]));
            match &mut extent {
                Some(e) => e.add(lo, hi),
                None => extent = Some(Extent { min: lo, max: hi }),
            }
        };
        match moved {
            Some(keys) => keys.offsets().for_each(|(_, d)| at(d)),
            None => at([0; 3]),
        }
    };
    for_each_paired::<RoomOf<C>>(text, |paired| {
        let (pos, statement, moved) = match paired {
            Paired::Statement { pos, statement, moved } => (pos, statement, moved),
            Paired::Error(_, Some(keyword)) => {
                failed.insert(keyword);
                return;
            }
            _ => return,
        };
        statement.count(&mut counts);
        let moved = moved.map(|(_, keys)| keys);
        match statement {
            Statement::Viewpoint(p) => {
                eye.get_or_insert((p, moved));
            }
            Statement::Light { position, .. } => add(position, position, moved),
            Statement::Surface { number, surface } => {
                // A full arena is reported by the build pass.
                let _ = scene.push_surface(SurfaceEntry { number, line: pos.line, column: pos.column, surface });
            }
            Statement::Frames(f) => {
                frames.get_or_insert(f);
            }
            s => {
                if let Some((lo, hi)) = s.object_bounds() {
                    add(lo, hi, moved);
                }
            }
        }
    });
    let (eye, moved) = eye.unwrap_or((scene.settings.view.eye, None));
    add(eye, eye, moved);
    scene.sort_surfaces();
    if let Some(e) = extent {
        scene.normalization = Normalization::fit(e.min, e.max);
    }
    Survey { needed: counts.with_objects(), frames, failed }
}
