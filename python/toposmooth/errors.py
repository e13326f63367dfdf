"""Exceptions of toposmooth: one per error kind of the library, all under :class:`Error`.

Each carries the library's message (``str(e)``, the CLI's text) and the attributes

kind : str
    ``"usage"``, ``"input"``, ``"io"``, ``"infeasible"``, ``"uncertified"``, ``"internal"``,
    ``"nosolution"`` or ``"cancelled"``.
exit_code : int
    The command-line tool's exit status for the same error (SPEC.md): 2 usage, 3 input, I/O
    and infeasible, 1 uncertified and internal, 4 no solution, 130 cancelled.

Ctrl-C during a computation raises Python's own ``KeyboardInterrupt`` once the run has
stopped (at its next check: between stages and solver iterations), not one of these.
path : str or None
    The file the error is about, when there is one.
"""

__all__ = [
    "Error",
    "UsageError",
    "InputError",
    "IoError",
    "InfeasibleError",
    "CertificateError",
    "SolverError",
    "InternalError",
    "Cancelled",
    "MemoryLimitError",
]


class Error(Exception):
    """Base class of every toposmooth error."""

    kind = "internal"
    exit_code = 1
    path = None


class UsageError(Error, ValueError):
    """Invalid or contradictory settings (CLI exit 2)."""

    kind, exit_code = "usage", 2


class InputError(Error, ValueError):
    """Malformed input: NaN without ``fill_missing``, wrong sizes, a degenerate mesh (exit 3)."""

    kind, exit_code = "input", 3


class IoError(Error, OSError):
    """A file could not be read or written (exit 3)."""

    kind, exit_code = "io", 3


class InfeasibleError(Error, ValueError):
    """A kept set that no strict function realizes (exit 3)."""

    kind, exit_code = "infeasible", 3


class CertificateError(Error, RuntimeError):
    """An output that fails its certificate; nothing is returned (exit 1)."""

    kind, exit_code = "uncertified", 1


class SolverError(Error, RuntimeError):
    """The solver returned no point (exit 4)."""

    kind, exit_code = "nosolution", 4


class InternalError(Error, RuntimeError):
    """A bug or a numerical failure on valid input (exit 1)."""

    kind, exit_code = "internal", 1


class Cancelled(Error):
    """The run was stopped by its ``cancel=`` token (exit 130); nothing was written."""

    kind, exit_code = "cancelled", 130


class MemoryLimitError(Error, MemoryError):
    """A run whose predicted peak passes the memory budget (``memory_limit=``, else the
    machine's), refused before its work (exit 3)."""

    kind, exit_code = "memory", 3
