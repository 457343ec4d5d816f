//! What runs before `main`, the same for every Pico firmware linked with
//! `octrace-pico-build`'s `link`, which says `octrace_pico::boot!();` once:
//! boot2, the second-stage loader for the Pico's W25Q16JV flash
//! (`rp2040-boot2`'s W25Q080 loader), in the first 256 bytes of flash
//! where the boot ROM runs it; and the copy of the code `sram-code.x`
//! places in SRAM (all of it and its constants, or the render path with or
//! without the parser, as `OCTRACE_CODE_IN` says; an empty copy for code
//! left in flash) from flash before anything else runs.
//!
//! Invariants: `__pre_init` is the first code cortex-m-rt's reset handler
//! calls, before `.bss` and `.data` are set up, so it touches no RAM but
//! the copy's destination and calls nothing (the code it would call is not
//! in SRAM yet); it lives in `.flash_code`, which stays in flash. Words are
//! copied: the linker script aligns both ends to 4 bytes. The copy is a
//! macro, expanded in the firmware itself, because only a firmware whose
//! linker script defines the copy's bounds may hold it.

/// boot2, the second-stage loader the boot ROM runs (`memory.x` keeps it at
/// the start of flash).
#[doc(hidden)]
pub use rp2040_boot2::BOOT_LOADER_W25Q080 as BOOT2;

/// The divider boot2 gives the flash's serial clock (SSI BAUDR: clk_sys / 2,
/// the Pico SDK's `PICO_FLASH_SPI_CLKDIV` for the Pico), which XIP keeps.
pub(crate) const BOOT2_FLASH_DIVIDER: u32 = 2;

/// Defines the firmware's boot2 (`.boot2`) and `__pre_init`, which
/// cortex-m-rt's reset handler calls first: it copies the code `sram-code.x`
/// places in SRAM from its load address in flash, a word at a time.
#[macro_export]
macro_rules! boot {
    () => {
        #[link_section = ".boot2"]
        #[used]
        static BOOT2: [u8; 256] = $crate::boot::BOOT2;

        core::arch::global_asm!(
            ".section .flash_code.__pre_init, \"ax\"",
            ".global __pre_init",
            ".type __pre_init, %function",
            ".thumb_func",
            "__pre_init:",
            "    ldr r0, =__sram_code_start",
            "    ldr r1, =__sram_code_end",
            "    ldr r2, =__sram_code_load",
            "0:  cmp r0, r1",
            "    beq 1f",
            "    ldm r2!, {{r3}}",
            "    stm r0!, {{r3}}",
            "    b 0b",
            "1:  bx lr",
            "    .ltorg",
        );
    };
}
