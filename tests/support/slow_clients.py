#!/usr/bin/env python3
"""slow_clients.py PORT COUNT SECONDS [INTERVAL] -- COUNT clients that
each send an HTTP request to 127.0.0.1:PORT one header line every INTERVAL
seconds (default 1) and never finish it, for SECONDS in all; a connection
the server closes is opened again a tenth of a second later.  Once all COUNT are connected it
writes "connected" to stdout (flushed); at the end, a line
"opened N closed_by_server N longest S": connections opened, those the
server closed, and the longest any one stayed open (seconds)."""
import select
import socket
import sys
import time


def main():
    port, count, seconds = int(sys.argv[1]), int(sys.argv[2]), float(sys.argv[3])
    interval = float(sys.argv[4]) if len(sys.argv) > 4 else 1.0
    start = time.monotonic()
    end = start + seconds
    conns = {}  # socket -> [opened at, lines sent, next send]
    opened = closed = 0
    longest = 0.0
    said = False
    reopen = []  # when to open again the connections the server closed

    def open_one():
        nonlocal opened
        s = socket.create_connection(("127.0.0.1", port), timeout=5)
        s.setblocking(False)
        try:
            s.send(b"GET /state.json HTTP/1.1\r\nHost: 127.0.0.1\r\n")
        except OSError:
            pass
        now = time.monotonic()
        conns[s] = [now, 0, now + interval]
        opened += 1

    def drop(s, by_server):
        nonlocal closed, longest
        longest = max(longest, time.monotonic() - conns[s][0])
        closed += by_server
        if by_server:
            reopen.append(time.monotonic() + 0.1)
        del conns[s]
        s.close()

    while time.monotonic() < end:
        now = time.monotonic()
        reopen[:] = [t for t in reopen if t > now]
        while len(conns) + len(reopen) < count:
            try:
                open_one()
            except OSError:
                time.sleep(0.05)
                break
        if not said and len(conns) == count:
            print("connected", flush=True)
            said = True
        now = time.monotonic()
        wait = max(0.0, min([c[2] for c in conns.values()] + reopen + [end]) - now)
        readable, _, _ = select.select(list(conns), [], [], min(wait, 0.1))
        for s in readable:
            try:
                data = s.recv(4096)
            except OSError:
                data = b""
            if not data:  # closed (a reply would be a failure to hold it)
                drop(s, 1)
        now = time.monotonic()
        for s, c in list(conns.items()):
            if now >= c[2]:
                c[1] += 1
                c[2] = now + interval
                try:
                    s.send(b"X-Slow-%d: x\r\n" % c[1])
                except OSError:
                    drop(s, 1)
    for s in list(conns):
        drop(s, 0)
    print("opened %d closed_by_server %d longest %.1f" % (opened, closed, longest), flush=True)


if __name__ == "__main__":
    main()
