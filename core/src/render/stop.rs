//! Stopping a render inside a pixel: the caller's [`Stop`], asked before
//! every ray (primary, reflected, transmitted and shadow rays) and before
//! each object of the screen lists' set-up, so that even a pixel whose ray
//! tree takes hours ends within one ray of the ask.
//!
//! Invariants: a pixel either completes with exactly the bits it has
//! without a `Stop`, or gives [`Stopped`] and nothing of it is drawn; a
//! caller that asks for no `Stop` runs the render path without any of it
//! (`shade::Unpolled`: the same code as before `Stop` existed).

use crate::shade::Poll;
use core::fmt;

/// What a caller asks a render whether to stop by, before every ray
/// ([`Renderer::pixel_until`]): any `FnMut() -> bool` is one, true to stop.
/// Asked that often, it must be cheap: the dearest ray of the largest
/// scene a Pico holds takes it about 15 ms, an ordinary one some ten
/// microseconds, so a board reads its clock and looks at its serial line
/// once a millisecond at most (octrace-link's `board::Rows::poll` does).
/// It may do a board's chores when it looks (feed a watchdog); it is asked
/// from inside a pixel, on the rendering core.
///
/// [`Renderer::pixel_until`]: super::Renderer::pixel_until
pub trait Stop {
    /// Whether the render stops before its next ray.
    fn stop(&mut self) -> bool;
}

impl<F: FnMut() -> bool> Stop for F {
    #[inline]
    fn stop(&mut self) -> bool {
        self()
    }
}

/// A pixel was stopped before it was complete, because its [`Stop`] said
/// so: nothing of it is drawn.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Stopped;

impl fmt::Display for Stopped {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str("the render was stopped before the pixel was complete")
    }
}

impl core::error::Error for Stopped {}

/// Why a draw ended before its picture did: its target's error, or its
/// poll said stop.
pub(crate) enum Halt<E, S> {
    Sink(E),
    Stopped(S),
}

/// A [`Stop`] asked before each ray, until it says stop.
pub(crate) struct Polling<'s, S> {
    pub(crate) stop: &'s mut S,
    pub(crate) stopped: bool,
}

impl<S: Stop> Poll for Polling<'_, S> {
    type Stopped = Stopped;

    #[inline]
    fn go_on(&mut self) -> bool {
        self.stopped = self.stopped || self.stop.stop();
        !self.stopped
    }

    fn stopped(&self) -> Result<(), Stopped> {
        match self.stopped {
            true => Err(Stopped),
            false => Ok(()),
        }
    }
}

#[cfg(test)]
mod tests {
    extern crate std;
    use super::*;

    #[test]
    fn a_stop_is_asked_before_every_ray_and_a_true_stops_the_next_for_good() {
        let mut asked = 0;
        let mut stop = || {
            asked += 1;
            asked == 3
        };
        let mut polling = Polling { stop: &mut stop, stopped: false };
        let mut traced = 0;
        while polling.go_on() {
            traced += 1;
        }
        assert_eq!(polling.stopped(), Err(Stopped));
        assert!(!polling.go_on(), "stopped for good");
        assert_eq!(traced, 2, "asked before rays 1, 2 and 3: the third says stop");
        assert_eq!(std::format!("{Stopped}"), "the render was stopped before the pixel was complete");
    }

    #[test]
    fn pixels_stopped_anywhere_and_asked_again_are_the_unstopped_bits() {
        use crate::profile::Board64K;
        use crate::render::Renderer;
        use crate::Raytracer;
        // Samples, two lights, a mirror and glass: stops fall in every
        // kind of ray, between samples and inside ray trees.
        let text = "SAMPLES 2 RDEPTH 4 LIGHT 10 5 5 5 LIGHT 5 -5 5 5\n\
                    SPHERE 1 1 0 0 0 SPHERE 2 0.6 1.2 0.5 1 RECTANGLE 3 -4 -1 -4 4 -1 -4 4 -1 4 -4 -1 4\n\
                    SURFACE 1 .1 .1 .1 .5 .2 .2 .3 .3 .3 10 0.4 0\n\
                    SURFACE 2 .1 .1 .1 .2 .5 .2 0 0 0 1 0.2 0.6\n\
                    SURFACE 3 .2 .2 .2 .5 .5 .5 0 0 0 1 0.3 0\n";
        let mut raytracer = Raytracer::<Board64K>::new();
        let scene = raytracer.load(text).unwrap();
        let accelerator = scene.accelerator();
        let (w, h) = (12, 10);
        let mut plain = Renderer::with_size(scene.view(), &accelerator, w, h).unwrap();
        let mut stopped = Renderer::with_size(scene.view(), &accelerator, w, h).unwrap();
        let mut next = crate::test_rng::seeded(0x5709_u64);
        let mut stops = 0;
        for y in 0..h {
            for x in 0..w {
                let want = plain.pixel(x, y);
                // Stopped at a random ask (if it has that many rays), then
                // asked again to the end.
                let mut asks = next() % 5;
                let mut stop = || match asks {
                    0 => true,
                    _ => {
                        asks -= 1;
                        false
                    }
                };
                let got = match stopped.pixel_until(x, y, &mut stop) {
                    Ok(pixel) => pixel,
                    Err(Stopped) => {
                        stops += 1;
                        stopped.pixel_until(x, y, &mut || false).unwrap()
                    }
                };
                assert_eq!(got, want, "pixel ({x}, {y})");
            }
        }
        assert!(stops >= 30, "{stops} stops");
    }
}
