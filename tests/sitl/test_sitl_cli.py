"""The command line: help, one-line errors with a non-zero exit for a port in use or a bad
config, listings, and a clean stop on SIGINT / SIGTERM."""

from __future__ import annotations

import signal
import socket
import subprocess

from sitl_client import Sitl


def run(binary, *args: str) -> subprocess.CompletedProcess:
    return subprocess.run([str(binary), *args], capture_output=True, text=True, timeout=10)


def test_help_lists_every_option(sitl_binary):
    result = run(sitl_binary, "--help")
    assert result.returncode == 0
    for option in (
        "--model", "--task", "--listen", "--gcs", "--mode", "--realtime", "--lockstep",
        "--vehicles", "--seed", "--config", "--log-level", "--home", "--no-state-reply",
        "--failsafe-timeout", "--state-rate", "--list-params", "--describe-frame",
    ):  # fmt: skip
        assert option in result.stdout, option


def test_a_port_in_use_is_one_line_and_a_non_zero_exit(sitl_binary):
    with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as taken:
        taken.bind(("127.0.0.1", 0))
        port = taken.getsockname()[1]
        result = run(sitl_binary, "--listen", f"127.0.0.1:{port}", "--gcs", "off")
    assert result.returncode != 0
    lines = result.stderr.strip().splitlines()
    assert len(lines) == 1, result.stderr
    assert lines[0].startswith("flyloop-sitl: error: cannot bind the controller socket")
    assert f"127.0.0.1:{port}" in lines[0] and "in use" in lines[0]
    assert result.stdout == ""


def test_a_bad_config_names_the_parameter_and_its_bound(sitl_binary, tmp_path):
    config = tmp_path / "bad.toml"
    config.write_text("max_steps = 100\nthrust_coefficient = -3.0\n")
    result = run(sitl_binary, "--config", str(config), "--gcs", "off", "--listen", "127.0.0.1:0")
    assert result.returncode != 0
    assert result.stderr.strip().splitlines() == [
        f"flyloop-sitl: error: config file {config}: parameter `thrust_coefficient` = -3 N "
        "is out of range: it must be in [0, 1e6] N"
    ]
    result = run(sitl_binary, "--config", str(tmp_path / "missing.toml"))
    assert result.returncode != 0 and "cannot read config file" in result.stderr
    config.write_text("moving_platform = true\nmax_steps = 0\n")
    result = run(sitl_binary, "--model", "lander2d", "--config", str(config))
    assert result.returncode != 0 and "`max_steps` = 0 is out of range" in result.stderr


def test_a_good_config_is_served_over_the_parameter_protocol(start_sitl, client_for, tmp_path):
    config = tmp_path / "quad.toml"
    config.write_text("mass = 1.5\nmax_steps = 250\nwind_enabled = false\n")
    client = client_for(start_sitl("--config", str(config)))
    for name, value in (("mass", 1.5), ("max_steps", 250.0), ("wind_enabled", 0.0)):
        assert client.param_read(name)[0].param_value == value


def test_a_wrong_task_for_the_model_is_refused(sitl_binary):
    result = run(sitl_binary, "--model", "lander2d", "--task", "waypoints")
    assert result.returncode != 0
    assert "task `waypoints` does not run on model `lander2d`" in result.stderr


def test_listings_print_and_exit(sitl_binary):
    params = run(sitl_binary, "--task", "waypoints", "--list-params")
    assert params.returncode == 0
    rows = [ln for ln in params.stdout.splitlines() if ln.startswith("| `")]
    ids = [r.split("`")[1] for r in rows]
    # 30 quadrotor parameters (22 + the 7 of the landing gear + turbulence_dt), 18 flight
    # (12 + the rates interface's 6), 4 waypoints, 27 of PX4's rate loop.
    assert len(ids) == 79 and len(set(ids)) == 79 and max(map(len, ids)) <= 16
    assert "| `en_oob_det` | `enable_out_of_bounds_detection` |" in params.stdout
    frame = run(sitl_binary, "--task", "hover", "--describe-frame")
    assert frame.returncode == 0
    assert "6..39 observation (33 values)" in frame.stdout
    assert "40..43 info.position (3 values)" in frame.stdout


def test_sigint_and_sigterm_stop_cleanly(sitl_binary):
    for sig in (signal.SIGINT, signal.SIGTERM):
        sitl = Sitl(sitl_binary, "--gcs", "off")
        assert sitl.stop(sig) == 0
        assert "stopped: datagrams=0" in sitl.stderr()
