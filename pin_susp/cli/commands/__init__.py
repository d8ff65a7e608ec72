"""The commands, by name: each is one module here (``pin_susp.cli.commands.<name>``),
listed with its one-line summary so that ``pin-susp --help`` names them all without
importing any, and a run imports its own command alone (pip's ``commands_dict``).

A command's module defines ``DESCRIPTION`` (its --help text; ``EPILOG`` optionally),
``arguments(parser)`` (its options) and ``run(args) -> int`` (the exit code); it
imports numpy, Pinocchio and the package's modules inside ``run``, so that its --help
costs no numerics (tests/test_startup.py).
"""

from __future__ import annotations

import importlib

# name → (module, summary), in the order --help lists them
COMMANDS = {
    "sweep": ("pin_susp.cli.commands.sweep", "solve a sweep and write one CSV row per step"),
    "urdf": ("pin_susp.cli.commands.urdf", "write the corner as URDF (tree + loop closures)"),
    "mjcf": (
        "pin_susp.cli.commands.mjcf",
        "write the corner as MJCF (MuJoCo; loop closures as equality connects)",
    ),
    "validate": (
        "pin_susp.cli.commands.validate",
        "re-solve a sweep with MuJoCo or Drake and a point-based solver; compare every column",
    ),
    "demo": ("pin_susp.cli.commands.demo", "run the embedded example and write its results"),
    "setup": (
        "pin_susp.cli.commands.setup",
        "setup sheet: static metrics, shim/trackrod/pushrod rows, sensitivities, inverse",
    ),
    "sensitivity": (
        "pin_susp.cli.commands.sensitivity",
        "exact d(metric)/d(hardpoint coordinate), at design or along a sweep",
    ),
    "plot": (
        "pin_susp.cli.commands.plot",
        "standard kinematics report from results CSVs (one panel per metric)",
    ),
    "draw": (
        "pin_susp.cli.commands.draw",
        "front and side view drawing of a corner (front view of an axle)",
    ),
    "view": (
        "pin_susp.cli.commands.view",
        "3D view in meshcat (live, or a self-contained HTML replay)",
    ),
    "loads": (
        "pin_susp.cli.commands.loads",
        "member and joint forces at every step under load cases",
    ),
    "kc": (
        "pin_susp.cli.commands.kc",
        "elastokinematics (K&C): compliance steer, camber and bushing deflections per case",
    ),
    "attitude": (
        "pin_susp.cli.commands.attitude",
        "a vehicle's attitude, wheel loads and load transfer (TLLTD) under steady g",
    ),
    "study": (
        "pin_susp.cli.commands.study",
        "many variants of a geometry on Dask: DOE, tolerance Monte Carlo, optimisation",
    ),
    "import": (  # the module's name has an underscore: import is a Python keyword
        "pin_susp.cli.commands.import_",
        "another tool's hardpoints (Lotus .shk, OptimumK CSV/Excel, Adams/Car) as a geometry",
    ),
    "export": (
        "pin_susp.cli.commands.export",
        "a corner's hardpoints as a Lotus .shk or an OptimumK table",
    ),
    "clearance": (
        "pin_susp.cli.commands.clearance",
        "along a sweep, each tyre's and rim's distance to the links and clearance bodies (coal)",
    ),
    "envelope": (
        "pin_susp.cli.commands.envelope",
        "the tyre's swept volume over a sweep as one watertight STL mesh (mm)",
    ),
}


def load(name: str, parser) -> None:
    """Import the command ``name`` and fill in its parser: its --help text, its
    arguments, the function that runs it."""
    module = importlib.import_module(COMMANDS[name][0])
    parser.description = module.DESCRIPTION
    parser.epilog = getattr(module, "EPILOG", None)
    module.arguments(parser)
    parser.set_defaults(run=module.run, command_name=name)
