"""Issue 35: the real PX4 v1.16.0 loses its link to flyloop for 2 s of simulation time in a
hover (`link_loss` in flyloop's --config, 10 s after takeoff): every step PX4 still gets a
HIL_SENSOR (its lockstep tick) with the last IMU sample again and no mag or baro, no
HIL_GPS, and its controls are dropped. What PX4 says on its console is printed and checked
(docs/faults.md quotes it); flyloop's track records the loss; PX4 steps on through it and
the vehicle holds its hover after, or PX4 calls a failsafe and lands it."""

from __future__ import annotations

import time

from px4_support import launch, settle

FAULTS = '[[faults]]\nkind = "link_loss"\nafter_takeoff = 10.0\nduration = 2.0\n'
LEVELS = ("INFO", "WARN", "ERROR")


def test_px4_rides_out_a_two_second_link_loss(pair, tmp_path):
    config = tmp_path / "faults.toml"
    config.write_text(FAULTS)
    flyloop = pair.flyloop("--config", str(config))
    px4 = pair.px4()
    _, target = launch(px4)
    settle(px4, target, 0.5, 60)
    console_before = len(px4.output())
    time.sleep(10)  # 40 s of simulation at speed factor 4: the loss and after
    said = [
        line
        for line in px4.output()[console_before:].splitlines()
        if any(w in line for w in LEVELS)
    ]
    print("PX4's console around the loss:", *said, sep="\n  ")
    flyloop.stop()
    rows = flyloop.rows()
    with open(flyloop.track) as f:
        events = [line.rsplit(",", 1)[1] for line in f.read().splitlines()[1:]]
    fired = [e for e in events if e.startswith("+link_loss@")]
    cleared = [e for e in events if e.startswith("-link_loss@")]
    print("flyloop's track:", fired, cleared, f"end: down {rows[-1]['down']:.2f} m")
    assert len(fired) == 1 and len(cleared) == 1, events
    t_fired = float(fired[0].split("@")[1])
    assert abs(float(cleared[0].split("@")[1]) - t_fired - 2.0) < 0.01
    # PX4 stepped on through the loss (the track goes on well past it) and either still
    # hovers or, as it did in 1 of 4 quiet runs and in two CI runs (docs/faults.md), declared
    # its compass faulty after the loss, said so with a failsafe and came down ("blind land").
    assert rows[-1]["time_us"] * 1e-6 > t_fired + 10, rows[-1]["time_us"]
    if any("Failsafe activated" in line for line in said):
        assert any("Compass" in line for line in said), said
        assert rows[-1]["down"] > -4.0, rows[-1]
    else:
        assert abs(rows[-1]["down"] + 5.0) < 1.0, rows[-1]
    assert any("BARO #0 failed:  TIMEOUT" in line for line in said), said
