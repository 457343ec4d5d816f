#!/usr/bin/env bash
# Instructions each core executes between the firmware's two bench_marker
# calls, and how many of them it spent waiting for the other core
# (octrace_wait_until): cores.sh ELF, for the dual-core MPS2-AN521 build.
# Prints "core N insns T wait W" lines. The qemu-cores plugin is built once
# into target/qemu-plugins/ (qemu.sh).
set -euo pipefail
HERE=$(cd "$(dirname "$0")" && pwd)
source "$HERE/qemu.sh"
ELF=$1
PLUGIN=$(build_plugin qemu-cores)
qemu_for mps2-an521
symbol() { arm-none-eabi-nm -S "$ELF" | awk -v name="$1" '$4 == name { print $1, $2 }'; }
read -r marker _ < <(symbol bench_marker)
read -r wait size < <(symbol octrace_wait_until)
OUT=$(mktemp)
timeout "${QEMU_TIMEOUT:-1800}" "${QEMU[@]}" -plugin "$PLUGIN,out=$OUT,marker=0x$marker,wait=0x$wait-$(printf '0x%x' $((0x$wait + 0x$size)))" \
  -kernel "$ELF" >/dev/null
cat "$OUT"
rm -f "$OUT"
