"""PX4s flying one flyloop world: each PX4 instance i on TCP 4560 + i with MAV_SYS_ID i + 1,
all in one lockstep; a PX4 that stops answering does not hang the others; two PX4s sent into
each other collide, and flyloop says so."""

from __future__ import annotations

import signal
import time

from fleet_support import FleetSitl, free_block, px4_ports_free
from px4_support import Px4, collect, fresh_dir, launch, settle

TAKEOFF_ALT = 5.0


def start_fleet(started, sitl_binary, px4_dir, n: int, *args: str, **params):
    """flyloop-sitl with n PX4 vehicles and the n PX4s, each waiting for its heartbeat."""
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
    )
    started.append(sitl)
    px4s = []
    for k in range(n):
        p = Px4(px4_dir, base + k, fresh_dir(f"px4-fleet-{k}-"), **params)
        started.append(p)
        px4s.append(p)
    for p in px4s:
        p.heartbeat(120)
    return sitl, px4s


def land_all(px4s) -> None:
    for p in px4s:
        p.land()
    for p in px4s:
        p.wait_for(
            "the automatic disarm after landing",
            lambda m, p=p: m.get_srcSystem() == p.target and not p.armed(m),
            120,
            "HEARTBEAT",
        )


def test_two_px4s_share_one_world_each_with_its_own_sysid(started, sitl_binary, px4_dir):
    sitl, px4s = start_fleet(started, sitl_binary, px4_dir, 2)
    assert [p.target for p in px4s] == [p.instance + 1 for p in px4s]
    targets = []
    for p in px4s:
        targets.append(launch(p))
    for p, (_, target) in zip(px4s, targets):
        settle(p, target, 0.3, 90)
    for p, (_, target) in zip(px4s, targets):
        hold = collect(p, 2.0)
        horizontal, vertical = hold.worst(target)
        assert vertical < 0.3 and horizontal < 0.3, (p.instance, horizontal, vertical)
    land_all(px4s)
    sitl.stop()
    counters = sitl.counters()
    assert counters["collisions"] == "0", counters
    assert "silent" not in sitl.stderr()
