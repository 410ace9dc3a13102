"""The real ArduCopter flies flyloop's hexacopter X and octocopter X (sitl/presets/
ardupilot_hexa_x.toml, ardupilot_octo_x.toml) with the FRAME_CLASS / FRAME_TYPE files
ardupilot_hexa_x.parm and ardupilot_octo_x.parm, which must be what
`flyloop-sitl --print-autopilot-params ardupilot` prints for each rotor table: GUIDED, arm,
takeoff to 5 m, hold, 10 m north, hold, LAND and ArduPilot's own disarm (issue 33)."""

from __future__ import annotations

import subprocess

import pytest
from ardupilot_support import (
    REPO,
    TAKEOFF_ALT,
    check_landed,
    fly_mission,
    truth_vs_estimate,
)

ALT = TAKEOFF_ALT


@pytest.mark.parametrize(
    "preset, rotors", [("ardupilot_hexa_x.toml", 6), ("ardupilot_octo_x.toml", 8)]
)
def test_ardupilot_flies_the_frame_preset_with_the_printed_parm(pair, sitl_binary, preset, rotors):
    frame = preset.removeprefix("ardupilot_").removesuffix(".toml")
    preset = REPO / "sitl" / "presets" / preset
    parm = preset.with_suffix(".parm")
    printed = subprocess.run(
        [str(sitl_binary), "--config", str(preset), "--print-autopilot-params", "ardupilot"],
        check=True,
        capture_output=True,
        text=True,
    ).stdout
    assert parm.read_text() == printed, f"{parm} differs from what flyloop-sitl prints"
    flyloop = pair.flyloop("--config", str(preset))
    ap = pair.ardupilot(flyloop, parm=parm)
    holds, rows = fly_mission(ap, flyloop)
    assert [k for k in rows[0] if k[0] == "m" and k[1:].isdigit()] == [
        f"m{i}" for i in range(rotors)
    ]
    flying = [r for r in rows if r["down"] < rows[0]["down"] - 4.0]
    assert flying and all(min(r[f"m{i}"] for r in flying) > 0.3 for i in range(rotors))
    for hold, (north, east) in holds:
        horizontal, vertical = hold.worst(north, east, ALT)
        assert vertical < 0.3, f"{frame}: altitude error {vertical:.3f} m at {north, east}"
        assert horizontal < 0.3, f"{frame}: position error {horizontal:.3f} m at {north, east}"
        error = truth_vs_estimate(rows, hold, 1)
        assert error < 0.5, f"{frame}: truth vs estimate {error:.3f} m at {north, east}"
        print(
            f"{frame} hold at {north, east}: altitude error {vertical:.3f} m, position error "
            f"{horizontal:.3f} m, truth vs estimate {error:.3f} m"
        )
    check_landed(rows, 10.0, 0.0)
