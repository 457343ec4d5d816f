//! The lists a message carries, a count byte and that many entries: a
//! board's [`Capacities`] (in `board`) and the [`Counters`] it read while
//! it loaded and drew a scene (in `done`). Each is a slice to send, or the
//! bytes received, kept as they came.
//!
//! Invariants: a received list was checked entry by entry when its frame
//! was decoded, so iterating it yields exactly its `count` entries; a list
//! to send is cut at 255 entries (the count is a byte), the same on the
//! wire and in `len` and `iter`.

use crate::cobs::Sink;
use crate::frame::FrameWriter;
use crate::wire::{put_str8, Reader};

/// A list type of entries of one kind, each a name and numbers: its
/// constructor from a slice, `iter`, `len`, equality, and its reading and
/// writing.
macro_rules! wire_list {
    (
        $(#[$doc:meta])* $list:ident of $entry:ident { $name:ident $(, $number:ident: $int:ident)* }
    ) => {
        $(#[$doc])*
        #[derive(Clone, Copy, Debug)]
        pub struct $list<'a>(Entries<'a, $entry<'a>>);

        impl<'a> $list<'a> {
            /// At most 255 of `list` (the count is a byte).
            pub const fn new(list: &'a [$entry<'a>]) -> $list<'a> {
                $list(Entries::Slice(list))
            }

            /// Each entry, in the order sent.
            pub fn iter(&self) -> impl Iterator<Item = $entry<'a>> + 'a {
                let (list, count, mut reader) = match self.0 {
                    Entries::Slice(list) => (&list[..list.len().min(255)], 0, Reader(&[])),
                    Entries::Wire { count, bytes } => (&[][..], count, Reader(bytes)),
                };
                let received = (0..count).map_while(move |_| $entry::read(&mut reader));
                list.iter().copied().chain(received)
            }

            /// How many there are.
            pub fn len(&self) -> usize {
                self.0.len()
            }

            /// Whether there are none.
            pub fn is_empty(&self) -> bool {
                self.len() == 0
            }

            /// The count and the entries.
            pub(crate) fn write<S: Sink + ?Sized>(&self, w: &mut FrameWriter<'_, S>) -> Result<(), S::Error> {
                w.put(&[self.len() as u8])?;
                for entry in self.iter() {
                    put_str8(w, entry.$name)?;
                    $(w.put(&entry.$number.to_be_bytes())?;)*
                }
                Ok(())
            }

            /// A count and that many entries, each checked now.
            pub(crate) fn read(r: &mut Reader<'a>) -> Option<$list<'a>> {
                let count = r.u8()?;
                let start = r.0;
                for _ in 0..count {
                    $entry::read(r)?;
                }
                Some($list(Entries::Wire { count, bytes: &start[..start.len() - r.0.len()] }))
            }
        }

        impl<'a> $entry<'a> {
            fn read(r: &mut Reader<'a>) -> Option<$entry<'a>> {
                Some($entry { $name: r.str8()?, $($number: r.$int()?,)* })
            }
        }

        impl PartialEq for $list<'_> {
            fn eq(&self, other: &Self) -> bool {
                self.len() == other.len() && self.iter().eq(other.iter())
            }
        }

        impl Eq for $list<'_> {}
    };
}

/// A list's entries: a slice to send, or the bytes received.
#[derive(Clone, Copy, Debug)]
enum Entries<'a, T> {
    Slice(&'a [T]),
    /// Checked when decoded: `count` entries.
    Wire {
        count: u8,
        bytes: &'a [u8],
    },
}

impl<T> Entries<'_, T> {
    fn len(&self) -> usize {
        match self {
            Entries::Slice(list) => list.len().min(255),
            Entries::Wire { count, .. } => *count as usize,
        }
    }
}

/// One capacity of a board's profile: its `profile!` field name
/// (`"spheres"`) and how many it holds.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct Capacity<'a> {
    /// The field's name, as octrace-core's `CapacityKind::field` says it.
    pub name: &'a str,
    /// How many the board holds (saturated at `u32::MAX`).
    pub count: u32,
}

wire_list! {
    /// A board's capacities: a list to send, or as received.
    Capacities of Capacity { name, count: u32 }
}

/// A count the board's hardware kept while it loaded a scene and while it
/// drew it, named as the board names it (the Pico: a bus fabric event,
/// `sram0_contested`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct Counter<'a> {
    /// The event counted.
    pub name: &'a str,
    /// Its count over the load (parse and index); [`Counter::RAN_OVER`]
    /// for a count that ran over.
    pub load: u32,
    /// Its count over the render, likewise.
    pub render: u32,
}

impl Counter<'_> {
    /// A count that ran over: more events than the board could count (its
    /// counter filled, or the count passed 32 bits), never a smaller
    /// number in its place.
    pub const RAN_OVER: u32 = u32::MAX;
}

wire_list! {
    /// The counters a board read over a scene: a list to send, or as
    /// received.
    Counters of Counter { name, load: u32, render: u32 }
}
