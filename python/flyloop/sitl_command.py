"""The `flyloop-sitl` console command of the wheel: the SITL program compiled into the
extension (flyloop_sitl::app), so an installed wheel needs no cargo and no separate binary.

    flyloop-sitl --task hover --listen 127.0.0.1:0     # same options as the cargo build
"""

from __future__ import annotations

import signal
import sys


def main() -> None:
    from . import _native

    # The SITL installs its own SIGINT / SIGTERM handlers and stops cleanly on them; Python's
    # SIGINT handler would only turn the same signal into a KeyboardInterrupt afterwards.
    signal.signal(signal.SIGINT, signal.SIG_DFL)
    sys.stdout.flush()
    sys.exit(_native.sitl_main(sys.argv))


if __name__ == "__main__":
    main()
