"""Frame cost of the views in rgb_array mode, and of building a scene from a step.

    python python/examples/render_benchmark.py [--frames 300]

Renders the sample trajectories of render_samples.py (HUD, trail, path and shades on) and
prints milliseconds per frame; one core, no display needed.
"""

from __future__ import annotations

import argparse
import time

from render_samples import lander_scenes, quad_scenes

from flyloop.rendering import LanderView, QuadrotorView, QuadScene


def per_call_ms(fn, items) -> float:
    start = time.perf_counter()
    for item in items:
        fn(item)
    return (time.perf_counter() - start) / len(items) * 1e3


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--frames", type=int, default=300)
    args = parser.parse_args()
    quads = (quad_scenes(90) * (args.frames // 90 + 1))[: args.frames]
    landers = (lander_scenes(260) * (args.frames // 260 + 1))[: args.frames]
    for name, view, scenes in (
        ("QuadrotorView 960x720", QuadrotorView("rgb_array"), quads),
        ("QuadrotorView 480x360", QuadrotorView("rgb_array", width=480, height=360), quads),
        ("LanderView 800x800", LanderView("rgb_array"), landers),
        ("LanderView 400x400", LanderView("rgb_array", width=400, height=400), landers),
    ):
        view.render(scenes[0])  # fonts and caches
        ms = per_call_ms(view.render, scenes)
        view.close()
        print(f"{name:24s} {ms:6.2f} ms/frame  ({1e3 / ms:5.0f} frames/s)")
    s = quads[0]
    build = per_call_ms(
        lambda _: QuadScene(
            time_s=s.time_s,
            step=s.step,
            position=s.position,
            velocity=s.velocity,
            quaternion=s.quaternion,
            motors=s.motors,
            wind=s.wind,
            target=s.target,
        ),
        range(2000),
    )
    print(f"{'QuadScene(...)':24s} {build * 1e3:6.1f} us/scene")


if __name__ == "__main__":
    main()
