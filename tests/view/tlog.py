"""The messages of a telemetry log (.tlog: flyloop-sitl --record), for the recording tests."""

from __future__ import annotations

import os

os.environ.setdefault("MAVLINK20", "1")
from pymavlink import mavutil  # noqa: E402


def tlog_by_type(path) -> dict[str, list[tuple[int, object]]]:
    """Every message of the log by type: (its time stamp, µs; the message), in order."""
    log = mavutil.mavlink_connection(str(path), dialect="common")
    out: dict[str, list] = {}
    while (m := log.recv_msg()) is not None:
        out.setdefault(m.get_type(), []).append((int(m._timestamp * 1e6 + 0.5), m))
    return out


def statustexts(by_type) -> list[tuple[int, int, str]]:
    """(time µs, system id, text) of every STATUSTEXT of `tlog_by_type`'s answer, chunks
    joined (a text longer than 50 characters comes in chunks sharing an id)."""
    out, parts = [], {}
    for t, m in by_type.get("STATUSTEXT", []):
        key = (m.get_srcSystem(), m.id)
        parts.setdefault(key, []).append(m.text)
        if m.id == 0 or len(m.text) < 50:
            out.append((t, m.get_srcSystem(), "".join(parts.pop(key))))
    return out
