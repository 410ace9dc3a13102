"""How far the live view in headless Chromium (SwiftShader, no GPU) runs behind a flight
(docs/view.md, "How far behind"): a SITL flight at `--speed` times real time, the view on its
ground-station stream, Chromium opened `--open-at` seconds into the flight; a screenshot at
each of `--shots` seconds. The viewer prints its own lag in its top bar ("N s latency"):
read it off the PNGs (`OUT/lag-<s>s.png`, and the top bar alone, `OUT/bar-<s>s.png`).

    PYTHONPATH=python .venv/bin/python benchmarks/view_lag.py --speed 4 --shots 60,120 OUT
"""

from __future__ import annotations

import argparse
import io
import os
import sys
import time
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO / "tests" / "view"))

from flight import Flight, View, free_port  # noqa: E402
from flyloop import find_sitl_binary  # noqa: E402
from flyloop.view.screenshot import Browser  # noqa: E402
from proc_cpu import machine_line  # noqa: E402


def top_bar(png: bytes) -> bytes:
    from PIL import Image

    img = Image.open(io.BytesIO(png))
    out = io.BytesIO()
    img.crop((0, 0, img.width // 2, 36)).save(out, format="PNG")
    return out.getvalue()


def main() -> int:
    a = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    a.add_argument("out", type=Path, help="a folder for the screenshots")
    a.add_argument("--speed", type=float, default=1.0, help="simulated s per wall s (1)")
    a.add_argument("--open-at", type=float, default=0.0, help="wall s into the flight (0)")
    a.add_argument("--shots", default="30,60,120", help="wall s of the screenshots")
    args = a.parse_args()
    args.out.mkdir(parents=True, exist_ok=True)
    shots = sorted(float(s) for s in args.shots.split(","))
    print(machine_line(), flush=True)
    gcs = free_port()
    view = View("--listen", f"127.0.0.1:{gcs}", "--wait", "120")
    flight = Flight(find_sitl_binary(build=True), gcs, period=0.01 / args.speed)
    browser = Browser()
    start = time.monotonic()
    opened = False
    try:
        for at in shots:
            # Up and down between 1.5 and 4 m every 10 s of wall time: the picture moves.
            while time.monotonic() - start < at:
                if not opened and time.monotonic() - start >= args.open_at:
                    browser.open(view.url)
                    opened = True
                up = int((time.monotonic() - start) // 10) % 2 == 0
                flight.fly_to([0.0, 0.0, -4.0 if up else -1.5])
                time.sleep(0.2)
            taken = time.monotonic() - start
            shot = browser.screenshot()
            (args.out / f"lag-{at:.0f}s.png").write_bytes(shot)
            (args.out / f"bar-{at:.0f}s.png").write_bytes(top_bar(shot))
            sim = flight.truth[-1][0] / 1e6
            print(
                f"shot at {taken:.0f} s wall (simulated {sim:.1f} s), load "
                f"{os.getloadavg()[0]:.1f}: {args.out / f'bar-{at:.0f}s.png'}",
                flush=True,
            )
    finally:
        browser.close()
        flight.stop()
        view.stop()
    return 0


if __name__ == "__main__":
    sys.exit(main())
