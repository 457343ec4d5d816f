//! The scene format's vocabulary: one enum of statement keywords, from which
//! statement matching, the once-only parameters and the unknown-keyword
//! message all derive.
//!
//! Invariant: the enum, the spellings and [`Keyword::ALL`] come from the one
//! list in `keywords!`, so they cannot drift apart; discriminants are the
//! default ones, so `k as usize` indexes a `[_; Keyword::COUNT]` table.

use core::fmt;

/// Declares [`Keyword`], its spelling and [`Keyword::ALL`] from one list, so
/// a keyword cannot be added to one and missed in another.
macro_rules! keywords {
    ($($(#[$doc:meta])* $variant:ident = $text:literal,)*) => {
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
        }
    };
}

keywords! {
    Viewpoint = "VIEWPOINT",
    Origin = "ORIGIN",
    Upvector = "UPVECTOR",
    Raster = "RASTER",
    Viewport = "VIEWPORT",
    Rdepth = "RDEPTH",
    Imagefile = "IMAGEFILE",
    Light = "LIGHT",
    Background = "BACKGROUND",
    Gamma = "GAMMA",
    Attenuation = "ATTENUATION",
    Samples = "SAMPLES",
    Sphere = "SPHERE",
    Box = "BOX",
    Superquadric = "SUPERQUADRIC",
    Triangle = "TRIANGLE",
    Rectangle = "RECTANGLE",
    Bspline = "BSPLINE",
    Surface = "SURFACE",
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
            | Keyword::Samples => true,
            Keyword::Light
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
        assert!(listed.ends_with(", BSPLINE or SURFACE"), "{listed}");
        let words: std::vec::Vec<&str> = listed.split([',', ' ']).filter(|w| !w.is_empty() && *w != "or").collect();
        assert_eq!(words, Keyword::ALL.map(Keyword::name));
    }
}
