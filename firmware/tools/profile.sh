#!/usr/bin/env bash
# Instructions executed per function: profile.sh MACHINE ELF [TOP]
# Builds the qemu-profile plugin (once, into target/qemu-plugins/: qemu.sh),
# runs the firmware under it and prints the
# functions that executed the most instructions (inlined code counted in the
# function it was inlined into), with their calls (runs of the first
# instruction; a loop back to it would count too) and cost per call.
set -euo pipefail
HERE=$(cd "$(dirname "$0")" && pwd)
MACHINE=$1; ELF=$2; TOP=${3:-25}
source "$HERE/qemu.sh"
PLUGIN=$(build_plugin qemu-profile)
qemu_for "$MACHINE"
OUT=$(mktemp)
timeout "${QEMU_TIMEOUT:-1800}" "${QEMU[@]}" -plugin "$PLUGIN,out=$OUT" -kernel "$ELF" >/dev/null || true
python3 - "$ELF" "$OUT" "$TOP" <<'PY'
import bisect, subprocess, sys
elf, prof, top = sys.argv[1], sys.argv[2], int(sys.argv[3])
syms = []
for line in subprocess.run(["arm-none-eabi-nm", "-n", "-C", elf], capture_output=True, text=True).stdout.splitlines():
    parts = line.split(maxsplit=2)
    if len(parts) == 3 and parts[1] in "tTwW":
        syms.append((int(parts[0], 16) & ~1, parts[2]))
addrs = [a for a, _ in syms]
per, calls = {}, {}
total = 0
for line in open(prof):
    a, n = line.split()
    a, n = int(a, 16), int(n)
    total += n
    i = bisect.bisect_right(addrs, a) - 1
    name = syms[i][1] if i >= 0 else "?"
    per[name] = per.get(name, 0) + n
    if i >= 0 and addrs[i] == a:
        calls[name] = n  # the first instruction runs once per call
print(f"{total:>14,} instructions in all")
print(f"{'instructions':>14} {'share':>7} {'calls':>11} {'per call':>8}  function")
for name, n in sorted(per.items(), key=lambda x: -x[1])[:top]:
    c = calls.get(name, 0)
    per_call = f"{n / c:8.0f}" if c else " " * 8
    print(f"{n:>14,} {100 * n / total:5.1f} % {c:>11,} {per_call}  {name[:100]}")
PY
rm -f "$OUT"
