//! The serial line to a board: what the link needs of it ([`Port`]), and
//! a board's serial port opened for one run ([`SerialLine`]).
//!
//! Invariant: reads and writes give up after a short while (50 ms), so
//! that the link's waits are kept by its own clock.

use serialport::SerialPort as _;
use std::io::{self, Read, Write};
use std::time::{Duration, Instant};

/// A serial line to a board: bytes both ways, reads and writes that give
/// up after a short while (so that the deadlines can be kept).
pub trait Port: Read + Write {
    /// Drops what the board sent before this run.
    fn discard_input(&mut self) -> io::Result<()>;

    /// The time now, which the link's deadlines are kept by: this machine's
    /// clock (a test's port may keep its own).
    fn now(&mut self) -> Instant {
        Instant::now()
    }
}

/// A board's serial port, opened for this run alone.
pub struct SerialLine(Device);

#[cfg(unix)]
type Device = serialport::TTYPort;
#[cfg(not(unix))]
type Device = Box<dyn serialport::SerialPort>;

impl SerialLine {
    /// Opens `path` exclusively: no other program can open it meanwhile.
    pub fn open(path: &str) -> io::Result<SerialLine> {
        // The rate means nothing to a USB serial class or a pseudo-terminal.
        let builder = serialport::new(path, 115_200).timeout(Duration::from_millis(50));
        #[cfg(unix)]
        let device = serialport::TTYPort::open(&builder)?;
        #[cfg(not(unix))]
        let device = builder.open()?;
        Ok(SerialLine(device))
    }
}

/// A pseudo-terminal (an emulated board's) stays exclusive after its last
/// close while its other end is open, which would refuse the next run of
/// anyone but root: the mode is given up explicitly.
#[cfg(unix)]
impl Drop for SerialLine {
    fn drop(&mut self) {
        let _ = self.0.set_exclusive(false);
    }
}

impl Read for SerialLine {
    fn read(&mut self, buf: &mut [u8]) -> io::Result<usize> {
        self.0.read(buf)
    }
}

impl Write for SerialLine {
    fn write(&mut self, buf: &[u8]) -> io::Result<usize> {
        self.0.write(buf)
    }

    /// Nothing to do: what `write` took is the system's. (The device's own
    /// flush waits until the board has read it all, with no time limit.)
    fn flush(&mut self) -> io::Result<()> {
        Ok(())
    }
}

impl Port for SerialLine {
    fn discard_input(&mut self) -> io::Result<()> {
        self.0.clear(serialport::ClearBuffer::Input).map_err(io::Error::from)
    }
}
