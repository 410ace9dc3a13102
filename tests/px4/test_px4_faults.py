"""Issue 35: the real PX4 v1.16.0 flies through faults flyloop injects on its control link
(`--control`): it loses GPS while it holds a hover. What PX4 reports (its console, its modes)
and what it does (its failsafe; flyloop's truth) are printed and checked; docs/faults.md
quotes them. PX4's offboard link (where the test listens) carries no STATUSTEXT: its words
are read from its console."""

from __future__ import annotations

import time
from pathlib import Path

from control_link import GPS, MOTOR, OFF, control_link, inject
from px4_support import SPEED, autopilot_params, collect, launch, settle
from pymavlink import mavutil


def px4_texts(px4, seconds: float) -> list[tuple[float, str, int]]:
    """PX4's STATUSTEXTs and mode changes over `seconds` of wall time: (wall s, text,
    custom_mode of the latest heartbeat)."""
    out = []
    mode = None
    end = time.monotonic() + seconds
    start = time.monotonic()
    while time.monotonic() < end:
        m = px4.link.recv_match(type=["STATUSTEXT", "HEARTBEAT"], blocking=True, timeout=0.2)
        if m is None or m.get_srcSystem() != px4.target:
            continue
        if m.get_type() == "HEARTBEAT":
            if m.custom_mode != mode:
                mode = m.custom_mode
                out.append((time.monotonic() - start, f"mode {mode:#010x}", mode))
            continue
        out.append((time.monotonic() - start, m.text, mode))
    return out


# PX4's custom_mode of AUTO.LAND (main mode 4 AUTO in bits 16-23, sub mode 6 LAND in 24-31).
AUTO_LAND = 0x06040000


def test_px4_loses_gps_in_a_hover_and_lands(pair):
    flyloop = pair.flyloop("--control", "127.0.0.1:0")
    px4 = pair.px4()
    _, target = launch(px4)
    settle(px4, target, 0.5, 60)
    console_before = len(px4.output())
    link = control_link(flyloop)
    ack, text = inject(link, GPS, OFF)
    assert ack is not None and ack.result == mavutil.mavlink.MAV_RESULT_ACCEPTED, ack
    assert text == "fault injected: sensor_off:gps", text
    events = px4_texts(px4, 25)
    for t, what, _ in events:
        print(f"{t * SPEED:6.1f} s after the fault (simulation)  {what}")
    console = px4.output()[console_before:]
    said = [line for line in console.splitlines() if "WARN" in line or "INFO" in line]
    print("PX4's console after the fault:", *said, sep="\n  ")
    flyloop.stop()
    rows = flyloop.rows()
    print(f"truth at the end: down {rows[-1]['down']:.2f} m, grounded {rows[-1]['grounded']}")
    # PX4 switches to AUTO.LAND and puts the vehicle down.
    assert any(mode == AUTO_LAND for _, _, mode in events), events
    assert rows[-1]["grounded"] == 1.0, rows[-1]
    assert "Failsafe: blind land" in console and "Disarmed by landing" in console, said


HEXA = Path(__file__).resolve().parents[2] / "sitl" / "presets" / "px4_hexa_x.toml"


def test_px4_hexa_loses_motor_1_in_a_hover_and_lands(pair, sitl_binary):
    params = autopilot_params(sitl_binary, HEXA, "px4")
    flyloop = pair.flyloop("--config", str(HEXA), "--control", "127.0.0.1:0")
    px4 = pair.px4(**params)
    _, target = launch(px4)
    settle(px4, target, 0.5, 60)
    console_before = len(px4.output())
    ack, text = inject(control_link(flyloop), MOTOR, OFF, 1)
    assert ack is not None and ack.result == mavutil.mavlink.MAV_RESULT_ACCEPTED, ack
    assert text == "fault injected: motor_off:1", text
    hold = collect(px4, 10.0)
    h, v = hold.worst(target)
    print(f"hexa without motor 1, 10 s hold: position error {h:.3f} m, altitude error {v:.3f} m")
    px4.land()
    px4.wait_for(
        "the automatic disarm after landing",
        lambda m: m.get_srcSystem() == px4.target and not px4.armed(m),
        60,
        "HEARTBEAT",
    )
    console = px4.output()[console_before:]
    said = [line for line in console.splitlines() if "WARN" in line or "INFO" in line]
    print("PX4's console after the fault:", *said, sep="\n  ")
    flyloop.stop()
    rows = flyloop.rows()
    flying = [r for r in rows if r["down"] < rows[0]["down"] - 3.0]
    print(f"motor 1 state in flight after the fault: {flying[-1]['m0']:.4f}")
    off = [r for r in flying if r["m0"] < 0.01]
    heights = [rows[0]["down"] - r["down"] for r in off]
    print(
        f"truth with motor 1 off: height {min(heights):.2f} to {max(heights):.2f} m, "
        f"{len(off)} rows"
    )
    assert flying[-1]["m0"] < 0.01, flying[-1]
    assert rows[-1]["grounded"] == 1.0, rows[-1]
