#!/usr/bin/env python3
"""The firmware's qemu runner for boards with a panel, and its helpers.

    runner.py info ELF KEY         print KEY (machine, output) of the ELF's
                                   .octrace_run section, written by build.rs
    runner.py screen ELF           run the LM3S6965EVB firmware, grab its OLED
                                   and write the panel's picture to the ELF's
                                   output (a PNG)
    runner.py convert DUMP PNG     convert a qemu screendump of the OLED (PPM)
                                   to the panel's own pixels

The screen grab: qemu runs headless (`-display none` keeps the display's
surface, which `screendump` reads) with a QMP monitor on a Unix socket in a
temporary directory, which is also qemu's working directory. When the guest
has drawn the whole picture it prints "octrace: screen ready" and waits; the
runner then has qemu `screendump` the panel, converts the dump, writes the
PNG (atomically: a failed run leaves no file), and creates the file
`octrace-screen-grabbed` there, on which the guest exits with its status
(0). An error in the guest (a bad scene: 2) ends qemu before the picture is
ready; the runner then writes nothing and exits with the guest's status.
Other exit codes: 124 when qemu runs longer than QEMU_TIMEOUT seconds
(default 600), 4 when the screen cannot be grabbed or is not what the panel
can show.

The conversion undoes exactly what qemu's SSD0323 model does when it draws:
each panel pixel becomes a 4×4 block (the dump is 512×256 for the 128×64
panel), and level i (0 to 15) is drawn as the gray (i << 4) | i = 17·i in
each of red, green and blue on the 32-bit surface a headless qemu uses. The
runner checks that every block is one uniform gray that is a multiple of 17,
recovers i, and writes an 8-bit gray PNG of 128×64 pixels holding 17·i —
the same value host-sim's `--color gray4` preview writes. Anything else is
an error, never a silently different picture.

Only the Python standard library: PNG through zlib.
"""

import json
import os
import socket
import struct
import subprocess
import sys
import tempfile
import threading
import time
import zlib

PANEL_WIDTH, PANEL_HEIGHT, MAGNIFY = 128, 64, 4
SCREEN_READY = b"octrace: screen ready"
GRABBED = "octrace-screen-grabbed"
EXIT_GRAB = 4
EXIT_TIMEOUT = 124


class GrabError(Exception):
    pass


def elf_section(path, name):
    """The contents of section `name` of a 32-bit little-endian ELF."""
    with open(path, "rb") as f:
        data = f.read()
    if data[:6] != b"\x7fELF\x01\x01":
        raise GrabError(f"{path}: not a 32-bit little-endian ELF")
    shoff, = struct.unpack_from("<I", data, 0x20)
    shentsize, shnum, shstrndx = struct.unpack_from("<HHH", data, 0x2E)

    def header(i):
        return struct.unpack_from("<IIIIIIIIII", data, shoff + i * shentsize)

    names = header(shstrndx)
    for i in range(shnum):
        h = header(i)
        start = names[4] + h[0]
        end = data.index(b"\0", start)
        if data[start:end] == name.encode():
            return data[h[4]:h[4] + h[5]]
    raise GrabError(f"{path}: no section {name} (built by an older firmware?)")


def elf_info(path):
    text = elf_section(path, ".octrace_run").decode()
    return dict(line.split("=", 1) for line in text.splitlines() if "=" in line)


def read_ppm(data):
    """Width, height and RGB bytes of a binary PPM (P6, maxval 255)."""
    fields, pos = [], 0
    while len(fields) < 4:
        while pos < len(data) and data[pos:pos + 1].isspace():
            pos += 1
        if data[pos:pos + 1] == b"#":
            pos = data.index(b"\n", pos)
            continue
        start = pos
        while pos < len(data) and not data[pos:pos + 1].isspace():
            pos += 1
        fields.append(data[start:pos])
    if fields[0] != b"P6" or fields[3] != b"255":
        raise GrabError("the screendump is not a P6 PPM with maxval 255")
    width, height = int(fields[1]), int(fields[2])
    pixels = data[pos + 1:]
    if len(pixels) != width * height * 3:
        raise GrabError("the screendump is truncated")
    return width, height, pixels


def panel_levels(width, height, rgb):
    """The panel's 128×64 gray levels (0 to 15) from qemu's magnified dump."""
    if (width, height) != (PANEL_WIDTH * MAGNIFY, PANEL_HEIGHT * MAGNIFY):
        raise GrabError(f"the screendump is {width}x{height}, not the OLED's {PANEL_WIDTH * MAGNIFY}x{PANEL_HEIGHT * MAGNIFY}")
    levels = bytearray()
    for y in range(PANEL_HEIGHT):
        for x in range(PANEL_WIDTH):
            block = set()
            for dy in range(MAGNIFY):
                row = (y * MAGNIFY + dy) * width
                for dx in range(MAGNIFY):
                    i = (row + x * MAGNIFY + dx) * 3
                    block.add(bytes(rgb[i:i + 3]))
            if len(block) != 1:
                raise GrabError(f"panel pixel ({x}, {y}) is not one uniform 4x4 block in the dump")
            r, g, b = block.pop()
            if not (r == g == b) or r % 17 != 0:
                raise GrabError(f"panel pixel ({x}, {y}) is ({r}, {g}, {b}), not a gray 17·i")
            levels.append(r // 17)
    return bytes(levels)


def png_gray8(width, height, pixels):
    def chunk(kind, body):
        return struct.pack(">I", len(body)) + kind + body + struct.pack(">I", zlib.crc32(kind + body))

    rows = b"".join(b"\0" + pixels[y * width:(y + 1) * width] for y in range(height))
    return (b"\x89PNG\r\n\x1a\n"
            + chunk(b"IHDR", struct.pack(">IIBBBBB", width, height, 8, 0, 0, 0, 0))
            + chunk(b"IDAT", zlib.compress(rows, 9))
            + chunk(b"IEND", b""))


def write_atomically(path, data):
    directory = os.path.dirname(os.path.abspath(path))
    fd, tmp = tempfile.mkstemp(dir=directory, prefix="." + os.path.basename(path) + ".", suffix=".tmp")
    try:
        with os.fdopen(fd, "wb") as f:
            f.write(data)
        # mkstemp makes the file private; give it the mode a new file gets.
        umask = os.umask(0)
        os.umask(umask)
        os.chmod(tmp, 0o666 & ~umask)
        os.replace(tmp, path)
    except BaseException:
        os.unlink(tmp)
        raise


def convert(dump_path, png_path):
    with open(dump_path, "rb") as f:
        width, height, rgb = read_ppm(f.read())
    levels = panel_levels(width, height, rgb)
    write_atomically(png_path, png_gray8(PANEL_WIDTH, PANEL_HEIGHT, bytes(17 * v for v in levels)))


class Qmp:
    """A minimal QMP client: one command at a time, events skipped."""

    def __init__(self, path):
        self.sock = socket.socket(socket.AF_UNIX)
        self.sock.settimeout(60)
        self.sock.connect(path)
        self.buffer = b""
        self.message()  # the greeting
        self.execute("qmp_capabilities")

    def message(self):
        while b"\n" not in self.buffer:
            more = self.sock.recv(65536)
            if not more:
                raise GrabError("qemu closed its QMP monitor")
            self.buffer += more
        line, self.buffer = self.buffer.split(b"\n", 1)
        return json.loads(line)

    def execute(self, command, **arguments):
        self.sock.sendall(json.dumps({"execute": command, "arguments": arguments}).encode() + b"\n")
        while True:
            reply = self.message()
            if "error" in reply:
                raise GrabError(f"qemu refused {command}: {reply['error'].get('desc', reply['error'])}")
            if "return" in reply:
                return reply["return"]


def screen(elf):
    info = elf_info(elf)
    output = info.get("output")
    if info.get("machine") != "lm3s6965evb" or not output:
        raise GrabError(f"{elf} is not firmware for the lm3s6965evb's OLED")
    timeout = float(os.environ.get("QEMU_TIMEOUT", "600"))
    with tempfile.TemporaryDirectory(prefix="octrace-oled-") as work:
        qmp_path = os.path.join(work, "qmp.sock")
        qemu = subprocess.Popen(
            ["qemu-system-arm", "-machine", "lm3s6965evb", "-display", "none",
             "-serial", "none", "-parallel", "none", "-monitor", "none",
             "-qmp", f"unix:{qmp_path},server=on,wait=off",
             "-semihosting-config", "enable=on,target=native", "-kernel", os.path.abspath(elf)],
            cwd=work, stdout=subprocess.PIPE, stderr=subprocess.STDOUT)
        ready = threading.Event()

        def forward():
            # Everything the guest prints goes on to our stdout as it comes.
            for line in qemu.stdout:
                sys.stdout.buffer.write(line)
                sys.stdout.buffer.flush()
                if line.strip() == SCREEN_READY:
                    ready.set()

        reader = threading.Thread(target=forward, daemon=True)
        reader.start()
        deadline = time.monotonic() + timeout
        while not ready.is_set() and qemu.poll() is None and time.monotonic() < deadline:
            ready.wait(0.05)
        if not ready.is_set():
            if qemu.poll() is None:
                qemu.kill()
                qemu.wait()
                print(f"runner: qemu still running after {timeout:g} s", file=sys.stderr)
                return EXIT_TIMEOUT
            reader.join()
            print(f"runner: the guest exited with {qemu.returncode} before showing a picture; nothing written",
                  file=sys.stderr)
            return qemu.returncode or EXIT_GRAB
        try:
            dump = os.path.join(work, "screen.ppm")
            Qmp(qmp_path).execute("screendump", filename=dump)
            convert(dump, output)
        except (GrabError, OSError, ValueError) as e:
            qemu.kill()
            qemu.wait()
            print(f"runner: cannot grab the screen: {e}", file=sys.stderr)
            return EXIT_GRAB
        open(os.path.join(work, GRABBED), "wb").close()
        try:
            status = qemu.wait(max(1.0, deadline - time.monotonic()))
        except subprocess.TimeoutExpired:
            qemu.kill()
            qemu.wait()
            return EXIT_TIMEOUT
        reader.join()
        print(f"runner: the panel's screen ({PANEL_WIDTH}x{PANEL_HEIGHT}, 16 grays) -> {output}")
        return status


def main(argv):
    try:
        if len(argv) == 4 and argv[1] == "info":
            print(elf_info(argv[2])[argv[3]])
            return 0
        if len(argv) == 3 and argv[1] == "screen":
            return screen(argv[2])
        if len(argv) == 4 and argv[1] == "convert":
            convert(argv[2], argv[3])
            return 0
    except (GrabError, OSError, KeyError) as e:
        print(f"runner: {e}", file=sys.stderr)
        return EXIT_GRAB
    print(__doc__.split("\n\n")[1], file=sys.stderr)
    return 2


if __name__ == "__main__":
    sys.exit(main(sys.argv))
