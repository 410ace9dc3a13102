"""What the view draws, in Rerun: the world in NED (north, east, down: MAVLink's frame, so the
SITL's, PX4's and ArduPilot's messages go in as they are), each vehicle as a body with its
rotors (from the frame's geometry), trail, target, wind arrow, motor commands, and an
autopilot's estimate beside the truth. Time is the simulation clock (timeline ``sim_time``)."""

from __future__ import annotations

import math
from collections import deque
from contextlib import contextmanager
from dataclasses import dataclass

import numpy as np
import rerun as rr
import rerun.blueprint as rrb

from .. import _native
from ..rendering.quadrotor import ROTOR_POSITION_SIGNS, ROTOR_SPIN
from ..tasks import HOVER, LANDING

TIMELINE = "sim_time"
# The vehicle's hub: a colour the browser test looks for (it appears nowhere else).
HUB = (255, 0, 200)
ESTIMATE = (255, 150, 0)
COLLISION = (230, 20, 20)
ROTOR_CCW, ROTOR_CW, ARM = (70, 200, 90), (235, 90, 80), (60, 60, 70)
GROUND, PAD, TRAIL, TARGET, WIND = (
    (150, 155, 150),
    (40, 40, 40),
    (60, 140, 220),
    (0, 170, 60),
    (0, 80, 220),
)
# The trail: a point every TRAIL_EVERY_S of simulated time at most, and only once the vehicle
# has moved TRAIL_STEP_M from the last one; the last TRAIL_POINTS of them (30 s of flight),
# re-drawn at each new point. A point per pose re-drawn whole ten times a second was most of a
# live view's bytes, and a browser that could not ingest them fell minutes behind the flight;
# a vehicle standing or hovering in place sends no trail at all (its chunks are what a loaded
# browser takes in slowest: docs/view.md, "How far behind").
TRAIL_POINTS = 300
EULER = ("roll", "pitch", "yaw")
TRAIL_EVERY_S = 0.1
TRAIL_STEP_M = 0.05
DRAW_SCALE = 3.0  # vehicles are drawn this many times their size (a 0.1 m arm is small)
GROUND_HALF = 5.0  # m: the ground grid is ±this around home


# A replay (batched) sends its high-rate rows as columns, this many rows at most at once: a
# served replay shows up in pieces, and a long recording does not wait in memory whole.
BATCH_ROWS = 50_000


# The core's shipped hexa X and octo X (core/src/quadrotor/frame.rs, PX4's motor order), read
# from the core: (forward, left) in arm lengths and spin (+1 CW, -1 CCW); the quad X comes from
# rendering's ROTOR_POSITION_SIGNS (the same table).
_FRAMES = _native.frames()
SHIPPED = {6: _FRAMES["hexa_x"], 8: _FRAMES["octo_x"]}


@dataclass(frozen=True)
class Frame:
    """A vehicle's geometry in the body frame FRD: rotor centres (n, 3) m and spins (n,)
    (−1 counter-clockwise, +1 clockwise, seen from above). The one place the view reads a
    frame's rotor layout from (the core's tables, through the extension)."""

    rotors: np.ndarray
    spins: tuple[int, ...]
    rotor_radius: float

    @staticmethod
    def quad_x(arm_length: float = HOVER.defaults["arm_length"]) -> Frame:
        # ROTOR_POSITION_SIGNS are (forward, left): FRD is (forward, -left, 0).
        fl = ROTOR_POSITION_SIGNS * (arm_length / math.sqrt(2.0))
        rotors = np.c_[fl[:, 0], -fl[:, 1], np.zeros(len(fl))]
        return Frame(rotors, tuple(ROTOR_SPIN), 0.38 * arm_length)

    @staticmethod
    def lander(width: float = LANDING.defaults["drone_width"]) -> Frame:
        rotors = np.array([[-width / 2, 0.0, 0.0], [width / 2, 0.0, 0.0]])
        return Frame(rotors, (-1, 1), 0.15 * width)

    @staticmethod
    def table(rows, arm_length: float = HOVER.defaults["arm_length"]) -> Frame:
        """From rotor rows (forward, left in arm lengths, spin +1 CW / -1 CCW), body FLU."""
        fl = np.array([(forward, left) for forward, left, _ in rows]) * arm_length
        rotors = np.c_[fl[:, 0], -fl[:, 1], np.zeros(len(fl))]
        return Frame(rotors, tuple(spin for _, _, spin in rows), 0.3 * arm_length)

    @staticmethod
    def for_motors(n: int) -> Frame:
        """The frame a vehicle with `n` motor outputs flies: the lander (2), the quad X (4),
        the core's hexa X (6) or octo X (8)."""
        if n in SHIPPED:
            return Frame.table(SHIPPED[n])
        return Frame.lander() if n == 2 else Frame.quad_x()


def _circle(center: np.ndarray, radius: float, n: int = 24) -> np.ndarray:
    a = np.linspace(0.0, 2.0 * math.pi, n + 1)
    return center + np.c_[radius * np.cos(a), radius * np.sin(a), np.zeros(n + 1)]


def quat_enu_to_ned(q_wxyz) -> np.ndarray:
    """Body FLU → world ENU quaternion [w, x, y, z] to body FRD → world NED (protocol.md §5)."""
    h = math.sqrt(0.5)
    return _mul(
        _mul(np.array([0.0, h, h, 0.0]), np.asarray(q_wxyz, float)), np.array([0.0, 1.0, 0.0, 0.0])
    )


def _mul(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    w1, x1, y1, z1 = a
    w2, x2, y2, z2 = b
    return np.array(
        [
            w1 * w2 - x1 * x2 - y1 * y2 - z1 * z2,
            w1 * x2 + x1 * w2 + y1 * z2 - z1 * y2,
            w1 * y2 - x1 * z2 + y1 * w2 + z1 * x2,
            w1 * z2 + x1 * y2 - y1 * x2 + z1 * w2,
        ]
    )


def blueprint() -> rrb.Blueprint:
    """The layout: the 3D world above the events (collisions, faults, what a fleet and its
    autopilots say), beside the motor commands, position, attitude, rates and the sensor
    samples an autopilot was sent, over time."""
    # South-west of home, looking at 2 m up: the rotors show, and a climb to 5 m stays in view.
    eye = rrb.EyeControls3D(position=[-4.5, -4.5, -4.0], look_target=[0.0, 0.0, -2.0])
    world = rrb.Spatial3DView(origin="/world", name="world (NED)", eye_controls=eye)
    events = rrb.TextLogView(origin="/events", name="events")
    plots = rrb.Vertical(
        rrb.TimeSeriesView(origin="/motors", name="motor commands"),
        rrb.TimeSeriesView(origin="/position", name="position (NED, m)"),
        rrb.TimeSeriesView(origin="/attitude", name="attitude (deg)"),
        rrb.TimeSeriesView(origin="/rates", name="body rates (deg/s)"),
        rrb.TimeSeriesView(origin="/sensors", name="IMU sent (m/s², deg/s; FRD)"),
    )
    left = rrb.Vertical(world, events, row_shares=[5, 1])
    return rrb.Blueprint(rrb.Horizontal(left, plots, column_shares=[3, 2]), collapse_panels=True)


class Scene:
    """Logs the world to a Rerun recording stream (`rec`)."""

    def __init__(self, rec: rr.RecordingStream) -> None:
        self.rec = rec
        self._drawn: set[str] = set()
        self._trails: dict[str, deque] = {}
        self._trail_at: dict[str, float] = {}
        self._now = 0.0
        # While batched: path -> (kind, times, rows) of the rows not sent yet.
        self._batch: dict[str, tuple[str, list, list]] | None = None
        self._batched_rows = 0
        self._world()

    def _log(self, path: str, *what, static: bool = False) -> None:
        self.rec.log(path, *what, static=static)

    @contextmanager
    def batched(self):
        """Within it, the rows that come at every step (series, poses, wind) are gathered and
        sent as columns (`rr.send_columns`) rather than logged one by one: a recording's
        replay, where a one-minute ArduPilot flight (60,000 steps) took a minute in
        `rr.log` calls. The same entities, times and values as logged live."""
        self._batch = {}
        try:
            yield self
        finally:
            self._flush()
            self._batch = None

    def _row(self, path: str, kind: str, row) -> bool:
        """Gathers `row` of `path` at the current time when batched; False when live."""
        if self._batch is None:
            return False
        _, times, rows = self._batch.setdefault(path, (kind, [], []))
        times.append(self._now)
        rows.append(row)
        self._batched_rows += 1
        if self._batched_rows >= BATCH_ROWS:
            self._flush()
        return True

    def _flush(self) -> None:
        batch, self._batch = self._batch or {}, {}
        self._batched_rows = 0
        for path, (kind, times, rows) in batch.items():
            # Nanoseconds rounded as `rr.set_time` rounds them (the column would truncate).
            ns = np.round(1e9 * np.asarray(times)).astype("timedelta64[ns]")
            index = [rr.TimeColumn(TIMELINE, duration=ns)]
            a = np.asarray(rows, dtype=float)
            if kind == "scalars":
                columns = rr.Scalars.columns(scalars=a)
            elif kind == "pose":
                columns = rr.Transform3D.columns(translation=a[:, :3], quaternion=a[:, 3:])
            else:  # an arrow from its origin
                columns = rr.Arrows3D.columns(origins=a[:, :3], vectors=a[:, 3:])
            self.rec.send_columns(path, indexes=index, columns=columns)

    def _world(self) -> None:
        self._log("/world", rr.ViewCoordinates.RIGHT_HAND_Z_DOWN, static=True)
        ticks = np.arange(-GROUND_HALF, GROUND_HALF + 0.5, 1.0)
        lines = [[[t, -GROUND_HALF, 0], [t, GROUND_HALF, 0]] for t in ticks]
        lines += [[[-GROUND_HALF, t, 0], [GROUND_HALF, t, 0]] for t in ticks]
        self._log("/world/ground", rr.LineStrips3D(lines, colors=[GROUND], radii=0.01), static=True)
        pad = [_circle(np.zeros(3), 0.5), [[-0.5, 0, 0], [0.5, 0, 0]], [[0, -0.5, 0], [0, 0.5, 0]]]
        self._log("/world/pad", rr.LineStrips3D(pad, colors=[PAD], radii=0.02), static=True)
        north = rr.Arrows3D(
            origins=[[0, 0, 0]], vectors=[[1, 0, 0]], colors=[(220, 40, 40)], labels=["N"]
        )
        self._log("/world/north", north, static=True)

    def time(self, t_s: float) -> None:
        """What is logged next happened at simulation time `t_s`."""
        self._now = float(t_s)
        self.rec.set_time(TIMELINE, duration=self._now)

    def _body(self, path: str, frame: Frame, color, hub: bool) -> None:
        """The static geometry under `path` (body frame FRD), drawn once."""
        if path in self._drawn:
            return
        self._drawn.add(path)
        s = DRAW_SCALE
        rotors = frame.rotors * s
        arms = [[[0, 0, 0], list(r)] for r in rotors]
        self._log(
            f"{path}/arms",
            rr.LineStrips3D(arms, colors=[color if not hub else ARM], radii=0.012 * s),
            static=True,
        )
        discs = [_circle(r, frame.rotor_radius * s) for r in rotors]
        colors = [ROTOR_CCW if spin < 0 else ROTOR_CW for spin in frame.spins]
        self._log(
            f"{path}/rotors",
            rr.LineStrips3D(discs, colors=colors if hub else [color], radii=0.008 * s),
            static=True,
        )
        nose = [[0, 0, 0], [float(np.max(np.abs(rotors[:, 0]))) * 1.3 or 0.1, 0, 0]]
        self._log(
            f"{path}/nose", rr.LineStrips3D([nose], colors=[color], radii=0.012 * s), static=True
        )
        if hub:
            half = 0.04 * s
            box = rr.Boxes3D(half_sizes=[[half, half, half / 2]], colors=[HUB], fill_mode="solid")
            self._log(f"{path}/hub", box, static=True)

    def vehicle(
        self,
        name: str,
        position_ned,
        quaternion_ned,
        frame: Frame,
        *,
        rates_frd=None,
        estimate: bool = False,
    ) -> None:
        """The vehicle's pose (truth, or an autopilot's `estimate`), body rates (FRD, rad/s)
        and trail."""
        path = f"/world/{name}" + ("_estimate" if estimate else "")
        self._body(path, frame, ESTIMATE if estimate else ARM, hub=not estimate)
        w, x, y, z = (float(v) for v in quaternion_ned)
        p = [float(v) for v in position_ned]
        if not self._row(path, "pose", [*p, x, y, z, w]):
            pose = rr.Transform3D(translation=p, quaternion=rr.Quaternion(xyzw=[x, y, z, w]))
            self._log(path, pose)
        kind = "estimate" if estimate else "truth"
        self._series(f"/position/{name}/{kind}", [f"{a}/{kind}" for a in "NED"], p)
        attitude = [math.degrees(v) for v in euler_ned([w, x, y, z])]
        self._series(f"/attitude/{name}/{kind}", [f"{a}/{kind}" for a in EULER], attitude)
        if rates_frd is not None:
            rates = [math.degrees(float(v)) for v in rates_frd]
            self._series(f"/rates/{name}/{kind}", [f"{a}/{kind}" for a in "pqr"], rates)
        self._trail(path, p, ESTIMATE if estimate else TRAIL)

    def _series(self, path: str, names: list[str], values) -> None:
        """One entity of several series (one `rr.log` for all, its lines named once):
        plot.series_of reads it back as one series per name."""
        if path not in self._drawn:
            self._drawn.add(path)
            self._log(path, rr.SeriesLines(names=names), static=True)
        values = [float(v) for v in values]
        if not self._row(path, "scalars", values):
            self._log(path, rr.Scalars(values))

    def _trail(self, path: str, p: list[float], color) -> None:
        now = self._now
        if now - self._trail_at.get(path, -math.inf) >= TRAIL_EVERY_S:
            trail = self._trails.setdefault(path, deque(maxlen=TRAIL_POINTS))
            if trail and math.dist(trail[-1], p) < TRAIL_STEP_M:
                return
            self._trail_at[path] = now
            trail.append(p)
            self._log(f"{path}_trail", rr.LineStrips3D([list(trail)], colors=[color], radii=0.015))

    def motors(self, name: str, fractions) -> None:
        """Motor commands in [0, 1], one series per motor."""
        fractions = [float(f) for f in fractions]
        self._series(f"/motors/{name}", [f"m{i}" for i in range(len(fractions))], fractions)

    def sensors(self, name: str, accel_frd, gyro_frd) -> None:
        """An IMU sample the SITL sent an autopilot (m/s², rad/s as deg/s; body FRD), as
        series under /sensors (the default layout's sensor panel)."""
        self._series(f"/sensors/{name}/accel", list("xyz"), accel_frd)
        gyro = [math.degrees(float(g)) for g in gyro_frd]
        self._series(f"/sensors/{name}/gyro", list("xyz"), gyro)

    def collision(self, name: str, position_ned, speed: float) -> None:
        """A collision the world reported for vehicle `name`: a red mark where it happened
        and its closing speed (m/s) as a series."""
        mark = rr.Points3D(
            [[float(v) for v in position_ned]], colors=[COLLISION], radii=0.2, labels=["collision"]
        )
        self._log(f"/world/{name}_collision", mark)
        self._log(f"/task/{name}/collision_speed", rr.Scalars(speed))
        self.event(name, f"collision, closing at {speed:.2f} m/s", "CRITICAL")

    def event(self, name: str, text: str, level: str = "INFO") -> None:
        """Something that happened (a fault fired, a collision, an autopilot gone): a line
        in the events log under /events/`name`."""
        self._log(f"/events/{name}", rr.TextLog(text, level=level))

    def faults(self, name: str, fired: list[str], ended: list[str]) -> None:
        """Faults that fired or ended at this time (labels as `flyloop.faults.active_faults`
        gives them), as events."""
        for label in fired:
            self.event(name, f"fault {label} fired", "WARN")
        for label in ended:
            self.event(name, f"fault {label} ended")

    def target(self, name: str, target_ned) -> None:
        point = rr.Points3D(
            [[float(v) for v in target_ned]], colors=[TARGET], radii=0.08, labels=["target"]
        )
        self._log(f"/world/{name}_target", point)

    def wind(self, name: str, position_ned, wind_ned) -> None:
        """The wind at the vehicle, an arrow of 0.3 m per m/s."""
        vec = [0.3 * float(v) for v in wind_ned]
        origin = [float(v) for v in position_ned]
        path = f"/world/{name}_wind"
        if path not in self._drawn:
            self._drawn.add(path)
            self._log(path, rr.Arrows3D.from_fields(colors=[WIND]), static=True)
        if not self._row(path, "arrow", [*origin, *vec]):
            self._log(path, rr.Arrows3D(origins=[origin], vectors=[vec]))

    def task(self, name: str, reward: float, terminated: bool, truncated: bool) -> None:
        self._log(f"/task/{name}/reward", rr.Scalars(float(reward)))
        if terminated or truncated:
            what = "terminated" if terminated else "truncated"
            self._log(f"/task/{name}/events", rr.TextLog(f"episode {what}", level="WARN"))


def euler_ned(q_wxyz) -> tuple[float, float, float]:
    """Roll, pitch, yaw (ZYX) of a body FRD → world NED quaternion, rad."""
    w, x, y, z = q_wxyz
    roll = math.atan2(2 * (w * x + y * z), 1 - 2 * (x * x + y * y))
    pitch = math.asin(max(-1.0, min(1.0, 2 * (w * y - z * x))))
    yaw = math.atan2(2 * (w * z + x * y), 1 - 2 * (y * y + z * z))
    return roll, pitch, yaw
