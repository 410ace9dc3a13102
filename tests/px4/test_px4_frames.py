"""The real PX4 flies flyloop's hexacopter X (sitl/presets/px4_hexa_x.toml) with the mixer
parameters `flyloop-sitl --print-autopilot-params px4` prints for its rotor table: takeoff,
hold, a 10 m leg and an automatic landing, PX4's estimate within 0.3 m of each target and
flyloop's truth within 0.5 m of PX4's estimate (issue 33)."""

from __future__ import annotations

from pathlib import Path

from px4_support import autopilot_params, check_mission, fly_mission

PRESET = Path(__file__).resolve().parents[2] / "sitl" / "presets" / "px4_hexa_x.toml"


def test_px4_flies_the_hexa_x_preset_with_the_printed_mixer(pair, sitl_binary):
    params = autopilot_params(sitl_binary, PRESET, "px4")
    assert params["CA_ROTOR_COUNT"] == "6" and params["PWM_MAIN_FUNC6"] == "106", params
    flyloop = pair.flyloop("--config", str(PRESET))
    px4 = pair.px4(**params)
    frame, holds, rows = fly_mission(px4, flyloop)
    assert [k for k in rows[0] if k[0] == "m" and k[1:].isdigit()] == [f"m{i}" for i in range(6)]
    # Every motor worked: each was above half its hover state in the hold.
    flying = [r for r in rows if r["down"] < rows[0]["down"] - 4.0]
    assert flying and all(min(r[f"m{i}"] for r in flying) > 0.3 for i in range(6))
    check_mission(rows, holds, frame)
    for hold, target in holds:
        h, v = hold.worst(target)
        print(f"hexa hold at {target}: position error {h:.3f} m, altitude error {v:.3f} m")
