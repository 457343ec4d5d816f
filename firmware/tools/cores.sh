#!/usr/bin/env bash
# Instructions each core executes between the firmware's two bench_marker
# calls, and how many of them it spent waiting for the other core
# (octrace_wait_until): cores.sh ELF, for the dual-core MPS2-AN521 build.
# Prints "core N insns T wait W" lines. Builds the qemu-cores plugin (the
# header comes from the shared qemu-insncount tool's cache).
set -euo pipefail
HERE=$(cd "$(dirname "$0")" && pwd)
ELF=$1
CACHE=$HOME/.cache/qemu-insncount
[ -f "$CACHE/qemu-plugin.h" ] || "$HERE/../../../shared/tools/qemu-insncount/build.sh" >/dev/null
PLUGIN=$CACHE/libqemu-cores.so
if [ ! -f "$PLUGIN" ] || [ "$HERE/qemu-cores.c" -nt "$PLUGIN" ]; then
  gcc -O2 -fPIC -shared -Wall -I"$CACHE" -o "$PLUGIN" "$HERE/qemu-cores.c"
fi
symbol() { arm-none-eabi-nm -S "$ELF" | awk -v name="$1" '$4 == name { print $1, $2 }'; }
read -r marker _ < <(symbol bench_marker)
read -r wait size < <(symbol octrace_wait_until)
OUT=$(mktemp)
timeout "${QEMU_TIMEOUT:-600}" qemu-system-arm -machine mps2-an521 -smp 2 -nographic -monitor none \
  -semihosting-config enable=on,target=native \
  -plugin "$PLUGIN,out=$OUT,marker=0x$marker,wait=0x$wait-$(printf '0x%x' $((0x$wait + 0x$size)))" \
  -kernel "$ELF" >/dev/null
cat "$OUT"
rm -f "$OUT"
