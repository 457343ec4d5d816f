//! The link check: arbitrary bytes from a serial line into octrace-link's
//! decoder, as a board and a host receive them, and every frame that reads
//! answered by the board's side. Nothing a line carries may panic either,
//! and what reads must read the same once written again.
//!
//! The board answers on a Board16K raytracer; a scene that loads is not
//! drawn (the render target does that), its `Drawing` is closed at once.

use octrace_core::profile::Board16K;
use octrace_core::Raytracer;
use octrace_link::board::Board;
use octrace_link::{
    encode_raw, Counter, Counters, Decoder, Kind, Message, Panel, PixelFormat, Reason, Timing, VERSION,
};
use std::cell::RefCell;

/// The buffers of a board with little RAM, a board, and a host.
const BUFFERS: [usize; 3] = [24, 600, 1 << 16];

thread_local! {
    static RAYTRACER: RefCell<Box<Raytracer<Board16K>>> = RefCell::new(Box::new(Raytracer::new()));
}

/// Feeds `data` to decoders of each size; panics on a broken promise:
/// - pushing never panics, and a frame ends only at a 0x00;
/// - a frame that reads is written again (same tag, same message) into
///   bytes that read as the same frame;
/// - a refusal formats to a message, and tags only what it could trust;
/// - the board answers each frame (refusals included) with frames that read.
pub fn check_link(data: &[u8]) {
    for size in BUFFERS {
        let mut decoder = Decoder::new(vec![0u8; size]);
        let board = Board::new(Panel { width: 4, height: 3, format: PixelFormat::Rgb565 }, "fuzz", &decoder);
        for &byte in data {
            let Some(received) = decoder.push(byte) else { continue };
            assert_eq!(byte, 0, "a frame ended at a byte that is no delimiter");
            match received {
                Ok(frame) => {
                    let mut again = Vec::new();
                    frame.message.encode(frame.tag, &mut again).unwrap();
                    let mut reader = Decoder::new(vec![0u8; again.len()]);
                    let mut read = 0;
                    for &b in &again {
                        if let Some(result) = reader.push(b) {
                            assert_eq!(result, Ok(frame), "written again, it reads otherwise");
                            read += 1;
                        }
                    }
                    assert_eq!(read, 1, "written again, it is not one frame");
                }
                Err(refusal) => {
                    assert!(!refusal.to_string().is_empty());
                    let trusted = matches!(
                        refusal.reason,
                        Reason::WrongVersion { .. } | Reason::Unexpected { .. } | Reason::Malformed { .. }
                    );
                    assert!(trusted || refusal.tag == 0, "an untrusted header's tag: {refusal:?}");
                }
            }
            let mut answer = Vec::new();
            RAYTRACER.with(|raytracer| {
                let mut raytracer = raytracer.borrow_mut();
                let received = decoder.received().expect("the frame just read");
                if let Some(drawing) = board.answer(received, &mut raytracer, None, &mut answer).unwrap() {
                    drawing.cancel(0, &mut answer).unwrap();
                }
            });
            let mut host = Decoder::new(vec![0u8; 1 << 16]);
            let mut answers = 0;
            for &b in &answer {
                if let Some(read) = host.push(b) {
                    assert!(read.is_ok(), "the board's answer does not read: {read:?}");
                    answers += 1;
                }
            }
            assert!(answers > 0, "a frame went unanswered");
        }
    }
}

/// The seed inputs (`link-seeds/`): frames each side sends, cut, damaged,
/// of another version, and a modem's greeting.
pub fn seeds() -> Vec<(&'static str, Vec<u8>)> {
    let scene = include_bytes!("../../scenes/fig5_1.txt");
    let frame = |message: Message<'_>, tag| {
        let mut bytes = Vec::new();
        message.encode(tag, &mut bytes).unwrap();
        bytes
    };
    let hello = frame(Message::Hello, 1);
    let scene_frame = frame(Message::Scene { pixels: true, text: scene }, 2);
    let panel = Panel { width: 4, height: 3, format: PixelFormat::Rgb565 };
    let answers = [
        frame(Message::Drawing { panel, pixels: true, frames: 0 }, 2),
        frame(Message::Row { y: 0, pixels: &[0xF8, 0, 0x07, 0xE0, 0, 0x1F, 0xFF, 0xFF] }, 2),
        frame(Message::Working { elapsed: Some(std::time::Duration::from_micros(20_000)) }, 2),
        frame(
            Message::Done(Timing {
                elapsed: Some(std::time::Duration::from_micros(1234)),
                load: Some(std::time::Duration::from_micros(34)),
                render: Some(std::time::Duration::from_micros(1200)),
                counters: Counters::new(&[Counter { name: "sram0_contested", load: 1, render: 5 }]),
            }),
            2,
        ),
        frame(Message::Cancelled { rows: 1 }, 2),
        frame(Message::Rejected { errors: 1 }, 3),
        frame(Message::Refused(Reason::BadChecksum { sent: 1, computed: 2 }), 0),
    ]
    .concat();
    let mut damaged = scene_frame.clone();
    damaged[40] ^= 0x04;
    let mut other_version = Vec::new();
    encode_raw(VERSION + 1, Kind::Hello.byte(), 9, &[], &mut other_version).unwrap();
    vec![
        ("hello.bin", hello.clone()),
        ("scene.bin", scene_frame.clone()),
        ("scene-errors.bin", frame(Message::Scene { pixels: false, text: b"SPHERE 1 -1 0 0 0\nFOO\n" }, 4)),
        ("scene-cut-then-hello.bin", [&scene_frame[..scene_frame.len() / 2], &hello].concat()),
        ("scene-damaged.bin", damaged),
        ("other-version.bin", other_version),
        ("board-answers.bin", answers),
        ("modem.bin", b"AT\r\nATZ\r\n\0\x01\x02\x00".to_vec()),
    ]
}
