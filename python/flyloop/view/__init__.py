"""The live view and recordings (docs/view.md): Rerun's web viewer (it ships in the rerun-sdk
wheel and works offline) shows the world as :class:`Scene` draws it — from a SITL's or an
autopilot's MAVLink stream (``python -m flyloop.view``), from a gym env (:class:`Watch`), or
from a recording (.tlog of ``flyloop-sitl --record``, .rrd of ``--save`` and of Watch)."""

from __future__ import annotations

import socket
import time
import urllib.parse
import uuid
from pathlib import Path

import rerun as rr

from .env import Watch, WatchVector
from .mavlink import Listener, MavlinkScene, poll, read_tlog
from .multi import WatchParallel
from .scene import Frame, Scene, blueprint

__all__ = [
    "Frame",
    "Scene",
    "ViewError",
    "Viewer",
    "Watch",
    "WatchParallel",
    "WatchVector",
    "blueprint",
    "read_recording",
]

APPLICATION = "flyloop"


class ViewError(RuntimeError):
    """What the view cannot do, in one line (what and where)."""


# How often the SDK cuts what was logged into chunks (Rerun's default: 0.2 s). The web viewer
# takes in chunks at a rate its frames set, whatever their size: on a software rasteriser
# (no GPU) at load 10, a chunk per entity every 0.2 s put it ever further behind a flight
# (16-26 s), every 1 s keeps it within ~2 s, and a page opened mid-flight catches up twice as
# fast as with 0.5 s (docs/view.md, "How far behind").
FLUSH_TICK_S = 1.0


def new_stream() -> rr.RecordingStream:
    batching = rr.ChunkBatcherConfig(flush_tick=FLUSH_TICK_S)
    return rr.RecordingStream(APPLICATION, recording_id=uuid.uuid4(), batcher_config=batching)


def _check_port_free(port: int, option: str, what: str) -> None:
    """ViewError naming `option` when TCP `port` on 127.0.0.1 cannot be bound (0: any)."""
    if port == 0:
        return
    with socket.socket(socket.AF_INET, socket.SOCK_STREAM) as probe:
        probe.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
        try:
            probe.bind(("127.0.0.1", port))
        except OSError as e:
            raise ViewError(
                f"cannot serve {what} port {port}: {e.strerror} (another flyloop.view? "
                f"choose a free one with {option})"
            ) from None


class Viewer:
    """A recording stream served to Rerun's web viewer (``url``), and/or saved (``save``)."""

    def __init__(
        self,
        *,
        web_port: int | None = 9090,
        grpc_port: int = 9876,
        save: str | Path | None = None,
        serve: bool = True,
    ) -> None:
        self.rec = new_stream()
        sinks = []
        self.url = None
        if save is not None:
            try:
                Path(save).parent.mkdir(parents=True, exist_ok=True)
                Path(save).open("wb").close()
            except OSError as e:
                raise ViewError(f"cannot write the recording {save}: {e.strerror}") from None
            sinks.append(rr.FileSink(str(save)))
        if serve:
            # The SDK binds in a thread of its own and only logs a port in use: ask first.
            _check_port_free(grpc_port, "--grpc-port", "the data's gRPC")
            if web_port is not None:
                _check_port_free(web_port, "--web-port", "the viewer's HTTP")
            sinks.append(rr.GrpcServerSink("127.0.0.1", grpc_port))
        try:
            self.rec.set_sinks(*sinks, default_blueprint=blueprint())
        except Exception as e:  # the SDK raises its own error types for a port in use
            raise ViewError(f"cannot serve the data on grpc port {grpc_port}: {e}") from None
        if serve and web_port is not None:
            grpc_url = f"rerun+http://127.0.0.1:{grpc_port}/proxy"
            try:
                rr.serve_web_viewer(web_port=web_port, open_browser=False, connect_to=grpc_url)
            except Exception as e:
                raise ViewError(f"cannot serve the viewer on http port {web_port}: {e}") from None
            self.url = f"http://127.0.0.1:{web_port}/?url={urllib.parse.quote(grpc_url, safe='')}"
        self.scene = Scene(self.rec)

    def replay(self, path: str | Path) -> int:
        """Draws a recording: a .tlog through the scene, an .rrd as it is. Returns the number
        of messages (tlog) or chunks (rrd)."""
        path = Path(path)
        if not path.is_file():
            raise ViewError(f"{path}: no such file")
        if path.suffix == ".rrd":
            try:
                chunks = read_recording(path)
            except Exception as e:
                raise ViewError(f"{path}: not a readable Rerun recording ({e})") from None
            self.rec.send_chunks(chunks)
            return len(chunks)
        try:
            with self.scene.batched():
                return read_tlog(str(path), MavlinkScene(self.scene))
        except ValueError as e:
            raise ViewError(str(e)) from None

    def watch(
        self,
        addresses: list[tuple[str, int]],
        *,
        connect: list[tuple[str, int]] = (),
        wait: float = 30.0,
        seconds: float | None = None,
    ) -> MavlinkScene:
        """Draws the MAVLink arriving at `addresses`, and from the autopilots at `connect`
        (talked to first), until `seconds` pass (or Ctrl-C); gives up with ViewError when
        nothing arrives within `wait` seconds."""
        view = MavlinkScene(self.scene)
        listeners: list[Listener] = []
        try:
            for address in addresses:
                listeners.append(Listener(address, view))
            for autopilot in connect:
                listeners.append(Listener(("127.0.0.1", 0), view))
                listeners[-1].connect(autopilot)
        except OSError as e:
            for listener in listeners:
                listener.close()
            raise ViewError(str(e)) from None
        where = ", ".join(
            [f"udp {h}:{p}" for h, p in addresses]
            + [f"udp {h}:{p} (talked to)" for h, p in connect]
        )
        print(f"flyloop.view: listening for MAVLink on {where}", flush=True)
        try:
            end = time.monotonic() + (seconds if seconds is not None else float("inf"))
            heard = time.monotonic() + wait
            while time.monotonic() < end:
                if poll(listeners):
                    heard = float("inf")
                elif time.monotonic() > heard:
                    raise ViewError(
                        f"no MAVLink on {where} within {wait:g} s: is flyloop-sitl running with its"
                        " --gcs pointed there (default 127.0.0.1:14550)?"
                    )
        finally:
            # What has arrived is drawn before the end (at most 2 s more).
            end = time.monotonic() + 2.0
            while time.monotonic() < end and poll(listeners, timeout=0.0):
                pass
            for listener in listeners:
                listener.close()
        return view

    def close(self) -> None:
        """Writes the recording out (with its footer) and stops serving."""
        self.rec.flush()
        self.rec.disconnect()


def read_recording(path: str | Path) -> list:
    """The chunks of an .rrd file (rerun's reader); raises on a file that is not one."""
    from rerun.chunk import RrdReader

    return list(RrdReader(path).stream())
