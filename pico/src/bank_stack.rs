//! Each core traces on a stack in an SRAM bank of its own: core 0 in SRAM4,
//! core 1 in SRAM5 (4 KiB each, RP2040 datasheet 2.6.2), which nothing
//! else uses (octrace-pico-build's `memory.x` ends the main RAM below
//! them). [`SecondCore::start`](crate::second_core::SecondCore::start)
//! guards both banks; [`both_cores`](crate::both_cores) traces each piece
//! on them.
//!
//! Why: the main SRAM is striped word by word across four banks, and both
//! cores' code and data are spread over all four, so their accesses meet
//! there and one waits (the bus fabric, 2.1.1). Half of a render's loads
//! and stores are each core's stack, and the deep frames that take them
//! sit under 10 to 17 KiB of frames that barely move (the loader's, the
//! picture's buffers): switched to a bank of its own for each row, a core's
//! stack never meets the other core (the emulated Pico's count: fig5_1's
//! contested accesses 21.6 M -> 6.8 M).
//!
//! An animation's frame is traced run by run, each run's pixels as the
//! ring to core 0 takes them, under the frame's own calls: core 1 traces
//! them on its bank with SRAM4 below it ([`with_both_banks`]: 8 KiB, the
//! guard at SRAM4's foot), while core 0, which draws the frame's runs into
//! the panel, keeps to its main stack.
//!
//! Invariants: [`on_bank_stack`] runs its closure to the end on the bank's
//! stack and puts the stack pointer back, on the core that called it; the
//! closure may not call `on_bank_stack` again (it would start the same
//! bank over its own frames); the bank's lowest 32 bytes are an MPU guard
//! ([`guard`]), so an overflow faults instead of writing into the other
//! core's bank (core 1's, into SRAM4) or core 0's main stack (core 0's,
//! below SRAM4); inside [`with_both_banks`] on core 1, core 1's guard is
//! SRAM4's lowest 32 bytes instead, and core 0 does not call
//! `on_bank_stack`.

use core::arch::asm;
use rp2040_hal::pac;
use rp2040_hal::sio::{CoreId, Sio};

/// SRAM4 and SRAM5: each core's bank, base and top.
const BANKS: [(usize, usize); 2] = [(0x2004_0000, 0x2004_1000), (0x2004_1000, 0x2004_2000)];

/// The MPU region for the guard (rp2040-hal's stack guard of core 1 is region 0).
const GUARD_REGION: u32 = 1;

fn bank() -> (usize, usize) {
    BANKS[match Sio::core() {
        CoreId::Core0 => 0,
        CoreId::Core1 => 1,
    }]
}

/// Sets the calling core's MPU to fault on any access to the lowest 32
/// bytes of its bank (the MPU's default map everywhere else): call once on
/// each core before [`on_bank_stack`].
pub fn guard() {
    guard_at(bank().0);
}

/// Runs `f` on core 1 with the guard at SRAM4's foot, so that its bank
/// stack ([`on_bank_stack`] inside `f`) may reach down through SRAM4,
/// core 0's bank (8 KiB in all), then guards its own bank again. Core 0
/// must not trace on its bank stack meanwhile.
pub fn with_both_banks<R>(f: impl FnOnce() -> R) -> R {
    guard_at(BANKS[0].0);
    let result = f();
    guard();
    result
}

/// The calling core's MPU faults on any access to the 32 bytes at `base`.
fn guard_at(base: usize) {
    // SAFETY: only this core's MPU, one region of it; the default map (PRIVDEFENA) stays for the rest.
    let mpu = unsafe { &*pac::PPB::ptr() };
    let guard_subregion = (base >> 5) & 7;
    unsafe {
        mpu.mpu_rnr().write(|w| w.bits(GUARD_REGION));
        mpu.mpu_rbar().write(|w| w.bits((base & !0xff) as u32 | 0x10 | GUARD_REGION));
        // 256 bytes, the guard's 32 alone not disabled, no access, no execution.
        mpu.mpu_rasr().write(|w| w.bits(1 | (7 << 1) | ((0xff ^ (1 << guard_subregion)) << 8) | (1 << 28)));
        mpu.mpu_ctrl().write(|w| w.bits(0b101));
    }
}

/// Runs `f` on the calling core's bank stack and returns what it returns.
pub fn on_bank_stack<R>(f: impl FnOnce() -> R) -> R {
    let mut f = Some(f);
    let mut result = None;
    let mut call = || result = f.take().map(|f| f());
    let (_, top) = bank();
    switch(top, &mut call);
    // `switch` calls the closure once, to its end.
    result.unwrap_or_else(|| unreachable!())
}

/// Calls `f` with the stack pointer at `top`, then puts it back.
#[inline(never)]
fn switch(top: usize, mut f: &mut dyn FnMut()) {
    extern "C" fn trampoline(f: *mut &mut dyn FnMut()) {
        // SAFETY: `switch` passes its own `f`, alive until the call returns.
        unsafe { (*f)() }
    }
    let f: *mut &mut dyn FnMut() = &mut f;
    // SAFETY: `top` is 8-byte aligned and the bank is this core's alone;
    // the old stack pointer is kept in r4, which the call preserves.
    unsafe {
        asm!(
            "mov r4, sp",
            "mov sp, {top}",
            "blx {trampoline}",
            "mov sp, r4",
            top = in(reg) top,
            trampoline = in(reg) trampoline as *const () as usize,
            out("r4") _,
            in("r0") f,
            clobber_abi("C"),
        );
    }
}
