"""Watch: a gym env (or one env of a vector env) in the live view and/or recorded to .rrd:
the vehicle, its trail and target, wind, motor commands, rewards and episode ends, and the
faults that fire or end and the collisions its info reports as events, on the simulation
clock (the steps' dt added up over the episodes)."""

from __future__ import annotations

import math
from pathlib import Path
from types import SimpleNamespace
from typing import Any

import gymnasium as gym
import numpy as np

from .scene import Frame, quat_enu_to_ned


def _quat_from_euler(roll: float, pitch: float, yaw: float) -> list[float]:
    cr, sr = math.cos(roll / 2), math.sin(roll / 2)
    cp, sp = math.cos(pitch / 2), math.sin(pitch / 2)
    cy, sy = math.cos(yaw / 2), math.sin(yaw / 2)
    return [
        cr * cp * cy + sr * sp * sy,
        sr * cp * cy - cr * sp * sy,
        cr * sp * cy + sr * cp * sy,
        cr * cp * sy - sr * sp * cy,
    ]


def _ned(v) -> list[float]:
    x, y, z = (float(a) for a in v)
    return [y, x, -z]


def draw_events(scene, name: str, info, position_ned, seen: dict[str, set]) -> None:
    """The events in one env's (or agent's) info: a collision the world reported
    (`collided`, `collision_speed`) and the faults that fired or ended since the last step
    (`faults`, flyloop.faults.active_faults' list); `seen` keeps each name's active faults."""
    if info.get("collided"):
        scene.collision(name, position_ned, float(info.get("collision_speed", 0.0)))
    if "faults" not in info:
        return
    active = {f["fault"] for f in info["faults"]}
    before = seen.get(name, set())
    scene.faults(name, sorted(active - before), sorted(before - active))
    seen[name] = active


def draw(scene, name: str, s, reward: float | None, terminated: bool, truncated: bool) -> None:
    """Draws one frame of an env (its QuadScene or LanderScene, the env's own render data)."""
    if hasattr(s, "quaternion"):  # the quadrotor, world ENU
        position = _ned(s.position)
        scene.vehicle(name, position, quat_enu_to_ned(s.quaternion), Frame.quad_x(s.arm_length))
        scene.motors(name + "_command", s.motors)
        scene.wind(name, position, _ned(s.wind))
        if s.target is not None:
            scene.target(name, _ned(s.target))
    else:  # the lander, in the east-up plane (protocol.md §5): FRD pitch = angle, yaw 90°
        position = [0.0, float(s.position[0]), -float(s.position[1])]
        q = _quat_from_euler(0.0, float(s.angle), math.pi / 2)
        scene.vehicle(name, position, q, Frame.lander(s.drone_width))
        scene.motors(name + "_command", np.asarray(s.thrust) / s.max_thrust)
        top_x, top_y = s.platform_top
        scene.target(name, [0.0, top_x, -top_y])
    if reward is not None:
        scene.task(name, reward, terminated, truncated)


def _position(s) -> list[float]:
    """The NED position `draw` puts a scene's vehicle at."""
    if hasattr(s, "quaternion"):
        return _ned(s.position)
    return [0.0, float(s.position[0]), -float(s.position[1])]


class _Watching:
    """What Watch and WatchVector share: the viewer, the simulation clock, reset and step."""

    def _start(self, serve: bool, save, web_port: int, grpc_port: int, dt: float) -> None:
        from . import Viewer

        self.viewer = Viewer(
            web_port=web_port if serve else None, grpc_port=grpc_port, save=save, serve=serve
        )
        if self.viewer.url:
            print(f"flyloop.view: open {self.viewer.url}", flush=True)
        self._dt, self._t, self._episode = dt, 0.0, -1
        self._faults: dict[str, set] = {}  # each vehicle's active faults, for their events

    def reset(self, *, seed: int | None = None, options: dict[str, Any] | None = None):
        obs, info = self.env.reset(seed=seed, options=options)
        self._episode += 1
        self._faults = {}  # a new episode's faults start afresh
        self.viewer.rec.set_time("episode", sequence=self._episode)
        self.viewer.scene.time(self._t)
        self._draw(obs, info, None, None, None)
        return obs, info

    def step(self, action):
        obs, reward, terminated, truncated, info = self.env.step(action)
        self._t += self._dt
        self.viewer.scene.time(self._t)
        self._draw(obs, info, reward, terminated, truncated)
        return obs, reward, terminated, truncated, info


class Watch(_Watching, gym.Wrapper):
    """Shows `env` in the live view (`serve=True`: prints the URL) and/or records it to the
    .rrd file `save`. Draws what the env's own rendering draws (its `_scene`), so the two
    stay one. For a vector env: :class:`WatchVector`."""

    def __init__(
        self,
        env: gym.Env,
        *,
        serve: bool = True,
        save: str | Path | None = None,
        web_port: int = 9090,
        grpc_port: int = 9876,
    ) -> None:
        gym.Wrapper.__init__(self, env)
        self._start(serve, save, web_port, grpc_port, float(env.unwrapped.dt))

    def _draw(self, obs, info, reward, terminated, truncated) -> None:
        s = self.env.unwrapped._scene(obs, info, reward)
        draw(self.viewer.scene, "vehicle1", s, reward, bool(terminated), bool(truncated))
        draw_events(self.viewer.scene, "vehicle1", info, _position(s), self._faults)

    def close(self) -> None:
        self.viewer.close()
        super().close()


class WatchVector(_Watching, gym.vector.VectorWrapper):
    """Shows env `index` of a flyloop vector env, as :class:`Watch` does a single env."""

    def __init__(
        self,
        envs,
        *,
        index: int = 0,
        serve: bool = True,
        save: str | Path | None = None,
        web_port: int = 9090,
        grpc_port: int = 9876,
    ) -> None:
        gym.vector.VectorWrapper.__init__(self, envs)
        if not 0 <= index < envs.num_envs:
            raise ValueError(f"index must be in [0, {envs.num_envs}), got {index}")
        self.index = index
        self._start(serve, save, web_port, grpc_port, float(envs.unwrapped.dt))

    def _draw(self, obs, infos, rewards, terminated, truncated) -> None:
        i, vector = self.index, self.env.unwrapped
        info = {k: v[i] for k, v in infos.items() if not k.startswith("_")}
        # The single env's scene from env i's values (the vector env keeps no episode return).
        owner = SimpleNamespace(core=vector.core, _episode_return=None)
        reward = None if rewards is None else float(rewards[i])
        s = vector.SINGLE._scene(owner, obs[i], info, reward)
        ended = (False, False) if terminated is None else (terminated[i], truncated[i])
        draw(self.viewer.scene, f"env{i}", s, reward, bool(ended[0]), bool(ended[1]))
        draw_events(self.viewer.scene, f"env{i}", info, _position(s), self._faults)

    def close(self, **kwargs):
        self.viewer.close()
        return super().close(**kwargs)
