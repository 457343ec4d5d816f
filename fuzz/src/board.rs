//! The board loop check: arbitrary byte streams, arriving in pieces at
//! arbitrary times, into octrace-link's board loop (`board::Link`, the one
//! the live firmware runs, with its stall handling) over a simulated line,
//! a 4×3 panel drawn on one core and polled between rays as on a board.
//! Every frame that ends on the line must be answered, in order, with
//! frames that read; nothing may panic or loop for ever.
//!
//! The input is a list of pieces: a control byte, then that many bytes of
//! the line (its low six bits, plus one). The control byte's top two bits
//! say when the piece arrives: at once, after 1, 30 or 2,000 of the
//! board's polls. A drawing is stopped after 20,000 polls (a scene may take
//! hours a pixel): it is then `cancelled`, as when a frame comes; an
//! animation after 3 frames (it would play until the host sends): then
//! `stopped`.

use embedded_graphics_core::geometry::Size;
use embedded_graphics_core::pixelcolor::Rgb565;
use octrace_core::animation::AnimationRoom;
use octrace_core::profile::Board16K;
use octrace_core::render::Renderer;
use octrace_core::Raytracer;
use octrace_link::board::{Line, Link};
use octrace_link::{Decoder, Kind, Message, Panel, PixelFormat};
use std::cell::RefCell;
use std::collections::VecDeque;

/// The board's frame buffer: small, so that frames too long for it come.
const BUFFER: usize = 600;
const PANEL: Panel = Panel { width: 4, height: 3, format: PixelFormat::Rgb565 };
/// Frames after which an animation stops by itself (it would play until
/// the host sends something).
const FRAMES_PLAYED: u32 = 3;

/// Polls after which a drawing stops by itself.
const POLLS_A_DRAWING: u32 = 20_000;

thread_local! {
    static RAYTRACER: RefCell<Box<Raytracer<Board16K>>> = RefCell::new(Box::new(Raytracer::new()));
}

/// The host's bytes, each piece readable after so many polls; what the
/// board writes, taken at once (or held while `holding`); a clock that
/// moves 100 µs each time it is read.
struct SimulatedLine {
    pieces: VecDeque<(u32, Vec<u8>)>,
    readable: VecDeque<u8>,
    polls: u32,
    /// The host does not take what the board writes (up to this many of the
    /// board's signs of life).
    holding_until: u32,
    taken: Vec<u8>,
    held: Vec<u8>,
    clock_us: u64,
}

impl Line for SimulatedLine {
    fn read(&mut self) -> Option<u8> {
        while self.pieces.front().is_some_and(|(at, _)| *at <= self.polls) {
            let (_, piece) = self.pieces.pop_front()?;
            self.readable.extend(piece);
        }
        self.readable.pop_front()
    }

    fn write(&mut self, bytes: &[u8]) -> usize {
        if self.polls < self.holding_until {
            // A device's buffer of 64 bytes, then nothing.
            let room = 64usize.saturating_sub(self.held.len());
            let taken = room.min(bytes.len());
            self.held.extend_from_slice(&bytes[..taken]);
            return taken;
        }
        self.taken.append(&mut self.held);
        self.taken.extend_from_slice(bytes);
        bytes.len()
    }

    fn discard(&mut self) {}

    fn now_us(&mut self) -> u64 {
        self.clock_us += 100;
        self.clock_us
    }

    fn sleep(&mut self) -> bool {
        // Nothing readable: the next piece comes now, if any will.
        match self.pieces.front_mut() {
            Some((at, _)) => {
                *at = self.polls;
                true
            }
            None => false,
        }
    }

    fn alive(&mut self) {
        self.polls += 1;
    }
}

/// The pieces `data` describes.
fn pieces(data: &[u8]) -> VecDeque<(u32, Vec<u8>)> {
    let mut pieces = VecDeque::new();
    let mut at = 0u32;
    let mut rest = data;
    while let Some((&control, after)) = rest.split_first() {
        let len = (usize::from(control & 0x3f) + 1).min(after.len());
        at += [0, 1, 30, 2_000][usize::from(control >> 6)];
        pieces.push_back((at, after[..len].to_vec()));
        rest = &after[len..];
    }
    pieces
}

/// What each frame of the line asks, as a board's decoder reads it: the
/// tag and kind of the frame that closes its answer (a scene's: rejected,
/// done or cancelled, told apart later).
fn closings_due(line: &[u8]) -> Vec<(u16, Kind)> {
    let mut decoder = Decoder::for_board(vec![0u8; BUFFER]);
    line.iter()
        .filter_map(|&byte| {
            decoder.push(byte).map(|received| match received {
                Ok(frame) => (frame.tag, if frame.message == Message::Hello { Kind::Board } else { Kind::Done }),
                Err(refusal) => (refusal.tag, Kind::Refused),
            })
        })
        .collect()
}

/// Serves `data`'s line to the end; what the host took.
fn serve(data: &[u8], holding_until: u32) -> SimulatedLine {
    let mut line = SimulatedLine {
        pieces: pieces(data),
        readable: VecDeque::new(),
        polls: 0,
        holding_until,
        taken: Vec::new(),
        held: Vec::new(),
        clock_us: 0,
    };
    // A 4×3 panel is one tile; room for four moving statements' keys.
    let mut room = Box::new(AnimationRoom::<1, 4, 16>::new());
    let size = Size::new(u32::from(PANEL.width), u32::from(PANEL.height));
    let animation = room.animation(size).expect("a 4x3 panel's one tile");
    let mut link = Link::new(PANEL, "fuzz", vec![0u8; BUFFER]).with_animations(animation);
    // Frames of an animation played so far: it is stopped after a few.
    let mut frames = 0;
    RAYTRACER.with(|raytracer| {
        let mut raytracer = raytracer.borrow_mut();
        while link
            .serve(&mut line, &mut raytracer, |drawing, rows| {
                let mut row = [Rgb565::default(); 4];
                if let Some(frame) = drawing.frame() {
                    if frame.number() == 0 {
                        frames = 0;
                    }
                    frames += 1;
                    return match frames > FRAMES_PLAYED {
                        true => 0,
                        false => rows.draw_on_one_core(drawing, &mut row, |_, _| {}),
                    };
                }
                let (w, h) = (u32::from(PANEL.width), u32::from(PANEL.height));
                let mut drawn = 0;
                // A still traced pixel by pixel, stopped after its polls.
                let _ = drawing.scene().with_renderer(Size::new(w, h), |renderer| {
                    let mut polls = 0;
                    let mut budgeted = BudgetedRows { rows, polls: &mut polls };
                    drawn = budgeted.draw(drawing, renderer, &mut row);
                });
                drawn
            })
            .is_some()
        {}
    });
    line.taken.append(&mut line.held);
    line
}

/// A drawing's rows, stopped after [`POLLS_A_DRAWING`] polls.
struct BudgetedRows<'r, 'o, 'l> {
    rows: &'r mut octrace_link::board::Rows<'o, 'l, SimulatedLine, Vec<u8>>,
    polls: &'r mut u32,
}

impl BudgetedRows<'_, '_, '_> {
    fn draw(
        &mut self,
        drawing: &octrace_link::board::Drawing<'_, Board16K>,
        renderer: &mut Renderer<'_, Board16K>,
        row: &mut [Rgb565],
    ) -> u16 {
        for y in 0..PANEL.height {
            for (x, pixel) in (0..u32::from(PANEL.width)).zip(row.iter_mut()) {
                let mut stop = || {
                    *self.polls += 1;
                    self.rows.poll() || *self.polls > POLLS_A_DRAWING
                };
                match renderer.pixel_until(x, y.into(), &mut stop) {
                    Ok(sample) => *pixel = sample.color.into(),
                    Err(_) => return y,
                }
            }
            self.rows.send(drawing, y, row);
        }
        PANEL.height
    }
}

/// Serves `data` twice: to a host that reads all along, whose every frame
/// must be answered, in order, by frames that read, each with its frame's
/// tag; and to one that stops reading for a while, which must end as well.
pub fn check_board_loop(data: &[u8]) {
    let line: Vec<u8> = pieces(data).into_iter().flat_map(|(_, piece)| piece).collect();
    let due = closings_due(&line);
    let served = serve(data, 0);
    let mut host = Decoder::for_host(vec![0u8; 1 << 16]);
    let mut closings = Vec::new();
    for &byte in &served.taken {
        let Some(read) = host.push(byte) else { continue };
        let frame = read.unwrap_or_else(|refusal| panic!("the board's answer does not read: {refusal}"));
        let kind = frame.message.kind();
        if let Some(&(tag, _)) = due.get(closings.len()) {
            assert_eq!(frame.tag, tag, "{kind} answers frame {} with another tag", closings.len());
        }
        let closing = match kind {
            Kind::Board | Kind::Refused => Some(kind),
            Kind::Rejected | Kind::Done | Kind::Cancelled | Kind::Stopped => Some(Kind::Done),
            _ => None,
        };
        closings.extend(closing.map(|kind| (frame.tag, kind)));
    }
    assert_eq!(closings, due, "each frame answered once, in order");
    // A host that stops reading for a while: the loop ends all the same.
    let _ = serve(data, 5_000);
}

/// The seed inputs (`board-loop-seeds/`): the link's frames as pieces of
/// the line, arriving at once and late.
pub fn seeds() -> Vec<(&'static str, Vec<u8>)> {
    let as_pieces = |line: &[u8], when: u8| -> Vec<u8> {
        line.chunks(64).flat_map(|chunk| [&[(when << 6) | (chunk.len() as u8 - 1)][..], chunk].concat()).collect()
    };
    let frame = |message: Message<'_>, tag| {
        let mut bytes = Vec::new();
        message.encode(tag, &mut bytes).unwrap();
        bytes
    };
    let scene = frame(Message::Scene { pixels: true, text: b"SPHERE 1 1 0 0 0\nLIGHT 1 5 5 5\n" }, 2);
    let wedge = frame(
        Message::Scene {
            pixels: false,
            text: b"VIEWPOINT 0 0 0 ORIGIN 0 0 -1 RDEPTH 1000000 SAMPLES 16 LIGHT 1 0 1 0\n\
                    RECTANGLE 1 -5 -5 -3 5 -5 -3 5 5 -3 -5 5 -3 RECTANGLE 1 -5 -5 3 -5 5 3 5 5 3 5 -5 3\n\
                    SURFACE 1 0.01 0.01 0.01 0 0 0 0 0 0 0 1 0\n",
        },
        3,
    );
    let hello = frame(Message::Hello, 1);
    let animation = frame(
        Message::Scene { pixels: true, text: b"FRAMES 3\nSPHERE 1 1 0 0 0 MOVE 0 0 0 0  2 1 0 0\nLIGHT 1 5 5 5\nSURFACE 1 .1 .1 .1 .7 .2 .2 0 0 0 1 0 0\n" },
        5,
    );
    vec![
        ("animation-then-late-hello.bin", [as_pieces(&animation, 0), as_pieces(&hello, 2)].concat()),
        ("hello-then-scene.bin", as_pieces(&[&hello[..], &scene].concat(), 0)),
        ("scene-then-late-hello.bin", [as_pieces(&scene, 0), as_pieces(&hello, 2)].concat()),
        ("wedge-then-hello.bin", [as_pieces(&wedge, 0), as_pieces(&hello, 2)].concat()),
        ("errors-burst.bin", as_pieces(&frame(Message::Scene { pixels: false, text: &b"FOO\n".repeat(100) }, 4), 1)),
    ]
}
