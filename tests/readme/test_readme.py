"""The README's commands and snippets, run as written.

A fenced block is checked when the line before it is a marker comment:

- ``<!-- check: run -->``: every command line of the sh block runs (bash, repository root).
- ``<!-- check: python -->``: the Python block runs in a fresh interpreter.
- ``<!-- check: python-sitl -->``: the same, against a SITL started on a free port that
  replaces the block's ``14560``.
- ``<!-- check: sitl-commands -->``: every ``target/release/flyloop-sitl`` line starts (on a
  free port, ground-station link off) and prints its ready line.
- ``<!-- check: doctest FILE -->``: the Rust block is the doc example of FILE (run by
  ``cargo test --doc``), line for line.
- ``<!-- check: tested-by PATH -->``: the commands run in the tests under PATH (too long
  for this file); every script the block names must appear there.
- ``<!-- check: ci -->``: the README's two top commands; ``.ci/run`` runs each line as written.

Every fenced block carries a marker: a block without one fails.
"""

from __future__ import annotations

import os
import re
import shlex
import signal
import subprocess
import sys
from dataclasses import dataclass
from pathlib import Path

import pytest
from flyloop import find_sitl_binary

REPO = Path(__file__).resolve().parents[2]
README = REPO / "README.md"
MARKER = re.compile(r"<!-- check: ([\w-]+)(?: (\S+))? -->")


@dataclass
class Block:
    line: int
    language: str
    text: str
    kind: str | None
    argument: str | None

    @property
    def id(self) -> str:
        return f"README.md:{self.line}:{self.kind}"


def blocks(text: str) -> list[Block]:
    found, lines = [], text.splitlines()
    i = 0
    while i < len(lines):
        fence = re.match(r"^```(\w*)\s*$", lines[i])
        if not fence:
            i += 1
            continue
        start = i
        end = next(j for j in range(i + 1, len(lines)) if lines[j].startswith("```"))
        before = next((lines[j] for j in range(start - 1, -1, -1) if lines[j].strip()), "")
        marker = MARKER.fullmatch(before.strip())
        found.append(
            Block(
                line=start + 1,
                language=fence.group(1),
                text="\n".join(lines[start + 1 : end]) + "\n",
                kind=marker.group(1) if marker else None,
                argument=marker.group(2) if marker else None,
            )
        )
        i = end + 1
    return found


ALL = blocks(README.read_text())


def of_kind(*kinds: str) -> list[Block]:
    return [b for b in ALL if b.kind in kinds]


def commands(block: Block) -> list[str]:
    """The block's command lines (comments and blank lines dropped, `\\` joined)."""
    joined = block.text.replace("\\\n", " ")
    out = []
    for line in joined.splitlines():
        line = line.split("  #")[0].strip()
        if line and not line.startswith("#"):
            out.append(line)
    return out


@pytest.fixture(scope="module")
def sitl_binary() -> Path:
    path = find_sitl_binary(build=True)
    os.environ["FLYLOOP_SITL"] = str(path)
    return path


def environment(sitl: Path) -> dict[str, str]:
    env = dict(os.environ, MPLBACKEND="Agg", FLYLOOP_SITL=str(sitl))
    env["PATH"] = f"{Path(sys.executable).parent}{os.pathsep}{env['PATH']}"
    return env


def test_the_markers_are_known_and_the_core_blocks_are_checked():
    known = {"run", "python", "python-sitl", "sitl-commands", "doctest", "tested-by", "ci"}
    assert {b.kind for b in ALL if b.kind} <= known
    unchecked = [f"README.md:{b.line} ({b.language})" for b in ALL if b.kind is None]
    assert not unchecked, f"README blocks that no test or CI step runs: {unchecked}"
    # The snippets the README has always had stay checked.
    assert len(of_kind("python", "python-sitl")) >= 3
    assert of_kind("doctest") and of_kind("sitl-commands") and of_kind("run")


@pytest.mark.parametrize("block", of_kind("run"), ids=lambda b: b.id)
def test_commands_run(block: Block, sitl_binary: Path):
    for command in commands(block):
        result = subprocess.run(
            ["bash", "-c", command],
            cwd=REPO,
            env=environment(sitl_binary),
            capture_output=True,
            text=True,
            timeout=900,
        )
        assert result.returncode == 0, f"{command}\n{result.stdout[-2000:]}{result.stderr[-2000:]}"


@pytest.mark.parametrize("block", of_kind("python"), ids=lambda b: b.id)
def test_python_snippets_run(block: Block, sitl_binary: Path):
    run_python(block.text, sitl_binary)


def run_python(code: str, sitl: Path) -> None:
    result = subprocess.run(
        [sys.executable, "-c", code],
        cwd=REPO,
        env=environment(sitl),
        capture_output=True,
        text=True,
        timeout=300,
    )
    assert result.returncode == 0, result.stdout[-2000:] + result.stderr[-4000:]


def start_sitl(binary: Path, args: list[str]) -> tuple[subprocess.Popen, str]:
    proc = subprocess.Popen(
        [str(binary), *args],
        cwd=REPO,
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )
    line = proc.stdout.readline()
    if not line.startswith("flyloop-sitl ready "):
        proc.kill()
        _, err = proc.communicate(timeout=10)
        raise AssertionError(f"{args}: {line!r} {err}")
    return proc, line


def stop(proc: subprocess.Popen) -> None:
    proc.send_signal(signal.SIGINT)
    try:
        assert proc.wait(timeout=10) == 0
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.wait()
        proc.stdout.close()
        proc.stderr.close()


@pytest.mark.parametrize("block", of_kind("python-sitl"), ids=lambda b: b.id)
def test_python_snippets_against_a_sitl_run(block: Block, sitl_binary: Path):
    assert "14560" in block.text
    proc, ready = start_sitl(sitl_binary, ["--listen", "127.0.0.1:0", "--gcs", "off"])
    try:
        port = re.search(r"listen=127\.0\.0\.1:(\d+)", ready).group(1)
        run_python(block.text.replace("14560", port), sitl_binary)
    finally:
        stop(proc)


@pytest.mark.parametrize("block", of_kind("sitl-commands"), ids=lambda b: b.id)
def test_sitl_command_lines_start(block: Block, sitl_binary: Path):
    started = 0
    for command in commands(block):
        words = shlex.split(command)
        if words[0] != "target/release/flyloop-sitl":
            continue
        args = words[1:]
        for option, value in (("--listen", "127.0.0.1:0"), ("--gcs", "off")):
            if option in args:
                args[args.index(option) + 1] = value
            else:
                args += [option, value]
        proc, ready = start_sitl(sitl_binary, args)
        stop(proc)
        assert "listen=127.0.0.1:" in ready and "gcs=off" in ready
        started += 1
    assert started > 0


@pytest.mark.parametrize("block", of_kind("doctest"), ids=lambda b: b.id)
def test_rust_snippets_are_doc_examples(block: Block):
    source = (REPO / block.argument).read_text()
    doc = [ln[4:] if ln.startswith("//! ") else ln[3:] for ln in source.splitlines()]
    doc = [ln for ln in doc if not ln.startswith("# ")]
    text = "\n".join(doc)
    assert block.text.strip() in text, f"README.md:{block.line} differs from {block.argument}"


@pytest.mark.parametrize("block", of_kind("ci"), ids=lambda b: b.id)
def test_the_top_commands_are_what_ci_runs(block: Block):
    ci = [line.strip() for line in (REPO / ".ci" / "run").read_text().splitlines()]
    for command in commands(block):
        assert command in ci, f"{command!r} is not a line of .ci/run"


@pytest.mark.parametrize("block", of_kind("tested-by"), ids=lambda b: b.id)
def test_long_commands_are_run_by_their_tests(block: Block):
    tests = sorted((REPO / block.argument).rglob("*.py"))
    assert tests, block.argument
    corpus = "\n".join(t.read_text() for t in tests)
    scripts = {w for c in commands(block) for w in shlex.split(c) if w.endswith(".py")}
    assert scripts
    for script in scripts:
        assert Path(script).name in corpus, f"{script} is run by no test in {block.argument}"
