//! What `build.rs` chose for this board and scene: the capacity profile
//! sized for exactly the embedded scene, the picture's size, its colour and
//! dithering (generated into `OUT_DIR`, so that `main` and `both_cores`
//! read one definition).

include!(concat!(env!("OUT_DIR"), "/config.rs"));
