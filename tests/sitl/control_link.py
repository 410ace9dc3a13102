"""flyloop-sitl's control link (`--control HOST:PORT`, named `control=` in its ready line) as
the autopilot fault tests use it: MAV_CMD_INJECT_FAILURE to the vehicle, answered with a
COMMAND_ACK and a STATUSTEXT."""

from __future__ import annotations

from pymavlink import mavutil

# FAILURE_UNIT (MAVLink common.xml): SENSOR_BARO, SENSOR_GPS, SYSTEM_MOTOR (PX4's instance
# numbering: 1 = first motor, 0 = all).
BARO, GPS, MOTOR = 3, 4, 101
# FAILURE_TYPE: OK (clears the unit), OFF, STUCK.
OK, OFF, STUCK = 0, 1, 2


def control_link(flyloop):
    """A pymavlink link to flyloop's control endpoint (from its ready line)."""
    return mavutil.mavlink_connection(
        f"udpout:{flyloop.ready['control']}", source_system=250, dialect="common"
    )


def inject(link, unit: int, failure: int, instance: int = 0):
    """MAV_CMD_INJECT_FAILURE to vehicle 1; returns flyloop's ack and its STATUSTEXT's text
    (None if none came)."""
    link.mav.command_long_send(
        1, 1, mavutil.mavlink.MAV_CMD_INJECT_FAILURE, 0, unit, failure, instance, 0, 0, 0, 0
    )
    ack = link.recv_match(type="COMMAND_ACK", blocking=True, timeout=10)
    return ack, statustext(link)


def statustext(link, timeout: float = 10) -> str | None:
    """The next STATUSTEXT's whole text: MAVLink 2 sends a text longer than 50 characters
    as chunks sharing an id, the last one shorter than 50."""
    text = ""
    while True:
        m = link.recv_match(type="STATUSTEXT", blocking=True, timeout=timeout)
        if m is None:
            return text or None
        text += m.text
        if m.id == 0 or len(m.text) < 50:
            return text
