//! Which picture a [`TracedImage`](super::TracedImage) draws, as a type:
//! its options change the image's type, so that a firmware links the
//! drawing of only the pictures it asks for (a two-core board's areas, a
//! frame's bands), once for each display it draws into.
//!
//! ```
//! use embedded_graphics::{pixelcolor::Rgb565, prelude::*, primitives::Rectangle};
//! use octrace_core::picture::{Areas, Still};
//! use octrace_core::{profile::Board16K, Raytracer, TracedImage};
//!
//! let mut raytracer = Raytracer::<Board16K>::new();
//! let scene = raytracer.load("BACKGROUND 0 0 1\n")?;
//! let still: TracedImage<'_, '_, Board16K, Rgb565, Still> = scene.image(Size::new(4, 2));
//! let next = || None::<Rectangle>;
//! // A draw of `areas` links the areas' loop alone.
//! let areas: TracedImage<'_, '_, Board16K, Rgb565, Areas> = still.areas(&next);
//! # let _ = areas;
//! # Ok::<(), Box<dyn core::error::Error>>(())
//! ```
//!
//! Invariants: an image's picture type and what it draws are set
//! together, by the scene's or frame's `image` and the options alone.

/// What a [`TracedImage`](super::TracedImage) draws: [`Still`] (the
/// whole picture or an area of it), [`Areas`], [`InOrder`] (the
/// progressive order) or a frame's [`Bands`]. Sealed: only these four.
pub trait Picture: sealed::Sealed {}

/// A still: the whole picture, or an [`area`](super::TracedImage::area)
/// of it. What [`LoadedScene::image`](super::LoadedScene::image) draws.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Still;

/// A still's areas, one after another
/// ([`TracedImage::areas`](super::TracedImage::areas)).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Areas;

/// A still in the progressive order
/// ([`TracedImage::progressive`](super::TracedImage::progressive)).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct InOrder;

/// A frame's tiles: every band of them, or the
/// [`bands`](super::TracedImage::bands) a core takes. What
/// [`Frame::image`](super::Frame::image) draws.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Bands;

impl Picture for Still {}
impl Picture for Areas {}
impl Picture for InOrder {}
impl Picture for Bands {}

pub(super) mod sealed {
    /// The pictures, as a value a draw matches on: a constant for each
    /// type, so that the compiler drops the others' code.
    #[derive(Clone, Copy, PartialEq, Eq, Debug)]
    pub enum Kind {
        Still,
        Areas,
        InOrder,
        Bands,
    }

    pub trait Sealed {
        const KIND: Kind;
    }

    impl Sealed for super::Still {
        const KIND: Kind = Kind::Still;
    }

    impl Sealed for super::Areas {
        const KIND: Kind = Kind::Areas;
    }

    impl Sealed for super::InOrder {
        const KIND: Kind = Kind::InOrder;
    }

    impl Sealed for super::Bands {
        const KIND: Kind = Kind::Bands;
    }
}
