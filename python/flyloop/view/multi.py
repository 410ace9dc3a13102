"""WatchParallel: every agent of a flyloop multi-agent env (`flyloop.parallel_env`) in the
live view and/or recorded to .rrd, at once: each vehicle with its trail, target and motor
commands, its reward and episode end, and a red mark where it collided; collisions and the
faults that fire or end as events (/events/AGENT)."""

from __future__ import annotations

from pathlib import Path

from .env import _ned, _Watching, draw_events
from .scene import Frame, quat_enu_to_ned


class WatchParallel(_Watching):
    """Shows a flyloop pettingzoo ParallelEnv (every agent, one body each, named by agent),
    as :class:`flyloop.view.Watch` does a single env; other attributes are the env's."""

    def __init__(
        self,
        env,
        *,
        serve: bool = True,
        save: str | Path | None = None,
        web_port: int = 9090,
        grpc_port: int = 9876,
    ) -> None:
        self.env = env
        layout, at = {}, 0
        for name, size in env.observation_layout:
            layout[name] = slice(at, at + size)
            at += size
        self._at = layout
        self._start(serve, save, web_port, grpc_port, float(env.dt))

    def __getattr__(self, name: str):
        return getattr(self.env, name)

    def _draw(self, obs, infos, rewards, terminated, truncated) -> None:
        scene, at = self.viewer.scene, self._at
        for agent, o in obs.items():
            info = infos[agent]
            position = _ned(info["position"])
            q = quat_enu_to_ned(o[at["quaternion"]]) if "quaternion" in at else [1, 0, 0, 0]
            scene.vehicle(agent, position, q, Frame.quad_x())
            if "motor_commands" in at:
                scene.motors(agent + "_command", o[at["motor_commands"]])
            if "target_position" in info:
                scene.target(agent, _ned(info["target_position"]))
            draw_events(scene, agent, info, position, self._faults)
            if rewards is not None:
                scene.task(agent, rewards[agent], bool(terminated[agent]), bool(truncated[agent]))

    def close(self) -> None:
        self.viewer.close()
        self.env.close()
