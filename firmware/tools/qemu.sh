# shellcheck shell=bash
# How the firmware is run in qemu, in one place: sourced by run.sh and by the
# measuring tools beside this file (qemu-count, cores.sh, profile.sh); it only
# defines functions.

# qemu_for MACHINE: sets the array QEMU to the command that runs a firmware
# on MACHINE (add -kernel ELF): headless, the guest's semihosting console on
# stdout, its files on the host's. Fails on a machine the firmware has no
# board for.
qemu_for() {
    case $1 in
        microbit | mps2-an505 | lm3s6965evb) QEMU=(qemu-system-arm -machine "$1") ;;
        mps2-an385) QEMU=(qemu-system-arm -machine mps2-an385 -cpu cortex-m3) ;;
        # Both cores: the second waits until the firmware releases it.
        mps2-an521) QEMU=(qemu-system-arm -machine mps2-an521 -smp 2) ;;
        # No firmware of qemu's own: the ELF starts at the RAM's base.
        virt) QEMU=(qemu-system-riscv32 -machine virt -bios none) ;;
        *)
            echo "no board named $1 (microbit, mps2-an385, mps2-an505, mps2-an521, lm3s6965evb, virt)" >&2
            return 2
            ;;
    esac
    QEMU+=(-nographic -monitor none -semihosting-config enable=on,target=native)
}

# build_plugin NAME: prints the path of the qemu plugin built from NAME.c
# beside this file, building it first into the repository's
# target/qemu-plugins/ when it is missing or older than its source or
# qemu-plugin-api.h. The build goes to a temporary name first, so a run that
# starts meanwhile never loads half a library.
build_plugin() {
    local tools target library
    tools=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
    target=$(cd "$tools/../.." && pwd)/target/qemu-plugins
    library=$target/lib$1.so
    if [ ! -f "$library" ] || [ "$tools/$1.c" -nt "$library" ] || [ "$tools/qemu-plugin-api.h" -nt "$library" ]; then
        mkdir -p "$target"
        gcc -O2 -fPIC -shared -fvisibility=hidden -Wall -o "$library.$$" "$tools/$1.c" || {
            rm -f "$library.$$"
            return 1
        }
        mv -f "$library.$$" "$library"
    fi
    printf '%s\n' "$library"
}
