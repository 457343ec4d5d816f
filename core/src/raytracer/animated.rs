//! An animation's frames loaded into a [`Raytracer`]: the loader records the
//! motion of a scene the [`Animation`] has not seen as it places it (and
//! checks every frame's camera then), or steps the animation's tiles on;
//! the [`Frame`] draws as a still does, tracing only its planned tiles.
//!
//! Invariants: a frame is handed out only once its scene loaded and its
//! tiles are planned for it; a scene with an error at any frame (its
//! camera included) is refused at its first load, before any frame.

use super::draw::Picture;
use super::picture::Bands;
use super::{LoadError, LoadedScene, Raytracer, RunBoth, SharedScene, TracedImage};
use crate::animation::{Animation, AnimationCapacity, AnimationNeeds, Coherence, NoRoom, Playing};
use crate::parse::ParseError;
use crate::profile::Profile;
use crate::scene::Frames;
use core::fmt;
use embedded_graphics_core::draw_target::DrawTarget;

/// Why an animation's frame was not loaded.
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum AnimationError<'t> {
    /// The scene has errors (at this frame, or a camera that cannot be set
    /// up at another: the message names the frame).
    Scene(LoadError<'t>),
    /// The animation's room holds less than the scene needs.
    NoRoom(NoRoom),
}

impl<'t> From<LoadError<'t>> for AnimationError<'t> {
    fn from(e: LoadError<'t>) -> Self {
        AnimationError::Scene(e)
    }
}

impl fmt::Display for AnimationError<'_> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            AnimationError::Scene(e) => write!(f, "{e}"),
            AnimationError::NoRoom(e) => write!(f, "{e}"),
        }
    }
}

impl core::error::Error for AnimationError<'_> {}

/// A frame of an animation, loaded ([`Animation::load`]): its scene, and
/// the tiles its draw traces. It draws as a still does
/// ([`Frame::image`]), only its planned tiles; a board's other cores draw
/// their bands of it from [`Frame::share`].
pub struct Frame<'a, 'r, P: Profile> {
    scene: LoadedScene<'r, P>,
    playing: Playing<'a>,
}

impl<P: Profile> fmt::Debug for Frame<'_, '_, P> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("Frame").field("frame", &self.playing.frame).field("scene", &self.scene).finish()
    }
}

impl<'a, 'r, P: Profile> Frame<'a, 'r, P> {
    /// The frame's scene, as any still: its view, its accelerator, its
    /// picture traced whole (`scene().image(size)`).
    pub fn scene(&self) -> &LoadedScene<'r, P> {
        &self.scene
    }

    /// The frame's scene alone, to draw as a still.
    pub fn into_scene(self) -> LoadedScene<'r, P> {
        self.scene
    }

    /// Which frame it is, from 0.
    pub fn number(&self) -> u32 {
        self.playing.frame
    }

    /// The animation's frames.
    pub fn frames(&self) -> Frames {
        self.playing.motion.frames()
    }

    /// The tiles of the image, planned for this frame: which its draw
    /// traces ([`Coherence::traced_pixels`], [`Coherence::traced_areas`]).
    pub fn tiles(&self) -> &Coherence<'a> {
        &self.playing.coherence
    }

    /// The frame as an image (at the animation's size) in the colour `C`:
    /// its draw traces the planned tiles only, and after the frame before
    /// it in the loop (or at the first frame, everything) the target shows
    /// the frame as a whole draw would.
    pub fn image<C>(&self) -> TracedImage<'_, 'r, P, C, Bands> {
        let size = self.playing.coherence.size();
        TracedImage::new(self.scene.source(), size, Picture::whole(size, Some(self.playing)))
    }

    /// The frame as an image in `target`'s colour (at the animation's
    /// size, which should be the target's).
    pub fn image_for<D: DrawTarget>(&self, target: &D) -> TracedImage<'_, 'r, P, D::Color, Bands> {
        let _ = target;
        self.image()
    }

    /// What another core needs to draw bands of this frame.
    pub fn share(&self) -> SharedScene<'_, P, Bands> {
        self.scene.share().frame(self.playing)
    }
}

impl<'s> Animation<'s> {
    /// Loads frame `frame` of the animation `text` into `raytracer`. A
    /// scene it has not seen (another text, or an edited one) is recorded
    /// as the loader places it, every frame's camera checked, and every
    /// tile is traced; the scene it holds steps its tiles from the frame
    /// loaded last to this one (forward round the loop), so that the
    /// frame's draw traces only what can have changed since that frame was
    /// drawn. A still scene is an animation of one frame that never moves.
    pub fn load<'a, 'r, 't, P: Profile>(
        &'a mut self,
        raytracer: &'r mut Raytracer<P>,
        text: &'t str,
        frame: u32,
    ) -> Result<Frame<'a, 'r, P>, AnimationError<'t>> {
        self.load_in(raytracer, text.as_bytes(), frame, &mut |_| {}, &mut super::one_core, false)
    }

    /// [`Animation::load`] on two cores, the light buffer built on the
    /// other core while this one builds the octree, as
    /// [`Raytracer::load_on_two_cores`] does: a board playing an animation
    /// loads each frame so.
    pub fn load_on_two_cores<'a, 'r, 't, P: Profile>(
        &'a mut self,
        raytracer: &'r mut Raytracer<P>,
        text: &'t str,
        frame: u32,
        both: impl FnOnce(&mut (dyn FnMut() + Send), &mut dyn FnMut()),
    ) -> Result<Frame<'a, 'r, P>, AnimationError<'t>> {
        self.load_in(raytracer, text.as_bytes(), frame, &mut |_| {}, &mut super::once(both), false)
    }

    /// Loads frame 0 of `text` (bytes; invalid UTF-8 is an error at its
    /// place) anew, whatever it held, handing every error to `on_error`
    /// (a camera that cannot be set up at any frame among them), and traces
    /// every tile of it: a board's answer to a scene it was sent.
    pub fn load_with<'a, 'r, 't, P: Profile>(
        &'a mut self,
        raytracer: &'r mut Raytracer<P>,
        text: &'t [u8],
        on_error: &mut dyn FnMut(ParseError<'t>),
    ) -> Result<Frame<'a, 'r, P>, AnimationError<'t>> {
        self.load_in(raytracer, text, 0, on_error, &mut super::one_core, true)
    }

    /// Loads frame `frame`, recording the scene's motion if it is new (or
    /// `anew`).
    fn load_in<'a, 'r, 't, P: Profile>(
        &'a mut self,
        raytracer: &'r mut Raytracer<P>,
        text: &'t [u8],
        frame: u32,
        on_error: &mut dyn FnMut(ParseError<'t>),
        both: &mut RunBoth<'_>,
        anew: bool,
    ) -> Result<Frame<'a, 'r, P>, AnimationError<'t>> {
        let indexing = self.indexing();
        // A frame past the loop's end is its frame in the loop (a player
        // may count on): the scene and the tiles' state agree on it.
        let scene = if anew || !self.holds(text) {
            let (mut recorder, loop_length) = self.recorder(text).map_err(AnimationError::NoRoom)?;
            let frame = frame % loop_length;
            let scene = raytracer.load_in(text, frame, &indexing, on_error, both, Some(&mut recorder))?;
            let (fits, counts) = (recorder.fits(), (recorder.track_count, recorder.key_count));
            if !fits {
                // The room was checked against the text's needs: only a
                // text unlike any parse could need more.
                let (needs, room) = (AnimationNeeds { tiles: 0, tracks: counts.0, keys: counts.1 }, self.room());
                let short = needs.beyond(&room).into_iter().flatten().next();
                // Not fitting, one of the counts is over the room's.
                let keys = NoRoom { what: AnimationCapacity::Keys, needed: counts.1, holds: room.keys };
                return Err(AnimationError::NoRoom(short.unwrap_or(keys)));
            }
            let frames = scene.frames().unwrap_or(Frames { count: 1, rate: Frames::DEFAULT_RATE });
            self.recorded(text, frames, counts, frame);
            scene
        } else {
            let frame = frame % self.loop_length();
            let scene = raytracer.load_in(text, frame, &indexing, on_error, both, None)?;
            self.step_to(frame);
            scene
        };
        let animation: &'a Animation<'s> = self;
        Ok(Frame { scene, playing: animation.playing() })
    }
}

#[cfg(feature = "alloc")]
impl<P: Profile> Raytracer<P> {
    /// Whether every frame of the animation `text` (bytes; invalid UTF-8
    /// is an error at its place) loads, its camera included, each error
    /// handed to `on_error`: frame 0 loaded anew (this raytracer holds it
    /// after), its motion recorded in a room made for the check (an image
    /// of one pixel: no tile is traced). What a front-end checks before it
    /// draws a frame alone (a scene is valid or not whichever frame is
    /// drawn).
    ///
    /// ```
    /// use octrace_core::{profile::Board16K, AnimationError, Raytracer};
    ///
    /// let mut raytracer = Raytracer::<Board16K>::new();
    /// // The eye reaches the point it looks at in frame 2.
    /// let text = b"FRAMES 4\nVIEWPOINT 0 0 5 MOVE 0 0 0 0  2 0 0 -5\nORIGIN 0 0 0\n";
    /// let mut errors = Vec::new();
    /// let checked = raytracer.check_every_frame(text, &mut |e| errors.push(e.to_string()));
    /// assert!(matches!(checked, Err(AnimationError::Scene(_))));
    /// assert_eq!(errors, ["2:17: at frame 2, VIEWPOINT equals ORIGIN: there is no view direction"]);
    /// ```
    pub fn check_every_frame<'t>(
        &mut self,
        text: &'t [u8],
        on_error: &mut dyn FnMut(ParseError<'t>),
    ) -> Result<(), AnimationError<'t>> {
        let one = embedded_graphics_core::geometry::Size::new(1, 1);
        let needs =
            core::str::from_utf8(text).map_or_else(|_| AnimationNeeds::default(), |t| AnimationNeeds::of(t, one));
        let mut room = crate::animation::HostAnimationRoom::new(needs);
        let mut animation = room.animation(one).map_err(AnimationError::NoRoom)?;
        animation.load_with(self, text, on_error).map(|_| ())
    }
}

#[cfg(test)]
mod tests {
    extern crate std;
    use crate::animation::{AnimationCapacity, AnimationRoom, NoRoom};
    use crate::profile::Board16K;
    use crate::{AnimationError, Raytracer};
    use embedded_graphics_core::geometry::Size;
    use std::string::ToString;

    /// The eye moves onto the point looked at at frame 2.
    const BROKEN_LATER: &str = "FRAMES 4\nVIEWPOINT 0 0 5 MOVE 0 0 0 0  2 0 0 -5\nORIGIN 0 0 0\n\
                                SURFACE 1 .1 .1 .1 .7 .2 .2 0 0 0 1 0 0\nLIGHT 10 5 5 5\nSPHERE 1 1 0 0 3\n";

    #[test]
    fn a_camera_broken_at_a_later_frame_refuses_the_animation_at_its_first_load() {
        let mut room = AnimationRoom::<4, 1, 2>::new();
        let mut animation = room.animation(Size::new(8, 8)).unwrap();
        let mut raytracer = Raytracer::<Board16K>::new();
        // Frame 0 alone loads: its camera is sound.
        assert!(raytracer.load_frame(BROKEN_LATER, 0).is_ok());
        for frame in [0, 1] {
            let Err(AnimationError::Scene(e)) = animation.load(&mut raytracer, BROKEN_LATER, frame) else {
                panic!("frame {frame} loads");
            };
            assert_eq!((e.first.pos.line, e.first.pos.column, e.count), (2, 17, 1));
            assert_eq!(e.to_string(), "2:17: at frame 2, VIEWPOINT equals ORIGIN: there is no view direction");
        }
        // Frame 3 is broken too, and says so first.
        let Err(AnimationError::Scene(e)) = animation.load(&mut raytracer, BROKEN_LATER, 3) else { panic!("loads") };
        assert!(e.to_string().starts_with("2:17: at frame 3,"), "{e}");
        let mut errors = std::vec::Vec::new();
        assert!(animation.load_with(&mut raytracer, BROKEN_LATER.as_bytes(), &mut |e| errors.push(e)).is_err());
        assert_eq!(errors.len(), 1);
        // Up parallel to the view at frame 1, from straight above.
        let above = "FRAMES 3\nVIEWPOINT 0 0 5 MOVE 0 0 0 0  1 0 5 -5\nORIGIN 0 0 0\nUPVECTOR 0 1 0\n";
        let Err(AnimationError::Scene(e)) = animation.load(&mut raytracer, above, 0) else { panic!("it loads") };
        assert!(e.to_string().starts_with("2:17: at frame 1, UPVECTOR"), "{e}");
    }

    #[test]
    fn a_frame_past_the_loops_end_is_its_frame_in_the_loop() {
        use embedded_graphics::mock_display::MockDisplay;
        use embedded_graphics_core::pixelcolor::Rgb888;
        let text = "FRAMES 3\nSURFACE 1 .1 .1 .1 .7 .2 .2 0 0 0 1 0 0\nLIGHT 10 5 5 5\n\
                    SPHERE 1 1 0 0 0\nSPHERE 1 0.5 -2 0 1 MOVE 0 0 0 0  2 4 0 0\n";
        let mut room = AnimationRoom::<4, 1, 2>::new();
        let mut animation = room.animation(Size::new(8, 8)).unwrap();
        let mut raytracer = Raytracer::<Board16K>::new();
        let mut shown = MockDisplay::<Rgb888>::new();
        shown.set_allow_overdraw(true);
        // Counted on past the end, as a player may, and first loaded there.
        for frame in [4, 5, 6, 7, 8, 9, 10] {
            let loaded = animation.load(&mut raytracer, text, frame).unwrap();
            assert_eq!(loaded.number(), frame % 3);
            loaded.image().try_draw(&mut shown).unwrap();
            let mut still = MockDisplay::<Rgb888>::new();
            let mut alone = Raytracer::<Board16K>::new();
            alone.load_frame(text, frame % 3).unwrap().image(Size::new(8, 8)).try_draw(&mut still).unwrap();
            assert_eq!(shown, still, "frame {frame}: the tiles traced are the frame's");
        }
    }

    #[test]
    fn an_animation_its_room_cannot_hold_is_refused_naming_what_runs_out() {
        let text = "FRAMES 4\nSURFACE 1 .1 .1 .1 .7 .2 .2 0 0 0 1 0 0\nLIGHT 10 5 5 5 MOVE 0 0 0 0  3 1 0 0\n\
                    SPHERE 1 1 0 0 0 MOVE 0 0 0 0  1 1 1 1  3 0 0 0\n";
        let mut raytracer = Raytracer::<Board16K>::new();
        let mut room = AnimationRoom::<4, 2, 4>::new();
        let mut animation = room.animation(Size::new(8, 8)).unwrap();
        let Err(AnimationError::NoRoom(short)) = animation.load(&mut raytracer, text, 0) else { panic!("room") };
        assert_eq!(short, NoRoom { what: AnimationCapacity::Keys, needed: 5, holds: 4 });
        assert_eq!(
            short.to_string(),
            "too many MOVE keys to play this animation: this build's room for it (keys) holds 4 and the scene needs 5"
        );
        let mut room = AnimationRoom::<3, 2, 5>::new();
        let e = room.animation(Size::new(8, 8)).unwrap_err();
        assert_eq!(e, NoRoom { what: AnimationCapacity::Tiles, needed: 4, holds: 3 });
        let mut room = AnimationRoom::<4, 2, 5>::new();
        assert!(room.animation(Size::new(8, 8)).unwrap().load(&mut raytracer, text, 2).is_ok());
    }
}
