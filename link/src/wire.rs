//! The payload's fields as bytes: a [`Reader`] taking them front to back,
//! and [`put_str8`] writing a string behind its length byte.
//!
//! Invariants: every read checks its length and yields `None` past the
//! end, never panics; integers are big-endian; a `str8` is at most 255
//! bytes of UTF-8, written cut at a character's boundary.

use crate::cobs::Sink;
use crate::frame::FrameWriter;

/// A length byte and at most 255 bytes of `text`, cut at a character's
/// boundary.
pub(crate) fn put_str8<S: Sink + ?Sized>(w: &mut FrameWriter<'_, S>, text: &str) -> Result<(), S::Error> {
    let mut end = text.len().min(255);
    while !text.is_char_boundary(end) {
        end -= 1;
    }
    w.put(&[end as u8])?;
    w.put(&text.as_bytes()[..end])
}

/// Reads a payload front to back; `None` once it runs out.
#[derive(Clone, Copy)]
pub(crate) struct Reader<'a>(pub(crate) &'a [u8]);

impl<'a> Reader<'a> {
    fn take<const N: usize>(&mut self) -> Option<[u8; N]> {
        let (head, rest) = self.0.split_first_chunk::<N>()?;
        self.0 = rest;
        Some(*head)
    }

    pub(crate) fn u8(&mut self) -> Option<u8> {
        self.take::<1>().map(|[b]| b)
    }

    pub(crate) fn u16(&mut self) -> Option<u16> {
        self.take().map(u16::from_be_bytes)
    }

    pub(crate) fn u32(&mut self) -> Option<u32> {
        self.take().map(u32::from_be_bytes)
    }

    pub(crate) fn u64(&mut self) -> Option<u64> {
        self.take().map(u64::from_be_bytes)
    }

    /// A byte that must be 0 or 1.
    pub(crate) fn flag(&mut self) -> Option<bool> {
        match self.u8()? {
            0 => Some(false),
            1 => Some(true),
            _ => None,
        }
    }

    /// A length byte and that many bytes of UTF-8.
    pub(crate) fn str8(&mut self) -> Option<&'a str> {
        let len = self.u8()? as usize;
        let (text, rest) = self.0.split_at_checked(len)?;
        self.0 = rest;
        core::str::from_utf8(text).ok()
    }

    /// Everything left.
    pub(crate) fn rest(&mut self) -> &'a [u8] {
        core::mem::take(&mut self.0)
    }
}
