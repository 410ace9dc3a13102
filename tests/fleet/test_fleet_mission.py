"""examples/fleet_mission.py flies 4 PX4s of one world on crossing legs at separated
altitudes: every leg end within 0.3 m, all land and disarm, no collision."""

from __future__ import annotations

import subprocess
import sys

from fleet_support import HOME
from test_fleet_px4 import EXAMPLE, start_fleet


def test_four_px4s_fly_the_crossing_legs_within_0_3_m(started, sitl_binary, px4_dir):
    sitl, px4s = start_fleet(started, sitl_binary, px4_dir, 4, talk=False)
    out = subprocess.run(
        [
            sys.executable,
            str(EXAMPLE),
            "--vehicles",
            "4",
            "--first-instance",
            str(px4s[0].instance),
            "--home",
            ",".join(str(v) for v in HOME[:3]),
        ],
        capture_output=True,
        text=True,
        timeout=600,
    )
    print(out.stdout)
    assert out.returncode == 0, out.stdout + out.stderr + sitl.stderr()[-3000:]
    lines = [line for line in out.stdout.splitlines() if line.startswith("vehicle ")]
    assert len(lines) == 4 and all("landed and disarmed" in line for line in lines), lines
    sitl.stop()
    assert sitl.counters()["collisions"] == "0"
