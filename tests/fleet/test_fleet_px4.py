"""PX4s flying one flyloop world: each PX4 instance i on TCP 4560 + i with MAV_SYS_ID i + 1,
all in one lockstep, every vehicle's truth in one track; a PX4 that stops answering does not
hang the others; two PX4s sent into each other collide, and flyloop says so."""

from __future__ import annotations

import re
import signal
import subprocess
import sys
import time
from pathlib import Path

from fleet_support import HOME, FleetSitl, free_block, land_all, px4_ports_free, read_track
from px4_support import Px4, collect, fresh_dir, launch, settle, truth_vs_estimate

TAKEOFF_ALT = 5.0
EXAMPLE = Path(__file__).resolve().parents[2] / "examples" / "fleet_mission.py"


def start_fleet(started, sitl_binary, px4_dir, n: int, *args: str, talk=True, speed=0, **params):
    """flyloop-sitl with n PX4 vehicles (world time paced at `speed` × real time; 0: as
    fast as they answer) and the n PX4s; with `talk`, each heard (its first heartbeat: PX4
    then answers this test's link only, so leave it out when another program is to command
    them)."""
    base = free_block(n, px4_ports_free, 10, 240)
    sitl = FleetSitl(
        sitl_binary,
        fresh_dir("flyloop-fleet-"),
        "--px4",
        "--vehicles",
        str(n),
        "--px4-listen",
        f"127.0.0.1:{4560 + base}",
        *args,
        speed=speed,
    )
    started.append(sitl)
    px4s = []
    for k in range(n):
        p = Px4(px4_dir, base + k, fresh_dir(f"px4-fleet-{k}-"), **params)
        started.append(p)
        px4s.append(p)
    for p in px4s if talk else ():
        p.heartbeat(120)
    return sitl, px4s


def test_two_px4s_share_one_world_each_with_its_own_sysid(started, sitl_binary, px4_dir):
    track = fresh_dir("flyloop-fleet-track-") / "track.csv"
    sitl, px4s = start_fleet(started, sitl_binary, px4_dir, 2, "--track", str(track))
    assert [p.target for p in px4s] == [p.instance + 1 for p in px4s]
    targets = []
    for p in px4s:
        targets.append(launch(p))
    for p, (_, target) in zip(px4s, targets, strict=False):
        settle(p, target, 0.3, 90)
    holds = []
    for p, (_, target) in zip(px4s, targets, strict=False):
        hold = collect(p, 2.0)
        holds.append(hold)
        horizontal, vertical = hold.worst(target)
        assert vertical < 0.3 and horizontal < 0.3, (p.instance, horizontal, vertical)
    land_all(px4s)
    sitl.stop()
    counters = sitl.counters()
    assert counters["collisions"] == "0", counters
    assert "silent" not in sitl.stderr()
    check_fleet_track(track, px4s, [frame for frame, _ in targets], holds)


def check_fleet_track(track, px4s, frames, holds) -> None:
    """The fleet's track: the single-vehicle columns after `vehicle,sysid`, a row per vehicle
    at the same world times 20 ms (+ at most one PX4 step) apart, each vehicle's truth where
    its own PX4 estimated it (< 0.5 m over the hold), 3 m apart at the start, landed at the
    end."""
    header = track.read_text().splitlines()[0]
    assert header == (
        "vehicle,sysid,connection,time_us,north,east,down,vn,ve,vd,roll,pitch,yaw,"
        "m0,m1,m2,m3,grounded,p,q,r,faults"
    ), header
    rows = read_track(track)
    assert sorted(rows) == ["px4-000", "px4-001"], sorted(rows)
    times = [[r["time_us"] for r in rows[name]] for name in sorted(rows)]
    assert times[0] == times[1] and len(times[0]) > 100, len(times[0])
    gaps = {b - a for a, b in zip(times[0], times[0][1:], strict=False)}
    assert min(gaps) >= 20_000 and max(gaps) <= 24_000, sorted(gaps)
    for name, p, frame, hold in zip(sorted(rows), px4s, frames, holds, strict=True):
        mine = rows[name]
        assert {r["sysid"] for r in mine} == {p.target}, (name, {r["sysid"] for r in mine})
        assert mine[0]["connection"] == 0 and mine[-1]["connection"] == 1, name
        error = truth_vs_estimate(mine, hold, 1, frame)
        assert error < 0.5, f"{name}: truth vs its PX4's estimate {error:.3f} m"
        assert mine[-1]["grounded"] == 1.0 and mine[-1]["m0"] < 0.01, mine[-1]
    first = [rows[name][0] for name in sorted(rows)]
    assert abs(first[1]["east"] - first[0]["east"] - 3.0) < 1e-3, first


def test_a_silent_px4_does_not_hang_the_others_and_rejoins(started, sitl_binary, px4_dir):
    # 2 s: under load (the fleet view tests beside it) a PX4 that is not stopped once took
    # longer than 1 s to answer, was silenced too, and never answered again.
    sitl, px4s = start_fleet(started, sitl_binary, px4_dir, 2, "--autopilot-timeout", "2")
    flying, stalled = px4s
    # Stopped before the other takes off: the world, and so the other PX4, waits 2 s of
    # wall time for it. Frozen so in mid-climb, the other PX4 held 9 m instead of its 5 m
    # takeoff in 1 of 3 runs: the frozen world delayed the takeoff's acknowledgement past the
    # 1 s after which Px4.takeoff sent it again, and PX4 takes a takeoff while it climbs,
    # 5 m above where it is (Px4.takeoff now waits 5 s and sends no more once PX4 took it).
    stalled.heartbeat(60)
    stalled.proc.send_signal(signal.SIGSTOP)
    text = sitl.statustext("silent", 30)
    assert text.startswith("px4-001: px4 silent for 2."), text
    _, target = launch(flying)
    # The world goes on without it: the other one climbs and holds.
    settle(flying, target, 0.3, 60)
    horizontal, vertical = collect(flying, 2.0).worst(target)
    assert vertical < 0.3 and horizontal < 0.3, (horizontal, vertical)
    stalled.proc.send_signal(signal.SIGCONT)
    sitl.statustext("px4-001: answers again", 30)
    land_all([flying])
    assert stalled.proc.poll() is None


def test_two_px4s_sent_into_each_other_collide_and_flyloop_says_so(started, sitl_binary, px4_dir):
    """As docs/fleet.md tells a user: examples/fleet_mission.py --collide sends vehicle 1 to
    where vehicle 0 hovers and hears flyloop's line on its ground-station address."""
    sitl, px4s = start_fleet(started, sitl_binary, px4_dir, 2, talk=False)
    gcs_port = sitl.gcs.port.getsockname()[1]
    sitl.gcs.close()  # the example listens there instead
    out = subprocess.run(
        [
            sys.executable,
            str(EXAMPLE),
            "--vehicles",
            "2",
            "--first-instance",
            str(px4s[0].instance),
            "--home",
            ",".join(str(v) for v in HOME[:3]),
            "--collide",
            "--gcs",
            f"127.0.0.1:{gcs_port}",
        ],
        capture_output=True,
        text=True,
        timeout=400,
    )
    print(out.stdout)
    assert out.returncode == 0, out.stdout + out.stderr + sitl.stderr()[-3000:]
    # The whole line (STATUSTEXT chunks joined), and the same in flyloop's log.
    said = re.search(
        r"^flyloop: collision px4-000 px4-001 at t=\S+ s, closing at \S+ m/s$", out.stdout, re.M
    )
    assert said, out.stdout
    deadline = time.monotonic() + 5
    while "collision px4-000 px4-001" not in sitl.stderr() and time.monotonic() < deadline:
        time.sleep(0.1)
    assert "collision px4-000 px4-001" in sitl.stderr()
