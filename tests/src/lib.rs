//! Support code for octrace's whole-pipeline tests (the tests themselves are
//! in `tests/`).

pub mod reference;
