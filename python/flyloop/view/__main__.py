"""python -m flyloop.view: a running simulation (or a recording) in the browser, live.

    python -m flyloop.view                  # a SITL's ground-station stream, udp 127.0.0.1:14550
    python -m flyloop.view --listen 127.0.0.1:14551 --listen 127.0.0.1:14550   # + PX4's stream
    python -m flyloop.view run.tlog                # replay a recording (.tlog or .rrd)
    python -m flyloop.view --save run.rrd          # watch and record

It prints the URL to open. docs/view.md says more."""

from __future__ import annotations

import argparse
import signal
import sys
import time
from pathlib import Path

from . import Viewer, ViewError


def _address(text: str) -> tuple[str, int]:
    host, _, port = text.rpartition(":")
    try:
        return host or "127.0.0.1", int(port)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected HOST:PORT, got {text!r}") from None


def parse_args(argv: list[str] | None) -> argparse.Namespace:
    p = argparse.ArgumentParser(prog="python -m flyloop.view", description=__doc__.split("\n\n")[0])
    p.add_argument(
        "file", nargs="?", help="a recording to replay (.tlog from flyloop-sitl --record, or .rrd)"
    )
    p.add_argument(
        "--listen",
        type=_address,
        action="append",
        help="UDP HOST:PORT where MAVLink arrives (repeatable; default 127.0.0.1:14550, "
        "the SITL's --gcs target)",
    )
    p.add_argument(
        "--connect",
        type=_address,
        action="append",
        default=[],
        help="an autopilot's MAVLink HOST:PORT to talk to first (PX4's ground-station port "
        "18570 + instance), repeatable",
    )
    p.add_argument(
        "--web-port", type=int, default=9090, help="the viewer's HTTP port (default 9090)"
    )
    p.add_argument(
        "--grpc-port", type=int, default=9876, help="the data's gRPC port (default 9876)"
    )
    p.add_argument("--save", help="also write what is shown to this .rrd file")
    p.add_argument(
        "--wait",
        type=float,
        default=30.0,
        help="seconds to wait for the first MAVLink message before giving up (default 30)",
    )
    p.add_argument(
        "--seconds", type=float, help="stop after this many seconds (default: at Ctrl-C)"
    )
    return p.parse_args(argv)


def _stop(signum: int, frame) -> None:
    raise KeyboardInterrupt


def main(argv: list[str] | None = None) -> int:
    args = parse_args(argv)
    # Ctrl-C and a supervisor's SIGTERM both end the watch with the recording written out,
    # also when started from a script whose background jobs ignore SIGINT (Python then
    # leaves it ignored, and the view could only be killed, its .rrd cut short).
    signal.signal(signal.SIGINT, signal.default_int_handler)
    signal.signal(signal.SIGTERM, _stop)
    if args.file and not Path(args.file).is_file():  # before a URL is printed for nothing
        print(f"flyloop.view: {args.file}: no such file", file=sys.stderr)
        return 1
    try:
        viewer = Viewer(web_port=args.web_port, grpc_port=args.grpc_port, save=args.save)
    except ViewError as e:
        print(f"flyloop.view: {e}", file=sys.stderr)
        return 1
    print(f"flyloop.view: open {viewer.url}", flush=True)
    try:
        if args.file:
            n = viewer.replay(args.file)
            what = "chunks" if args.file.endswith(".rrd") else "messages"
            print(f"flyloop.view: {args.file}: {n} {what} replayed", flush=True)
            _serve(args.seconds)
        else:
            listen = args.listen or ([] if args.connect else [("127.0.0.1", 14550)])
            viewer.watch(listen, connect=args.connect, wait=args.wait, seconds=args.seconds)
    except ViewError as e:
        print(f"flyloop.view: {e}", file=sys.stderr)
        return 1
    except KeyboardInterrupt:
        pass
    finally:
        viewer.close()
    return 0


def _serve(seconds: float | None) -> None:
    end = time.monotonic() + (seconds if seconds is not None else float("inf"))
    while time.monotonic() < end:
        time.sleep(min(0.5, max(0.0, end - time.monotonic())))


if __name__ == "__main__":
    sys.exit(main())
