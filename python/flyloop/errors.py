"""The errors the envs raise when something outside Python goes wrong."""

from __future__ import annotations


class SitlError(RuntimeError):
    """The SITL process failed: it could not start, it died, or it stopped answering.

    Raised by `reset()`, `step()` and the constructors of every flyloop env. The message says
    what happened, the SITL's exit code when it has exited, and the last lines it wrote on
    stderr. After a SitlError the env cannot step any more: `close()` it (safe to call) and
    make a new one.
    """

    def __init__(self, message: str, *, exit_code: int | None = None, stderr_tail: str = ""):
        self.exit_code = exit_code
        self.stderr_tail = stderr_tail
        text = message
        if stderr_tail:
            text += "\nlast lines of the SITL's stderr:\n" + stderr_tail
        super().__init__(text)


class SitlNotFoundError(SitlError):
    """No flyloop-sitl binary was found where the envs look for it (see `find_sitl_binary`)."""


class SitlParameterError(ValueError):
    """An env argument was refused by the core's parameter table (the message names it)."""
