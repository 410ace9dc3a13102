"""Two PX4s and two ArduPilots in one flyloop world (a fleet file): each takes off to 5 m
and holds it within 0.3 m, all four at once, then lands and disarms. CI runs this one."""

from __future__ import annotations

from ardupilot_support import GUIDED, LAND, PARM, ArduPilot
from ardupilot_support import collect as ap_collect
from ardupilot_support import settle as ap_settle
from fleet_support import HOME, FleetSitl, ardupilot_ports_free, free_block, px4_ports_free
from px4_support import Px4, collect, fresh_dir, launch, settle

ALT = 5.0
# docs/fleet.md: a fleet's ArduPilots get the fleet's parameter file last, after the frame's.
FLEET_PARM = f"{PARM},{PARM.with_name('ardupilot_fleet.parm')}"


def quiet(ap) -> None:
    """Only positions (5 Hz) besides heartbeats and texts: while the test waits on one
    vehicle it reads no other link, and an ArduPilot whose TCP link fills up blocks in its
    write, stops answering flyloop, and is silenced after the timeout."""
    mav = ap.link.mav
    from pymavlink import mavutil

    mav.request_data_stream_send(ap.target, 1, mavutil.mavlink.MAV_DATA_STREAM_ALL, 0, 0)
    mav.request_data_stream_send(ap.target, 1, mavutil.mavlink.MAV_DATA_STREAM_POSITION, 5, 1)


def test_two_px4s_and_two_ardupilots_fly_in_one_world(started, sitl_binary, px4_dir, ardupilot):
    px4_base = free_block(2, px4_ports_free, 10, 150)
    ap_base = free_block(2, ardupilot_ports_free, 3, 150)
    work = fresh_dir("flyloop-fleet-mixed-")
    vehicles = []
    for k in range(2):
        vehicles.append(
            f'[[vehicle]]\nautopilot = "px4"\ninstance = {px4_base + k}\n'
            f"position = [{3.0 * k}, 0.0]\n"
        )
        vehicles.append(
            f'[[vehicle]]\nautopilot = "ardupilot"\ninstance = {ap_base + k}\n'
            f"sysid = {240 + k}\nposition = [{3.0 * k}, 4.0]\n"
        )
    fleet = work / "fleet.toml"
    fleet.write_text("\n".join(vehicles))
    sitl = FleetSitl(sitl_binary, work, "--fleet", str(fleet))
    started.append(sitl)
    assert sitl.ready["vehicles"] == "4"

    px4s = [Px4(px4_dir, px4_base + k, fresh_dir(f"px4-mixed-{k}-")) for k in range(2)]
    started.extend(px4s)
    home = ",".join(str(v) for v in HOME)
    aps = [
        ArduPilot(
            ardupilot,
            ap_base + k,
            9002 + 10 * (ap_base + k),
            fresh_dir(f"ap-mixed-{k}-"),
            "--home",
            home,
            "--sysid",
            str(240 + k),
            parm=FLEET_PARM,
        )
        for k in range(2)
    ]
    started.extend(aps)
    for ap in aps:
        ap.connect(60)
        quiet(ap)
    for k, ap in enumerate(aps):
        assert ap.target == 240 + k
    targets = [launch(p)[1] for p in px4s]
    assert [p.target for p in px4s] == [px4_base + 1, px4_base + 2]
    for ap in aps:
        ap.wait_for_gps(180)
        ap.mode(GUIDED)
        ap.arm()
        ap.takeoff(ALT)
    for p, target in zip(px4s, targets, strict=False):
        settle(p, target, 0.3, 90)
    for ap in aps:
        origin = ap.estimate().position
        ap_settle(ap, origin[0], origin[1], ALT, 0.3, 90)
    # All four hold at once.
    for p, target in zip(px4s, targets, strict=False):
        horizontal, vertical = collect(p, 2.0).worst(target)
        assert vertical < 0.3 and horizontal < 0.3, (p.instance, horizontal, vertical)
    for ap in aps:
        heights = [s.relative_alt for s in ap_collect(ap, 2.0).samples]
        assert max(abs(h - ALT) for h in heights) < 0.3, (ap.instance, heights)
    for p in px4s:
        p.land()
    for ap in aps:
        ap.mode(LAND)
    for v in (*px4s, *aps):
        v.wait_for(
            "the automatic disarm after landing",
            lambda m, v=v: m.get_srcSystem() == v.target and not v.armed(m),
            120,
            "HEARTBEAT",
        )
    sitl.stop()
    assert sitl.counters()["collisions"] == "0"
    assert "silent" not in sitl.stderr(), sitl.stderr()[-3000:]
