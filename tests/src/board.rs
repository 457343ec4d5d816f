//! A board at the end of a serial line, for the tests of `host-sim board`
//! and the studio's "Send to board": any command that serves a serial
//! device and names it on its standard output — the software board
//! (`software-board`: octrace-link's board logic on a host, behind a
//! pseudo-terminal) or an emulated one, chosen by [`RunningBoard::for_tests`]
//! — and a raw host that sends it frames the protocol refuses.
//!
//! A board's command also takes commands, a line each on its standard
//! input, answered with a line on its standard output
//! ([`RunningBoard::command`]): `hold` and `release` (the host stops taking
//! what the board sends, and takes it again), `times` (the board's clock
//! when the host last handed it bytes, when it last sent some, now, its
//! watchdog's time left, and whether it waits for the host:
//! [`BoardTimes`]) and `panel PATH` (its panel's picture as a PNG file).
//!
//! Invariants: a [`RunningBoard`] is ended (by its own process id) when it
//! is dropped, and its command ends by itself when its standard input
//! closes, so no board outlives its test; a board is handed to a test once
//! it has started and waits for a host; every wait (a [`RawHost`]'s read,
//! a command's answer) is for an event, and gives up only at its guard
//! against a hang ([`crate::HANG_GUARD`]).

use host_sim::board::{BoardDescription, BoardLink, Waits};
use octrace_link::{Decoder, Frame, Refusal};
use std::collections::VecDeque;
use std::fs::File;
use std::io::{self, BufRead, BufReader, Write};
use std::path::PathBuf;
use std::process::{Child, ChildStdin, Command, Stdio};
use std::sync::mpsc::{self, Receiver};
use std::time::{Duration, Instant};

/// A scene that wedged the board before it could stop inside a pixel:
/// two facing mirrors with the eye between them, so wide that every sample
/// bounces as often as a sample may (4,096 rays), `lights` lights (up to
/// eight), 16² samples a pixel: a pixel takes hours on a Pico and seconds
/// on a PC, a picture minutes at least, so that what waits on a drawing
/// never sees it end. The format allows all of it.
pub fn wedging_scene(lights: u32) -> String {
    let lights = lights.clamp(1, 8);
    let positions = ["0 1", "0 -1", "1 0", "-1 0", "1 1", "-1 1", "1 -1", "-1 -1"];
    let mut text = String::from("VIEWPOINT 0 0 0\nORIGIN 0 0 -1\nRDEPTH 1000000\nSAMPLES 16\n");
    for position in &positions[..lights as usize] {
        text += &format!("LIGHT 1 {position} 0\n");
    }
    text + "RECTANGLE 1 -1000 -1000 -3 1000 -1000 -3 1000 1000 -3 -1000 1000 -3\n\
            RECTANGLE 1 -1000 -1000 3 -1000 1000 3 1000 1000 3 1000 -1000 3\n\
            SURFACE 1 0.01 0.01 0.01 0.1 0.1 0.1 0 0 0 0 1 0\n"
}

/// A pseudo-terminal in raw mode (no echo, no line editing): the board's
/// end (the controller) and the path a host opens.
pub fn open_pty() -> io::Result<(File, PathBuf)> {
    use rustix::pty::{grantpt, openpt, ptsname, unlockpt, OpenptFlags};
    use rustix::termios::{tcgetattr, tcsetattr, OptionalActions};
    let controller = openpt(OpenptFlags::RDWR | OpenptFlags::NOCTTY)?;
    grantpt(&controller)?;
    unlockpt(&controller)?;
    let path = ptsname(&controller, Vec::new())?;
    // Set through the controller, the modes are the device's.
    let mut modes = tcgetattr(&controller)?;
    modes.make_raw();
    tcsetattr(&controller, OptionalActions::Now, &modes)?;
    let path =
        PathBuf::from(path.into_string().map_err(|_| io::Error::other("a pseudo-terminal's path is not UTF-8"))?);
    Ok((File::from(controller), path))
}

/// host-sim's `--patience` with a board in the tests that do not test its
/// waits: its silence allowance (8 s times this) as long as the guard
/// against a hang, so that a board slowed by a busy machine (the emulated
/// Pico can run hundreds of times slower than a Pico) is waited for as every
/// test waits, for the event.
pub const PATIENCE: u32 = (crate::HANG_GUARD.as_secs() / host_sim::board::SILENCE.as_secs()) as u32;

/// A board serving a serial device, ended when dropped.
pub struct RunningBoard {
    child: Child,
    /// The serial device a host opens.
    pub port: PathBuf,
    commands: ChildStdin,
    answers: Receiver<String>,
}

/// What a board's `times` command answers: microseconds by the board's
/// clock.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct BoardTimes {
    /// When the host last handed the board bytes.
    pub last_in: Option<u64>,
    /// When the board last sent bytes to the host.
    pub last_out: Option<u64>,
    /// Now.
    pub now: u64,
    /// How long the board's watchdog has left; None when it is stopped or
    /// the board has none.
    pub watchdog_left: Option<u64>,
    /// Whether the board waits for the host (nothing to do).
    pub idle: bool,
}

impl RunningBoard {
    /// Starts `command`, which names the serial device it serves on a line
    /// of its standard output (the line's last word, a path under `/dev`),
    /// then serves it until its standard input closes.
    pub fn start(mut command: Command) -> Result<RunningBoard, String> {
        let program = format!("{:?}", command.get_program());
        command.stdin(Stdio::piped()).stdout(Stdio::piped()).stderr(Stdio::inherit());
        let mut child = crate::children::spawn(&mut command).map_err(|e| format!("cannot start {program}: {e}"))?;
        let stdout = child.stdout.take().ok_or("no standard output")?;
        let commands = child.stdin.take().ok_or("no standard input")?;
        let mut lines = BufReader::new(stdout).lines();
        let port = loop {
            match lines.next() {
                Some(Ok(line)) => {
                    if let Some(path) = line.split_whitespace().last().filter(|w| w.starts_with("/dev/")) {
                        break PathBuf::from(path);
                    }
                }
                _ => {
                    let _ = child.kill();
                    let _ = child.wait();
                    return Err(format!("{program} ended without naming its serial device"));
                }
            }
        };
        // The rest of its output answers commands, read as it comes.
        let (send, answers) = mpsc::channel();
        std::thread::spawn(move || {
            for line in lines.map_while(Result::ok) {
                let _ = send.send(line);
            }
        });
        let mut board = RunningBoard { child, port, commands, answers };
        // Started (an emulated board boots first) and waiting for a host.
        let deadline = Instant::now() + crate::HANG_GUARD;
        while !board.times().idle {
            if Instant::now() >= deadline {
                return Err(format!("{program} never came to wait for a host"));
            }
            std::thread::sleep(Duration::from_millis(50));
        }
        Ok(board)
    }

    /// Sends the board `command` (see the module's documentation) and
    /// returns its answer.
    pub fn command(&mut self, command: &str) -> String {
        writeln!(self.commands, "{command}").and_then(|()| self.commands.flush()).expect("the board takes commands");
        self.answers.recv_timeout(crate::HANG_GUARD).unwrap_or_else(|e| panic!("no answer to {command}: {e}"))
    }

    /// The board's `times`.
    pub fn times(&mut self) -> BoardTimes {
        let answer = self.command("times");
        let field = |word: Option<&str>| word.and_then(|w| w.parse::<u64>().ok());
        let mut words = answer.strip_prefix("times ").unwrap_or_else(|| panic!("times: {answer}")).split(' ');
        let (last_in, last_out, now, watchdog_left) =
            (field(words.next()), field(words.next()), field(words.next()), field(words.next()));
        let idle = words.next() == Some("1");
        BoardTimes { last_in, last_out, now: now.unwrap_or_else(|| panic!("times: {answer}")), watchdog_left, idle }
    }

    /// Waits until the board has taken bytes sent after `since` (its
    /// clock) and has nothing more to do; its times then.
    pub fn wait_idle_after(&mut self, since: u64) -> BoardTimes {
        self.wait_for("to take bytes and be idle", |times| times.idle && times.last_in.is_some_and(|t| t > since))
    }

    /// Waits until the board's times satisfy `until` (`what` says what, for
    /// a hang's message); its times then.
    pub fn wait_for(&mut self, what: &str, until: impl Fn(&BoardTimes) -> bool) -> BoardTimes {
        let deadline = Instant::now() + crate::HANG_GUARD;
        loop {
            let times = self.times();
            if until(&times) {
                return times;
            }
            assert!(Instant::now() < deadline, "the board never came {what}: {times:?}");
            std::thread::sleep(Duration::from_millis(50));
        }
    }

    /// The software board with these arguments (`--profile`, `--panel`,
    /// `--max-scene`; see its `--help`).
    pub fn software(program: &str, args: &[&str]) -> RunningBoard {
        let mut command = Command::new(program);
        command.args(args);
        RunningBoard::start(command).unwrap_or_else(|e| panic!("{e}"))
    }

    /// The board the tests talk to: the command `OCTRACE_BOARD_COMMAND` names, run
    /// in the repository (for instance the emulated Pico's `node
    /// emulator/run.mjs ELF --serial`), or else the
    /// software board `software` (the path of the tests' `software-board`)
    /// with a 16 KiB board's profile, a 160×128 panel and scenes of up to
    /// 8 KiB. The tests ask it what it is ([`RunningBoard::describe`]) and
    /// choose their scenes by that.
    pub fn for_tests(software: &str) -> RunningBoard {
        match std::env::var("OCTRACE_BOARD_COMMAND") {
            Ok(command) => {
                let mut words = command.split_whitespace();
                let mut command = Command::new(words.next().expect("OCTRACE_BOARD_COMMAND names a command"));
                command.args(words).current_dir(crate::repo());
                RunningBoard::start(command).unwrap_or_else(|e| panic!("{e}"))
            }
            Err(_) => RunningBoard::software(
                software,
                &["--profile", "board16k", "--panel", "160x128", "--max-scene", "8192"],
            ),
        }
    }

    /// What the board says it is.
    pub fn describe(&self) -> BoardDescription {
        let waits = Waits { cap: None, patience: PATIENCE };
        let mut link = BoardLink::open(&self.port.to_string_lossy(), waits).expect("the port opens");
        let description = link.hello().expect("the board answers");
        drop(link);
        crate::children::settle_after_closing();
        description
    }

    /// Whether its process still runs.
    pub fn alive(&mut self) -> bool {
        matches!(self.child.try_wait(), Ok(None))
    }
}

impl Drop for RunningBoard {
    fn drop(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}

/// The dearest scene `board` holds: exactly its longest text, as many of
/// each kind of object as it holds (and of lights and surfaces), all of
/// them around the origin and filling the view from just outside them, so
/// that every ray meets the bounds of every object (one octree leaf, one
/// light-buffer cell), 16² samples, mirrors and glass: its pixels are the
/// dearest the board can be given from the first, each ray the longest
/// between two of its polls.
pub fn dearest_scene(board: &BoardDescription) -> String {
    let holds = |name: &str| board.capacities.iter().find(|(n, _)| n == name).map_or(0, |(_, n)| *n as usize);
    let mut objects = holds("objects");
    let mut take = |kind: &str| {
        let count = holds(kind).min(objects);
        objects -= count;
        count
    };
    let surfaces = holds("surfaces").max(1);
    let mut text = String::from("VIEWPOINT 0 0 3.5\nORIGIN 0 0 0\nRDEPTH 1000000\nSAMPLES 16\n");
    for light in 0..holds("lights") {
        text += &format!("LIGHT 1 {} {} 9\n", light % 3 * 4, light / 3 * 4);
    }
    // Each object a little off the last, all around the origin.
    let mut surface = 0;
    let mut next = || {
        surface += 1;
        (surface - 1) % surfaces + 1
    };
    let at = |i: usize| (i % 10) as f64 / 50.0;
    for i in 0..take("spheres") {
        text += &format!("SPHERE {} 2 {} {} 0\n", next(), at(i), at(i / 10));
    }
    for i in 0..take("boxes") {
        text += &format!("BOX {} {} 0 0 1.5 1.5 1.5\n", next(), at(i));
    }
    for i in 0..take("superquadrics") {
        text += &format!("SUPERQUADRIC {} 3.5 0 {} 0 1.8 1.8 1.8\n", next(), at(i));
    }
    for i in 0..take("triangles") {
        text += &format!("TRIANGLE {} -3 -3 {} 3 -3 0 0 3 0\n", next(), at(i));
    }
    for i in 0..take("rectangles") {
        let (s, z) = (next(), at(i) - 0.5);
        text += &format!("RECTANGLE {s} -3 -3 {z} 3 -3 {z} 3 3 {z} -3 3 {z}\n");
    }
    for n in 1..=surfaces {
        text += &format!("SURFACE {n} .05 .05 .05 .3 .3 .3 .2 .2 .2 10 .5 .4\n");
    }
    let room = (board.max_scene as usize).checked_sub(text.len() + 4);
    let room = room.unwrap_or_else(|| panic!("the dearest scene is {} bytes: longer than the board takes", text.len()));
    text + "/*" + &"x".repeat(room) + "*/"
}

/// How many lights `board` holds.
pub fn lights(board: &BoardDescription) -> u32 {
    board.capacities.iter().find(|(name, _)| name == "lights").map_or(0, |(_, n)| *n)
}

/// Whether scene `text` fits what the board holds: its length and every
/// capacity of its profile.
pub fn fits(board: &BoardDescription, text: &str) -> bool {
    let needs = octrace_core::parse::count(text);
    text.len() <= board.max_scene as usize
        && octrace_core::capacity::CapacityKind::ALL.into_iter().all(|kind| {
            let holds = board.capacities.iter().find(|(name, _)| name == kind.field()).map_or(0, |(_, n)| *n);
            needs.get(kind) <= holds as usize
        })
}

/// A host that writes any bytes to a board and reads its frames.
pub struct RawHost {
    /// Open until dropped.
    port: Option<Box<dyn serialport::SerialPort>>,
    decoder: Decoder<Vec<u8>>,
    unread: VecDeque<u8>,
    /// Bytes read from the board so far.
    read: u64,
}

/// Its port closed, no child started meanwhile keeps it locked.
impl Drop for RawHost {
    fn drop(&mut self) {
        // Closed here, not after this with the other fields: the settling
        // follows the close.
        self.port = None;
        crate::children::settle_after_closing();
    }
}

impl RawHost {
    pub fn open(port: &std::path::Path) -> RawHost {
        // Not exclusive: host-sim opens it next, while this one may still be open.
        let port = serialport::new(port.to_string_lossy(), 115_200)
            .exclusive(false)
            .timeout(Duration::from_millis(50))
            .open()
            .unwrap_or_else(|e| panic!("cannot open {}: {e}", port.display()));
        RawHost { port: Some(port), decoder: Decoder::for_host(vec![0; 1 << 18]), unread: VecDeque::new(), read: 0 }
    }

    /// Bytes read from the board so far (up to the end of the last frame
    /// handed on).
    pub fn bytes_read(&self) -> u64 {
        self.read
    }

    fn line(&mut self) -> &mut dyn serialport::SerialPort {
        self.port.as_deref_mut().expect("open until dropped")
    }

    pub fn send(&mut self, bytes: &[u8]) {
        self.line().write_all(bytes).expect("the board's port takes bytes");
        self.line().flush().expect("the board's port takes bytes");
    }

    /// Hands each frame that comes to `each` until it returns true; false
    /// if none did within [`crate::HANG_GUARD`] (a hang).
    pub fn receive_until(&mut self, each: &mut dyn FnMut(Result<Frame<'_>, Refusal>) -> bool) -> bool {
        let deadline = Instant::now() + crate::HANG_GUARD;
        loop {
            while let Some(byte) = self.unread.pop_front() {
                self.read += 1;
                if let Some(received) = self.decoder.push(byte) {
                    if each(received) {
                        return true;
                    }
                }
            }
            if Instant::now() >= deadline {
                return false;
            }
            let mut chunk = [0u8; 4096];
            match self.line().read(&mut chunk) {
                Ok(n) => self.unread.extend(&chunk[..n]),
                Err(e) if e.kind() == io::ErrorKind::TimedOut => {}
                Err(e) => panic!("reading the board: {e}"),
            }
        }
    }
}
