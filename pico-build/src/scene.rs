//! The firmware's scene: the file `OCTRACE_SCENE` names, checked on the
//! host with the parser the board runs (its errors fail the build with
//! their line and column), embedded in flash, with a capacity profile that
//! holds exactly what it needs, its octree included, so the Pico's RAM
//! holds just this scene (the linker says so if it does not fit).
//!
//! The profile also holds the camera rays' screen lists of first hits,
//! which render the same picture faster for RAM the Pico has to spare (at
//! most 28 bytes an object), and for a scene walked in an octree a light
//! buffer, built in RAM when the scene loads (its shadow rays test only the
//! objects their direction's cell lists; a scene of a few objects tests
//! them all, and the buffer does not pay there). The octree's shadow shafts
//! are left out: on the thesis's scenes they take longer to build than they
//! save in one picture (BENCHMARKS.md).
//!
//! An animation (`FRAMES` of more than one frame, and a `MOVE`) is played
//! in a loop ([`SceneKind::Animation`]): its profile gets `coherence: true`
//! (each frame re-traces only what its motion can change), `scene.rs` says
//! `ANIMATED` and `MOTION` (what its motion takes, `AnimationNeeds::of`:
//! the firmware adds the tiles of its panel), and its
//! profile is sized at frame 0 (a frame whose octree or light buffer needs
//! more leaves boxes unsplit or fewer cells: the same picture, a little
//! slower). A still links none of it.

use crate::{out_dir, write, BuildError};
use octrace_core::accel::{OctreeConfig, MAX_CELLS_A_SIDE};
use octrace_core::animation::AnimationNeeds;
use octrace_core::capacity::Counts;
use octrace_core::parse::parse;
use octrace_core::profile::{needed_by, needed_with_light_buffer, Host, ProfileText};
use octrace_core::scene::Scene;
use octrace_core::AccelMode;
use std::path::PathBuf;

/// The variable a user sets to pick the scene.
const VARIABLE: &str = "OCTRACE_SCENE";

/// The scene embedded when `OCTRACE_SCENE` is not set: the thesis's figure
/// 5.1, `scenes/fig5_1.txt` of the octrace checkout this crate is built
/// from (by path or by `git =`), so that a template copied out of the
/// repository finds it as well as one built in place.
pub const DEFAULT_SCENE: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/../scenes/fig5_1.txt");

/// What the embedded scene is: what its firmware does with it, and so
/// where its code runs ([`link`](crate::link) copies an animation's
/// tracking into SRAM with the render path).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SceneKind {
    /// Drawn once.
    Still,
    /// Played in a loop, each frame re-tracing what its motion changes.
    Animation,
}

/// Writes `OUT_DIR/scene.rs`: `SCENE_TEXT`, the scene `OCTRACE_SCENE` names
/// (a path from the firmware's folder; [`DEFAULT_SCENE`] when it is not set),
/// `SCENE_NAME`, its file's name without the extension (what a firmware
/// reports it drew), and `SceneProfile`, a `profile!` holding exactly what
/// it needs; `ANIMATED` and `MOTION` (the tracks and keys an animation
/// takes, an `AnimationNeeds` without tiles: none for a still). Returns what the scene is; a scene whose arenas
/// the Pico's RAM cannot hold, or whose octree 16-bit indices cannot number, is refused
/// ([`BuildError::TooLarge`]). The firmware includes it:
///
/// ```ignore
/// mod scene {
///     include!(concat!(env!("OUT_DIR"), "/scene.rs"));
/// }
/// ```
pub fn embed_scene() -> Result<SceneKind, BuildError> {
    let (scene, path, text) = read_scene()?;
    let (kind, source) = scene_source(&scene, &path, &text)?;
    write(&out_dir()?.join("scene.rs"), &source)?;
    Ok(kind)
}

/// Writes `OUT_DIR/scene.rs` for a firmware that draws one still picture
/// with the camera rays' first hits alone (no light buffer, no animation):
/// `SCENE_TEXT`, the scene `OCTRACE_SCENE` names ([`DEFAULT_SCENE`] when it
/// is not set), and `SceneProfile`, exactly what it needs. The ESP32-C3's and the
/// Pico 2's templates take it.
pub fn embed_still_scene() -> Result<(), BuildError> {
    let (scene, path, text) = read_scene()?;
    let needs = needed_by(&text, AccelMode::Auto, &OctreeConfig::DEFAULT, &mut |error| eprintln!("{scene}:{error}"))
        .map_err(|errors| BuildError::Scene { scene: scene.clone(), errors })?;
    let doc = format!("Exactly what `{scene}` needs, its octree included.");
    let motion = AnimationNeeds::of(&text, Default::default());
    let profile = profile_text(&doc, &needs, false, motion.moves(), surveyed(&text, &motion).1);
    fits(&scene, &profile, None)?;
    let source =
        format!("/// The scene, from `{scene}`.\npub const SCENE_TEXT: &str = include_str!({path:?});\n{profile}");
    write(&out_dir()?.join("scene.rs"), &source)
}

/// The scene `OCTRACE_SCENE` names (a path from the firmware's folder;
/// [`DEFAULT_SCENE`] when it is not set): that name, its path and its
/// text, both announced to cargo.
fn read_scene() -> Result<(String, PathBuf, String), BuildError> {
    let manifest: PathBuf = std::env::var_os("CARGO_MANIFEST_DIR")
        .map(Into::into)
        .ok_or(BuildError::NotInBuildScript("CARGO_MANIFEST_DIR"))?;
    println!("cargo:rerun-if-env-changed={VARIABLE}");
    let given = std::env::var(VARIABLE).ok();
    let scene = given.as_deref().unwrap_or(DEFAULT_SCENE).to_owned();
    let path = manifest.join(&scene);
    println!("cargo:rerun-if-changed={}", path.display());
    let bytes = std::fs::read(&path).map_err(|error| BuildError::File {
        path: match given {
            Some(_) => format!("{VARIABLE}={scene} (a path from {})", manifest.display()),
            None => format!("the default scene {scene} ({VARIABLE} is not set)"),
        },
        error,
    })?;
    let text = octrace_core::parse::scene_text(&bytes).map(str::to_owned).map_err(|error| {
        eprintln!("{scene}:{error}");
        BuildError::Scene { scene: scene.clone(), errors: 1 }
    })?;
    Ok((scene, path, text))
}

/// `SceneProfile`, holding `counts`: `Raytracer::load` picks the
/// accelerator as `Auto` does, with the octree `profile!` builds by
/// default, and walks it by 3DDDA (no room for the thesis's hash table);
/// with the camera rays' first hits and, for a scene it indexes that has a
/// `mirror`, their reflections' off it, `coherence` for an animation, and
/// `motion` for a scene with a `MOVE` (a still's links no interpolation).
fn profile_text<'a>(doc: &'a str, counts: &'a Counts, coherence: bool, motion: bool, mirror: bool) -> ProfileText<'a> {
    ProfileText {
        name: "SceneProfile",
        doc,
        counts,
        octree: None,
        named_walk: false,
        first_hits: true,
        // A scene of a few objects is traced naively: a reflection tests
        // them all for what the lists would cost.
        mirror_hits: mirror && counts.objects > AccelMode::AUTO_NAIVE_UP_TO,
        coherence,
        motion,
    }
}

/// The most RAM a Pico template's arenas can take, in bytes: the 256 KiB
/// of striped SRAM that statics go in (`memory.x`), less core 0's stack
/// (the 16 KiB the link requires) and core 1's (a static of 16 KiB). The
/// rest of the firmware's statics and the code it copies into SRAM come
/// on top, which the link checks; a scene over this fits no placement.
const RP2040_ARENA_ROOM: usize = (256 - 16 - 16) * 1024;

/// Refuses, before anything is compiled, a scene whose `profile` the board
/// cannot hold: an octree its 16-bit indices cannot number, or arenas over
/// `room` bytes (when the board's RAM is known here).
fn fits(scene: &str, profile: &ProfileText<'_>, room: Option<usize>) -> Result<(), BuildError> {
    let too_large = |limit: String| BuildError::TooLarge {
        scene: scene.to_owned(),
        needs: profile.counts.described().to_string(),
        limit,
    };
    if let Some((room, bytes)) = room.map(|room| (room, profile.arena_bytes())).filter(|&(room, bytes)| bytes > room) {
        return Err(too_large(format!(
            "its arenas take about {bytes} bytes of RAM, more than the {room} a Pico leaves them beside both \
             cores' stacks"
        )));
    }
    profile.counts.check_octree_index().map_err(|e| too_large(e.to_string()))
}

/// What the scene `text`, whose motion takes `motion`, is: an animation if
/// it has frames and something moves (a scene of one frame, or where
/// nothing moves, is drawn once); and whether it has a mirror
/// (`SceneView::has_mirror`).
fn surveyed(text: &str, motion: &AnimationNeeds) -> (SceneKind, bool) {
    let mut parsed = Box::new(Scene::<Host>::new());
    let frames = parse(text, &mut parsed, &mut |_| {}).ok().and_then(|p| p.frames).map_or(1, |f| f.count);
    let kind = match motion.moves() && frames > 1 {
        true => SceneKind::Animation,
        false => SceneKind::Still,
    };
    (kind, parsed.view().has_mirror())
}

/// `scene.rs` for the scene `name`, read from `path` as `text`, and what
/// the scene is.
fn scene_source(name: &str, path: &std::path::Path, text: &str) -> Result<(SceneKind, String), BuildError> {
    let mut report = |error| eprintln!("{name}:{error}");
    let failed = |errors| BuildError::Scene { scene: name.to_owned(), errors };
    // `Raytracer::load` picks the accelerator as `Auto` does, with the
    // octree `profile!` builds by default.
    // The shadow rays' light buffer: a cube for a scene walked in an
    // octree, a cone an object a light for a few objects.
    let needs = needed_with_light_buffer(text, AccelMode::Auto, &OctreeConfig::DEFAULT, MAX_CELLS_A_SIDE, &mut report)
        .map_err(failed)?;
    let doc = format!("Exactly what `{name}` needs, its octree included.");
    // Counted once: what the scene is, whether its profile holds motion (a
    // MOVE places its frame 0 even where it is drawn once), and what an
    // animation's motion takes.
    let motion = AnimationNeeds::of(text, Default::default());
    let (kind, mirror) = surveyed(text, &motion);
    let animated = kind == SceneKind::Animation;
    let profile = profile_text(&doc, &needs, animated, motion.moves(), mirror);
    fits(name, &profile, Some(RP2040_ARENA_ROOM))?;
    let motion = if animated { motion } else { Default::default() };
    let stem = path.file_stem().map_or_else(|| name.to_owned(), |stem| stem.to_string_lossy().into_owned());
    let source = format!(
        "/// The scene, from `{name}`.\npub const SCENE_TEXT: &str = include_str!({path:?});\n\
         /// Its file's name, without the extension (for a firmware that reports what it drew).\n\
         #[allow(dead_code)]\npub const SCENE_NAME: &str = {stem:?};\n{profile}\
         /// Whether the scene is an animation the firmware plays.\npub const ANIMATED: bool = {animated};\n\
         /// What its motion takes (`AnimationNeeds::of`): the firmware adds its panel's tiles.\n\
         pub const MOTION: octrace_core::animation::AnimationNeeds = octrace_core::animation::AnimationNeeds {{ \
         tiles: 0, tracks: {}, keys: {} }};\n",
        motion.tracks, motion.keys
    );
    Ok((kind, source))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_scene_gets_a_light_buffer_in_ram_a_few_objects_cones() {
        let spheres: String =
            (0..40).map(|k| format!("SPHERE 1 0.5 {} {} 0\n", k % 7, k / 7)).collect::<String>() + "LIGHT 1 0 10 10\n";
        let path = std::path::Path::new("scene.txt");
        let (_, walked) = scene_source("many", path, &format!("SURFACE 1 1 1 1 1 1 1 0 0 0 1 0 0\n{spheres}")).unwrap();
        assert!(walked.contains("light_buffer_lights: 1"), "{walked}");
        let (_, few) =
            scene_source("few", path, "SURFACE 1 1 1 1 1 1 1 0 0 0 1 0 0\nSPHERE 1 1 0 0 0\nLIGHT 1 0 10 10\n")
                .unwrap();
        // One light's cone around one sphere: the header and two words.
        assert!(few.contains("light_buffer_lights: 1, light_buffer_words: 5"), "{few}");
        assert!(few.contains("pub const SCENE_TEXT: &str = include_str!(\"scene.txt\");"), "{few}");
        assert!(few.contains("pub const SCENE_NAME: &str = \"scene\";"), "{few}");
    }

    #[test]
    fn an_animation_gets_coherence_and_its_motion_and_a_still_neither() {
        let path = std::path::Path::new("scene.txt");
        let still = "SURFACE 1 1 1 1 1 1 1 0 0 0 1 0 0\nSPHERE 1 1 0 0 0\nLIGHT 1 0 10 10\n";
        let (kind, source) = scene_source("still", path, still).unwrap();
        assert_eq!(kind, SceneKind::Still);
        assert!(source.contains("    coherence: false\n") && source.contains("ANIMATED: bool = false"), "{source}");
        assert!(source.contains("    motion: false\n"), "{source}");
        assert!(source.contains("tiles: 0, tracks: 0, keys: 0"), "{source}");
        // Frames where nothing moves, or a move in one frame, are stills;
        // the second still parses its MOVE.
        for (text, motion) in
            [(format!("FRAMES 4\n{still}"), false), (format!("FRAMES 1\n{still}SPHERE 1 1 3 0 0 MOVE 0 0 0 0\n"), true)]
        {
            let (kind, source) = scene_source("still", path, &text).unwrap();
            assert_eq!(kind, SceneKind::Still, "{text}");
            assert!(source.contains(&format!("    motion: {motion}\n")), "{source}");
        }
        let moving = format!("FRAMES 4\n{still}SPHERE 1 1 3 0 0 MOVE 0 0 0 0  3 0 2 0\n");
        let (kind, source) = scene_source("moving", path, &moving).unwrap();
        assert_eq!(kind, SceneKind::Animation);
        assert!(source.contains("    coherence: true\n    motion: true\n}\n"), "{source}");
        assert!(source.contains("ANIMATED: bool = true"), "{source}");
        assert!(source.contains("tiles: 0, tracks: 1, keys: 2"), "{source}");
    }

    #[test]
    fn a_scene_the_pico_cannot_hold_is_refused_before_it_is_compiled() {
        // 12,000 spheres: some 40 bytes each, over the arenas' room.
        let spheres: String =
            (0..12_000).map(|k| format!("SPHERE 1 0.2 {} {} {}\n", k % 20, k / 20 % 20, k / 400)).collect();
        let text = format!("SURFACE 1 1 1 1 1 1 1 0 0 0 1 0 0\nLIGHT 1 0 10 10\n{spheres}");
        let error = scene_source("crowd", std::path::Path::new("crowd.txt"), &text).unwrap_err();
        let message = error.to_string();
        assert!(matches!(error, BuildError::TooLarge { .. }), "{message}");
        assert!(
            message.starts_with("crowd is too large for this board: it needs 12000 objects, 12000 spheres"),
            "{message}"
        );
        assert!(message.contains(&format!("more than the {RP2040_ARENA_ROOM} a Pico leaves them")), "{message}");
    }

    #[test]
    fn an_octree_its_indices_cannot_number_is_refused_on_any_board() {
        let counts =
            |octree_boxes, octree_references| Counts { spheres: 3, octree_boxes, octree_references, ..Counts::ZERO };
        let last = Counts::OCTREE_INDEX_LIMIT - 1;
        for (boxes, references, fits_the_index) in
            [(last, last, true), (last + 1, 9, false), (9, last + 1, false), (100_000, 200_000, false)]
        {
            let counts = counts(boxes, references);
            let result = fits("big", &profile_text("", &counts, false, false, false), None);
            match fits_the_index {
                true => assert!(result.is_ok(), "{boxes} {references}"),
                false => {
                    let message = result.unwrap_err().to_string();
                    assert!(
                        message.contains(&format!("{boxes} octree boxes, {references} octree references")),
                        "{message}"
                    );
                    assert!(message.contains("16-bit indices number at most 65533 of each"), "{message}");
                }
            }
        }
    }

    #[test]
    fn a_scene_with_errors_is_refused_with_their_count() {
        let error = scene_source("bad", std::path::Path::new("bad.txt"), "SPHERE 1 1 0 0\nRASTER 0 0\n").unwrap_err();
        assert!(matches!(error, BuildError::Scene { errors, .. } if errors >= 1), "{error}");
        assert!(error.to_string().starts_with("bad: "), "{error}");
    }
}
