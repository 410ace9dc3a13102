"""Fly a trained rates policy through PX4 in offboard mode: PX4 keeps its estimator, rate
loop, mixer and failsafes; the policy replaces its position and attitude loops.

    python examples/px4_offboard.py POLICY_DIR --connect udpin:0.0.0.0:14540 \\
        [--waypoints "N,E,U;N,E,U;..."] [--hold SECONDS]

The script waits for PX4 (heartbeat, then an estimator ready to arm), arms and takes off with
PX4's own takeoff, streams the policy's setpoints before it asks for OFFBOARD, then runs the
policy on PX4's estimate (LOCAL_POSITION_NED, ATTITUDE_QUATERNION) and sends
SET_ATTITUDE_TARGET (body rates + collective thrust, attitude ignored) once per policy period
of PX4's clock. With `--controller px4` the same targets go to PX4's own position controller
(SET_POSITION_TARGET_LOCAL_NED), for comparison.

Waypoints are north, east, up metres from PX4's home; the target moves to each at `--speed`
m/s, settles for `--settle` s, then holds it for `--hold` s while the error is measured. At
the end, on Ctrl-C or on any error, control goes back to PX4: position hold
(AUTO.LOITER), then landing.

Prints `waypoint i: hold error mean X m, max Y m` per waypoint (distance of PX4's position
estimate from the waypoint during its hold), then `mean hold error M m` and, last,
`max hold error Z m` (the largest distance of all holds). On stderr it says each phase as
it starts: waiting for PX4, arming, the takeoff, the switch to OFFBOARD, each waypoint.
Exit codes: 0 flown, 2 PX4 not reachable or not ready, 3 offboard refused or lost, 4
telemetry stopped, 130 interrupted.

Nothing here depends on flyloop: the same script flies a real PX4 vehicle (pymavlink and numpy
only; the policy is a numpy MLP in POLICY_DIR/policy.npz with its interface in
POLICY_DIR/policy.json). Test it in simulation first.
"""

from __future__ import annotations

import argparse
import json
import math
import os
import sys
import time
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

os.environ.setdefault("MAVLINK20", "1")
from pymavlink import mavutil  # noqa: E402

MAV = mavutil.mavlink
# PX4's custom modes (main mode << 16 | sub mode << 24).
PX4_OFFBOARD = 6 << 16
PX4_AUTO_LOITER = (4 << 16) | (3 << 24)
PX4_AUTO_TAKEOFF = (4 << 16) | (2 << 24)
# SET_ATTITUDE_TARGET type_mask: attitude ignored; body rates and thrust used.
ATTITUDE_IGNORE = 128
# SET_POSITION_TARGET_LOCAL_NED type_mask: position only (velocity, acceleration, yaw and yaw
# rate ignored).
POSITION_ONLY = 8 | 16 | 32 | 64 | 128 | 256 | 1024 | 2048


class FlightError(Exception):
    """A reason to stop flying, with the exit code it maps to."""

    def __init__(self, message: str, code: int) -> None:
        super().__init__(message)
        self.code = code


# ---- the policy ----


@dataclass
class Policy:
    """A tanh MLP with observation normalisation; actions in [-1, 1] mapped to the
    interface's bounds."""

    weights: list[tuple[np.ndarray, np.ndarray]]
    obs_mean: np.ndarray
    obs_std: np.ndarray
    action_low: np.ndarray
    action_high: np.ndarray
    dt: float
    layout: str

    @classmethod
    def load(cls, folder: Path) -> Policy:
        meta = json.loads((folder / "policy.json").read_text())
        if meta.get("interface") != "px4-rates-v1":
            raise FlightError(
                f"{folder}: not a rates policy (interface {meta.get('interface')!r})", 2
            )
        data = np.load(folder / "policy.npz")
        layers = int(data["layers"])
        weights = [(data[f"w{i}"], data[f"b{i}"]) for i in range(layers)]
        return cls(
            weights,
            data["obs_mean"],
            np.sqrt(data["obs_var"] + 1e-8),
            np.asarray(meta["action_low"], float),
            np.asarray(meta["action_high"], float),
            float(meta["dt"]),
            meta["observation"],
        )

    def __call__(self, obs: np.ndarray) -> np.ndarray:
        x = np.clip((obs - self.obs_mean) / self.obs_std, -10, 10)
        for i, (w, b) in enumerate(self.weights):
            x = x @ w.T + b
            if i < len(self.weights) - 1:
                x = np.tanh(x)
        unit = np.clip(x, -1.0, 1.0)
        return self.action_low + (unit + 1.0) * 0.5 * (self.action_high - self.action_low)


# ---- PX4's estimate as the policy sees it ----


def euler(q: tuple[float, float, float, float]) -> tuple[float, float, float]:
    """Roll, pitch, yaw (ZYX) of a body FRD → world NED quaternion w, x, y, z."""
    w, x, y, z = q
    roll = math.atan2(2 * (w * x + y * z), 1 - 2 * (x * x + y * y))
    pitch = math.asin(max(-1.0, min(1.0, 2 * (w * y - z * x))))
    yaw = math.atan2(2 * (w * z + x * y), 1 - 2 * (y * y + z * z))
    return roll, pitch, yaw


def heading(yaw: float, v: np.ndarray) -> np.ndarray:
    """A world NED vector in the heading frame (x forward, y right, horizontal; z down)."""
    c, s = math.cos(yaw), math.sin(yaw)
    return np.array([c * v[0] + s * v[1], -s * v[0] + c * v[1], v[2]])


def observation(position, velocity, q, rates, target, previous) -> np.ndarray:
    """The 16 values of flyloop's rates interface from an estimate in PX4's frames:
    target − position and velocity in the heading frame, the body's down axis in the heading
    frame, body rates FRD, the previous action."""
    roll, pitch, yaw = euler(q)
    down = np.array(
        [math.sin(pitch) * math.cos(roll), -math.sin(roll), math.cos(pitch) * math.cos(roll)]
    )
    return np.concatenate(
        [
            heading(yaw, np.asarray(target) - np.asarray(position)),
            heading(yaw, np.asarray(velocity)),
            down,
            np.asarray(rates, float),
            np.asarray(previous, float),
        ]
    )


# ---- the link to PX4 ----


@dataclass
class State:
    """The latest estimate PX4 sent, and PX4's clock (ms since boot) at it."""

    position: np.ndarray | None = None
    velocity: np.ndarray | None = None
    q: tuple[float, float, float, float] | None = None
    rates: np.ndarray = field(default_factory=lambda: np.zeros(3))
    time_ms: int = 0
    wall: float = 0.0
    custom_mode: int = 0
    heartbeat: bool = False
    armed: bool = False
    landed_state: int = 0
    texts: list[str] = field(default_factory=list)


class Px4Link:
    def __init__(self, url: str, timeout: float) -> None:
        self.timeout = timeout
        self.mav = mavutil.mavlink_connection(url, source_system=245, dialect="common")
        self.target = 1
        self.state = State()
        self.last_beat = 0.0

    def pump(self, block: float = 0.0) -> None:
        """Reads whatever PX4 sent (waiting up to `block` s for the first message) and sends
        our heartbeat twice a second."""
        now = time.monotonic()
        if now - self.last_beat > 0.5:
            self.last_beat = now
            self.mav.mav.heartbeat_send(
                MAV.MAV_TYPE_ONBOARD_CONTROLLER, MAV.MAV_AUTOPILOT_INVALID, 0, 0, 0
            )
        m = self.mav.recv_match(blocking=block > 0, timeout=block or None)
        while m is not None:
            self._take(m)
            m = self.mav.recv_match(blocking=False)

    def _take(self, m) -> None:
        s, kind = self.state, m.get_type()
        if kind == "HEARTBEAT" and m.autopilot == MAV.MAV_AUTOPILOT_PX4:
            self.target = m.get_srcSystem()
            s.heartbeat = True
            s.custom_mode = m.custom_mode
            s.armed = bool(m.base_mode & MAV.MAV_MODE_FLAG_SAFETY_ARMED)
        elif kind == "LOCAL_POSITION_NED":
            s.position = np.array([m.x, m.y, m.z])
            s.velocity = np.array([m.vx, m.vy, m.vz])
            s.time_ms = max(s.time_ms, m.time_boot_ms)
            s.wall = time.monotonic()
        elif kind == "ATTITUDE_QUATERNION":
            s.q = (m.q1, m.q2, m.q3, m.q4)
            s.rates = np.array([m.rollspeed, m.pitchspeed, m.yawspeed])
            s.time_ms = max(s.time_ms, m.time_boot_ms)
            s.wall = time.monotonic()
        elif kind == "EXTENDED_SYS_STATE":
            s.landed_state = m.landed_state
        elif kind == "STATUSTEXT":
            s.texts.append(m.text)

    def wait(self, what: str, predicate, timeout: float, code: int = 2):
        end = time.monotonic() + timeout
        while time.monotonic() < end:
            self.pump(0.05)
            if predicate(self.state):
                return
        raise FlightError(f"timed out after {timeout:.0f} s waiting for {what}", code)

    def command(self, command: int, *params: float) -> None:
        p = list(params) + [0.0] * (7 - len(params))
        self.mav.mav.command_long_send(self.target, 1, command, 0, *p)

    def accepted(
        self, what: str, command: int, params: tuple, timeout: float, code: int, taken=None
    ) -> None:
        """Sends a command (again every second) until PX4 accepts it, or `taken(state)` says
        PX4 acted on it though its acknowledgement has not come (yet)."""
        end = time.monotonic() + timeout
        last = "no answer"
        while time.monotonic() < end:
            self.command(command, *params)
            until = time.monotonic() + 1.0
            while time.monotonic() < until:
                m = self.mav.recv_match(blocking=True, timeout=0.1)
                if m is None:
                    continue
                self._take(m)
                if taken is not None and taken(self.state):
                    return
                if m.get_type() == "COMMAND_ACK" and m.command == command:
                    if m.result == MAV.MAV_RESULT_ACCEPTED:
                        return
                    last = f"result {m.result}"
        texts = "; ".join(self.state.texts[-3:])
        raise FlightError(
            f"PX4 did not accept {what} ({last}; PX4 said: {texts or 'nothing'})", code
        )

    def interval(self, message_id: int, hz: float) -> None:
        self.command(MAV.MAV_CMD_SET_MESSAGE_INTERVAL, message_id, 1e6 / hz)

    def set_mode(self, custom_mode: int, what: str, code: int) -> None:
        main, sub = (custom_mode >> 16) & 0xFF, (custom_mode >> 24) & 0xFF
        params = (MAV.MAV_MODE_FLAG_CUSTOM_MODE_ENABLED, main, sub)
        self.accepted(what, MAV.MAV_CMD_DO_SET_MODE, params, 5, code)

    def send_position(self, target: np.ndarray) -> None:
        n, e, d = (float(v) for v in target)
        self.mav.mav.set_position_target_local_ned_send(
            self.state.time_ms,
            self.target,
            1,
            MAV.MAV_FRAME_LOCAL_NED,
            POSITION_ONLY,
            n,
            e,
            d,
            0,
            0,
            0,
            0,
            0,
            0,
            0,
            0,
        )

    def send_rates(self, action: np.ndarray) -> None:
        thrust, p, q, r = (float(v) for v in action)
        self.mav.mav.set_attitude_target_send(
            self.state.time_ms,
            self.target,
            1,
            ATTITUDE_IGNORE,
            [1.0, 0.0, 0.0, 0.0],
            p,
            q,
            r,
            thrust,
        )


# ---- the flight ----


def parse_waypoints(text: str) -> list[tuple[float, float, float]]:
    points = []
    for part in filter(None, (p.strip() for p in text.split(";"))):
        values = [float(v) for v in part.split(",")]
        if len(values) != 3 or not all(math.isfinite(v) for v in values):
            raise ValueError(f"waypoint {part!r}: expected N,E,U in metres")
        points.append(tuple(values))
    if not points:
        raise ValueError("no waypoints")
    return points


def phase(text: str) -> None:
    """Says what the script does now (on stderr, beside its other messages; stdout keeps the
    results): a person waits through each of these phases for seconds."""
    print(f"px4_offboard: {text}", file=sys.stderr, flush=True)


def fresh(link: Px4Link, stale_s: float) -> None:
    if time.monotonic() - link.state.wall > stale_s:
        raise FlightError(f"telemetry stopped: no estimate from PX4 for {stale_s:.1f} s", 4)


def take_off(link: Px4Link, args: argparse.Namespace) -> np.ndarray:
    """Asks PX4 for the estimate's streams, arms and takes off; returns home (NED, m) once
    the drone is in the air, still (< 0.3 m/s) and over 1 m above it."""
    s = link.state
    phase(f"waiting for PX4's heartbeat at {args.connect} (up to {args.timeout:.0f} s)")
    try:
        link.wait("PX4's heartbeat", lambda st: st.heartbeat, args.timeout)
    except FlightError as exc:
        raise FlightError(f"PX4 not reachable at {args.connect}: {exc}", 2) from None
    for message, hz in (
        (MAV.MAVLINK_MSG_ID_LOCAL_POSITION_NED, 100),
        (MAV.MAVLINK_MSG_ID_ATTITUDE_QUATERNION, 100),
        (MAV.MAVLINK_MSG_ID_EXTENDED_SYS_STATE, 5),
    ):
        link.interval(message, hz)
    phase("PX4 is there; waiting for its position and attitude estimate")
    link.wait("an estimate", lambda st: st.position is not None and st.q is not None, args.timeout)
    phase("arming (retried every second until PX4's estimator is ready)")
    link.accepted("arming", MAV.MAV_CMD_COMPONENT_ARM_DISARM, (1,), args.timeout, 2)
    phase("armed; taking off with PX4's takeoff")
    nan = float("nan")
    # Never sent again once PX4 took it: PX4 takes a takeoff while it climbs too, with a new
    # target MIS_TAKEOFF_ALT above where it is then (a late acknowledgement on a loaded
    # machine once sent a vehicle to 10-14 m).
    params = (-1, 0, 0, nan, nan, nan, nan)
    link.accepted("takeoff", MAV.MAV_CMD_NAV_TAKEOFF, params, 30, 2, taken=taking_off)
    link.command(MAV.MAV_CMD_REQUEST_MESSAGE, MAV.MAVLINK_MSG_ID_HOME_POSITION)
    home_msg = link.mav.recv_match(type="HOME_POSITION", blocking=True, timeout=5)
    home = np.array([home_msg.x, home_msg.y, home_msg.z]) if home_msg else s.position.copy()
    phase("climbing: waiting until in the air, 1 m above home and still")
    link.wait(
        "the takeoff",
        lambda st: (
            st.landed_state == MAV.MAV_LANDED_STATE_IN_AIR
            and st.velocity is not None
            and np.linalg.norm(st.velocity) < 0.3
            and st.position[2] < home[2] - 1.0
        ),
        60,
    )
    return home


def taking_off(s: State) -> bool:
    """PX4 armed in AUTO.TAKEOFF, or its land detector no longer says on the ground."""
    in_takeoff = s.armed and s.custom_mode & 0xFFFF0000 == PX4_AUTO_TAKEOFF
    climbing = s.landed_state in (MAV.MAV_LANDED_STATE_TAKEOFF, MAV.MAV_LANDED_STATE_IN_AIR)
    return in_takeoff or climbing


class Setpoints:
    """What goes to PX4 each control period (dt_ms): without a policy, `target` as a
    position setpoint; with one, the policy's rates and thrust for the way to `target`."""

    def __init__(self, link: Px4Link, policy: Policy | None, hover_thrust: float) -> None:
        self.link, self.policy = link, policy
        self.dt_ms = 1000 * (policy.dt if policy is not None else 0.02)
        self.previous = np.array([hover_thrust, 0.0, 0.0, 0.0])
        self.target = link.state.position.copy()

    def send(self) -> None:
        if self.policy is None:
            self.link.send_position(self.target)
            return
        s = self.link.state
        obs = observation(s.position, s.velocity, s.q, s.rates, self.target, self.previous)
        self.previous = self.policy(obs)
        self.link.send_rates(self.previous)


def in_offboard(s: State, switched_ms: int, was: bool) -> bool:
    """Whether PX4 is in OFFBOARD, `was` whether it has been since the switch at
    `switched_ms`: raises once it left, or when it has not shown it 3 s after the switch."""
    if s.custom_mode == PX4_OFFBOARD:
        return True
    if was:
        raise FlightError(f"PX4 left OFFBOARD (custom mode {s.custom_mode:#x})", 3)
    if s.time_ms - switched_ms > 3000:
        said = "; ".join(s.texts[-3:]) or "nothing"
        raise FlightError(
            f"PX4 refused OFFBOARD: it acknowledged the switch but stayed in custom "
            f"mode {s.custom_mode:#x} for 3 s (PX4 said: {said})",
            3,
        )
    return False


def fly(link: Px4Link, policy: Policy | None, args: argparse.Namespace) -> list[list[float]]:
    """Takes off, flies the waypoints in OFFBOARD, returns each hold's errors (m)."""
    s = link.state
    home = take_off(link, args)
    points = [home + np.array([n, e, -u]) for n, e, u in parse_waypoints(args.waypoints)]
    setpoints = Setpoints(link, policy, args.hover_thrust)

    # Stream setpoints for a second of PX4 time before asking for OFFBOARD.
    who = "the policy's" if policy is not None else "position"
    phase(f"in the air; streaming {who} setpoints for 1 s before OFFBOARD")
    start = s.time_ms
    next_ms = s.time_ms
    while s.time_ms - start < 1000:
        link.pump(0.01)
        fresh(link, args.stale)
        if s.time_ms >= next_ms:
            setpoints.send()
            next_ms = s.time_ms + setpoints.dt_ms
    phase("switching to OFFBOARD")
    link.set_mode(PX4_OFFBOARD, "the switch to OFFBOARD", 3)
    # The heartbeat that shows the new mode may come up to a second later.
    switched_ms, offboard = s.time_ms, False

    results = []
    for i, point in enumerate(points):
        origin = setpoints.target.copy()
        leg = np.linalg.norm(point - origin)
        leg_ms = 1000 * leg / args.speed
        north, east, up = (point - home) * np.array([1, 1, -1])
        phase(
            f"waypoint {i}: flying to {north:.1f} N, {east:.1f} E, {up:.1f} m up, then "
            f"settling {args.settle:g} s and holding {args.hold:g} s"
        )
        t0 = s.time_ms
        errors: list[float] = []
        hold_start = t0 + leg_ms + 1000 * args.settle
        hold_end = hold_start + 1000 * args.hold
        while s.time_ms < hold_end:
            link.pump(0.002)
            fresh(link, args.stale)
            offboard = in_offboard(s, switched_ms, offboard)
            if s.time_ms < next_ms:
                continue
            next_ms += setpoints.dt_ms
            if s.time_ms > next_ms:  # fell behind: do not send a burst
                next_ms = s.time_ms + setpoints.dt_ms
            frac = min(1.0, (s.time_ms - t0) / leg_ms) if leg_ms > 0 else 1.0
            setpoints.target = origin + frac * (point - origin)
            setpoints.send()
            if s.time_ms >= hold_start:
                errors.append(float(np.linalg.norm(s.position - point)))
        mean, worst = float(np.mean(errors)), float(np.max(errors))
        print(f"waypoint {i}: hold error mean {mean:.3f} m, max {worst:.3f} m", flush=True)
        results.append(errors)
    return results


def hand_back(link: Px4Link, land: bool) -> None:
    """Position hold, then land: PX4 takes over. Errors here are reported, not raised."""
    try:
        link.set_mode(PX4_AUTO_LOITER, "the switch to position hold", 3)
        print("px4_offboard: PX4 holds position", file=sys.stderr, flush=True)
        if land:
            link.accepted("landing", MAV.MAV_CMD_NAV_LAND, (), 10, 3)
            print("px4_offboard: PX4 lands", file=sys.stderr, flush=True)
    except FlightError as exc:
        print(f"px4_offboard: handing back to PX4: {exc}", file=sys.stderr, flush=True)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument(
        "policy", type=Path, help="folder with policy.npz and policy.json (- with --controller px4)"
    )
    parser.add_argument("--connect", default="udpin:0.0.0.0:14540", help="pymavlink URL of PX4")
    parser.add_argument("--waypoints", default="0,0,3;2,0,3;2,2,3", help='"N,E,U;..." m from home')
    parser.add_argument("--hold", type=float, default=5.0, help="seconds to hold each waypoint")
    parser.add_argument("--settle", type=float, default=2.0, help="seconds to settle before a hold")
    parser.add_argument(
        "--speed", type=float, default=1.0, help="target speed between waypoints, m/s"
    )
    parser.add_argument(
        "--hover-thrust", type=float, default=0.6, help="thrust of the first setpoint"
    )
    parser.add_argument("--timeout", type=float, default=60.0, help="seconds to wait for PX4")
    parser.add_argument(
        "--stale", type=float, default=1.0, help="seconds without an estimate = lost"
    )
    parser.add_argument(
        "--no-land", action="store_true", help="hold position at the end, do not land"
    )
    parser.add_argument(
        "--controller",
        choices=("policy", "px4"),
        default="policy",
        help="px4: fly the same targets with PX4's own position controller (OFFBOARD position "
        "setpoints) instead of the policy, for comparison",
    )
    args = parser.parse_args(argv)
    try:
        parse_waypoints(args.waypoints)
        policy = Policy.load(args.policy) if args.controller == "policy" else None
    except (OSError, ValueError, KeyError, FlightError) as exc:
        parser.error(str(exc))
    link = Px4Link(args.connect, args.timeout)
    code = 0
    try:
        holds = fly(link, policy, args)
        means = [float(np.mean(h)) for h in holds]
        print(f"mean hold error {float(np.mean(means)):.3f} m", flush=True)
        print(f"max hold error {max(max(h) for h in holds):.3f} m", flush=True)
    except FlightError as exc:
        print(f"px4_offboard: {exc}", file=sys.stderr, flush=True)
        code = exc.code
    except KeyboardInterrupt:
        print("px4_offboard: interrupted", file=sys.stderr, flush=True)
        code = 130
    except Exception as exc:  # anything else: say it in one line, then hand back
        print(f"px4_offboard: {type(exc).__name__}: {exc}", file=sys.stderr, flush=True)
        code = 1
    if link.state.heartbeat and (link.state.armed or code != 2):
        hand_back(link, land=not args.no_land)
    link.mav.close()
    return code


if __name__ == "__main__":
    sys.exit(main())
