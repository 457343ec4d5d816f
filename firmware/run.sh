#!/usr/bin/env bash
# qemu runner for the firmware: run.sh MACHINE ELF. Exits with the guest's
# semihosting exit code (0 ok, 2 bad scene, 101 panic, 102 HardFault), or 124
# if it runs longer than QEMU_TIMEOUT seconds (default 600).
set -euo pipefail
machine=$1
elf=$2
cpu=()
[ "$machine" = mps2-an385 ] && cpu=(-cpu cortex-m3)
exec timeout "${QEMU_TIMEOUT:-600}" qemu-system-arm -machine "$machine" "${cpu[@]}" -nographic -monitor none \
    -semihosting-config enable=on,target=native -kernel "$elf"
