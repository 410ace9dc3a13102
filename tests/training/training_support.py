"""Paths and a script runner shared by the training tests."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

REPO = Path(__file__).resolve().parents[2]
TRAIN = REPO / "examples" / "train"
EXAMPLES = REPO / "examples"


def run_script(script: Path, *args: str, timeout: float = 600, env: dict | None = None):
    """Runs an example script with the venv's python; returns the CompletedProcess (stdout
    and stderr as text). The progress bar is off: it writes control characters."""
    return subprocess.run(
        [sys.executable, str(script), *args],
        cwd=REPO,
        capture_output=True,
        text=True,
        timeout=timeout,
        env={**os.environ, **(env or {})},
    )
