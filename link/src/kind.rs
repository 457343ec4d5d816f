//! The vocabulary of messages: a frame's second byte names its [`Kind`].
//!
//! Invariants: each kind has one byte and one name; hosts' kinds are below
//! 0x40 and boards' above, so either end can refuse a frame sent the wrong
//! way before reading its payload.

use core::fmt;

macro_rules! kinds {
    ($($(#[$doc:meta])* $kind:ident = $byte:literal, $name:literal, $from_host:literal;)*) => {
        /// What a frame carries: its second byte. Hosts send kinds below
        /// 0x40, boards the others.
        #[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
        #[repr(u8)]
        pub enum Kind {
            $($(#[$doc])* $kind = $byte,)*
        }

        impl Kind {
            /// Every kind, in the order of their bytes.
            pub const ALL: [Kind; [$($byte),*].len()] = [$(Kind::$kind),*];

            /// The kind whose byte is `byte`.
            pub const fn from_byte(byte: u8) -> Option<Kind> {
                match byte {
                    $($byte => Some(Kind::$kind),)*
                    _ => None,
                }
            }

            /// Its name in messages and in the protocol's documentation.
            pub const fn name(self) -> &'static str {
                match self {
                    $(Kind::$kind => $name,)*
                }
            }

            /// Whether a host sends it (else a board does).
            pub const fn from_host(self) -> bool {
                match self {
                    $(Kind::$kind => $from_host,)*
                }
            }
        }
    };
}

kinds! {
    /// Host: who are you? Answered with [`Message::Board`](crate::Message::Board).
    Hello = 0x01, "hello", true;
    /// Host: draw this scene.
    Scene = 0x02, "scene", true;
    /// Board: its panel, buffer and capacities.
    Board = 0x41, "board", false;
    /// Board: one error of the scene.
    SceneError = 0x42, "scene-error", false;
    /// Board: the scene had errors (all sent before); nothing is drawn.
    Rejected = 0x43, "rejected", false;
    /// Board: the scene loaded and is being drawn.
    Drawing = 0x44, "drawing", false;
    /// Board: a row is drawn.
    Row = 0x45, "row", false;
    /// Board: every row is drawn.
    Done = 0x46, "done", false;
    /// Board: the drawing stopped because another frame came.
    Cancelled = 0x47, "cancelled", false;
    /// Board: a run of pixels of an animation's frame is drawn.
    Run = 0x48, "run", false;
    /// Board: every run of an animation's frame is drawn.
    FrameDrawn = 0x49, "frame-drawn", false;
    /// Board: the animation stopped because another frame came.
    Stopped = 0x4A, "stopped", false;
    /// Board: it is still working on the request (a drawing that has sent
    /// nothing for a while).
    Working = 0x4B, "working", false;
    /// Board: a frame it cannot take, and why.
    Refused = 0x7F, "refused", false;
}

impl Kind {
    /// Its byte.
    pub const fn byte(self) -> u8 {
        self as u8
    }
}

impl fmt::Display for Kind {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn kinds_and_bytes_agree() {
        for kind in Kind::ALL {
            assert_eq!(Kind::from_byte(kind.byte()), Some(kind));
            assert_eq!(kind.from_host(), kind.byte() < 0x40, "{kind}");
        }
        assert_eq!(Kind::from_byte(0x00), None);
    }
}
