"""pin_susp: suspension kinematics on Pinocchio.

A corner is read from a YAML file of hardpoints, generated as a URDF tree
plus loop closures, and solved by Newton's method on the joint manifold.

    import pin_susp
    corner = pin_susp.Corner("examples/double_wishbone.yaml")
    results = corner.run_sweep("examples/bump_steer.yaml")
    results["camber"]            # deg, one value per step
    results.to_csv("out.csv")

    # setup: exact sensitivities, and the inverse (shim, trackrod, pushrod)
    sheet = pin_susp.setup_sheet(corner.geometry, shim=[15, 30])
    found = pin_susp.solve_setup(corner.geometry, {"camber": -2.5, "roadwheel_angle": 0.1})

Files, the CLI, the CSV and this API speak mm and degrees; inside, the model
is in SI units (m, rad).
"""

__version__ = "0.1.0"

from .corner import Corner, Results  # noqa: E402
from .errors import InputError, PinSuspError  # noqa: E402
from .geometry import Geometry, load_geometry  # noqa: E402
from .loads import LoadCase, load_cases, member_forces  # noqa: E402
from .metrics import METRICS, Pose  # noqa: E402
from .sensitivity import hardpoint_sensitivities  # noqa: E402
from .setup import SetupModel, apply_setup, setup_sheet, solve_setup  # noqa: E402
from .sweep import Sweep, Target, load_sweep  # noqa: E402

__all__ = [
    "METRICS",
    "Corner",
    "Geometry",
    "InputError",
    "LoadCase",
    "PinSuspError",
    "Pose",
    "Results",
    "SetupModel",
    "Sweep",
    "Target",
    "load_cases",
    "member_forces",
    "load_geometry",
    "apply_setup",
    "hardpoint_sensitivities",
    "load_sweep",
    "setup_sheet",
    "solve_setup",
]
