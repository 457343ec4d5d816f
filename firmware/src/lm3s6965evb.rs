//! The TI Stellaris LM3S6965EVB (Cortex-M3, 64 KiB RAM) and its display,
//! the 128×64 16-gray OLED (`ssd0323`). Invariant: a rendered picture stays
//! on the panel until the host has grabbed it.

use crate::semihosting::HostFile;
use crate::ssd0323::Ssd0323;
use cortex_m_semihosting::hprintln;

/// The panel, brought up and cleared.
pub fn open_output() -> Option<Ssd0323> {
    Ssd0323::take()
}

/// What the guest prints when the picture is complete on the panel; the
/// runner (`tools/runner.py`) then grabs the screen.
const SCREEN_READY: &str = "octrace: screen ready";
/// The file the runner creates, in qemu's working directory, once it has
/// grabbed the screen.
const GRABBED: &str = "octrace-screen-grabbed\0";

/// Keeps the picture on the panel until the host says it has grabbed it (a
/// real board would simply keep showing it).
pub fn show_until_grabbed() {
    hprintln!("{}", SCREEN_READY);
    while HostFile::open(GRABBED).is_none() {
        // Between polls, leave the emulator time for the host's requests.
        cortex_m::asm::delay(1_000_000);
    }
}
