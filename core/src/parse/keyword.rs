//! The scene format's vocabulary: one enum of statement keywords, from which
//! statement matching, the once-only parameters, the unknown-keyword message
//! and the arities editors read ([`super::statement_arities`]) all derive.
//!
//! Invariant: the enum, the spellings, the arities and [`Keyword::ALL`] come
//! from the one list in `keywords!`, so they cannot drift apart (a test
//! checks each arity against what its statement reads); discriminants are the
//! default ones, so `k as usize` indexes a `[_; Keyword::COUNT]` table.

use core::fmt;

/// Declares [`Keyword`], its spelling, its arity and [`Keyword::ALL`] from
/// one list, so a keyword cannot be added to one and missed in another.
macro_rules! keywords {
    ($($(#[$doc:meta])* $variant:ident = $text:literal / $arity:literal,)*) => {
        /// A statement keyword of the scene format.
        #[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
        pub(crate) enum Keyword {
            $($(#[$doc])* $variant,)*
        }

        impl Keyword {
            /// Every keyword, in the format's order.
            pub(crate) const ALL: [Keyword; [$(Keyword::$variant),*].len()] = [$(Keyword::$variant),*];

            /// The keyword as the format writes it (upper case).
            pub(crate) const fn name(self) -> &'static str {
                match self {
                    $(Keyword::$variant => $text,)*
                }
            }

            /// How many arguments follow the keyword; for `BSPLINE`, those
            /// before its 3 × rows × cols control point coordinates; for
            /// `FRAMES` and `MOVE`, the fewest (a rate may follow; more
            /// keys may follow).
            pub(crate) const fn arity(self) -> usize {
                match self {
                    $(Keyword::$variant => $arity,)*
                }
            }
        }
    };
}

/// A set of keywords, a bit each.
#[derive(Clone, Copy, Default)]
pub(crate) struct KeywordSet(u32);

impl KeywordSet {
    pub(crate) fn insert(&mut self, keyword: Keyword) {
        self.0 |= 1 << keyword as u32;
    }

    pub(crate) fn contains(self, keyword: Keyword) -> bool {
        self.0 & 1 << keyword as u32 != 0
    }
}

// Every keyword has its bit.
const _: () = assert!(Keyword::COUNT <= 32);

keywords! {
    Viewpoint = "VIEWPOINT" / 3,
    Origin = "ORIGIN" / 3,
    Upvector = "UPVECTOR" / 3,
    Raster = "RASTER" / 2,
    Viewport = "VIEWPORT" / 2,
    Rdepth = "RDEPTH" / 1,
    Imagefile = "IMAGEFILE" / 1,
    Light = "LIGHT" / 4,
    Background = "BACKGROUND" / 3,
    Gamma = "GAMMA" / 1,
    Attenuation = "ATTENUATION" / 1,
    Samples = "SAMPLES" / 1,
    Sphere = "SPHERE" / 5,
    Box = "BOX" / 7,
    Superquadric = "SUPERQUADRIC" / 8,
    Triangle = "TRIANGLE" / 10,
    Rectangle = "RECTANGLE" / 13,
    Bspline = "BSPLINE" / 6,
    Surface = "SURFACE" / 13,
    Frames = "FRAMES" / 1,
    Move = "MOVE" / 4,
}

impl Keyword {
    /// How many keywords there are (the length of a table indexed by one).
    pub(crate) const COUNT: usize = Keyword::ALL.len();

    /// The keyword `text` spells, ignoring ASCII case.
    pub(crate) fn from_text(text: &str) -> Option<Keyword> {
        Keyword::ALL.into_iter().find(|k| k.name().eq_ignore_ascii_case(text))
    }

    /// Whether the statement sets a scene parameter, which a scene may give
    /// at most once; the other statements add objects, lights or surfaces.
    pub(crate) const fn once_only(self) -> bool {
        match self {
            Keyword::Viewpoint
            | Keyword::Origin
            | Keyword::Upvector
            | Keyword::Raster
            | Keyword::Viewport
            | Keyword::Rdepth
            | Keyword::Imagefile
            | Keyword::Background
            | Keyword::Gamma
            | Keyword::Attenuation
            | Keyword::Samples
            | Keyword::Frames => true,
            Keyword::Light
            | Keyword::Move
            | Keyword::Sphere
            | Keyword::Box
            | Keyword::Superquadric
            | Keyword::Triangle
            | Keyword::Rectangle
            | Keyword::Bspline
            | Keyword::Surface => false,
        }
    }
}

impl fmt::Display for Keyword {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

/// Every keyword, as a message lists them: "A, B, … or Z".
pub(crate) struct Listed;

impl fmt::Display for Listed {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let last = Keyword::COUNT - 1;
        for (i, k) in Keyword::ALL.into_iter().enumerate() {
            let separator = match i {
                0 => "",
                _ if i == last => " or ",
                _ => ", ",
            };
            write!(f, "{separator}{k}")?;
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    extern crate std;
    use super::*;
    use std::string::ToString;

    #[test]
    fn arities_are_what_the_statements_read() {
        use super::super::statement::{statement, Cursor};
        // A valid statement of each keyword, its BSPLINE of 2 × 2 points.
        let samples = [
            "VIEWPOINT 0 0 5",
            "ORIGIN 0 0 0",
            "UPVECTOR 0 1 0",
            "RASTER 16 12",
            "VIEWPORT 4 3",
            "RDEPTH 2",
            "IMAGEFILE out.png",
            "LIGHT 1 3 3 3",
            "BACKGROUND 0 0 1",
            "GAMMA 2.2",
            "ATTENUATION 1",
            "SAMPLES 4",
            "SPHERE 1 1 0 0 0",
            "BOX 1 0 0 0 1 1 1",
            "SUPERQUADRIC 1 4 0 0 0 1 1 1",
            "TRIANGLE 1 0 0 0 1 0 0 0 1 0",
            "RECTANGLE 1 0 0 0 1 0 0 1 1 0 0 1 0",
            "BSPLINE 1 2 2 2 4 4 0 0 0 1 0 0 0 1 0 1 1 0",
            "SURFACE 1 0.1 0.1 0.1 0.8 0.2 0.2 0.5 0.5 0.5 20 0 0",
            "FRAMES 48",
            "MOVE 0 1 2 3",
        ];
        assert_eq!(samples.len(), Keyword::COUNT);
        for (keyword, sample) in Keyword::ALL.into_iter().zip(samples) {
            let mut cursor = Cursor::new(sample);
            let first = cursor.next().unwrap().unwrap();
            assert_eq!(Keyword::from_text(first.text), Some(keyword), "{sample}");
            statement::<super::super::AnyRoom>(&mut cursor, keyword, first.pos).unwrap();
            assert!(cursor.next().unwrap().is_none(), "{sample}: the statement ends at its last token");
            let points = if keyword == Keyword::Bspline { 3 * 2 * 2 } else { 0 };
            assert_eq!(sample.split_whitespace().count(), 1 + keyword.arity() + points, "{sample}");
        }
    }

    #[test]
    fn matching_ignores_case_and_nothing_else() {
        assert_eq!(Keyword::from_text("sphere"), Some(Keyword::Sphere));
        assert_eq!(Keyword::from_text("SuperQuadric"), Some(Keyword::Superquadric));
        assert_eq!(Keyword::from_text("SPHERES"), None);
        assert_eq!(Keyword::from_text("SPHER"), None);
        assert_eq!(Keyword::from_text(""), None);
        // A non-ASCII letter that upper-cases to ASCII is not a keyword.
        assert_eq!(Keyword::from_text("\u{17f}PHERE"), None);
        for k in Keyword::ALL {
            assert_eq!(Keyword::from_text(k.name()), Some(k));
            assert_eq!(Keyword::from_text(&k.name().to_ascii_lowercase()), Some(k));
        }
    }

    #[test]
    fn the_list_names_every_keyword_once() {
        let listed = Listed.to_string();
        assert!(listed.starts_with("VIEWPOINT, ORIGIN, "), "{listed}");
        assert!(listed.ends_with(", SURFACE, FRAMES or MOVE"), "{listed}");
        let words: std::vec::Vec<&str> = listed.split([',', ' ']).filter(|w| !w.is_empty() && *w != "or").collect();
        assert_eq!(words, Keyword::ALL.map(Keyword::name));
    }
}
