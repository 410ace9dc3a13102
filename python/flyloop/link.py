"""One UDP conversation with a SITL: send a datagram, collect the replies, never hang.

The socket is connected to the SITL, so a SITL that has gone away shows up at once as
ECONNREFUSED (loopback delivers the ICMP port-unreachable) instead of a silent wait; a SITL
that is alive but mute is caught by the reply timeout. Either way a SitlError says what
happened (exit code and stderr of our own child process when there is one).
"""

from __future__ import annotations

import os
import select
import socket
import time
from collections.abc import Callable

from .errors import SitlError
from .protocol import Datagram, Decoder, FrameSink, ProtocolError
from .sitl_process import SitlProcess

RECEIVE_BUFFER = 1 << 16
# How long to poll for a reply before sleeping in the kernel. A lockstep reply comes back in
# tens of microseconds; sleeping costs a wake-up on top (one more when the SITL runs on the
# other core), so a short busy wait is cheaper than it looks.
# FLYLOOP_SPIN_US sets it (0 = never spin, e.g. many envs on few cores).


def _spin_seconds(default_us: float = 100.0) -> float:
    try:
        us = float(os.environ.get("FLYLOOP_SPIN_US", default_us))
    except ValueError:
        us = default_us
    return min(max(us, 0.0), 10_000.0) * 1e-6


SPIN_SECONDS = _spin_seconds()
PROCESS_CHECK_SECONDS = 0.05

# Loss recovery (docs/protocol.md section 3): a request without a complete reply after
# RESEND_AFTER seconds is sent again, then after twice that, and so on, at most MAX_RESENDS
# times, all within the link's timeout. Every request an env sends is safe to repeat: steps
# are named by their time_usec (the SITL re-sends its cached reply for a step it has done),
# resets carry an explicit seed, parameter sets and requests are idempotent.
RESEND_AFTER = 0.02
MAX_RESENDS = 8


class SitlLink:
    """A controller link to the SITL at `address` (our own `process`, or None if attached)."""

    def __init__(
        self,
        address: tuple[str, int],
        *,
        timeout: float = 5.0,
        process: SitlProcess | None = None,
        spin: float = SPIN_SECONDS,
        resend_after: float = RESEND_AFTER,
        max_resends: int = MAX_RESENDS,
    ) -> None:
        if not timeout > 0:
            raise ValueError(f"timeout must be > 0 seconds, got {timeout!r}")
        if not resend_after > 0 or max_resends < 0:
            raise ValueError(
                f"resend_after must be > 0 s and max_resends >= 0, got {resend_after!r}, "
                f"{max_resends!r}"
            )
        self.address = address
        self.timeout = float(timeout)
        self.resend_after = float(resend_after)
        self.max_resends = int(max_resends)
        # Requests sent again for want of a reply, and datagrams from the SITL dropped as
        # late duplicates, since the link was made.
        self.resends = 0
        self.stale = 0
        self.process = process
        self.broken: str | None = None
        self.decoder = Decoder()
        self.spin = float(spin)
        family = socket.AF_INET6 if ":" in address[0] else socket.AF_INET
        self.sock = socket.socket(family, socket.SOCK_DGRAM)
        try:
            self.sock.setsockopt(socket.SOL_SOCKET, socket.SO_RCVBUF, 1 << 20)
            self.sock.connect(address)
            self.sock.setblocking(False)
        except OSError:
            self.sock.close()
            raise
        self._poll = select.poll()
        self._poll.register(self.sock, select.POLLIN)

    def close(self) -> None:
        self.sock.close()

    def _fail(self, what: str, cause: BaseException | None = None) -> SitlError:
        """The error for a lost SITL; the link refuses every later exchange."""
        where = f"{self.address[0]}:{self.address[1]}"
        if self.process is not None:
            code, tail = self.process.exit_report(grace=0.5)
            if code is not None:
                how = f"exited with code {code}"
                if code < 0:
                    how = f"was killed by signal {-code}"
                err = SitlError(
                    f"the SITL (pid {self.process.pid}, {where}) {how}: {what}",
                    exit_code=code,
                    stderr_tail=tail,
                )
            else:
                err = SitlError(
                    f"the SITL (pid {self.process.pid}, {where}) is running but {what}",
                    stderr_tail=tail,
                )
        else:
            err = SitlError(f"the SITL at {where} {what}")
        self.broken = str(err).splitlines()[0]
        if cause is not None:
            err.__cause__ = cause
        return err

    def check(self) -> None:
        if self.broken is not None:
            raise SitlError(
                f"this env lost its SITL earlier ({self.broken}); close it and make a new one"
            )

    def send(self, data: bytes) -> None:
        self.check()
        try:
            try:
                self.sock.send(data)
            except BlockingIOError:  # a full socket buffer: wait for room, once
                select.select([], [self.sock], [], self.timeout)
                self.sock.send(data)
        except OSError as exc:
            raise self._fail(f"cannot be sent to ({exc})", exc) from exc

    def exchange(
        self,
        data: bytes,
        done: Callable[[Datagram], bool],
        what: str = "a reply",
        sink: FrameSink | None = None,
    ) -> Datagram:
        """Sends `data` and collects replies until `done(collected)` holds, within the
        timeout; raises SitlError if the SITL dies or stays silent. Task frames go to
        `sink` (cleared first) when one is given."""
        self.check()
        if sink is not None:
            sink.clear()
        self._drain(what)
        out = Datagram()
        deadline = time.monotonic() + self.timeout
        wait = self.resend_after
        for attempt in range(self.max_resends + 1):
            if attempt:
                self.resends += 1
            self.send(data)
            until = deadline
            if attempt < self.max_resends:
                until = min(deadline, time.monotonic() + wait)
            if self._collect(out, done, what, sink, until):
                if sink is not None:
                    sink.commit()
                return out
            if time.monotonic() >= deadline:
                break
            wait *= 2
        resent = f" (sent {attempt + 1} times)" if attempt else ""
        raise self._fail(f"sent no {what} within {self.timeout:g} s{resent}")

    def _drain(self, what: str) -> None:
        """Drops datagrams that arrived since the last exchange was complete: late
        duplicates of replies already taken (a re-sent request whose first reply came after
        all). Cheap: one non-blocking read when, as usual, there is none."""
        while True:
            try:
                self.sock.recv(RECEIVE_BUFFER)
            except BlockingIOError:
                return
            except ConnectionRefusedError as exc:
                raise self._fail(
                    f"refused the datagram (nothing listens) while waiting for {what}", exc
                ) from exc
            except OSError as exc:
                raise self._fail(f"could not be read from ({exc})", exc) from exc
            self.stale += 1

    def _receive(self, deadline: float) -> bytes | None:
        """The next datagram, or None at the deadline: a short busy poll, then poll(2)."""
        recv = self.sock.recv
        try:
            return recv(RECEIVE_BUFFER)
        except BlockingIOError:
            pass
        if self.spin > 0:
            end = time.perf_counter() + self.spin
            while time.perf_counter() < end:
                try:
                    return recv(RECEIVE_BUFFER)
                except BlockingIOError:
                    pass
        while True:
            left = deadline - time.monotonic()
            if left <= 0:
                return None
            if self.process is not None:
                # Our own child may die with our datagram unread (no ICMP then): look at it
                # every so often instead of waiting out the whole timeout.
                left = min(left, PROCESS_CHECK_SECONDS)
            if self._poll.poll(left * 1000.0 + 1.0):
                try:
                    return recv(RECEIVE_BUFFER)
                except BlockingIOError:
                    continue
            elif self.process is not None and self.process.poll() is not None:
                return None

    def _collect(
        self,
        out: Datagram,
        done: Callable[[Datagram], bool],
        what: str,
        sink: FrameSink | None,
        deadline: float,
    ) -> bool:
        """Replies into `out` until `done(out)` holds (True) or the deadline (False)."""
        while True:
            try:
                reply = self._receive(deadline)
            except ConnectionRefusedError as exc:
                raise self._fail(
                    f"refused the datagram (nothing listens) while waiting for {what}", exc
                ) from exc
            except OSError as exc:
                raise self._fail(f"could not be read from ({exc})", exc) from exc
            if reply is None:
                if self.process is not None and self.process.poll() is not None:
                    raise self._fail(f"while this env waited for {what}")
                return False
            try:
                self.decoder.decode(reply, out, sink)
            except ProtocolError as exc:
                raise self._fail(f"sent a datagram this client cannot read: {exc}", exc) from exc
            if done(out):
                return True
