//! The few semihosting calls the firmware needs: open and write a host file,
//! exit with a status code. On a real board these would be a display driver
//! and a reset; under qemu they carry the pixels to the host.

// The two crates give the same calls: Arm's (BKPT 0xAB) and RISC-V's
// (EBREAK between the marker shifts).
#[cfg(target_arch = "arm")]
use cortex_m_semihosting as host;
use host::{nr, syscall};
#[cfg(target_arch = "riscv32")]
use riscv_semihosting as host;

/// An open host file.
pub struct HostFile {
    handle: usize,
}

impl HostFile {
    /// Creates (truncates) `name`, a NUL-terminated path on the host.
    #[cfg_attr(board = "lm3s6965evb", allow(dead_code))]
    pub fn create(name: &str) -> Option<HostFile> {
        let bytes = name.as_bytes();
        if bytes.last() != Some(&0) {
            return None;
        }
        // SAFETY: SYS_OPEN reads `len` bytes of the NUL-terminated name from
        // the pointer, which stays valid for the call.
        let handle = unsafe { syscall!(OPEN, bytes.as_ptr(), nr::open::W_TRUNC_BINARY, bytes.len() - 1) };
        (handle != usize::MAX).then_some(HostFile { handle })
    }

    /// Opens `name`, a NUL-terminated path on the host, for reading; `None`
    /// if it does not exist.
    #[cfg_attr(not(board = "lm3s6965evb"), allow(dead_code))]
    pub fn open(name: &str) -> Option<HostFile> {
        let bytes = name.as_bytes();
        if bytes.last() != Some(&0) {
            return None;
        }
        // SAFETY: as in `create`.
        let handle = unsafe { syscall!(OPEN, bytes.as_ptr(), nr::open::R_BINARY, bytes.len() - 1) };
        (handle != usize::MAX).then_some(HostFile { handle })
    }

    /// Writes all of `data`; false if the host refused.
    #[cfg_attr(board = "lm3s6965evb", allow(dead_code))]
    pub fn write(&mut self, data: &[u8]) -> bool {
        // SAFETY: SYS_WRITE reads `len` bytes from the pointer during the
        // call; it returns the number of bytes *not* written.
        unsafe { syscall!(WRITE, self.handle, data.as_ptr(), data.len()) == 0 }
    }
}

impl Drop for HostFile {
    fn drop(&mut self) {
        // SAFETY: SYS_CLOSE takes the handle SYS_OPEN returned.
        unsafe {
            syscall!(CLOSE, self.handle);
        }
    }
}

/// Ends the program with `code` as qemu's exit status (SYS_EXIT_EXTENDED).
pub fn exit(code: u32) -> ! {
    const SYS_EXIT_EXTENDED: usize = 0x20;
    const APPLICATION_EXIT: usize = 0x20026;
    loop {
        // SAFETY: the call reads the two-word block during the call.
        unsafe {
            host::syscall(SYS_EXIT_EXTENDED, &[APPLICATION_EXIT, code as usize]);
        }
    }
}
