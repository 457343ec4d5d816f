//! A board at the end of a serial line, for the tests of `host-sim board`
//! and the studio's "Send to board": any command that serves a serial
//! device and names it on its standard output — the software board
//! (`software-board`: octrace-link's board logic on a host, behind a
//! pseudo-terminal) or an emulated one, chosen by [`RunningBoard::for_tests`]
//! — and a raw host that sends it frames the protocol refuses.
//!
//! Invariants: a [`RunningBoard`] is ended (by its own process id) when it
//! is dropped, and its command ends by itself when its standard input
//! closes, so no board outlives its test; every read of a [`RawHost`]
//! gives up after its timeout.

use host_sim::board::{BoardDescription, BoardLink};
use octrace_link::{Decoder, Frame, Refusal};
use std::collections::VecDeque;
use std::fs::File;
use std::io::{self, BufRead, BufReader, Read, Write};
use std::path::PathBuf;
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

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

/// A board serving a serial device, ended when dropped.
pub struct RunningBoard {
    child: Child,
    /// The serial device a host opens.
    pub port: PathBuf,
}

impl RunningBoard {
    /// Starts `command`, which names the serial device it serves on a line
    /// of its standard output (the line's last word, a path under `/dev`),
    /// then serves it until its standard input closes.
    pub fn start(mut command: Command) -> Result<RunningBoard, String> {
        let program = format!("{:?}", command.get_program());
        let mut child = command
            .stdin(Stdio::piped())
            .stdout(Stdio::piped())
            .stderr(Stdio::inherit())
            .spawn()
            .map_err(|e| format!("cannot start {program}: {e}"))?;
        let stdout = child.stdout.take().ok_or("no standard output")?;
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
        // The rest of its output goes nowhere, without blocking it.
        std::thread::spawn(move || lines.for_each(drop));
        Ok(RunningBoard { child, port })
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
        let mut link = BoardLink::open(&self.port.to_string_lossy(), Duration::from_secs(30)).expect("the port opens");
        link.hello().expect("the board answers")
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
    port: Box<dyn serialport::SerialPort>,
    decoder: Decoder<Vec<u8>>,
    unread: VecDeque<u8>,
}

impl RawHost {
    pub fn open(port: &std::path::Path) -> RawHost {
        // Not exclusive: host-sim opens it next, while this one may still be open.
        let port = serialport::new(port.to_string_lossy(), 115_200)
            .exclusive(false)
            .timeout(Duration::from_millis(50))
            .open()
            .unwrap_or_else(|e| panic!("cannot open {}: {e}", port.display()));
        RawHost { port, decoder: Decoder::new(vec![0; 1 << 18]), unread: VecDeque::new() }
    }

    pub fn send(&mut self, bytes: &[u8]) {
        self.port.write_all(bytes).expect("the board's port takes bytes");
        self.port.flush().expect("the board's port takes bytes");
    }

    /// Hands each frame that comes within `timeout` to `each` until it
    /// returns true; false if time ran out first.
    pub fn receive_until(
        &mut self,
        timeout: Duration,
        each: &mut dyn FnMut(Result<Frame<'_>, Refusal>) -> bool,
    ) -> bool {
        let deadline = Instant::now() + timeout;
        loop {
            while let Some(byte) = self.unread.pop_front() {
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
            match self.port.read(&mut chunk) {
                Ok(n) => self.unread.extend(&chunk[..n]),
                Err(e) if e.kind() == io::ErrorKind::TimedOut => {}
                Err(e) => panic!("reading the board: {e}"),
            }
        }
    }
}
