"""Issue 35: the real ArduCopter 4.6.0 flies through faults. ArduPilot loses its GPS in a
GUIDED hover; a hexa loses motor 1 in a hover. What ArduPilot says (its STATUSTEXTs) and does
(its modes; flyloop's truth) are printed and checked; docs/faults.md quotes them.

ArduPilot's GPS is not flyloop's: in the JSON backend ArduPilot computes GPS, baro and mag
itself from the position flyloop sends (its SITL::GPS), and the JSON frame has no GPS field to
withhold. So flyloop's control link refuses FAILURE_UNIT_SENSOR_GPS naming ArduPilot's own
switch, and the test takes the GPS away the way a ground station does: SIM_GPS_DISABLE = 1
(ArduCopter 4.6's name) over ArduPilot's MAVLink link."""

from __future__ import annotations

import math
import time

from ardupilot_support import GUIDED, LAND, REPO, TAKEOFF_ALT, collect, settle
from control_link import GPS, MOTOR, OFF, control_link, inject
from pymavlink import mavutil

# ArduCopter's flight modes by number (the ones these flights pass through).
MODES = {0: "STABILIZE", 2: "ALT_HOLD", 3: "AUTO", 4: "GUIDED", 5: "LOITER", 9: "LAND"}


def distance(row) -> float:
    """Horizontal distance of a track row from home, m."""
    return math.hypot(row["north"], row["east"])


def tilt(row) -> float:
    """Tilt of a track row from level, deg."""
    return math.degrees(math.hypot(row["roll"], row["pitch"]))


def take_off(ap) -> None:
    """GUIDED, arm, takeoff to TAKEOFF_ALT and a settled hover above home."""
    ap.wait_for_gps(120)
    ap.mode(GUIDED)
    ap.arm()
    ap.takeoff()
    settle(ap, 0.0, 0.0, TAKEOFF_ALT, 0.25, 60)
    collect(ap, 1.0)


def watch(ap, seconds: float, until=None, servos=None) -> list[tuple[float, str]]:
    """ArduPilot's STATUSTEXTs, mode changes and disarm over `seconds` of wall time, or until
    `until(events, now)` holds (now: ArduPilot's clock, s): (ArduPilot's clock in s, what).
    `servos`, a list, gets ArduPilot's servo outputs 1-6 (µs) every 0.5 s: (time µs, PWMs)."""
    out: list[tuple[float, str]] = []
    mode, armed = None, None
    now = ap.estimate().time_ms / 1000
    end = time.monotonic() + seconds
    while time.monotonic() < end and not (until and until(out, now)):
        m = ap.link.recv_match(blocking=True, timeout=0.2)
        if m is None or m.get_srcSystem() != ap.target:
            continue
        if hasattr(m, "time_boot_ms"):
            now = m.time_boot_ms / 1000
        if m.get_type() == "STATUSTEXT":
            ap.texts.append(m.text)
            out.append((now, m.text))
        elif m.get_type() == "SERVO_OUTPUT_RAW" and servos is not None:
            if not servos or m.time_usec - servos[-1][0] >= 500_000:
                servos.append((m.time_usec, [getattr(m, f"servo{i}_raw") for i in range(1, 7)]))
        elif m.get_type() == "HEARTBEAT" and m.type != mavutil.mavlink.MAV_TYPE_GCS:
            if m.custom_mode != mode:
                mode = m.custom_mode
                out.append((now, f"mode {MODES.get(mode, mode)}"))
            if ap.armed(m) != armed:
                armed = ap.armed(m)
                out.append((now, "armed" if armed else "disarmed"))
    return out


def disarmed(events, _now) -> bool:
    return any(what == "disarmed" for _, what in events)


def show(events: list[tuple[float, str]], since: float) -> None:
    for t, what in events:
        print(f"  {t - since:6.1f} s  {what}")


def set_param(ap, name: str, value: float) -> None:
    """PARAM_SET until ArduPilot echoes the value."""
    for _ in range(10):
        ap.link.mav.param_set_send(
            ap.target, 1, name.encode(), value, mavutil.mavlink.MAV_PARAM_TYPE_REAL32
        )
        m = ap.link.recv_match(type="PARAM_VALUE", blocking=True, timeout=1)
        if m is not None and m.param_id == name and m.param_value == value:
            return
    raise AssertionError(f"ArduPilot did not take {name} = {value}:\n{ap.report()}")


def test_ardupilot_loses_gps_in_a_guided_hover_and_lands(pair):
    flyloop = pair.flyloop("--control", "127.0.0.1:0")
    ap = pair.ardupilot(flyloop)
    take_off(ap)
    # flyloop cannot take ArduPilot's GPS: it says so and names ArduPilot's own switch.
    ack, text = inject(control_link(flyloop), GPS, OFF)
    assert ack is not None and ack.result == mavutil.mavlink.MAV_RESULT_UNSUPPORTED, ack
    print(f"flyloop: {text}")
    assert text is not None and "SIM_GPS" in text, text
    set_param(ap, "SIM_GPS_DISABLE", 1)
    start = ap.estimate().time_ms / 1000
    events = watch(ap, 60, until=disarmed)
    print("ArduPilot after SIM_GPS_DISABLE = 1 (s of its clock):")
    show(events, start)
    time.sleep(0.5)
    flyloop.stop()
    rows = flyloop.rows()
    last = rows[-1]
    print(f"truth at the end: {distance(last):.2f} m from home, grounded {last['grounded']}")
    said = [w for _, w in events]
    assert "mode LAND" in said and "disarmed" in said, said
    assert any("EKF Failsafe" in w for w in said), said
    assert last["grounded"] == 1.0 and max(last[f"m{i}"] for i in range(4)) < 0.01, last


HEXA = REPO / "sitl" / "presets" / "ardupilot_hexa_x.toml"
# Seconds of ArduPilot's clock the hexa holds on five motors before it is told to land, and
# the longest its landing from 5 m may take before the test disarms it.
HOLD_S, LAND_S = 10.0, 15.0


def disarm(ap) -> list[tuple[float, str]]:
    """Asks ArduPilot to disarm (it refuses while its land detector says it flies), then
    forces it (MAV_CMD_COMPONENT_ARM_DISARM's 21196); what it said on the way."""
    arm = mavutil.mavlink.MAV_CMD_COMPONENT_ARM_DISARM
    events = []
    for force in (0, 21196):
        ap.command(arm, 0, force)
        ack = ap.wait_for("the disarm's ack", lambda m: m.command == arm, 10, "COMMAND_ACK")
        events.append(
            (
                ap.estimate().time_ms / 1000,
                f"disarm{' forced' if force else ''}: result {ack.result}",
            )
        )
        events += watch(ap, 5, until=disarmed)
        if disarmed(events, 0):
            break
    return events


def test_ardupilot_hexa_loses_motor_1_in_a_hover_and_lands(pair):
    flyloop = pair.flyloop("--config", str(HEXA), "--control", "127.0.0.1:0")
    ap = pair.ardupilot(flyloop, parm=HEXA.with_suffix(".parm"))
    take_off(ap)
    start = ap.estimate().time_ms / 1000
    ack, text = inject(control_link(flyloop), MOTOR, OFF, 1)
    assert ack is not None and ack.result == mavutil.mavlink.MAV_RESULT_ACCEPTED, ack
    assert text == "fault injected: motor_off:1", text
    servos: list = []
    held = watch(ap, 60, until=lambda _e, now: now - start >= HOLD_S, servos=servos)
    ap.mode(LAND)
    land_start = ap.estimate().time_ms / 1000
    landing = watch(ap, 60, until=lambda e, now: disarmed(e, now) or now - land_start > LAND_S)
    if not disarmed(landing, 0):
        landing += disarm(ap)
    print("ArduPilot after motor 1 went off (s of its clock):")
    show(held + landing, start)
    time.sleep(0.5)
    flyloop.stop()
    rows = flyloop.rows()
    hold = [r for r in rows if start * 1e6 <= r["time_us"] < land_start * 1e6]
    down = [r for r in rows if r["time_us"] >= land_start * 1e6]
    ground = rows[0]["down"]
    heights = [ground - r["down"] for r in hold]
    last = rows[-1]
    fired = next(r for r in hold if r["m0"] < 0.01)["time_us"]
    touch = next((r["time_us"] for r in rows if r["time_us"] > fired and r["grounded"]), None)
    if touch is not None:
        print(f"the truth touches the ground {(touch - fired) / 1e6:.1f} s after motor 1 stopped")
    print(
        f"truth in the {HOLD_S:.0f} s hold on five motors: height {min(heights):.2f} to "
        f"{max(heights):.2f} m, up to {max(distance(r) for r in hold):.2f} m from home, "
        f"tilt up to {max(tilt(r) for r in hold):.1f} deg, motor 1 state "
        f"{max(r['m0'] for r in hold[len(hold) // 2 :]):.4f}; landing: tilt up to "
        f"{max(tilt(r) for r in down):.1f} deg; at the end {distance(last):.2f} m from home, "
        f"tilt {tilt(last):.1f} deg, grounded {last['grounded']}"
    )
    print("ArduPilot's servo outputs 1-6 in the hold (µs):")
    for t, pwm in servos[::2]:
        print(f"  {t / 1e6 - start:5.1f} s  {pwm}")
    said = [w for _, w in held + landing]
    assert "mode LAND" in said and "disarmed" in said, said
    assert max(r["m0"] for r in hold[len(hold) // 2 :]) < 0.01
    assert last["grounded"] == 1.0 and max(last[f"m{i}"] for i in range(6)) < 0.01, last
    # ArduCopter's mixer answers the dead motor the same way every run: servo 1 at its
    # maximum, the opposite servo 2 near its minimum (1150-1263 µs seen), hundreds of µs
    # below the four left (1596-1757 µs); on those four the hexa comes down.
    late = [pwm for t, pwm in servos if t / 1e6 - start >= HOLD_S / 2]
    assert late and all(p[0] >= 1900 and p[1] + 200 < min(p[2:]) for p in late), late
    assert touch is not None and touch < land_start * 1e6, "the hexa held on five motors"
    # Where it ends is not asserted: in LAND, when ArduPilot's land detector does not fire,
    # its motors lift the hexa off again and it hops (tilt up to 78°) until it is disarmed;
    # it came to rest 0.3-13.8 m from home in nine runs (docs/faults.md).
