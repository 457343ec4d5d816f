//! What octrace-core's `math::ARMV6M` is told by, checked against the
//! compiler's own view of each Arm target the repository builds for: the
//! ARMv6-M forms (part-wise products, for a core without `umull` and `clz`)
//! for the Cortex-M0 alone, the general ones for the Cortex-M3, M4 and
//! M33. The condition below is `ARMV6M`'s `cfg!` (target_arch "arm", no
//! 32-bit atomics), read from `rustc --print cfg`.

use std::process::Command;

/// Whether `target`'s configuration is ARMv6-M's by `math::ARMV6M`'s condition.
fn armv6m(target: &str) -> bool {
    let out = Command::new(std::env::var_os("RUSTC").unwrap_or_else(|| "rustc".into()))
        .args(["--print", "cfg", "--target", target])
        .output()
        .expect("rustc runs");
    assert!(out.status.success(), "{target}: {}", String::from_utf8_lossy(&out.stderr));
    let cfg = String::from_utf8(out.stdout).expect("UTF-8");
    let lines: Vec<&str> = cfg.lines().collect();
    lines.contains(&r#"target_arch="arm""#) && !lines.contains(&r#"target_has_atomic="32""#)
}

#[test]
fn armv6m_forms_are_the_cortex_m0s_alone() {
    assert!(armv6m("thumbv6m-none-eabi"), "Cortex-M0, M0+");
    for target in ["thumbv7m-none-eabi", "thumbv7em-none-eabihf", "thumbv8m.main-none-eabihf"] {
        assert!(!armv6m(target), "{target} has umull and clz");
    }
    assert!(!armv6m("riscv32imc-unknown-none-elf"));
}
