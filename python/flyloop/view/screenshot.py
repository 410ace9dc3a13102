"""python -m flyloop.view.screenshot URL PNG: the view as a person sees it, in headless
Chromium (Debian's package, driven by playwright; the web viewer's WebGL runs on SwiftShader,
the software rasteriser). Waits for the viewer to load (its wasm takes ~20 s on 2 cores) and
for the vehicle (the hub's colour) to appear, then writes the PNG. Used by the browser tests
and for the README's picture (docs/view.md). The browser: $FLYLOOP_CHROMIUM, else `chromium`
on the PATH, else /usr/bin/chromium."""

from __future__ import annotations

import argparse
import os
import shutil
import sys
import time
from collections.abc import Callable
from pathlib import Path

import numpy as np

from .scene import HUB

CHROMIUM_ARGS = [
    "--use-angle=swiftshader",
    "--enable-unsafe-swiftshader",
    "--no-sandbox",
    "--disable-background-networking",
    "--disable-component-update",
    "--disable-sync",
    "--disable-quic",
    "--no-first-run",
]


class BrowserError(RuntimeError):
    """The browser could not be started or the page not shown, in one line."""


def chromium_path() -> str:
    path = os.environ.get("FLYLOOP_CHROMIUM") or shutil.which("chromium") or "/usr/bin/chromium"
    if not Path(path).exists():
        raise BrowserError(
            f"no Chromium at {path}: install Debian's chromium (scripts/apt-packages.txt)"
            " or set FLYLOOP_CHROMIUM"
        )
    return path


# The 3D view's part of the page (the blueprint's left 3/5, below the top bar): the plots'
# series may take any colour.
WORLD_PANEL = (0.0, 0.08, 0.58, 0.95)  # left, top, right, bottom as fractions


def world_panel(png: bytes | str | Path) -> tuple[np.ndarray, tuple[int, int], tuple[int, int]]:
    """The 3D view's pixels (rows, columns, RGB as int), the offset of its top-left corner in
    the page, and the page's size (height, width)."""
    import io

    from PIL import Image

    data = png if isinstance(png, bytes) else Path(png).read_bytes()
    img = np.asarray(Image.open(io.BytesIO(data)).convert("RGB")).astype(int)
    h, w = img.shape[:2]
    left, top, right, bottom = WORLD_PANEL
    t0, l0 = int(top * h), int(left * w)
    return img[t0 : int(bottom * h), l0 : int(right * w)], (t0, l0), (h, w)


def hub_pixels(png: bytes | str | Path) -> np.ndarray:
    """(row, column) of the pixels in the hub's colour (shaded: magenta hues) in the 3D view."""
    img, (t0, l0), _ = world_panel(png)
    r, g, b = img[..., 0], img[..., 1], img[..., 2]
    # HUB is (255, 0, 200): red and blue well above green, whatever the light.
    target = np.array(HUB)
    mask = (
        (r > g + 90)
        & (b > g + 70)
        & (g < 110)
        & (abs((b - g) / np.maximum(r - g, 1) - target[2] / target[0]) < 0.35)
    )
    return np.argwhere(mask) + [t0, l0]


def world_drawn(png: bytes) -> bool:
    """Whether the 3D view shows the ground (its grid, GROUND's grey, and the pad): the viewer
    has loaded and taken in the view's static world, before any vehicle (not the viewer's
    welcome page, nor its dark loading screen)."""
    from .scene import GROUND

    img, _, (h, w) = world_panel(png)
    grid = (np.abs(img - np.array(GROUND)) < 25).all(axis=-1).sum()
    dark = (img < 80).all(axis=-1).sum()
    # Measured at 1280 x 720: the world drawn 5,306 grid and 917 dark pixels; the welcome
    # page 2,129 and 4,894; the loading screen is nearly all dark.
    return grid >= 3500 * (h * w) / (1280 * 720) and dark < grid


class Browser:
    """One headless Chromium page at `size` (width, height)."""

    def __init__(self, size: tuple[int, int] = (1280, 720)) -> None:
        try:
            from playwright.sync_api import sync_playwright
        except ImportError:
            raise BrowserError("playwright is not installed (tests/requirements.txt)") from None
        path = chromium_path()
        self._pw = sync_playwright().start()
        try:
            self._browser = self._pw.chromium.launch(
                executable_path=path, headless=True, args=CHROMIUM_ARGS, timeout=60_000
            )
        except Exception as e:
            self._pw.stop()
            first = str(e).strip().splitlines()[0] if str(e).strip() else type(e).__name__
            raise BrowserError(f"cannot start Chromium at {path}: {first}") from None
        self.page = self._browser.new_page(viewport={"width": size[0], "height": size[1]})

    def open(self, url: str, timeout: float = 60.0) -> None:
        try:
            self.page.goto(url, timeout=timeout * 1000)
        except Exception as e:
            raise BrowserError(f"cannot open {url}: {str(e).splitlines()[0]}") from None

    def screenshot(self, path: str | Path | None = None, timeout: float = 120.0) -> bytes:
        """The page as PNG. The software rasteriser on a loaded machine can take tens of
        seconds to finish a frame (playwright's default 30 s timed out at load 25)."""
        return self.page.screenshot(path=str(path) if path else None, timeout=timeout * 1000)

    def wait_for_world(self, timeout: float = 90.0) -> bool:
        """Screenshots until the 3D view shows the ground ([`world_drawn`]) or `timeout`
        passes; whether it did. For a page opened before the data flows: it then takes the
        flight in as it comes instead of a backlog (docs/view.md, "How far behind")."""
        end = time.monotonic() + timeout
        while True:
            if world_drawn(self.screenshot()):
                return True
            if time.monotonic() > end:
                return False
            time.sleep(1.0)

    def wait_for_vehicle(
        self,
        min_pixels: int = 30,
        timeout: float = 90.0,
        until: Callable[[np.ndarray], bool] | None = None,
    ) -> tuple[bytes, int]:
        """Screenshots until the hub shows (at least `min_pixels`, and `until(hub pixels)`
        holds when given) or `timeout` passes; returns the last screenshot and its hub pixel
        count. `until` is for a fleet: the viewer ingests a stream in order, so the first
        vehicles can show seconds before the last."""
        end = time.monotonic() + timeout
        while True:
            shot = self.screenshot()
            pixels = hub_pixels(shot)
            n = len(pixels)
            done = n >= min_pixels and (until is None or until(pixels))
            if done or time.monotonic() > end:
                return shot, n
            time.sleep(2.0)

    def close(self) -> None:
        self._browser.close()
        self._pw.stop()


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(
        prog="python -m flyloop.view.screenshot", description=__doc__.split("\n\n")[0]
    )
    p.add_argument("url", help="the URL python -m flyloop.view printed")
    p.add_argument("png", help="the PNG to write")
    p.add_argument(
        "--timeout", type=float, default=90.0, help="seconds to wait for the vehicle (default 90)"
    )
    args = p.parse_args(argv)
    try:
        browser = Browser()
        try:
            browser.open(args.url)
            shot, n = browser.wait_for_vehicle(timeout=args.timeout)
            Path(args.png).write_bytes(shot)
        finally:
            browser.close()
    except BrowserError as e:
        print(f"flyloop.view.screenshot: {e}", file=sys.stderr)
        return 1
    print(f"flyloop.view.screenshot: wrote {args.png} ({n} vehicle pixels)")
    return 0 if n else 2


if __name__ == "__main__":
    sys.exit(main())
