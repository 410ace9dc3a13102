"""A lossy UDP relay for tests: datagrams between one client and a SITL, of which a seeded
fraction is dropped and a few are held back and delivered after the next one (reordered),
in each direction.

    python lossy_relay.py --target 127.0.0.1:40123 --seed 7 --drop 0.02 --reorder 0.005

Prints `relay listen=HOST:PORT` on stdout once it listens (the client talks to that), and on
SIGTERM one line of counters on stdout: `relay stopped up=... down=... dropped_up=...
dropped_down=... reordered_up=... reordered_down=...` ("up" is client -> SITL).
"""

from __future__ import annotations

import argparse
import random
import select
import signal
import socket
import sys
import time

HOLD_SECONDS = 0.2  # a held datagram goes out after the next one, or after this at the latest


class Direction:
    def __init__(self, rng: random.Random, drop: float, reorder: float) -> None:
        self.rng, self.drop, self.reorder = rng, drop, reorder
        self.count = self.dropped = self.reordered = 0
        self.held: tuple[bytes, float] | None = None

    def route(self, data: bytes, send) -> None:
        """Drops, holds or sends `data`; a held datagram follows the next one sent."""
        self.count += 1
        r = self.rng.random()
        if r < self.drop:
            self.dropped += 1
            return
        if r < self.drop + self.reorder and self.held is None:
            self.reordered += 1
            self.held = (data, time.monotonic() + HOLD_SECONDS)
            return
        send(data)
        self.release(send)

    def release(self, send, now: float | None = None) -> None:
        if self.held is not None and (now is None or now >= self.held[1]):
            data, self.held = self.held[0], None
            send(data)


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--target", required=True, help="the SITL's HOST:PORT")
    ap.add_argument("--listen", default="127.0.0.1:0")
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--drop", type=float, default=0.02)
    ap.add_argument("--reorder", type=float, default=0.005)
    args = ap.parse_args()
    host, port = args.target.rsplit(":", 1)
    target = (host, int(port))
    lhost, lport = args.listen.rsplit(":", 1)

    front = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)  # the client talks to this
    front.bind((lhost, int(lport)))
    back = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)  # this talks to the SITL
    back.connect(target)
    for s in (front, back):
        s.setsockopt(socket.SOL_SOCKET, socket.SO_RCVBUF, 1 << 22)
    # One generator per direction, so the drops of one do not depend on traffic in the other.
    up = Direction(random.Random(args.seed * 2 + 1), args.drop, args.reorder)
    down = Direction(random.Random(args.seed * 2 + 2), args.drop, args.reorder)
    client: tuple[str, int] | None = None
    stopping = False

    def stop(*_: object) -> None:
        nonlocal stopping
        stopping = True

    signal.signal(signal.SIGTERM, stop)
    signal.signal(signal.SIGINT, stop)
    print(f"relay listen={front.getsockname()[0]}:{front.getsockname()[1]}", flush=True)

    def to_sitl(data: bytes) -> None:
        try:
            back.send(data)
        except OSError:  # the SITL is gone: as lossy as the link
            pass

    def to_client(data: bytes) -> None:
        if client is not None:
            front.sendto(data, client)

    while not stopping:
        try:
            ready, _, _ = select.select([front, back], [], [], 0.02)
        except InterruptedError:
            continue
        for s in ready:
            try:
                data, addr = s.recvfrom(1 << 16)
            except OSError:
                continue
            if s is front:
                client = addr
                up.route(data, to_sitl)
            else:
                down.route(data, to_client)
        now = time.monotonic()
        up.release(to_sitl, now)
        down.release(to_client, now)
    print(
        f"relay stopped up={up.count} down={down.count} dropped_up={up.dropped} "
        f"dropped_down={down.dropped} reordered_up={up.reordered} "
        f"reordered_down={down.reordered}",
        flush=True,
    )
    return 0


if __name__ == "__main__":
    sys.exit(main())
