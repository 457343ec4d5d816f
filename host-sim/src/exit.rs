//! The exit codes every host-sim command shares: 0 done, 1 a file could not
//! be read or written, 2 a bad scene or bad arguments.

/// Exit code for a bad scene or bad arguments.
pub const EXIT_SCENE: i32 = 2;
/// Exit code for a file that cannot be read or written.
pub const EXIT_IO: i32 = 1;
