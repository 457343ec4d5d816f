//! Builds the studio's WebAssembly module (`studio/`, octrace-core for
//! wasm32-unknown-unknown) so `host-sim studio` can serve it from the
//! binary. Nothing prebuilt is committed: a fresh clone builds it here.
//!
//! The module gets its own target directory beside this build's (under
//! `target/studio-wasm`), so debug and release builds of host-sim share one
//! WebAssembly build and never wait on each other's lock.

use std::path::{Path, PathBuf};
use std::process::Command;

fn main() {
    let manifest_dir = PathBuf::from(std::env::var_os("CARGO_MANIFEST_DIR").expect("cargo sets CARGO_MANIFEST_DIR"));
    let out_dir = PathBuf::from(std::env::var_os("OUT_DIR").expect("cargo sets OUT_DIR"));
    let studio = manifest_dir.join("../studio");
    // The module is built from the studio, the core and the image files crate.
    for crate_dir in ["../studio", "../core", "../images"] {
        for watched in ["src", "Cargo.toml"] {
            println!("cargo:rerun-if-changed={crate_dir}/{watched}");
        }
    }
    println!("cargo:rerun-if-changed=../studio/Cargo.lock");
    install_wasm_target();
    let target_dir = wasm_target_dir(&out_dir);
    let cargo = std::env::var_os("CARGO").unwrap_or_else(|| "cargo".into());
    let mut command = Command::new(cargo);
    command
        .args(["build", "--release", "--locked", "--target", "wasm32-unknown-unknown", "--manifest-path"])
        .arg(studio.join("Cargo.toml"))
        .arg("--target-dir")
        .arg(&target_dir);
    // This build's settings (flags, clippy's wrapper, the host target) are
    // not the module's.
    for variable in [
        "RUSTFLAGS",
        "CARGO_ENCODED_RUSTFLAGS",
        "RUSTC_WRAPPER",
        "RUSTC_WORKSPACE_WRAPPER",
        "CARGO_BUILD_TARGET",
        "CARGO_TARGET_DIR",
        "CARGO_PRIMARY_PACKAGE",
    ] {
        command.env_remove(variable);
    }
    let status = command.status().unwrap_or_else(|e| panic!("cannot run cargo to build the studio module: {e}"));
    if !status.success() {
        panic!(
            "building the studio's WebAssembly module failed (is the target installed? \
             `rustup target add wasm32-unknown-unknown`)"
        );
    }
    let built = target_dir.join("wasm32-unknown-unknown/release/octrace_studio.wasm");
    std::fs::copy(&built, out_dir.join("octrace_studio.wasm"))
        .unwrap_or_else(|e| panic!("cannot copy {}: {e}", built.display()));
}

/// rust-toolchain.toml names the WebAssembly target, but rustup adds a
/// toolchain file's targets only when it installs the toolchain itself; on a
/// machine that already had stable, the README's first command would stop
/// here. So the target is added the way the toolchain file asks for it.
fn install_wasm_target() {
    const TARGET: &str = "wasm32-unknown-unknown";
    let rustc = std::env::var_os("RUSTC").unwrap_or_else(|| "rustc".into());
    let sysroot = Command::new(rustc)
        .args(["--print", "sysroot"])
        .output()
        .ok()
        .filter(|output| output.status.success())
        .map(|output| PathBuf::from(String::from_utf8_lossy(&output.stdout).trim()));
    if sysroot.is_some_and(|sysroot| sysroot.join("lib/rustlib").join(TARGET).is_dir()) {
        return;
    }
    println!("cargo:warning=adding the {TARGET} target for the studio (rustup target add {TARGET})");
    // rustup picks the toolchain this build runs on from RUSTUP_TOOLCHAIN.
    let added = Command::new("rustup").args(["target", "add", TARGET]).status();
    if !added.is_ok_and(|status| status.success()) {
        println!("cargo:warning=`rustup target add {TARGET}` failed; the build below will say what is missing");
    }
}

/// `target/studio-wasm` for an OUT_DIR of `target/<profile>/build/<pkg>/out`
/// (or `target/<triple>/<profile>/…`), else a directory under OUT_DIR.
fn wasm_target_dir(out_dir: &Path) -> PathBuf {
    out_dir
        .ancestors()
        .find(|dir| dir.file_name().is_some_and(|name| name == "build"))
        .and_then(|build| build.parent())
        .and_then(|profile| profile.parent())
        .map(|target| target.join("studio-wasm"))
        .unwrap_or_else(|| out_dir.join("studio-wasm"))
}
