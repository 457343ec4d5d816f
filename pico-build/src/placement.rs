//! The RP2040's memory map (`memory.x`: boot2, flash, 264 KiB of SRAM, at
//! least 16 KiB left for core 0's stack) and where each firmware's code
//! runs: in place in flash through the XIP cache, or copied into SRAM at
//! boot (`sram-code.x`, filled in with the input sections a
//! [`CodePlacement`] copies; `octrace_pico::boot!` copies
//! them).
//!
//! Invariants: `memory.x` includes `code-placement.x`, which [`link`]
//! writes into a folder of its own for each firmware, so that each links
//! with its own placement; every placement defines the copy's bounds (an
//! empty copy for code left in flash), so every firmware expands
//! `octrace_pico::boot!` whatever its placement.

use crate::{out_dir, write, BuildError, SceneKind};

/// The memory map, which `cortex-m-rt`'s `link.x` includes.
const MEMORY_X: &str = include_str!("../memory.x");

/// The code copied into SRAM; `COPIED` is replaced by the input sections.
const SRAM_CODE_X: &str = include_str!("../sram-code.x");

/// The variable a user sets to place the code.
const VARIABLE: &str = "OCTRACE_CODE_IN";

/// The render path's input sections: octrace-core's tracing and indexing,
/// both cores' loop and core 1's job runner, the compiler's 64-bit helpers.
const RENDER_PATH: &str = concat!(
    ".text.*octrace_core*accel* .text.*octrace_core*shapes* .text.*octrace_core*shade* ",
    ".text.*octrace_core*render* .text.*octrace_core*math* .text.*both_cores* .text.*second_core* ",
    ".text.__aeabi_* .text.__*di3 .text.__*di4"
);

/// What the render path's patterns match but only loading runs: the
/// octree's building and the choice of index, left in flash by `render`
/// (22 KiB of SRAM, for a load a little slower).
const INDEX_BUILDING: &str = ".text.*octrace_core*accel*octree*build* .text.*octrace_core*accel*octree*overlap* .text.*octrace_core*accel*choice*";

/// An animation's, beside the render path: the tracking, the tiles, both
/// cores' frames (copied only for an animation: in a still they would take
/// SRAM, linked, never run).
const ANIMATION: &str = ".text.*octrace_core*motion* .text.*octrace_core*animation* .text.*animation*";

/// The loader's: the parser and the scene's set-up.
const LOADER: &str = ".text.*octrace_core*parse* .text.*octrace_core*scene*";

/// Where a firmware's code runs.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum CodePlacement {
    /// All of it (and its constants) copied into SRAM at boot: a little
    /// faster than `RenderInSram` for a small scene, too large beside a
    /// large one (`OCTRACE_CODE_IN=sram`).
    AllInSram,
    /// `RenderInSram` and the loader (the parser, the scene's set-up):
    /// what runs once the board is up, for 34 KiB more of SRAM than
    /// `RenderInSram` (`parse-and-render`, the default).
    LoadAndRenderInSram,
    /// The render path copied into SRAM at boot (octrace-core's tracing
    /// and its index's queries, both cores' loop, the compiler's 64-bit
    /// helpers); the rest (the parser, the octree's building, USB, the
    /// panel's set-up) runs from flash, so that SRAM is left to the scene
    /// (`render`).
    RenderInSram,
    /// All of it in place in flash, through the XIP cache (`flash`).
    Flash,
}

impl CodePlacement {
    /// Every placement with the name `OCTRACE_CODE_IN` gives it, the default first.
    pub const ALL: [(CodePlacement, &'static str); 4] = [
        (CodePlacement::LoadAndRenderInSram, "parse-and-render"),
        (CodePlacement::RenderInSram, "render"),
        (CodePlacement::AllInSram, "sram"),
        (CodePlacement::Flash, "flash"),
    ];

    /// The placement `OCTRACE_CODE_IN` names, `parse-and-render` when it is
    /// not set.
    pub fn from_env() -> Result<CodePlacement, BuildError> {
        println!("cargo:rerun-if-env-changed={VARIABLE}");
        let Ok(value) = std::env::var(VARIABLE) else { return Ok(CodePlacement::ALL[0].0) };
        CodePlacement::ALL.iter().find(|(_, name)| *name == value).map(|&(placement, _)| placement).ok_or(
            BuildError::Variable {
                name: VARIABLE,
                value,
                expected: "`parse-and-render` (the default), `render`, `sram` or `flash`",
            },
        )
    }

    /// The input sections `sram-code.x` copies for a firmware drawing
    /// `kind` (none for code left in flash).
    fn copied(self, kind: SceneKind) -> String {
        let render = match kind {
            SceneKind::Still => RENDER_PATH.to_owned(),
            SceneKind::Animation => format!("{RENDER_PATH} {ANIMATION}"),
        };
        match self {
            CodePlacement::AllInSram => "*(.text .text.*); *(.rodata .rodata.*);".to_owned(),
            CodePlacement::LoadAndRenderInSram => format!("*({render} {LOADER});"),
            CodePlacement::RenderInSram => format!("*({render});"),
            CodePlacement::Flash => String::new(),
        }
    }

    /// The input sections `sram-code.x` keeps in flash although the
    /// copied ones match them.
    fn kept(self) -> String {
        match self {
            CodePlacement::RenderInSram => format!("*({INDEX_BUILDING});"),
            _ => String::new(),
        }
    }

    /// The linker script `memory.x` includes for a firmware so placed.
    fn script(self, kind: SceneKind) -> String {
        SRAM_CODE_X.replace("COPIED", &self.copied(kind)).replace("KEPT", &self.kept())
    }
}

/// Puts `memory.x` where the linker finds it, and for each of `binaries`
/// (a binary's name, where its code runs and what it draws: the embedded
/// scene's kind, or [`SceneKind::Still`] for one that draws pictures) its
/// `code-placement.x`.
pub fn link(binaries: &[(&str, CodePlacement, SceneKind)]) -> Result<(), BuildError> {
    let out = out_dir()?;
    for &(binary, placement, kind) in binaries {
        let dir = out.join(binary);
        std::fs::create_dir_all(&dir).map_err(|error| BuildError::File { path: dir.display().to_string(), error })?;
        write(&dir.join("code-placement.x"), &placement.script(kind))?;
        println!("cargo:rustc-link-arg-bin={binary}=-L{}", dir.display());
    }
    write(&out.join("memory.x"), MEMORY_X)?;
    println!("cargo:rustc-link-search={}", out.display());
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn each_placement_copies_its_sections_and_flash_none() {
        let render = CodePlacement::RenderInSram.script(SceneKind::Still);
        assert!(render.contains(".text.*octrace_core*shade*") && !render.contains("parse"), "{render}");
        // The octree's building is matched first by the flash's section.
        let kept = render.find("*octree*build*").expect("kept in flash");
        assert!(kept < render.find(".sram_code :").unwrap(), "{render}");
        let load = CodePlacement::LoadAndRenderInSram.script(SceneKind::Still);
        assert!(load.contains(".text.*octrace_core*parse*") && load.contains(".text.*both_cores*"), "{load}");
        assert!(CodePlacement::AllInSram.script(SceneKind::Still).contains("*(.rodata .rodata.*);"));
        let flash = CodePlacement::Flash.script(SceneKind::Animation);
        assert!(!flash.contains(".text.*") && flash.contains("__sram_code_end"), "{flash}");
        for (placement, _) in CodePlacement::ALL {
            for kind in [SceneKind::Still, SceneKind::Animation] {
                let script = placement.script(kind);
                assert!(!script.contains("COPIED") && !script.contains("KEPT"), "{placement:?}");
            }
        }
    }

    #[test]
    fn an_animation_copies_its_tracking_with_the_render_path_and_a_still_not() {
        for placement in [CodePlacement::RenderInSram, CodePlacement::LoadAndRenderInSram] {
            assert!(placement.script(SceneKind::Animation).contains(".text.*octrace_core*motion*"), "{placement:?}");
            assert!(!placement.script(SceneKind::Still).contains("motion"), "{placement:?}");
        }
    }
}
