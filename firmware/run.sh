#!/usr/bin/env bash
# qemu runner for the firmware: run.sh ELF. The machine (and, for the
# LM3S6965EVB, where its screen goes) comes from the ELF itself, written
# there by build.rs. Exits with the guest's semihosting exit code (0 ok,
# 2 bad scene, 101 panic, 102 HardFault), 124 if it runs longer than
# QEMU_TIMEOUT seconds (default 1800, a hang guard), 4 if the OLED's screen cannot be
# grabbed (tools/runner.py).
set -euo pipefail
here=$(dirname "$0")
source "$here/tools/qemu.sh"
elf=$1
machine=$(python3 "$here/tools/runner.py" info "$elf" machine)
[ "$machine" != lm3s6965evb ] || exec python3 "$here/tools/runner.py" screen "$elf"
qemu_for "$machine"
exec timeout "${QEMU_TIMEOUT:-1800}" "${QEMU[@]}" -kernel "$elf"
