//! The parse check: arbitrary bytes into the scene parser, which must never
//! panic, loop or break its contract (see [`crate::parse_checked`]).

use crate::parse_checked;
use octrace_core::profile::{Board16K, Board64K};
use octrace_core::scene::Scene;
use std::cell::RefCell;

thread_local! {
    // Allocated once: `clear`ed by the parser before each input.
    static SCENE64: RefCell<Box<Scene<Board64K>>> = RefCell::new(Box::new(Scene::new()));
    static SCENE16: RefCell<Box<Scene<Board16K>>> = RefCell::new(Box::new(Scene::new()));
}

/// Parses `data` with both board profiles; panics on a broken contract.
pub fn check_parse(data: &[u8]) {
    let ok64 = SCENE64.with(|s| parse_checked(data, &mut s.borrow_mut()));
    // The small board's profile too: the same text, more capacity errors.
    let ok16 = SCENE16.with(|s| parse_checked(data, &mut s.borrow_mut()));
    // Whatever fits the small board fits the large one.
    assert!(!ok16 || ok64, "parses with Board16K but not with Board64K");
}
