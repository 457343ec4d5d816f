//! The module's `extern "C"` interface. The page writes its input into the
//! input buffer (`studio_input(len)` gives its address), calls an operation,
//! and reads the output buffer (`studio_output_ptr`/`studio_output_len`).
//! Operations return 0 on success; otherwise the output holds the error as
//! UTF-8 text (scene errors one per line, `line:col: message`).
//!
//! Invariant: Rust only ever hands out the buffers' addresses; it never
//! reads memory through a pointer, so the page cannot make it read outside
//! its own buffers.

// Exported symbols need `no_mangle`, which the `unsafe_code` lint counts;
// nothing here dereferences a pointer.
#![allow(unsafe_code)]

use crate::error::StudioError;
use crate::studio::{self, Display, Studio};
use octrace_core::AccelMode;
use octrace_images::formats::Format;
use std::cell::RefCell;

struct State {
    studio: Studio,
    input: Vec<u8>,
    output: Vec<u8>,
}

thread_local! {
    static STATE: RefCell<State> =
        RefCell::new(State { studio: Studio::default(), input: Vec::new(), output: Vec::new() });
}

/// Runs `operation` on the state; its error, if any, becomes the output.
fn run(operation: impl FnOnce(&mut State) -> Result<(), StudioError>) -> u32 {
    STATE.with_borrow_mut(|state| match operation(state) {
        Ok(()) => 0,
        Err(e) => {
            state.output = e.to_string().into_bytes();
            1
        }
    })
}

/// Makes the input buffer `len` bytes long and returns its address.
#[no_mangle]
pub extern "C" fn studio_input(len: usize) -> *mut u8 {
    STATE.with_borrow_mut(|state| {
        state.input.clear();
        state.input.resize(len, 0);
        state.input.as_mut_ptr()
    })
}

#[no_mangle]
pub extern "C" fn studio_output_ptr() -> *const u8 {
    STATE.with_borrow(|state| state.output.as_ptr())
}

#[no_mangle]
pub extern "C" fn studio_output_len() -> usize {
    STATE.with_borrow(|state| state.output.len())
}

/// Parses frame `frame` of the input, scene text (any frame of a scene
/// without FRAMES is the scene); the output is `W H OBJECTS FRAMES RATE`
/// (RASTER, the object count, and the animation's frames and rate, both 0
/// for a still scene).
#[no_mangle]
pub extern "C" fn studio_load(frame: u32) -> u32 {
    run(|state| {
        let loaded = state.studio.load(&state.input, frame)?;
        let ((w, h), objects) = (loaded.raster, loaded.objects);
        let (count, rate) = loaded.frames.map_or((0, 0), |f| (f.count, f.rate));
        state.output = format!("{w} {h} {objects} {count} {rate}").into_bytes();
        Ok(())
    })
}

/// The code of the mode the Process menu starts at: the core's default,
/// which host-sim's `--accel` defaults to too, so that a render in the
/// studio and one on the command line index a scene alike.
#[no_mangle]
pub extern "C" fn studio_default_accel() -> u32 {
    studio::accel_code(AccelMode::default())
}

/// Sets the image size and builds the octree for `accel` (0 auto, 1 naive,
/// 2 octree, 3 dda); the output names the mode used.
#[no_mangle]
pub extern "C" fn studio_prepare(accel: u32, width: u32, height: u32) -> u32 {
    run(|state| {
        let accel = studio::accel_from_code(accel).ok_or(StudioError::BadInput("no such mode"))?;
        let used = state.studio.prepare(accel, width, height)?;
        state.output = used.name().as_bytes().to_vec();
        Ok(())
    })
}

/// Renders a rectangle of the image: the output is its RGB bytes, then a
/// little-endian `u32` object number per pixel.
#[no_mangle]
pub extern "C" fn studio_render(x: u32, y: u32, width: u32, height: u32) -> u32 {
    run(|state| state.studio.render_rect(x, y, width, height, &mut state.output))
}

/// Traces the loaded frame whole at the prepared size (`studio_prepare`):
/// the output is the number of pixels traced (a little-endian `u32`), then
/// the frame as `studio_render` writes it. The frames of an animation
/// traced in turn re-trace only what moved (any forward step round the
/// loop; anything else traces every pixel), with the same bits.
#[no_mangle]
pub extern "C" fn studio_trace_frame() -> u32 {
    run(|state| {
        let mut frame = Vec::new();
        let traced = state.studio.trace_frame(&mut frame)?;
        state.output.clear();
        state.output.extend(u32::try_from(traced).unwrap_or(u32::MAX).to_le_bytes());
        state.output.append(&mut frame);
        Ok(())
    })
}

/// The input (a whole render, as `studio_render` writes it) shown in
/// `display` (0 truecolour, 1 scan, 2 dither, 3 coarse, 4 gray, 5 rgb565,
/// 6 gray4, 7 mono, 8 gray2, 9 bwr; the panels of few levels dithered by
/// `dithering`: 0 fs-pe, 1 fs, 2 bayer, 3 nearest): the output is its RGB
/// bytes.
#[no_mangle]
pub extern "C" fn studio_display(display: u32, dithering: u32, width: u32, height: u32) -> u32 {
    run(|state| {
        let display = Display::from_codes(display, dithering).ok_or(StudioError::BadInput("no such display"))?;
        let (image, objects) = studio::split_render(width, height, &state.input)?;
        state.output = studio::display(&image, &objects, display).to_rgb().data;
        Ok(())
    })
}

/// The input (a whole render) in `display` (as `studio_display` takes it),
/// as a file of `format` (0 PNG, 1 Targa, 2 Sun raster): indexed for the
/// 256-colour displays.
#[no_mangle]
pub extern "C" fn studio_encode(display: u32, dithering: u32, format: u32, width: u32, height: u32) -> u32 {
    run(|state| {
        let display = Display::from_codes(display, dithering).ok_or(StudioError::BadInput("no such display"))?;
        let format = Format::ALL.get(format as usize).copied().ok_or(StudioError::BadInput("no such format"))?;
        let (image, objects) = studio::split_render(width, height, &state.input)?;
        state.output = studio::encode(&studio::display(&image, &objects, display), format)?;
        Ok(())
    })
}

/// Reads the input as an image file: the output is its width and height
/// (little-endian `u32`s), then its RGB bytes.
#[no_mangle]
pub extern "C" fn studio_decode() -> u32 {
    run(|state| {
        let image = studio::decode(&state.input)?;
        let mut out = Vec::with_capacity(8 + image.data.len());
        out.extend(image.width.to_le_bytes());
        out.extend(image.height.to_le_bytes());
        out.extend(&image.data);
        state.output = out;
        Ok(())
    })
}
