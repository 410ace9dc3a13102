"""Human mode in a real X window: Xvfb on a free display, its framebuffer read back (-fbdir
writes the screen as an XWD file) and compared with what rgb_array mode draws; real pygame
events (only Escape and closing act); clean close. Needs the Debian package xvfb."""

import os
import select
import shutil
import struct
import subprocess
import sys
import time

import numpy as np
import pygame  # a hard dependency: its absence must fail, not skip
import pytest

from flyloop.rendering import LanderScene, LanderView, OrbitCamera, QuadrotorView, QuadScene

QUAD = QuadScene(
    time_s=1.0,
    step=10,
    position=(0.3, -0.2, 1.4),
    velocity=(0.5, 0.2, 0.0),
    quaternion=(0.98, 0.1, -0.05, 0.15),
    motors=(0.6, 0.5, 0.4, 0.55),
    wind=(2.0, 1.0, 0.0),
    target=(1.0, 1.0, 2.0),
    reward=0.5,
)
LANDER = LanderScene(
    time_s=1.0,
    step=10,
    position=(24.0, 30.0),
    velocity=(0.5, -1.0),
    angle=0.1,
    angular_velocity=0.2,
    thrust=(6.0, 8.0),
    battery=90.0,
    platform_x=25.0,
    wind_force=(2.5, 0.0),
    wind_speed=5.0,
)


@pytest.fixture(scope="module")
def xvfb(tmp_path_factory):
    exe = shutil.which("Xvfb")
    if exe is None:
        pytest.skip("Xvfb is not installed (apt-get install xvfb): no display for human mode")
    fbdir = tmp_path_factory.mktemp("xvfb")
    read_fd, write_fd = os.pipe()
    proc = subprocess.Popen(
        [exe, "-displayfd", str(write_fd), "-screen", "0", "1024x900x24", "-br"]
        + ["-nolisten", "tcp", "-fbdir", str(fbdir)],
        pass_fds=(write_fd,),
        stdout=subprocess.DEVNULL,
        stderr=subprocess.DEVNULL,
    )
    os.close(write_fd)
    try:
        ready, _, _ = select.select([read_fd], [], [], 15.0)
        number = os.read(read_fd, 16).decode().strip() if ready else ""
        if not number:
            pytest.fail("Xvfb did not report a display within 15 s")
        yield f":{number}", fbdir / "Xvfb_screen0"
    finally:
        os.close(read_fd)
        proc.terminate()
        proc.wait(timeout=10)


@pytest.fixture
def display(xvfb, monkeypatch):
    name, framebuffer = xvfb
    monkeypatch.setenv("DISPLAY", name)
    monkeypatch.delenv("SDL_VIDEODRIVER", raising=False)  # rgb_array tests may have set dummy
    monkeypatch.setenv("SDL_VIDEO_WINDOW_POS", "0,0")
    return framebuffer


@pytest.fixture
def views(display):
    """Views a test opens; closed even when it fails, before Xvfb goes away."""
    opened = []
    yield opened
    for view in opened:
        view.close()


def read_xwd(path) -> np.ndarray:
    """The (H, W, 3) RGB pixels of an XWD screen dump (32 bits per pixel, TrueColor)."""
    data = path.read_bytes()
    fields = struct.unpack(">25I", data[:100])
    header_size, width, height = fields[0], fields[4], fields[5]
    byte_order, bits_per_pixel, bytes_per_line = fields[7], fields[11], fields[12]
    masks, ncolors = fields[14:17], fields[19]
    assert bits_per_pixel == 32, bits_per_pixel
    offset = header_size + ncolors * 12
    raw = np.frombuffer(data, np.uint8, count=height * bytes_per_line, offset=offset)
    rows = raw.reshape(height, bytes_per_line)[:, : width * 4].copy()
    value = rows.view("<u4" if byte_order == 0 else ">u4")
    shift = [int(m & -m).bit_length() - 1 for m in masks]
    return np.stack([(value & m) >> s for m, s in zip(masks, shift, strict=True)], -1).astype(
        np.uint8
    )


def wait_for_window(framebuffer, expected: np.ndarray, rows: int) -> float:
    """Largest fraction of the window's first `rows` rows equal to `expected`, polled ~3 s."""
    best = 0.0
    deadline = time.monotonic() + 3.0
    while time.monotonic() < deadline:
        pygame.event.pump()
        screen = read_xwd(framebuffer)
        h, w = expected.shape[:2]
        same = np.all(screen[:rows, :w] == expected[:rows], axis=-1).mean()
        best = max(best, float(same))
        if best > 0.995:
            break
        time.sleep(0.05)
    return best


def test_quadrotor_window_shows_the_frame_and_closes_cleanly(display, views):
    offscreen = QuadrotorView("rgb_array", width=640, height=480)
    expected = offscreen.render(QUAD)
    offscreen.close()
    view = QuadrotorView("human", width=640, height=480, fps=0)
    views.append(view)
    for _ in range(3):
        assert view.render(QUAD) is None
    assert pygame.display.get_driver() == "x11"
    assert pygame.display.get_surface().get_size() == (640, 480)
    # The window draws what rgb_array returns, to the last row.
    assert wait_for_window(display, expected, rows=480) > 0.995
    view.close()
    view.close()
    assert not pygame.display.get_init()
    assert not view.is_open


def test_lander_window_shows_the_frame(display, views):
    offscreen = LanderView("rgb_array", width=600, height=600)
    expected = offscreen.render(LANDER)
    offscreen.close()
    view = LanderView("human", width=600, height=600, fps=0)
    views.append(view)
    for _ in range(3):
        view.render(LANDER)
    assert wait_for_window(display, expected, rows=600) > 0.995
    view.close()
    assert not pygame.display.get_init()


def post(kind, **attrs):
    pygame.event.post(pygame.event.Event(kind, **attrs))


def test_a_turned_camera_is_drawn_and_input_other_than_escape_leaves_it(display, views):
    # Orbiting and zooming are the Rerun view's (flyloop.view.Watch): the window keeps the
    # camera it is given, whatever the mouse and keys do.
    camera = OrbitCamera(azimuth_deg=120.0, elevation_deg=40.0, distance=5.0)
    offscreen = QuadrotorView("rgb_array", width=480, height=360, camera=camera)
    expected = offscreen.render(QUAD)
    offscreen.close()
    view = QuadrotorView("human", width=480, height=360, fps=0, camera=camera)
    views.append(view)
    view.render(QUAD)
    post(pygame.MOUSEBUTTONDOWN, button=1, pos=(200, 200))
    post(pygame.MOUSEMOTION, pos=(250, 210), rel=(50, 10), buttons=(1, 0, 0))
    post(pygame.MOUSEWHEEL, x=0, y=2, flipped=False)
    post(pygame.KEYDOWN, key=pygame.K_w, mod=0, unicode="w", scancode=26)
    assert view.render(QUAD) is None and view.is_open
    assert (camera.azimuth_deg, camera.elevation_deg, camera.distance) == (120.0, 40.0, 5.0)
    assert wait_for_window(display, expected, rows=360) > 0.995
    view.close()


def test_closing_the_window_stops_rendering_and_frees_it(display, views):
    view = LanderView("human", width=300, height=300, fps=0)
    views.append(view)
    view.render(LANDER)
    with pytest.raises(RuntimeError, match="already owns the pygame window"):
        QuadrotorView("human", width=300, height=300)
    post(pygame.QUIT)
    assert view.render(LANDER) is None
    assert not view.is_open
    assert not pygame.display.get_init()
    view.close()  # after the user closed it: still fine
    again = QuadrotorView("human", width=300, height=300, fps=0)  # the window is free again
    views.append(again)
    again.render(QUAD)
    post(pygame.KEYDOWN, key=pygame.K_ESCAPE, mod=0, unicode="\x1b", scancode=41)
    assert again.render(QUAD) is None
    assert not again.is_open
    again.close()


def test_human_mode_without_a_display_is_a_clear_error(monkeypatch):
    monkeypatch.delenv("DISPLAY", raising=False)
    monkeypatch.delenv("WAYLAND_DISPLAY", raising=False)
    monkeypatch.setenv("SDL_VIDEODRIVER", "x11")
    with pytest.raises(RuntimeError, match="needs a display"):
        QuadrotorView("human", width=200, height=200)


NO_DISPLAY_SCRIPT = """
import gymnasium as gym, flyloop
env = gym.make("flyloop/QuadHover-v0", backend="native", render_mode="human")
env.reset(seed=0)
print("no error: a window opened?")
"""


def run_headless(**env_vars: str) -> subprocess.CompletedProcess:
    """The script in a fresh interpreter with no display at all (as on a server or in CI),
    plus `env_vars`: what a user without a desktop gets."""
    env = {
        k: v
        for k, v in os.environ.items()
        if k not in ("DISPLAY", "WAYLAND_DISPLAY", "SDL_VIDEODRIVER", "XDG_RUNTIME_DIR")
    }
    return subprocess.run(
        [sys.executable, "-c", NO_DISPLAY_SCRIPT],
        env={**env, **env_vars},
        capture_output=True,
        text=True,
        timeout=120,
    )


@pytest.mark.parametrize(
    "env_vars,why",
    [
        ({}, "DISPLAY and WAYLAND_DISPLAY are not set"),
        # A display that is not there: SDL falls back to its off-screen driver by itself.
        ({"DISPLAY": ":97"}, "SDL fell back to its 'offscreen' driver"),
    ],
)
def test_human_mode_with_no_display_says_what_is_wrong_and_what_to_do(env_vars, why):
    done = run_headless(**env_vars)
    assert done.returncode == 1, done.stdout + done.stderr
    last = done.stderr.strip().splitlines()[-1]
    assert last.startswith("RuntimeError: render_mode='human' needs a display"), done.stderr
    for advice in (why, "desktop", "xvfb-run", "render_mode='rgb_array'"):
        assert advice in last, (advice, last)
    assert "no error" not in done.stdout


def test_an_off_screen_driver_the_user_asked_for_is_kept():
    done = run_headless(SDL_VIDEODRIVER="offscreen")
    assert done.returncode == 0 and "no error" in done.stdout, done.stderr
