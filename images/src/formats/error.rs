//! Why an image could not be read or written: [`FormatError`], and the
//! shorthands each format's reader returns it with.

use std::fmt;

/// Why an image could not be read or written.
#[derive(Debug)]
pub enum FormatError {
    /// Writing the file failed.
    Io(std::io::Error),
    /// The file ends inside the named part.
    Truncated(&'static str),
    /// A kind of file this module does not handle.
    Unsupported(String),
    /// A malformed file, or an image that no file can hold as it is.
    Invalid(String),
}

impl fmt::Display for FormatError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            FormatError::Io(e) => write!(f, "{e}"),
            FormatError::Truncated(part) => write!(f, "truncated {part}"),
            FormatError::Unsupported(what) | FormatError::Invalid(what) => f.write_str(what),
        }
    }
}

impl std::error::Error for FormatError {
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        match self {
            FormatError::Io(e) => Some(e),
            _ => None,
        }
    }
}

impl From<std::io::Error> for FormatError {
    fn from(e: std::io::Error) -> FormatError {
        FormatError::Io(e)
    }
}

pub(super) fn invalid<T>(message: String) -> Result<T, FormatError> {
    Err(FormatError::Invalid(message))
}

pub(super) fn unsupported<T>(message: String) -> Result<T, FormatError> {
    Err(FormatError::Unsupported(message))
}
