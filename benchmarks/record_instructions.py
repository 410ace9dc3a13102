"""What `flyloop-sitl --record` adds per lockstep step, in instructions (callgrind: repeatable
whatever else the machine does): the SITL under valgrind, stepped 1,000 and 4,000 times by a
pymavlink client (state + frame per reply), with and without a recording; the difference of
the totals over 3,000 steps. Figures in docs/performance.md.

    .venv/bin/python benchmarks/record_instructions.py
"""

from __future__ import annotations

import os
import re
import signal
import socket
import subprocess
import sys
import tempfile
from pathlib import Path

os.environ["MAVLINK20"] = "1"
from pymavlink.dialects.v20 import common as mavlink2  # noqa: E402

REPO = Path(__file__).resolve().parents[1]


def instructions(extra: list[str], steps: int) -> int:
    """Total instructions of a SITL run of `steps` lockstep steps."""
    with tempfile.TemporaryDirectory() as tmp:
        out = Path(tmp) / "callgrind.out"
        binary = REPO / "target" / "release" / "flyloop-sitl"
        cmd = ["valgrind", "--tool=callgrind", f"--callgrind-out-file={out}", str(binary)]
        cmd += ["--listen", "127.0.0.1:0", "--gcs", "off", *extra]
        proc = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.DEVNULL, text=True)
        host, port = proc.stdout.readline().split("listen=")[1].split()[0].rsplit(":", 1)
        sock = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
        sock.settimeout(30)
        mav = mavlink2.MAVLink(None, srcSystem=1)
        controls = mav.hil_actuator_controls_encode(0, [0.5] * 4 + [0.0] * 12, 0, 1).pack(mav)
        for _ in range(steps):
            sock.sendto(controls, (host, int(port)))
            sock.recvfrom(65536)
        sock.close()
        proc.send_signal(signal.SIGINT)
        proc.wait(timeout=60)
        text = out.read_text()
    return int(re.search(r"^(?:summary|totals): (\d+)", text, re.M).group(1))


def main() -> int:
    per_step = {}
    with tempfile.TemporaryDirectory() as tmp:
        for name, extra in (("base", []), ("record", ["--record", f"{tmp}/run.tlog"])):
            a, b = instructions(extra, 1000), instructions(extra, 4000)
            per_step[name] = (b - a) / 3000
            print(f"{name:6s} {per_step[name]:8.0f} instructions per step", flush=True)
    print(f"record / base = {per_step['record'] / per_step['base']:.3f}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
