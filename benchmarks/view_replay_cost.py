"""The view's own cost: a recording (.tlog) replayed through the view's scene into an .rrd,
with no server and no browser; prints the messages, the CPU seconds and the .rrd's size
(docs/view.md). Run it with two checkouts' python/ on PYTHONPATH to compare them:

    PYTHONPATH=python .venv/bin/python benchmarks/view_replay_cost.py run.tlog out.rrd
"""

from __future__ import annotations

import argparse
import os
import time

from flyloop.view import Viewer


def main() -> None:
    a = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    a.add_argument("tlog", help="a flyloop-sitl --record telemetry log")
    a.add_argument("rrd", help="where the replay's recording is written")
    args = a.parse_args()
    viewer = Viewer(web_port=None, grpc_port=None, save=args.rrd, serve=False)
    start = time.process_time()
    n = viewer.replay(args.tlog)  # as `python -m flyloop.view FILE` and flyloop.plot replay it
    viewer.close()
    cpu = time.process_time() - start
    size = os.path.getsize(args.rrd) / 1e6
    print(f"{n} messages, {cpu:.2f} CPU s ({cpu / n * 1e6:.0f} us per message), {size:.2f} MB")


if __name__ == "__main__":
    main()
