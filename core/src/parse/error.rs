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
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub struct Pos {
    pub line: u32,
    pub column: u32,
}

/// A parameter of a statement, as the messages name it ("SPHERE radius").
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Field {
    pub statement: &'static str,
    pub name: &'static str,
}

impl fmt::Display for Field {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{} {}", self.statement, self.name)
    }
}

/// What a token was found instead of the expected one.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Found<'a> {
    Token(&'a str),
    EndOfFile,
}

impl fmt::Display for Found<'_> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Found::Token(t) => write!(f, "`{}`", Shown(t)),
            Found::EndOfFile => f.write_str("the end of the file"),
        }
    }
}

/// Scene text as a message shows it: control characters escaped (a scene
/// must not be able to send escape sequences to a terminal) and at most
/// [`Shown::LIMIT`] characters, with the length of the rest.
pub struct Shown<'a>(pub &'a str);

impl Shown<'_> {
    pub const LIMIT: usize = 40;
}

impl fmt::Display for Shown<'_> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        for c in self.0.chars().take(Self::LIMIT) {
            if c.is_control() || c == '\u{feff}' {
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

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ErrorKind<'a> {
    /// The scene is not valid UTF-8 (the position is the first bad byte).
    InvalidUtf8,
    /// A `/*` that is never closed (the position is where it opened).
    UnterminatedComment,
    /// A `"` that is never closed.
    UnterminatedString,
    UnknownKeyword(&'a str),
    ExpectedNumber {
        field: Field,
        found: Found<'a>,
    },
    ExpectedInteger {
        field: Field,
        found: Found<'a>,
    },
    ExpectedName {
        field: Field,
    },
    OutOfRange {
        field: Field,
        rule: Rule,
        found: &'a str,
    },
    /// A scene parameter given twice.
    Repeated {
        keyword: &'static str,
        first_line: u32,
    },
    SurfaceRepeated {
        number: u32,
        first_line: u32,
    },
    UndefinedSurface {
        keyword: &'static str,
        number: u32,
    },
    /// A shape with no area or volume: `why` says how.
    Degenerate {
        keyword: &'static str,
        why: &'static str,
    },
    NotPlanar,
    NotConvex,
    /// A B-spline with fewer control points along a side than its order.
    TooFewControlPoints {
        order: u32,
        rows: u32,
        cols: u32,
    },
    /// A shape that rounds to nothing at the scale the whole scene needs.
    TooSmall {
        keyword: &'static str,
    },
    EyeAtOrigin,
    UpParallel,
    Capacity(CapacityError),
}

/// One error in a scene.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ParseError<'a> {
    pub pos: Pos,
    pub kind: ErrorKind<'a>,
}

impl<'a> ParseError<'a> {
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
        }
    }
}

impl fmt::Display for ParseError<'_> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}:{}: {}", self.pos.line, self.pos.column, self.kind)
    }
}
