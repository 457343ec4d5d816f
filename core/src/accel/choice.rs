//! The one place a scene's accelerator is chosen and built: the board API
//! ([`crate::Raytracer`]), host-sim and the studio all call [`prepare`].
//!
//! Invariant: the mode [`prepare`] returns is never `Auto` and is one the
//! octree store has room for; the store holds an octree built over the
//! scene exactly when that mode walks one, and then the report is `Some`.

use super::{AccelMode, BuildReport, OctreeConfig, OctreeStore};
use crate::scene::SceneView;

/// How a loaded scene is indexed: the mode asked for, and the octree's
/// criterion (`None`: the profile's, [`Profile::OCTREE`](crate::profile::Profile::OCTREE)).
/// A mode alone is one.
///
/// ```
/// use octrace_core::accel::{Indexing, OctreeConfig};
/// use octrace_core::AccelMode;
///
/// assert_eq!(Indexing::from(AccelMode::Dda), Indexing { mode: AccelMode::Dda, octree: None });
/// let deep = Indexing { octree: Some(OctreeConfig { max_depth: 16, ..OctreeConfig::DEFAULT }), ..Indexing::default() };
/// assert_eq!(deep.mode, AccelMode::Auto);
/// ```
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Indexing {
    /// The mode asked for.
    pub mode: AccelMode,
    /// How the octree is built, if not as the profile says.
    pub octree: Option<OctreeConfig>,
}

impl From<AccelMode> for Indexing {
    fn from(mode: AccelMode) -> Self {
        Indexing { mode, octree: None }
    }
}

/// What [`prepare`] chose and built.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Prepared {
    /// The mode used: `Auto` resolved for the scene, then fallen back to
    /// what the octree store has room for.
    pub mode: AccelMode,
    /// The octree's build report, when the mode walks an octree.
    pub report: Option<BuildReport>,
}

/// Resolves `mode` for `scene` and builds the octree it needs in `octree`,
/// with `config` (its walk set by the mode). A store without boxes gives
/// the naive mode (what an octree of no boxes would do too), and one without
/// the thesis's hash table gives 3DDDA for [`AccelMode::Octree`]: the same
/// image either way. Decided on the store's constants, so a board without
/// room for an octree carries no octree code.
///
/// ```
/// use octrace_core::accel::{prepare, Octree};
/// use octrace_core::parse::parse;
/// use octrace_core::profile::{Board64K, Profile};
/// use octrace_core::scene::Scene;
/// use octrace_core::AccelMode;
///
/// let mut scene: Scene<Board64K> = Scene::new();
/// parse("VIEWPOINT 0 0 5\nLIGHT 1 3 3 3\nSPHERE 1 1 0 0 0\nSURFACE 1 0 0 0 1 1 1 0 0 0 0 0 0\n", &mut scene, &mut |_| {})
///     .unwrap();
/// let mut octree: Octree<Board64K> = Octree::new();
/// let prepared = prepare(AccelMode::Dda, &scene.view(), &mut octree, &Board64K::OCTREE);
/// assert_eq!(prepared.mode, AccelMode::Dda);
/// assert!(prepared.report.is_some());
/// // Auto takes the naive mode for a handful of objects: nothing is built.
/// assert_eq!(prepare(AccelMode::Auto, &scene.view(), &mut octree, &Board64K::OCTREE).report, None);
/// ```
pub fn prepare<O: OctreeStore>(
    mode: AccelMode,
    scene: &SceneView<'_>,
    octree: &mut O,
    config: &OctreeConfig,
) -> Prepared {
    let mode = match mode.resolve(scene.object_count()) {
        _ if !O::HAS_BOXES => AccelMode::Naive,
        AccelMode::Octree if !O::NAMED_WALK => AccelMode::Dda,
        mode => mode,
    };
    let report = mode.traversal().map(|traversal| octree.build(scene, &OctreeConfig { traversal, ..*config }));
    Prepared { mode, report }
}
