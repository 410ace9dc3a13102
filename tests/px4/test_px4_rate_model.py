"""The core's model of PX4's rate loop against the real PX4: the same body-rate and thrust
steps flown once through PX4 in OFFBOARD (SET_ATTITUDE_TARGET, body rates + thrust) on
flyloop's Iris, and once through the model (the gym env's rates interface, in-process, one
rate-loop tick per step) on the same vehicle; the body-rate responses agree within 10 % of
the step size (RMS). The same for the hexacopter X preset, PX4 started with the mixer
`--print-autopilot-params px4` prints and the model mixing for the same rotor table
(`frame="hexa_x"`).

With FLYLOOP_RATE_MODEL_OUT=DIR the test also writes DIR/rate_model.png (the responses side
by side) and DIR/rate_model.json (the figures) for the quad, DIR/rate_model_hexa_x.* for the
hexa; docs/px4.md's plot is made so."""

from __future__ import annotations

import json
import math
import os
from pathlib import Path

import flyloop as _registers_envs  # noqa: F401
import gymnasium as gym
import numpy as np
import pytest
import tomllib
from px4_support import TAKEOFF_ALT, autopilot_params, collect, settle
from pymavlink import mavutil

ROOT = Path(__file__).resolve().parents[2]
PRESETS = ROOT / "sitl" / "presets"


def vehicle(preset: str) -> tuple[dict, str]:
    """A PX4 preset's quadrotor parameters (its wind switch is the env's use_wind) and its
    frame's name (the quad X when it has no [frame])."""
    params = tomllib.loads((PRESETS / f"{preset}.toml").read_text())
    params.pop("wind_enabled")
    frame = params.pop("frame", {"name": "quad_x"})["name"]
    return params, frame


IRIS, _ = vehicle("px4_iris")
TICK_MS = 4
STEP = 0.8  # rad/s
# (seconds, thrust offset from hover, roll, pitch, yaw rate): the steps of the comparison.
SEQUENCE = [
    (1.0, 0.0, 0.0, 0.0, 0.0),
    (0.3, 0.0, STEP, 0.0, 0.0),
    (0.3, 0.0, -STEP, 0.0, 0.0),
    (0.8, 0.0, 0.0, 0.0, 0.0),
    (0.3, 0.0, 0.0, STEP, 0.0),
    (0.3, 0.0, 0.0, -STEP, 0.0),
    (0.8, 0.0, 0.0, 0.0, 0.0),
    (0.5, 0.0, 0.0, 0.0, STEP),
    (0.5, 0.0, 0.0, 0.0, -STEP),
    (0.8, 0.0, 0.0, 0.0, 0.0),
    (0.5, 0.05, 0.0, 0.0, 0.0),
    (0.5, -0.05, 0.0, 0.0, 0.0),
    (0.8, 0.0, 0.0, 0.0, 0.0),
]
OFFBOARD = 6


def setpoint_at(seconds: float, hover: float) -> tuple[float, float, float, float]:
    at = 0.0
    for duration, dthrust, p, q, r in SEQUENCE:
        at += duration
        if seconds < at:
            return (hover + dthrust, p, q, r)
    return (hover, 0.0, 0.0, 0.0)


def fly_sequence(px4, hover: float) -> tuple[list[tuple[int, tuple]], int]:
    """Streams the sequence to PX4 at 50 Hz of its clock (after a second of hover setpoints
    and the switch to OFFBOARD); returns [(PX4 ms when sent, setpoint)] and the start ms."""
    link = px4.link

    def send(sp, time_ms):
        t, p, q, r = sp
        link.mav.set_attitude_target_send(time_ms, px4.target, 1, 128, [1, 0, 0, 0], p, q, r, t)

    def clock() -> int:
        # PX4's newest time this side has: whatever is queued is read first (a test process
        # that lags under load would otherwise stamp its setpoints with an old time, and the
        # model would apply them early by a lag that wanders).
        kinds = ["ATTITUDE_QUATERNION", "LOCAL_POSITION_NED"]
        m = px4.wait_for("PX4's clock", lambda m: True, 10, kinds)
        while (newer := link.recv_match(type=kinds, blocking=False)) is not None:
            m = newer
        return m.time_boot_ms

    now = clock()
    end = now + 1000
    while now < end:
        send((hover, 0.0, 0.0, 0.0), now)
        now = clock()
    custom = mavutil.mavlink.MAV_MODE_FLAG_CUSTOM_MODE_ENABLED
    setmode = mavutil.mavlink.MAV_CMD_DO_SET_MODE
    px4.accepted(setmode, lambda: px4.command(setmode, custom, OFFBOARD), 10)
    sent = []
    start = clock()
    total_ms = 1000 * sum(s[0] for s in SEQUENCE)
    next_ms = start
    while now - start < total_ms:
        now = clock()
        if now >= next_ms:
            sp = setpoint_at((now - start) / 1000, hover)
            send(sp, now)
            sent.append((now, sp))
            next_ms += 20
    return sent, start


def model_rates(sent, start, hover, lag_ms, ticks, params=IRIS, frame="quad_x") -> np.ndarray:
    """The model's body rates (FRD) at each 4 ms tick from `start`, the setpoint applied
    `lag_ms` after it was sent, on the vehicle `params` with the rotor table `frame`."""
    env = gym.make(
        "flyloop/QuadHover-v0",
        backend="native",
        action_interface="rates",
        dt=TICK_MS / 1000,
        max_steps=100_000,
        use_wind=False,
        start_attitude_range=0.0,
        start_height=10.0,
        space_side_length=20.0,
        model_params=params,
        frame=frame,
    )
    try:
        obs, _ = env.reset(seed=0)
        times = np.array([t for t, _ in sent])
        rates = np.zeros((ticks, 3))
        for k in range(ticks):
            now = start + k * TICK_MS - lag_ms
            i = np.searchsorted(times, now, side="right") - 1
            sp = sent[i][1] if i >= 0 else (hover, 0.0, 0.0, 0.0)
            obs, *_ = env.step(np.array(sp, np.float32))
            rates[k] = obs[9:12]
    finally:
        env.close()
    return rates


@pytest.mark.parametrize("preset", ["px4_iris", "px4_hexa_x"], ids=["quad_x", "hexa_x"])
def test_the_rate_loop_model_follows_px4s_body_rate_responses(pair, sitl_binary, preset):
    params, frame = vehicle(preset)
    rotors = {"quad_x": 4, "hexa_x": 6}[frame]
    if frame == "quad_x":
        # PX4's stock none_iris mixer, as every quad test flies it.
        flyloop = pair.flyloop("--track-interval-us", str(TICK_MS * 1000))
        px4 = pair.px4()
    else:
        config = PRESETS / f"{preset}.toml"
        flyloop = pair.flyloop("--config", str(config), "--track-interval-us", str(TICK_MS * 1000))
        px4 = pair.px4(**autopilot_params(sitl_binary, config, "px4"))
    px4.heartbeat(60)
    for message in ("ATTITUDE_QUATERNION", "LOCAL_POSITION_NED"):
        message_id = getattr(mavutil.mavlink, f"MAVLINK_MSG_ID_{message}")
        px4.command(mavutil.mavlink.MAV_CMD_SET_MESSAGE_INTERVAL, message_id, 10_000)
    px4.arm_and_take_off(60)
    home = px4.home()
    settle(px4, (home[0], home[1], home[2] - TAKEOFF_ALT), 0.3, 60)
    collect(px4, 2.0)
    hover = math.sqrt(params["mass"] * 9.81 / (rotors * params["thrust_coefficient"]))
    sent, start = fly_sequence(px4, hover)
    loiter = mavutil.mavlink.MAV_CMD_DO_SET_MODE
    px4.accepted(loiter, lambda: px4.command(loiter, 1, 4, 3), 10)
    px4.land()
    flyloop.stop()
    rows = [r for r in flyloop.rows() if r["connection"] == 1]
    t_ms = np.array([r["time_us"] / 1000 for r in rows])
    total = int(1000 * sum(s[0] for s in SEQUENCE) / TICK_MS)
    first = int(np.searchsorted(t_ms, start))
    px4_rates = np.array([[r["p"], r["q"], r["r"]] for r in rows[first : first + total]])
    assert len(px4_rates) == total, (len(px4_rates), total)

    # The setpoint reaches PX4's rate loop some ticks after the telemetry time it was sent
    # at: the best lag in whole ticks, searched over 0..60 ms.
    fits = {}
    for lag in range(0, 64, TICK_MS):
        model = model_rates(sent, start, hover, lag, total, params, frame)
        fits[lag] = (np.sqrt(np.mean((model - px4_rates) ** 2, axis=0)), model)
    lag = min(fits, key=lambda k: fits[k][0].sum())
    rms, model = fits[lag]
    relative = rms / STEP
    figures = dict(
        frame=frame,
        lag_ms=lag,
        rms_rad_s=dict(zip("pqr", rms.tolist(), strict=True)),
        rms_of_step=dict(zip("pqr", relative.tolist(), strict=True)),
        step_rad_s=STEP,
    )
    out = os.environ.get("FLYLOOP_RATE_MODEL_OUT")
    if out:
        name = "rate_model" if frame == "quad_x" else f"rate_model_{frame}"
        t = t_ms[first : first + total] - start
        write(Path(out), name, figures, t, px4_rates, model, sent, start)
    print(figures)
    assert (relative < 0.10).all(), figures


def write(out: Path, stem: str, figures, t, px4_rates, model, sent, start) -> None:
    from matplotlib.figure import Figure

    out.mkdir(parents=True, exist_ok=True)
    (out / f"{stem}.json").write_text(json.dumps(figures, indent=2) + "\n")
    fig = Figure(figsize=(9, 6), layout="constrained")
    axes = fig.subplots(3, 1, sharex=True)
    st = np.array([t for t, _ in sent]) - start
    sp = np.array([s[1:] for _, s in sent])
    for i, (ax, name) in enumerate(zip(axes, ("roll", "pitch", "yaw"), strict=True)):
        ax.step(st / 1000, sp[:, i], where="post", color="grey", lw=1, label="setpoint (sent)")
        ax.plot(t / 1000, px4_rates[:, i], color="tab:blue", lw=2, label="PX4 on flyloop")
        ax.plot(t / 1000, model[:, i], color="tab:orange", lw=1.2, ls="--", label="core model")
        rms = figures["rms_of_step"]["pqr"[i]]
        ax.set_ylabel(f"{name} rate, rad/s")
        ax.set_title(f"{name}: RMS difference {100 * rms:.1f} % of the step", fontsize=9)
        ax.grid(alpha=0.3)
    axes[0].legend(loc="upper right", fontsize=8)
    axes[-1].set_xlabel(f"seconds (model lag {figures['lag_ms']} ms)")
    fig.savefig(out / f"{stem}.png", dpi=100)
