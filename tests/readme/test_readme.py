"""The commands and snippets of README.md and every page under docs/, run as written.

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
  for this file); every script and preset (``.py``, ``.toml``, ``.parm``) the block names must
  appear there (or be a test file there).
- ``<!-- check: sitl-config -->``: the TOML block is a ``--config`` file flyloop-sitl accepts.
- ``<!-- check: autopilot-config -->``: the TOML block is a ``--config`` file of the PX4 and
  ArduPilot modes (vehicle parameters and a ``[frame]``) that flyloop-sitl accepts.
- ``<!-- check: ci -->``: the README's two top commands; ``.ci/run`` runs each line as written.

Python blocks must run without a warning. Every fenced block carries a marker: a block
without one fails. Beyond the blocks: the README
starts with its two commands and stays under 200 lines; every link and every repository path
a page names exists; no page names a path outside the repository.
"""

from __future__ import annotations

import os
import re
import shlex
import shutil
import signal
import socket
import subprocess
import sys
import threading
import time
from dataclasses import dataclass
from pathlib import Path

import pytest
from flyloop import find_sitl_binary

REPO = Path(__file__).resolve().parents[2]
README = REPO / "README.md"
PAGES = [README, *sorted((REPO / "docs").rglob("*.md"))]
MARKER = re.compile(r"<!-- check: ([\w-]+)(?: (\S+))? -->")
WARNING = re.compile(r"^.*\b\w*Warning: .*$", re.M)


@dataclass
class Block:
    page: Path
    line: int
    language: str
    text: str
    kind: str | None
    argument: str | None

    @property
    def id(self) -> str:
        return f"{self.where}:{self.kind}"

    @property
    def where(self) -> str:
        return f"{self.page.relative_to(REPO)}:{self.line}"


def blocks(page: Path) -> list[Block]:
    found, lines = [], page.read_text().splitlines()
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
                page=page,
                line=start + 1,
                language=fence.group(1),
                text="\n".join(lines[start + 1 : end]) + "\n",
                kind=marker.group(1) if marker else None,
                argument=marker.group(2) if marker else None,
            )
        )
        i = end + 1
    return found


ALL = [block for page in PAGES for block in blocks(page)]


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
    known.update({"sitl-config", "autopilot-config"})
    assert {b.kind for b in ALL if b.kind} <= known
    unchecked = [f"{b.where} ({b.language})" for b in ALL if b.kind is None]
    assert not unchecked, f"blocks that no test or CI step runs: {unchecked}"
    # Every page with blocks is read, and the snippets the docs have always had stay checked.
    assert {b.page.name for b in ALL} >= {"README.md", "fmu.md", "sitl.md", "gym.md", "px4.md"}
    assert len(of_kind("python", "python-sitl")) >= 8
    assert of_kind("doctest") and of_kind("sitl-commands") and of_kind("run")
    assert of_kind("tested-by") and of_kind("sitl-config")
    # The README shows the core, an FMU, the SITL and the gym envs.
    in_readme = {b.kind for b in ALL if b.page == README}
    assert in_readme >= {"ci", "doctest", "run", "python", "sitl-commands"}


def test_the_readme_starts_with_its_two_commands_and_stays_short():
    lines = README.read_text().splitlines()
    assert len(lines) <= 200, f"README.md has {len(lines)} lines; move detail into docs/"
    first = next(b for b in ALL if b.page == README)
    assert first.kind == "ci" and first.line <= 10, first.where
    assert [c.split()[:2] for c in commands(first)] == [
        ["bash", "scripts/setup.sh"],
        ["bash", "scripts/test.sh"],
    ]
    # Only the README carries them: CI runs that block, so it is written once.
    assert [b.where for b in of_kind("ci")] == [first.where]


LINK = re.compile(r"!?\[[^\]]*\]\(([^)\s]+)\)")


def anchors(page: Path) -> set[str]:
    """GitHub's heading anchors of `page`: lower case, punctuation dropped, spaces to `-`."""
    out, fenced = set(), False
    for line in page.read_text().splitlines():
        fenced ^= line.startswith("```")
        heading = re.match(r"#+ (.*)", line)
        if heading and not fenced:
            out.add(re.sub(r"[^\w\- ]", "", heading.group(1).lower()).replace(" ", "-"))
    return out


@pytest.mark.parametrize("page", PAGES, ids=lambda p: str(p.relative_to(REPO)))
def test_links_and_images_resolve_inside_the_repository(page: Path):
    broken = []
    for target in LINK.findall(page.read_text()):
        if re.match(r"[a-z]+:", target):
            continue  # a web address
        path, _, anchor = target.partition("#")
        resolved = (page.parent / path).resolve() if path else page
        inside = resolved == REPO or REPO in resolved.parents
        if not inside or not resolved.exists():
            broken.append(target)
        elif anchor and resolved.suffix == ".md" and anchor not in anchors(resolved):
            broken.append(target)
    assert not broken, f"{page.relative_to(REPO)}: links to nothing: {broken}"


# A machine's own places: home and work directories, a checkout's neighbours.
OUTSIDE = re.compile(r"\$HOME|~/|(?<![\w.])/(?:home|root|work|tmp|mnt|opt|srv|Users)/|\.\./")


@pytest.mark.parametrize("page", PAGES, ids=lambda p: str(p.relative_to(REPO)))
def test_no_page_names_a_path_outside_the_repository(page: Path):
    # Links may climb out of docs/ (checked above to stay inside); nothing else may.
    text = LINK.sub("", page.read_text())
    found = [m.group(0) for m in OUTSIDE.finditer(text)]
    assert not found, (
        f"{page.relative_to(REPO)} names paths outside the repository: {found}; say what to "
        "build and where to point it (e.g. PATH_TO_PX4_BUILD)"
    )


# What the checkout holds (build outputs such as target/, dist/ and runs/ are made by commands).
TRACKED = (
    "core fmu sitl python examples benchmarks scripts tests policies docs modelDescription .ci"
)
NAMED = re.compile(rf"(?<![\w./-])((?:{'|'.join(map(re.escape, TRACKED.split()))})/[\w./*-]*)")


@pytest.mark.parametrize("page", PAGES, ids=lambda p: str(p.relative_to(REPO)))
def test_every_repository_path_a_page_names_exists(page: Path):
    text = LINK.sub("", page.read_text())
    missing = sorted(
        {
            name
            for name in (m.group(1).rstrip(".") for m in NAMED.finditer(text))
            if not any(REPO.glob(name)) and not (REPO / name).exists()
        }
    )
    assert not missing, f"{page.relative_to(REPO)} names what the repository lacks: {missing}"


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
    # A snippet a reader copies runs clean: no warning (fmpy's "Warning: missing input ...",
    # Python's UserWarning, ...) that would leave the reader wondering what is wrong.
    warned = WARNING.findall(result.stdout + result.stderr)
    output = result.stdout[-2000:] + result.stderr[-2000:]
    assert not warned, f"the snippet warns: {warned}\n{output}"


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
    assert block.text.strip() in text, f"{block.where} differs from {block.argument}"


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
    named = (".py", ".toml", ".parm", ".sh")
    words = [shlex.split(c) for c in commands(block)]
    scripts = {w for c in words for w in c if w.endswith(named)}
    # `python -m MODULE`: a test that runs the module names it as "MODULE".
    modules = {c[i + 1] for c in words for i, w in enumerate(c[:-1]) if w == "-m"}
    assert scripts or modules
    for module in modules:
        assert f'"{module}"' in corpus, (
            f"{block.where}: {module} is run by no test in {block.argument}"
        )
    for script in scripts:
        is_a_test = (REPO / script) in tests
        assert is_a_test or Path(script).name in corpus, (
            f"{block.where}: {script} is run by no test in {block.argument}"
        )


@pytest.mark.parametrize("block", of_kind("autopilot-config"), ids=lambda b: b.id)
def test_frame_configs_are_accepted_by_the_autopilot_modes(
    block: Block, sitl_binary: Path, tmp_path: Path
):
    config = tmp_path / "vehicle.toml"
    config.write_text(block.text)
    result = subprocess.run(
        [str(sitl_binary), "--config", str(config), "--print-autopilot-params", "px4"],
        capture_output=True,
        text=True,
        timeout=60,
    )
    assert result.returncode == 0, f"{block.where}: {result.stderr}"
    rotors = block.text.count("[[frame.rotor]]")
    assert f"CA_ROTOR_COUNT {rotors}\n" in result.stdout, result.stdout


@pytest.mark.parametrize("block", of_kind("sitl-config"), ids=lambda b: b.id)
def test_config_files_are_accepted_by_the_sitl(block: Block, sitl_binary: Path, tmp_path: Path):
    config = tmp_path / "config.toml"
    config.write_text(block.text)
    result = subprocess.run(
        [str(sitl_binary), "--config", str(config), "--list-params", "toml"],
        capture_output=True,
        text=True,
        timeout=60,
    )
    assert result.returncode == 0, f"{block.where}: {result.stderr}"
    # The top-level values come back as the parameters' values.
    for name, value in re.findall(r"^(\w+) = ([\d.]+)$", block.text.split("\n[")[0], re.M):
        assert re.search(rf"^{name} = {re.escape(value)}\b", result.stdout, re.M), name


def shell_blocks() -> list[Block]:
    return [b for b in ALL if b.language == "sh"]


def test_commands_name_the_venvs_programs_by_their_path():
    """A program setup.sh installs into .venv (mavproxy.py, pytest, tensorboard, ...) is
    named .venv/bin/NAME, as every other command names it: a bare name runs whatever PATH
    finds, or nothing. The RLlib cluster block is the exception: it runs on other machines,
    in their own environment."""
    venv = REPO / ".venv" / "bin"
    elsewhere = os.pathsep.join(p for p in os.environ["PATH"].split(os.pathsep) if p != str(venv))
    # Programs only the venv has (cargo, bash, ... are found on PATH anyway).
    programs = {p.name for p in venv.iterdir() if not shutil.which(p.name, path=elsewhere)}
    assert "mavproxy.py" in programs and "pytest" in programs
    bare = [
        f"{block.where}: {command}"
        for block in shell_blocks()
        if "ray start" not in block.text
        for command in commands(block)
        if set(programs_run(command)) & programs
    ]
    assert not bare, bare


def programs_run(command: str) -> list[str]:
    """The programs a command line runs: its first word and the first after each ;, &&, ||
    or |, past VAR=value assignments."""
    out, first = [], True
    for word in shlex.split(command):
        if word in (";", "&&", "||", "|"):
            first = True
        elif first and not re.match(r"^\w+=", word):
            out.append(word)
            first = False
    return out


def test_mavproxy_as_the_docs_run_it_leaves_the_checkout_clean(tmp_path: Path):
    """Every MAVProxy command of the docs, run from the repository root as they say, keeps
    its log (mav.tlog, mav.tlog.raw) and parameter file out of the checkout's tracked tree.
    The link is a local UDP port here (the docs' PX4 or ArduPilot is not needed for where
    MAVProxy writes its state)."""
    lines = [c for b in shell_blocks() for c in commands(b) if "mavproxy.py" in c]
    assert len(lines) >= 2, lines  # PX4's and ArduPilot's
    status = ["git", "status", "--porcelain", "--untracked-files=all"]
    for line in lines:
        words = [w for w in shlex.split(line) if not w.startswith("--master=")]
        with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as s:
            s.bind(("127.0.0.1", 0))
            port = s.getsockname()[1]
        before = subprocess.run(status, cwd=REPO, capture_output=True, text=True).stdout
        proc = subprocess.Popen(
            [*words, f"--master=udpin:127.0.0.1:{port}"],
            cwd=REPO,
            stdin=subprocess.PIPE,
            stdout=subprocess.PIPE,
            stderr=subprocess.STDOUT,
            text=True,
            start_new_session=True,  # MAVProxy forks helpers: stopped with its group
        )
        # A MAVProxy that never says where it logs is stopped after 60 s (the test fails).
        guard = threading.Timer(60, os.killpg, (proc.pid, signal.SIGKILL))
        guard.start()
        try:
            seen = ""
            for out in proc.stdout:
                seen += out
                if out.startswith("Telemetry log: "):  # its log files are open now
                    break
            time.sleep(1.0)
        finally:
            guard.cancel()
            try:
                os.killpg(proc.pid, signal.SIGKILL)
            except ProcessLookupError:  # the guard stopped it
                pass
            proc.wait()
        after = subprocess.run(status, cwd=REPO, capture_output=True, text=True).stdout
        new = sorted(set(after.splitlines()) - set(before.splitlines()))
        assert not new, f"{line} left {new} in the checkout"
        logged = re.search(r"Telemetry log: (\S+)", seen)
        assert logged, seen
        assert (REPO / logged.group(1)).resolve().is_relative_to(REPO / "runs"), logged.group(1)
