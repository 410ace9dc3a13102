"""The Ray cluster commands of docs/training.md, run as written on this one machine: a head
node, a worker node joining it, and train_rllib.py attaching with `--address auto`. Only the
scale is cut (2 env runners, one small iteration) and the port is a free one; HEAD_IP is this
machine."""

from __future__ import annotations

import os
import re
import shlex
import signal
import socket
import subprocess
import sys
import time
from pathlib import Path

import pytest
from training_support import REPO

# What a laptop-sized run changes in the documented cluster command.
SMALLER = {"--num-env-runners": "2", "--iterations": "1", "--train-batch": "500"}
# Keep each node small: the machine is shared with the rest of the test run.
NODE = ["--num-cpus", "1", "--object-store-memory", "100000000", "--node-ip-address", "127.0.0.1"]


def readme_cluster_commands() -> list[str]:
    text = (REPO / "docs" / "training.md").read_text()
    block = re.search(r"```sh\n(ray start --head.*?)```", text, re.S)
    assert block, "docs/training.md has no Ray cluster block"
    return [line.split("  #")[0].strip() for line in block.group(1).splitlines() if line.strip()]


def free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def start_node(words: list[str], log: Path, env: dict[str, str]) -> subprocess.Popen:
    """`ray start ... --block` in its own session, so stopping it stops every process it
    started and nothing else (`ray stop` would stop any Ray on the machine)."""
    proc = subprocess.Popen(
        [*words, *NODE, "--block"],
        stdout=log.open("w"),
        stderr=subprocess.STDOUT,
        env=env,
        start_new_session=True,
    )
    deadline = time.monotonic() + 120
    while "Ray runtime started" not in log.read_text():
        assert proc.poll() is None and time.monotonic() < deadline, log.read_text()[-3000:]
        time.sleep(0.5)
    return proc


def active_nodes(env: dict[str, str], timeout: float = 90) -> int:
    """The cluster's active node count once `ray status` reports both nodes (it needs a few
    seconds after `ray start` to have a status at all)."""
    deadline, count, text = time.monotonic() + timeout, 0, ""
    while time.monotonic() < deadline:
        status = subprocess.run(
            ["ray", "status"], env=env, capture_output=True, text=True, timeout=60
        )
        text = status.stdout + status.stderr
        if "Active:" in status.stdout:
            count = status.stdout.split("Active:")[1].split("Pending:")[0].count("node_")
            if count == 2:
                break
        time.sleep(2)
    print(text)
    return count


def stop_node(proc: subprocess.Popen) -> None:
    for sig, wait in ((signal.SIGTERM, 20), (signal.SIGKILL, 10)):
        try:
            os.killpg(proc.pid, sig)
        except ProcessLookupError:
            return
        try:
            proc.wait(timeout=wait)
            return
        except subprocess.TimeoutExpired:
            continue


@pytest.mark.training
def test_the_readme_cluster_commands_train_on_a_two_node_cluster(sitl_binary, tmp_path):
    head, worker, train = readme_cluster_commands()
    port = free_port()
    bin_dir = Path(sys.executable).parent
    env = dict(os.environ, PATH=f"{bin_dir}{os.pathsep}{os.environ['PATH']}")
    env["RAY_ADDRESS"] = f"127.0.0.1:{port}"  # what `--address auto` finds
    env["FLYLOOP_SITL"] = str(sitl_binary)
    # Ray >= 2.60 turns token authentication on for a new local cluster (and an in-process
    # ray.init() earlier in this test run exports RAY_AUTH_MODE=token); nodes and driver must
    # agree. This loopback cluster runs without it, in a home of its own (no ~/.ray token).
    env["RAY_AUTH_MODE"] = "disabled"
    (tmp_path / "home").mkdir()
    env["HOME"] = str(tmp_path / "home")

    head_words = shlex.split(head.replace("6379", str(port)))
    worker_words = shlex.split(worker.replace("HEAD_IP", "127.0.0.1").replace("6379", str(port)))
    train_words = shlex.split(train)
    assert head_words[:3] == ["ray", "start", "--head"] and worker_words[:2] == ["ray", "start"]
    assert train_words[:2] == ["python", "examples/train/train_rllib.py"]
    assert train_words[train_words.index("--address") + 1] == "auto"
    for option, value in SMALLER.items():
        train_words[train_words.index(option) + 1] = value
    train_words[0] = sys.executable

    nodes = []
    try:
        nodes.append(start_node(head_words, tmp_path / "head.log", env))
        nodes.append(start_node(worker_words, tmp_path / "worker.log", env))
        assert active_nodes(env) == 2

        done = subprocess.run(
            [*train_words, "--minibatch", "100", "--epochs", "1"],
            cwd=REPO,
            env=env,
            capture_output=True,
            text=True,
            timeout=600,
        )
        assert done.returncode == 0, done.stdout[-3000:] + done.stderr[-3000:]
        assert re.search(r"^1 iterations, \d+ env steps", done.stdout, re.M), done.stdout
    finally:
        for node in reversed(nodes):
            stop_node(node)
