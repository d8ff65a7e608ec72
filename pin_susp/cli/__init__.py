"""The ``pin-susp`` command line: ``main``, the top-level parser, and the commands
registered by name in ``cli.commands`` (one module each), imported on demand.

- ``run``: how a command runs and ends (exit codes, signals, what an interrupt leaves);
- ``options``: the arguments the commands share, and the output paths checked before
  any work;
- ``report``: the summary, Digest, warnings, failure report and progress bar every
  command prints through;
- ``commands/<name>.py``: a command's arguments and its run.

Exit codes: 0 success; 1 the run finished but some steps did not converge
(their rows are written, flagged ``solver_converged = False`` with empty
metric cells); 2 a problem with the input (one line on stderr, nothing
written).

Start-up time: ``pin-susp --help`` imports no command module, a command imports its
own module alone, and each command imports what it uses inside its run function
(numpy, Pinocchio and the package's modules included), so that ``--help`` costs no
numpy and a sweep no plotting, loads or studies (tests/test_startup.py).
"""

from __future__ import annotations

import argparse

from .. import __version__
from ..errors import EXIT_INPUT
from .commands import COMMANDS, load
from .options import Parser
from .run import execute


def main(argv: list[str] | None = None) -> int:
    parser = _parser()
    try:
        args = parser.parse_args(argv)
    except SystemExit as exc:  # --help, --version, or a usage error (one line, exit 2)
        return exc.code if isinstance(exc.code, int) else EXIT_INPUT
    return execute(args)


class _Commands(argparse._SubParsersAction):
    """The subcommands: each listed by its summary, its parser filled in (its module
    imported) only once its name is read from the command line."""

    def __call__(self, parser, namespace, values, option_string=None):
        name = values[0]
        chosen = self._name_parser_map.get(name)
        if chosen is not None and chosen.get_default("run") is None:
            load(name, chosen)
        super().__call__(parser, namespace, values, option_string)


def _parser() -> argparse.ArgumentParser:
    p = Parser(
        prog="pin-susp",
        description="Suspension kinematics on Pinocchio: a corner from a YAML file of "
        "hardpoints (mm, ISO 8855), solved exactly through bump and steer sweeps.",
        epilog="Start with `pin-susp demo`. Formats: docs/geometry.md, docs/sweep.md, "
        "docs/results.md, docs/urdf.md.",
    )
    p.add_argument("--version", action="version", version=f"pin_susp {__version__}")
    sub = p.add_subparsers(title="commands", metavar="COMMAND", required=True, action=_Commands)
    for name, (_, summary) in COMMANDS.items():
        sub.add_parser(name, help=summary)
    return p
