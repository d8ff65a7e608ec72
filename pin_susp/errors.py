"""The few exceptions pin_susp raises for a user's mistake.

The CLI turns each into one line on stderr and exit code 2; the Python API
lets them propagate. Anything else is a bug in pin_susp.
"""

from __future__ import annotations

# The command line's exit codes for how a run ended (0: success; 128 + N: signal N).
EXIT_NOT_CONVERGED = 1  # it finished, but some steps did not converge (their rows flagged)
EXIT_LIMIT = 1  # it finished, but some steps are past a hard travel limit (limit_exceeded)
EXIT_INPUT = 2  # a problem with the input: one line on stderr, nothing written


class PinSuspError(Exception):
    """Base class: a problem the user can act on."""


class InputError(PinSuspError):
    """A geometry or sweep file (or dict) that cannot be used as it is.

    The message names the source, the key path and what is wrong, e.g.
    ``corner.yaml: hardpoints.upper_wishbone_outboard: missing point``.
    """

    def __init__(self, source: str, key: str, problem: str):
        self.source = source
        self.key = key
        self.problem = problem
        where = f"{source}: {key}" if key else source
        super().__init__(f"{where}: {problem}")


class NoRoom(PinSuspError):
    """An output that ran out of room (a full disk, a quota, ``ulimit -f``) part-way:
    ``path`` the file, ``why`` the system's words; what is left is the raiser's to say."""

    def __init__(self, path, why: str, left: str = "nothing written"):
        self.path, self.why = str(path), why
        super().__init__(f"{path}: cannot be written ({why}): {left}")


class PlausibilityWarning(UserWarning):
    """A value that is valid but outside what a car has (docs/geometry.md, plausible
    ranges): usually a unit mistake. The CLI prints one line each on stderr."""
