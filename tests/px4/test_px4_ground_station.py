"""A ground station flies flyloop's quadrotor through PX4: a real MAVProxy on PX4's
ground-station port (`mavproxy.py --master=udpout:127.0.0.1:18570+instance`, as docs/px4.md's
"Fly it with PX4" starts it) is typed what an operator types (arm, takeoff, fly to a point,
land), and PX4's reports, which MAVProxy forwards to the test, are checked against the targets
and against flyloop's ground truth.

Positions are compared in the NED frame around flyloop's home (the global positions PX4
reports, converted), so no local origin enters."""

from __future__ import annotations

import math
import time

from mavproxy_peer import MavProxy
from px4_support import (
    HOME,
    TAKEOFF_ALT,
    Estimate,
    LocalFrame,
    check_mission,
    collect,
    mavutil,
    settle,
)

# flyloop's frame: NED from its home; its truth needs no conversion.
FLYLOOP = LocalFrame(*HOME)


class Telemetry:
    """What MAVProxy forwards (`--out`) from PX4: a pymavlink link that only listens."""

    def __init__(self):
        self.link = mavutil.mavlink_connection("udpin:127.0.0.1:0", dialect="common")
        self.port = self.link.port.getsockname()[1]

    def wait_for(self, what: str, types: str | list[str], predicate, timeout: float):
        end = time.monotonic() + timeout
        while time.monotonic() < end:
            m = self.link.recv_match(type=types, blocking=True, timeout=0.2)
            if m is not None and predicate(m):
                return m
        raise AssertionError(f"PX4 did not report {what} within {timeout} s")

    def estimate(self) -> Estimate:
        """PX4's next GLOBAL_POSITION_INT, in flyloop's frame."""
        m = self.wait_for("a global position", "GLOBAL_POSITION_INT", lambda m: True, 30)
        ned = FLYLOOP.from_global(m.lat * 1e-7, m.lon * 1e-7, m.alt * 1e-3)
        return Estimate(m.time_boot_ms, ned, math.hypot(m.vx, m.vy, m.vz) / 100)

    def armed(self, armed: bool, timeout: float):
        flag = mavutil.mavlink.MAV_MODE_FLAG_SAFETY_ARMED

        def matches(m) -> bool:
            is_px4 = m.autopilot == mavutil.mavlink.MAV_AUTOPILOT_PX4
            return is_px4 and bool(m.base_mode & flag) == armed

        return self.wait_for(f"armed={armed}", "HEARTBEAT", matches, timeout)

    def close(self):
        self.link.close()


def until(what: str, attempt, timeout: float) -> None:
    """Repeats `attempt` (an operator retyping a command PX4 refused or a datagram that got
    lost) until it returns true."""
    end = time.monotonic() + timeout
    while time.monotonic() < end:
        try:
            if attempt():
                return
        except AssertionError:
            pass
    raise AssertionError(f"{what} did not happen within {timeout} s")


def command(gcs: MavProxy, telemetry: Telemetry, line: str, command_id: int) -> None:
    """Types `line` until PX4 acknowledges `command_id` as accepted (it refuses some while
    its state is changing, as an operator sees and retypes)."""

    def accepted(m) -> bool:
        return m.command == command_id and m.result == mavutil.mavlink.MAV_RESULT_ACCEPTED

    until(
        line,
        lambda: gcs.type(line) or telemetry.wait_for(line, "COMMAND_ACK", accepted, 2.0),
        30,
    )


def test_mavproxy_arms_takes_off_flies_to_a_point_and_lands_through_px4(pair, tmp_path):
    flyloop = pair.flyloop()
    px4 = pair.px4()
    telemetry = Telemetry()
    # MAVProxy talks first to PX4's ground-station port (18570 + instance), so PX4 answers it.
    gcs = MavProxy(
        tmp_path,
        f"--master=udpout:127.0.0.1:{18570 + px4.instance}",
        f"--out=udp:127.0.0.1:{telemetry.port}",
        "--nowait",
    )
    try:
        gcs.wait_for(f"Detected vehicle {px4.instance + 1}:1", 60)
        # Arm: PX4 refuses until its estimator has settled on the GPS; retype until armed.
        until("arming", lambda: gcs.type("arm throttle") or telemetry.armed(True, 2.0), 60)
        # Home (set at arming): MAVProxy asks for it, the test reads it from the forward.
        home = None

        def read_home() -> bool:
            nonlocal home
            gcs.type("long REQUEST_MESSAGE HOME_POSITION")
            home = telemetry.wait_for("its home", "HOME_POSITION", lambda m: True, 2.0)
            return True

        until("HOME_POSITION", read_home, 30)
        lat, lon, alt = home.latitude * 1e-7, home.longitude * 1e-7, home.altitude * 1e-3
        # Takeoff to TAKEOFF_ALT above home. PX4 reads NAV_TAKEOFF's param7 as metres above
        # MSL and params 5, 6 as the place (MAVProxy's own `takeoff` sends 0, 0 there, which
        # is a point in the Gulf of Guinea to PX4): NaN keeps the current one.
        takeoff = f"long NAV_TAKEOFF -1 0 0 nan nan nan {alt + TAKEOFF_ALT:.3f}"
        command(gcs, telemetry, takeoff, mavutil.mavlink.MAV_CMD_NAV_TAKEOFF)
        hover_target = FLYLOOP.from_global(lat, lon, alt + TAKEOFF_ALT)
        settle(telemetry, hover_target, 0.25, 60)
        collect(telemetry, 2.0)  # the climb's overshoot dies out
        hover = collect(telemetry, 2.0)
        # Fly to the point 10 m north of home: DO_REPOSITION in integer degE7 (COMMAND_INT).
        north = lat + math.degrees(10.0 / 6_378_137.0)
        point = f"{round(north * 1e7)} {round(lon * 1e7)} {alt + TAKEOFF_ALT:.3f}"
        goto = f"command_int GLOBAL DO_REPOSITION 0 0 -1 1 0 nan {point}"
        command(gcs, telemetry, goto, mavutil.mavlink.MAV_CMD_DO_REPOSITION)
        away_target = FLYLOOP.from_global(north, lon, alt + TAKEOFF_ALT)
        settle(telemetry, away_target, 0.25, 60)
        collect(telemetry, 2.0)
        away = collect(telemetry, 2.0)
        command(gcs, telemetry, "long NAV_LAND", mavutil.mavlink.MAV_CMD_NAV_LAND)
        telemetry.armed(False, 90)  # PX4 disarms by itself once landed
        time.sleep(0.5)  # a little rest on the ground in the track
    except AssertionError as e:
        console = f"MAVProxy:\n{gcs.console()}\nPX4:\n{px4.output()[-3000:]}"
        raise AssertionError(f"{e}\n{console}") from None
    finally:
        gcs.kill()
        telemetry.close()
    flyloop.stop()
    rows = flyloop.rows()

    check_mission(rows, [(hover, hover_target), (away, away_target)], FLYLOOP)
