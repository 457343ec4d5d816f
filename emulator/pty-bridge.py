#!/usr/bin/env python3
"""A pseudo-terminal for the emulated Pico's USB serial port.

Prints the terminal's path (what a serial program opens: host-sim board,
picocom) as its first line on standard output, then relays bytes: what a
program writes to the terminal comes out on standard output, and what
arrives on standard input goes to the program. Ends when standard input
closes.

Invariants: the terminal is raw (no echo, no line editing, no newline
translation: every byte passes as it is); this process keeps the terminal's
own end open, so a program may close it and open it again (one `host-sim
board` after another) without ending the relay.
"""

import os
import select
import sys
import tty

def main() -> int:
    controller, terminal = os.openpty()
    tty.setraw(terminal)
    out = sys.stdout.buffer
    out.write(os.ttyname(terminal).encode() + b"\n")
    out.flush()
    stdin = sys.stdin.buffer.fileno()
    while True:
        readable, _, _ = select.select([controller, stdin], [], [])
        if stdin in readable:
            data = os.read(stdin, 65536)
            if not data:
                return 0
            view = memoryview(data)
            while view:
                view = view[os.write(controller, view):]
        if controller in readable:
            try:
                data = os.read(controller, 65536)
            except OSError:
                # Nobody has the terminal open right now: nothing to relay.
                continue
            out.write(data)
            out.flush()

if __name__ == "__main__":
    sys.exit(main())
