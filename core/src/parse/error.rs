//! Scene errors: where (line and column) and what, with the offending text
//! borrowed from the scene (no allocation).
//!
//! `Display` writes `line:col: message`; a caller that knows the file name
//! puts it in front (`fig5_3.txt:41:12: SPHERE radius must be > 0, found -1`).

use super::keyword::Listed;
use crate::capacity::CapacityError;
use crate::scene::CameraError;
use core::fmt;

/// A position in the scene text: line and column (in characters), from 1.
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub struct Pos {
    /// The line, from 1.
    pub line: u32,
    /// The column in characters (not bytes), from 1.
    pub column: u32,
}

/// A parameter of a statement, as the messages name it ("SPHERE radius").
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Field {
    /// The statement's keyword ("SPHERE").
    pub statement: &'static str,
    /// The parameter as the scene format names it ("radius").
    pub name: &'static str,
}

impl fmt::Display for Field {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{} {}", self.statement, self.name)
    }
}

/// What a token was found instead of the expected one.
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Found<'a> {
    /// This word of the scene text.
    Token(&'a str),
    /// This quoted string (without its quotes): text where a number was
    /// expected, however much it looks like one.
    Quoted(&'a str),
    /// The text ended before the statement did.
    EndOfFile,
}

impl fmt::Display for Found<'_> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Found::Token(t) => write!(f, "`{}`", Shown(t)),
            Found::Quoted(t) => write!(f, "`\"{}\"` (a quoted name, not a number)", Shown(t)),
            Found::EndOfFile => f.write_str("the end of the file"),
        }
    }
}

/// Whether a message shows `c` as its Unicode escape (`\u{202e}`) rather
/// than as itself: the control characters, with which text could move a
/// terminal's cursor, recolour it or fake a line, and the invisible ones
/// that reorder or hide the text around them (the bidirectional controls,
/// the zero-width characters, the byte-order mark), with which it could
/// show one name and hold another.
///
/// ```
/// use octrace_core::parse::escaped_in_messages;
///
/// assert!(escaped_in_messages('\u{1b}')); // an escape sequence's start
/// assert!(escaped_in_messages('\u{202e}')); // right-to-left override
/// assert!(escaped_in_messages('\u{feff}')); // byte-order mark
/// assert!(!escaped_in_messages('é'));
/// ```
pub fn escaped_in_messages(c: char) -> bool {
    c.is_control()
        || matches!(
            c,
            '\u{ad}'
                | '\u{61c}'
                | '\u{180e}'
                | '\u{200b}'..='\u{200f}'
                | '\u{202a}'..='\u{202e}'
                | '\u{2060}'..='\u{2064}'
                | '\u{2066}'..='\u{206f}'
                | '\u{feff}'
                | '\u{fff9}'..='\u{fffb}'
        )
}

/// Scene text as a message shows it: the characters
/// [`escaped_in_messages`] names escaped (a scene must not be able to send
/// escape sequences to a terminal) and at most [`Shown::LIMIT`]
/// characters, with the length of the rest.
pub struct Shown<'a>(pub &'a str);

impl Shown<'_> {
    pub const LIMIT: usize = 40;
}

impl fmt::Display for Shown<'_> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        for c in self.0.chars().take(Self::LIMIT) {
            if escaped_in_messages(c) {
                write!(f, "{}", c.escape_unicode())?;
            } else {
                write!(f, "{c}")?;
            }
        }
        let total = self.0.chars().count();
        if total > Self::LIMIT {
            write!(f, "… ({total} characters)")?;
        }
        Ok(())
    }
}

/// The range a value must lie in.
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Rule {
    /// > 0
    Positive,
    /// ≥ 0
    NonNegative,
    /// 0 to 1
    UnitInterval,
    /// An integer from `.0` to `.1`.
    Between(i64, i64),
    /// A real number from `.0` to `.1`.
    BetweenReal(i64, i64),
    /// > 0, for a positive value so small that it reads as 0.
    AboveResolution,
    /// Magnitude at most 10^6 (every number).
    Magnitude,
}

impl fmt::Display for Rule {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Rule::Positive => f.write_str("> 0"),
            Rule::NonNegative => f.write_str(">= 0"),
            Rule::UnitInterval => f.write_str("between 0 and 1"),
            Rule::Between(a, b) => write!(f, "an integer from {a} to {b}"),
            Rule::BetweenReal(a, b) => write!(f, "between {a} and {b}"),
            Rule::AboveResolution => f.write_str("at least 2^-32 (smaller positive values read as 0)"),
            Rule::Magnitude => f.write_str("at most 1e6 in magnitude"),
        }
    }
}

#[cfg_attr(feature = "defmt", derive(defmt::Format))]
/// What is wrong, with the text it concerns borrowed from the scene; its
/// `Display` is the message without the position.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ErrorKind<'a> {
    /// The scene is not valid UTF-8 (the position is the first bad byte).
    InvalidUtf8,
    /// A `/*` that is never closed (the position is where it opened).
    UnterminatedComment,
    /// A `"` that is never closed.
    UnterminatedString,
    /// A word where a statement should start that is no keyword.
    UnknownKeyword(&'a str),
    /// A parameter that is not a number.
    ExpectedNumber {
        /// The parameter.
        field: Field,
        /// What stood in its place.
        found: Found<'a>,
    },
    /// A parameter that must be a whole number and is not.
    ExpectedInteger {
        /// The parameter.
        field: Field,
        /// What stood in its place.
        found: Found<'a>,
    },
    /// A name (IMAGEFILE's) missing at the end of the text.
    ExpectedName {
        /// The parameter.
        field: Field,
    },
    /// A number outside the range its parameter allows.
    OutOfRange {
        /// The parameter.
        field: Field,
        /// The range it must lie in.
        rule: Rule,
        /// The number as written.
        found: &'a str,
    },
    /// A scene parameter given twice.
    Repeated {
        /// The parameter's keyword.
        keyword: &'static str,
        /// Where it was first given.
        first_line: u32,
    },
    /// Two SURFACE statements with one number.
    SurfaceRepeated {
        /// The surface's number.
        number: u32,
        /// Where it was first defined.
        first_line: u32,
    },
    /// An object whose surface is defined nowhere in the scene.
    UndefinedSurface {
        /// The object's keyword.
        keyword: &'static str,
        /// The missing surface's number.
        number: u32,
    },
    /// A shape with no area or volume: `why` says how.
    Degenerate {
        /// The shape's keyword.
        keyword: &'static str,
        /// How it is degenerate.
        why: &'static str,
    },
    /// A RECTANGLE whose fourth corner is off the plane of the others.
    NotPlanar,
    /// A RECTANGLE whose corners do not all turn the same way.
    NotConvex,
    /// A B-spline with fewer control points along a side than its order.
    TooFewControlPoints {
        /// The B-spline's order.
        order: u32,
        /// Control points down.
        rows: u32,
        /// Control points across.
        cols: u32,
    },
    /// A shape that rounds to nothing at the scale the whole scene needs.
    TooSmall {
        /// The shape's keyword.
        keyword: &'static str,
    },
    /// VIEWPOINT equals ORIGIN ([`CameraError::EyeAtOrigin`]).
    EyeAtOrigin,
    /// UPVECTOR is zero or along the view ([`CameraError::UpParallel`]).
    UpParallel,
    /// The scene needs more of something than the profile holds.
    Capacity(CapacityError),
    /// A MOVE in a scene that has no FRAMES.
    MoveWithoutFrames,
    /// A MOVE that does not follow an object, LIGHT, VIEWPOINT or ORIGIN
    /// statement: it follows `after` (`None`: nothing; `MOVE`: another MOVE).
    NothingToMove {
        /// The keyword of the statement before it.
        after: Option<&'static str>,
    },
    /// A MOVE key whose frame is not after the key before it.
    FramesOutOfOrder {
        /// The key's frame.
        frame: u32,
        /// The frame of the key before it.
        previous: u32,
    },
    /// A MOVE key at a frame the animation does not have.
    FrameBeyond {
        /// The key's frame.
        frame: u32,
        /// The animation's frames (FRAMES count).
        count: u32,
    },
    /// A MOVE that takes a coordinate of its statement beyond 10^6 in
    /// magnitude.
    MovedOutOfRange {
        /// The moved statement's keyword.
        keyword: &'static str,
        /// The key's frame.
        frame: u32,
    },
    /// A MOVE of VIEWPOINT or ORIGIN that leaves no camera at `frame`.
    MovedCamera {
        /// What is wrong with the camera.
        error: CameraError,
        /// The frame loaded.
        frame: u32,
    },
    /// A MOVE in a build whose profile holds no motion.
    NoMotion {
        /// The profile's name.
        profile: &'static str,
    },
}

/// One error in a scene.
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ParseError<'a> {
    /// Where the error is: the start of the offending word, or of the
    /// statement when the whole statement is wrong.
    pub pos: Pos,
    /// What is wrong.
    pub kind: ErrorKind<'a>,
}

impl<'a> ParseError<'a> {
    /// The error `kind` at `pos`.
    pub fn new(pos: Pos, kind: ErrorKind<'a>) -> ParseError<'a> {
        ParseError { pos, kind }
    }
}

impl fmt::Display for ErrorKind<'_> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            ErrorKind::InvalidUtf8 => f.write_str("the file is not valid UTF-8 (invalid byte here)"),
            ErrorKind::UnterminatedComment => f.write_str("unterminated comment: this `/*` is never closed"),
            ErrorKind::UnterminatedString => f.write_str("unterminated string: this `\"` is never closed"),
            // A number where a statement begins: most often one too many
            // for the statement before it.
            ErrorKind::UnknownKeyword(k) if super::number::Decimal::parse(k).is_some() => {
                write!(
                    f,
                    "expected a statement's keyword, found the number `{}`, one too many for the statement before it",
                    Shown(k)
                )
            }
            ErrorKind::UnknownKeyword(k) => {
                write!(f, "unknown keyword `{}`: expected a statement ({})", Shown(k), Listed)
            }
            ErrorKind::ExpectedNumber { field, found } => {
                write!(f, "expected a number for {field}, found {found}")
            }
            ErrorKind::ExpectedInteger { field, found } => {
                write!(f, "expected an integer for {field}, found {found}")
            }
            ErrorKind::ExpectedName { field } => write!(f, "expected {field}, found the end of the file"),
            ErrorKind::OutOfRange { field, rule, found } => write!(f, "{field} must be {rule}, found {}", Shown(found)),
            ErrorKind::Repeated { keyword, first_line } => {
                write!(f, "{keyword} is given twice (first on line {first_line})")
            }
            ErrorKind::SurfaceRepeated { number, first_line } => {
                write!(f, "SURFACE {number} is defined twice (first on line {first_line})")
            }
            ErrorKind::UndefinedSurface { keyword, number } => {
                write!(f, "{keyword} uses surface {number}, which is never defined")
            }
            ErrorKind::Degenerate { keyword, why } => write!(f, "{keyword} is degenerate: {why}"),
            ErrorKind::NotPlanar => {
                f.write_str("RECTANGLE is not planar: its fourth corner is off the plane of the other three")
            }
            ErrorKind::NotConvex => f.write_str(
                "RECTANGLE is not convex: its corners must turn the same way (counter-clockwise seen from the front)",
            ),
            ErrorKind::TooFewControlPoints { order, rows, cols } => write!(
                f,
                "BSPLINE of order {order} needs at least {order} control points along each side, found {rows} × {cols}"
            ),
            ErrorKind::TooSmall { keyword } => write!(
                f,
                "{keyword} is too small to represent next to the rest of the scene \
                 (sizes below about 2^-29 of the scene's extent round to 0 in fixed point)"
            ),
            ErrorKind::EyeAtOrigin => CameraError::EyeAtOrigin.fmt(f),
            ErrorKind::UpParallel => CameraError::UpParallel.fmt(f),
            ErrorKind::Capacity(c) => c.fmt(f),
            ErrorKind::MoveWithoutFrames => f.write_str(
                "MOVE in a scene without FRAMES: an animation first says how many frames it has (FRAMES count)",
            ),
            ErrorKind::NothingToMove { after } => {
                f.write_str("MOVE must follow an object, LIGHT, VIEWPOINT or ORIGIN statement")?;
                match after {
                    None => f.write_str(", and nothing comes before it"),
                    Some("MOVE") => f.write_str(": a statement moves by one MOVE, and this one follows another"),
                    Some(keyword) => write!(f, ", not {keyword}"),
                }
            }
            ErrorKind::FramesOutOfOrder { frame, previous } => {
                write!(f, "MOVE frames must increase: frame {frame} comes after frame {previous}")
            }
            ErrorKind::FrameBeyond { frame, count } => write!(
                f,
                "MOVE frame {frame} is beyond the animation: FRAMES gives {count} frame{}, 0 to {}",
                if *count == 1 { "" } else { "s" },
                count - 1
            ),
            ErrorKind::MovedOutOfRange { keyword, frame } => write!(
                f,
                "MOVE takes {keyword} beyond 1e6 at frame {frame}: its coordinates must stay at most 1e6 in magnitude \
                 in every frame"
            ),
            ErrorKind::MovedCamera { error, frame } => write!(f, "at frame {frame}, {error}"),
            ErrorKind::NoMotion { profile } => write!(
                f,
                "MOVE, but this build's profile {profile} holds no motion (built for a still: `motion: false`)"
            ),
        }
    }
}

impl fmt::Display for ParseError<'_> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}:{}: {}", self.pos.line, self.pos.column, self.kind)
    }
}

impl core::error::Error for ParseError<'_> {}

impl core::error::Error for ErrorKind<'_> {}
