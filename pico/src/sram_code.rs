//! Copying the code `sram-code.x` places in SRAM (all of it and its
//! constants, or the render path with or without the parser, as
//! `OCTRACE_CODE_IN` says; `octrace-pico-build` writes the script) from
//! flash before anything else runs: every firmware linked with that
//! crate's `link` says `octrace_pico::copy_code_into_sram!();` once (with
//! the code left in flash, the copy is empty).
//!
//! Invariants: `__pre_init` is the first code cortex-m-rt's reset handler
//! calls, before `.bss` and `.data` are set up, so it touches no RAM but
//! the copy's destination and calls nothing (the code it would call is not
//! in SRAM yet); it lives in `.flash_code`, which stays in flash. Words are
//! copied: the linker script aligns both ends to 4 bytes. The copy is a
//! macro, expanded in the firmware itself, because only a firmware whose
//! linker script defines the copy's bounds may hold it.

/// Defines `__pre_init`, which cortex-m-rt's reset handler calls first: it
/// copies the code `sram-code.x` places in SRAM from its load address in
/// flash, a word at a time.
#[macro_export]
macro_rules! copy_code_into_sram {
    () => {
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
