//! The studio's player: an animation's frames traced one after another into
//! an image it keeps, each re-tracing only the tiles the motion can have
//! changed since the frame traced before it (the core's
//! [`Animation`](octrace_core::animation::Animation), whose room it keeps
//! between calls).
//!
//! Invariants: `colours` and `objects` hold the frame the animation in
//! `room` was last loaded at, of its text, at `size`, bit for bit the frame
//! traced whole (nothing is kept while a frame is half traced); another
//! text, an edited one, or another size starts again from every tile.

use embedded_graphics_core::geometry::Size;
use octrace_core::animation::{AnimationNeeds, HostAnimationRoom};
use octrace_core::profile::Host;
use octrace_core::{AccelMode, AnimationError, Raytracer};
use octrace_images::{SampleImage, NO_OBJECT};

/// What a trace of a frame could not do, said as the studio says it.
#[derive(Debug)]
pub(crate) enum Refused {
    /// The scene has errors (a camera that cannot be set up at some frame
    /// among them), each `line:col: message`.
    Scene(Vec<String>),
    /// The camera cannot be set up, or the animation's room made: why.
    Setup(String),
}

/// The last frame traced, and the animation's room between frames.
#[derive(Default)]
pub(crate) struct Player {
    room: Option<HostAnimationRoom>,
    size: (u32, u32),
    /// The image is the last frame loaded, whole.
    whole: bool,
    colours: Vec<u8>,
    objects: Vec<u32>,
    /// The text whose every frame was checked last, and what was found.
    checked: Option<Checked>,
}

/// A text whose every frame was checked, and its errors (none: it loads).
struct Checked {
    text: Vec<u8>,
    errors: Result<(), Vec<String>>,
}

impl Player {
    /// Whether every frame of `text` loads (its camera included): errors
    /// at line and column; a text checked before is not loaded again.
    /// Leaves `raytracer` holding frame 0 when it loads it.
    pub(crate) fn check(&mut self, raytracer: &mut Raytracer<Host>, text: &[u8]) -> Result<(), Vec<String>> {
        if let Some(checked) = self.checked.as_ref().filter(|checked| checked.text == text) {
            return checked.errors.clone();
        }
        let mut errors = Vec::new();
        let result = match raytracer.check_every_frame(text, &mut |e| errors.push(e.to_string())) {
            Ok(()) => Ok(()),
            Err(AnimationError::Scene(_)) => Err(errors),
            Err(AnimationError::NoRoom(e)) => Err(vec![e.to_string()]),
        };
        self.checked = Some(Checked { text: text.to_vec(), errors: result.clone() });
        result
    }

    /// Traces frame `frame` of `text` at `size`, its scenes loaded into
    /// `raytracer` and indexed by `accel`, into the image kept: only the
    /// tiles whose count ran out on the way from the frame traced last
    /// (every tile for another text or size). Returns how many pixels it
    /// traced.
    pub(crate) fn trace(
        &mut self,
        raytracer: &mut Raytracer<Host>,
        (text, frame): (&str, u32),
        accel: AccelMode,
        size: (u32, u32),
    ) -> Result<u64, Refused> {
        let (w, h) = size;
        let image = Size::new(w, h);
        let needs = AnimationNeeds::of(text, image);
        let fits = self.room.as_ref().is_some_and(|room| needs.beyond(&room.room()).iter().all(Option::is_none));
        if !fits || self.size != size {
            self.room = Some(HostAnimationRoom::new(needs));
            self.size = size;
            self.colours = vec![0; 3 * w as usize * h as usize];
            self.objects = vec![NO_OBJECT; w as usize * h as usize];
        }
        // Nothing is shown until this frame is traced whole.
        self.whole = false;
        let Some(room) = self.room.as_mut() else { return Err(Refused::Setup("no room".into())) };
        let animation = room.animation(image).map_err(|e| Refused::Setup(e.to_string()))?;
        let mut animation = animation.indexed(accel);
        let loaded = animation.load(raytracer, text, frame).map_err(|e| match e {
            AnimationError::Scene(e) => Refused::Scene(vec![e.to_string()]),
            AnimationError::NoRoom(e) => Refused::Setup(e.to_string()),
        })?;
        let traced = loaded.tiles().traced_pixels();
        let mut kept = SampleImage { colours: &mut self.colours, objects: &mut self.objects, size: image };
        loaded.image().try_draw(&mut kept).map_err(|e| Refused::Setup(e.to_string()))?;
        self.whole = true;
        Ok(traced)
    }

    /// The image kept, as [`crate::Studio::render_rect`] writes one: its
    /// colours, then the object under each pixel.
    pub(crate) fn write(&self, out: &mut Vec<u8>) {
        out.clear();
        if self.whole {
            out.extend_from_slice(&self.colours);
            out.extend(self.objects.iter().flat_map(|o| o.to_le_bytes()));
        }
    }
}
