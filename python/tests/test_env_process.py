"""The SITL process behind an env: errors instead of hangs, no zombie, no orphan, no leak."""

from __future__ import annotations

import gc
import os
import signal
import subprocess
import sys
import textwrap
import time
from pathlib import Path

import numpy as np
import pytest

from flyloop import SitlError
from flyloop.envs import Lander2DEnv, QuadHoverEnv


def gone(pid: int) -> bool:
    """True when `pid` neither runs nor lingers as a zombie."""
    try:
        state = Path(f"/proc/{pid}/stat").read_text().split(")")[-1].split()[0]
    except FileNotFoundError:
        return True
    return state == "X"


def wait_gone(pid: int, seconds: float = 3.0) -> bool:
    end = time.monotonic() + seconds
    while time.monotonic() < end:
        if gone(pid):
            return True
        time.sleep(0.01)
    return gone(pid)


def children() -> set[int]:
    pids = set()
    for task in Path(f"/proc/{os.getpid()}/task").iterdir():
        text = (task / "children").read_text().split()
        pids.update(int(p) for p in text)
    return pids


def test_a_sitl_killed_mid_episode_raises_sitl_error_at_once(make_env):
    env = make_env(QuadHoverEnv, timeout=5.0)
    env.reset(seed=0)
    env.step(np.full(4, 0.5, np.float32))
    pid = env.sitl_process.pid
    os.kill(pid, signal.SIGKILL)
    start = time.monotonic()
    with pytest.raises(SitlError) as err:
        for _ in range(3):  # the first send may still be queued before the refusal shows
            env.step(np.full(4, 0.5, np.float32))
    assert time.monotonic() - start < 2.0, "not the 5 s timeout: the refusal is seen at once"
    text = str(err.value)
    assert f"pid {pid}" in text and "was killed by signal 9" in text, text
    assert err.value.exit_code == -9
    assert gone(pid), "reaped, not a zombie"
    with pytest.raises(SitlError, match="lost its SITL earlier"):
        env.reset()
    env.close()
    env.close()


def test_a_sitl_that_stops_answering_raises_within_the_timeout(make_env):
    env = make_env(Lander2DEnv, timeout=0.3)
    env.reset(seed=0)
    pid = env.sitl_process.pid
    os.kill(pid, signal.SIGSTOP)
    try:
        start = time.monotonic()
        with pytest.raises(
            SitlError, match=r"is running but sent no task frame after a step within 0.3 s"
        ):
            env.step(np.zeros(2, np.float32))
        assert 0.25 < time.monotonic() - start < 2.0
    finally:
        os.kill(pid, signal.SIGCONT)
    env.close()
    assert gone(pid)


def test_a_sitl_stopped_by_sigterm_reports_its_exit_code_and_stderr(make_env):
    env = make_env(QuadHoverEnv)
    env.reset(seed=0)
    pid = env.sitl_process.pid
    os.kill(pid, signal.SIGTERM)
    assert wait_gone(pid) or env.sitl_process.poll() is not None
    with pytest.raises(SitlError, match=r"exited with code 0") as err:
        for _ in range(3):
            env.step(np.full(4, 0.5, np.float32))
    assert err.value.exit_code == 0


def test_close_stops_and_reaps_the_sitl_and_a_forgotten_env_is_cleaned_up(sitl_binary):
    env = QuadHoverEnv()
    pid = env.sitl_process.pid
    assert not gone(pid)
    env.close()
    assert gone(pid)
    env.close()
    with pytest.raises(SitlError, match="closed"):
        env.reset()

    forgotten = QuadHoverEnv()
    pid = forgotten.sitl_process.pid
    del forgotten
    gc.collect()
    assert wait_gone(pid), "the finalizer stopped the SITL"


def test_a_killed_python_process_leaves_no_orphan_sitl(sitl_binary, tmp_path):
    script = textwrap.dedent(
        """
        import os, signal, sys
        from flyloop.envs import QuadHoverEnv
        env = QuadHoverEnv()
        env.reset(seed=0)
        print(env.sitl_process.pid, flush=True)
        os.kill(os.getpid(), signal.SIGKILL)
        """
    )
    out = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, timeout=60)
    assert out.returncode == -9, out.stderr
    pid = int(out.stdout.split()[0])
    assert wait_gone(pid), f"SITL {pid} outlived its parent"


def test_start_failures_are_sitl_errors_with_the_exit_code(tmp_path):
    with pytest.raises(SitlError, match="exited with code 1 before it was ready") as err:
        QuadHoverEnv(sitl_path="/bin/false")
    assert err.value.exit_code == 1
    mute = tmp_path / "mute-sitl"
    mute.write_text("#!/bin/sh\nexec sleep 30\n")
    mute.chmod(0o755)
    before = children()
    start = time.monotonic()
    with pytest.raises(SitlError, match="printed no ready line within 0.3 s"):
        QuadHoverEnv(sitl_path=str(mute), timeout=0.3)
    assert time.monotonic() - start < 3.0
    assert children() == before, "the mute process was stopped"
    chatty = tmp_path / "other-tool"
    chatty.write_text("#!/bin/sh\necho hello\nexec sleep 30\n")
    chatty.chmod(0o755)
    with pytest.raises(SitlError, match="did not start as flyloop-sitl: first line 'hello'"):
        QuadHoverEnv(sitl_path=str(chatty))
    assert children() == before


def test_ten_thousand_resets_leak_no_descriptor_process_or_memory(make_env):
    env = make_env(QuadHoverEnv)
    env.reset(seed=0)
    fds = len(os.listdir("/proc/self/fd"))
    kids = children()
    start = time.monotonic()
    for seed in range(10_000):
        obs, info = env.reset(seed=seed)
    elapsed = time.monotonic() - start
    assert info["step_count"] == 0
    assert len(os.listdir("/proc/self/fd")) == fds
    assert children() == kids
    status = Path(f"/proc/{env.unwrapped.sitl_process.pid}/status").read_text()
    rss_kb = int(next(x for x in status.splitlines() if x.startswith("VmRSS")).split()[1])
    assert rss_kb < 50_000, f"SITL resident memory {rss_kb} kB after 10,000 resets"
    print(f"10,000 resets in {elapsed:.2f} s")


def test_many_envs_made_and_closed_leave_nothing_behind(sitl_binary):
    fds = len(os.listdir("/proc/self/fd"))
    kids = children()
    for _ in range(20):
        env = Lander2DEnv()
        env.reset(seed=1)
        env.close()
    assert len(os.listdir("/proc/self/fd")) == fds
    assert children() == kids
