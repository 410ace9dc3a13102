"""Finding the flyloop-sitl binary and running it as a child process.

A `SitlProcess` starts the SITL on an ephemeral UDP port, reads the address it bound from its
first stdout line, and stops it on `stop()` — or, if the owner forgets, when the owner is
garbage-collected or the interpreter exits (a `weakref.finalize` guard). On Linux the child
also gets SIGTERM if the thread that started it dies (PR_SET_PDEATHSIG), so a killed Python
process leaves no orphan SITL behind.
"""

from __future__ import annotations

import ctypes
import os
import selectors
import shutil
import signal
import subprocess
import sys
import sysconfig
import tempfile
import threading
import time
import weakref
from collections.abc import Sequence
from pathlib import Path

from .errors import SitlError, SitlNotFoundError

BINARY_NAME = "flyloop-sitl"
ENV_VAR = "FLYLOOP_SITL"
BUILD_COMMAND = "cargo build --release -p flyloop-sitl"
READY_PREFIX = "flyloop-sitl ready "
STDERR_TAIL_LINES = 15
_PR_SET_PDEATHSIG = 1


def _workspace_root() -> Path | None:
    """The repository this package sits in (python/flyloop/ inside it), if it is one."""
    root = Path(__file__).resolve().parents[2]
    manifest = root / "Cargo.toml"
    try:
        if "[workspace]" in manifest.read_text():
            return root
    except OSError:
        pass
    return None


def _workspace_binary() -> Path | None:
    root = _workspace_root()
    if root is None:
        return None
    target = Path(os.environ.get("CARGO_TARGET_DIR") or root / "target")
    if not target.is_absolute():
        target = root / target
    return target / "release" / BINARY_NAME


def _installed_command() -> Path:
    """The `flyloop-sitl` console command the wheel installs beside this interpreter (found
    even when the venv is not activated, i.e. not on PATH)."""
    return Path(sysconfig.get_path("scripts")) / BINARY_NAME


def _usable(path: Path) -> bool:
    return path.is_file() and os.access(path, os.X_OK)


def find_sitl_binary(
    sitl_path: str | os.PathLike[str] | None = None, *, build: bool = False
) -> Path:
    """The flyloop-sitl binary, looked up in this order:

    1. `sitl_path` (an env's constructor argument),
    2. the environment variable FLYLOOP_SITL,
    3. `flyloop-sitl` on PATH,
    4. the workspace build: <repo>/target/release/flyloop-sitl, or
       $CARGO_TARGET_DIR/release/flyloop-sitl when CARGO_TARGET_DIR is set
       (only when this package is used from the repository, e.g. `pip install -e python`),
    5. the `flyloop-sitl` command installed with this package (the wheel's console script,
       the SITL compiled into the extension) in this interpreter's scripts directory.

    With `build=True` (the test suites), 3 is skipped and 4 is first brought up to date
    with `cargo build --release -p flyloop-sitl`, so tests fly the code of the checkout.

    An explicit path (1 or 2) that is not an executable file is an error, not skipped.
    Raises SitlNotFoundError naming every place it looked and the command that builds it.
    """
    for source, value in (("sitl_path", sitl_path), (ENV_VAR, os.environ.get(ENV_VAR))):
        if value:
            path = Path(value).expanduser()
            if not _usable(path):
                raise SitlNotFoundError(
                    f"{source} = {str(value)!r} is not an executable file; point it at a "
                    f"flyloop-sitl binary (build one with: {BUILD_COMMAND})"
                )
            return path
    root = _workspace_root()
    if build and root is not None:
        subprocess.run([*BUILD_COMMAND.split(), "--quiet"], cwd=root, check=True)
    on_path = None if build else shutil.which(BINARY_NAME)
    if on_path:
        return Path(on_path)
    workspace = _workspace_binary()
    if workspace is not None and _usable(workspace):
        return workspace
    installed = _installed_command()
    if _usable(installed):
        return installed
    looked = [
        "the sitl_path argument (not given)",
        f"${ENV_VAR} (not set)",
        f"{BINARY_NAME} on PATH (not found)",
    ]
    if workspace is not None:
        looked.append(f"the workspace build {workspace} (missing)")
    looked.append(f"the command installed with this package, {installed} (missing)")
    raise SitlNotFoundError(
        "cannot find the flyloop-sitl binary; looked at: "
        + "; ".join(looked)
        + f". Build it with: {BUILD_COMMAND} (in the flyloop repository), "
        f"or set {ENV_VAR}=/path/to/flyloop-sitl"
    )


def _parent_death_signal():
    """A preexec_fn that makes the child get SIGTERM when the starting thread dies (Linux)."""
    if not sys.platform.startswith("linux"):
        return None
    if threading.current_thread() is not threading.main_thread():
        # The signal fires when the *thread* that forked exits, not the process: a worker
        # thread that ends would take the SITL with it. The finalizer guards those instead.
        return None
    try:
        prctl = ctypes.CDLL(None, use_errno=True).prctl
    except (OSError, AttributeError):
        return None
    parent = os.getpid()

    def preexec() -> None:
        prctl(_PR_SET_PDEATHSIG, int(signal.SIGTERM), 0, 0, 0)
        if os.getppid() != parent:  # the parent died before prctl took effect
            os._exit(1)

    return preexec


def _stop(proc: subprocess.Popen, stderr_file, grace: float) -> int | None:
    """Terminates and reaps `proc` (kill after `grace` seconds); closes its files."""
    try:
        if proc.poll() is None:
            proc.terminate()
            try:
                proc.wait(timeout=grace)
            except subprocess.TimeoutExpired:
                proc.kill()
                proc.wait()
        return proc.returncode
    finally:
        for f in (proc.stdout, stderr_file):
            try:
                if f is not None:
                    f.close()
            except OSError:
                pass


class SitlProcess:
    """A flyloop-sitl child process on an ephemeral port (127.0.0.1:0 unless told otherwise).

    `address` is the (host, port) the SITL listens on. Its stderr goes to an anonymous
    temporary file (never a pipe that could fill up); `stderr_tail()` reads its last lines.
    """

    def __init__(
        self,
        binary: Path,
        args: Sequence[str],
        *,
        listen: str = "127.0.0.1:0",
        start_timeout: float = 10.0,
        stop_grace: float = 2.0,
    ) -> None:
        self.binary = Path(binary)
        self.command = [str(self.binary), "--listen", listen, *args]
        self._stderr = tempfile.TemporaryFile(prefix="flyloop-sitl-", suffix=".log")
        try:
            self.proc = subprocess.Popen(
                self.command,
                stdin=subprocess.DEVNULL,
                stdout=subprocess.PIPE,
                stderr=self._stderr,
                preexec_fn=_parent_death_signal(),
                close_fds=True,
            )
        except OSError as exc:
            self._stderr.close()
            raise SitlError(f"cannot start {self.binary}: {exc}") from exc
        self._finalizer = weakref.finalize(self, _stop, self.proc, self._stderr, stop_grace)
        self._stop_grace = stop_grace
        try:
            line = self._read_ready_line(start_timeout)
        except BaseException:
            self.stop()
            raise
        self.ready = dict(kv.split("=", 1) for kv in line.split()[2:] if "=" in kv)
        host, port = self.ready["listen"].rsplit(":", 1)
        self.address = (host.strip("[]"), int(port))

    @property
    def pid(self) -> int:
        return self.proc.pid

    def _read_ready_line(self, timeout: float) -> str:
        stdout = self.proc.stdout
        assert stdout is not None
        deadline = time.monotonic() + timeout
        buf = b""
        with selectors.DefaultSelector() as sel:
            sel.register(stdout, selectors.EVENT_READ)
            while b"\n" not in buf:
                left = deadline - time.monotonic()
                if left <= 0:
                    raise SitlError(
                        f"{self.binary} printed no ready line within {timeout:g} s "
                        f"(command: {' '.join(self.command)})",
                        stderr_tail=self.stderr_tail(),
                    )
                if not sel.select(left):
                    continue
                chunk = os.read(stdout.fileno(), 4096)
                if not chunk:  # stdout closed: the SITL exited
                    code = self._wait_exit(2.0)
                    raise SitlError(
                        f"{self.binary} exited with code {code} before it was ready "
                        f"(command: {' '.join(self.command)})",
                        exit_code=code,
                        stderr_tail=self.stderr_tail(),
                    )
                buf += chunk
        line = buf.split(b"\n", 1)[0].decode(errors="replace")
        if not line.startswith(READY_PREFIX):
            raise SitlError(
                f"{self.binary} did not start as flyloop-sitl: first line {line!r}",
                stderr_tail=self.stderr_tail(),
            )
        return line

    def _wait_exit(self, timeout: float) -> int | None:
        try:
            return self.proc.wait(timeout=timeout)
        except subprocess.TimeoutExpired:
            return None

    def poll(self) -> int | None:
        """The exit code if the SITL has exited (reaping it), else None."""
        return self.proc.poll()

    def stderr_tail(self, lines: int = STDERR_TAIL_LINES) -> str:
        """The last `lines` lines the SITL wrote on stderr."""
        if self._stderr.closed:
            return ""
        try:
            size = os.fstat(self._stderr.fileno()).st_size
            start = max(0, size - 16384)
            text = os.pread(self._stderr.fileno(), size - start, start).decode(errors="replace")
        except OSError:
            return ""
        return "\n".join(text.splitlines()[-lines:])

    def exit_report(self, grace: float = 0.5) -> tuple[int | None, str]:
        """(exit code or None if still running after `grace` s, stderr tail)."""
        code = self._wait_exit(grace) if grace > 0 else self.poll()
        return code, self.stderr_tail()

    @property
    def running(self) -> bool:
        return self._finalizer.alive and self.proc.poll() is None

    def stop(self) -> int | None:
        """Terminates the SITL (SIGTERM, then SIGKILL after the grace period) and reaps it.
        Returns its exit code. Safe to call more than once."""
        if self._finalizer.alive:
            return self._finalizer()
        return self.proc.returncode
