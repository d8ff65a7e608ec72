"""pin_susp: suspension kinematics on Pinocchio.

A corner is read from a YAML file of hardpoints, generated as a URDF tree
plus loop closures, and solved by Newton's method on the joint manifold.

    import pin_susp
    corner = pin_susp.Corner("examples/double_wishbone.yaml")
    results = corner.run_sweep("examples/bump_steer.yaml")
    results["camber"]            # deg, one value per step
    results.to_pandas()          # a DataFrame, as the CSV has it
    results.to_csv("out.csv")
    results.plot("report.png")   # the standard report
    corner.geometry.hardpoints_mm["lower_wishbone_outboard"]  # mm, as in the file

    axle = pin_susp.Axle("examples/axle_front.yaml")  # an axle, the same way
    axle.run_sweep("examples/roll.yaml")["roll_center_z"]

    # setup: exact sensitivities, and the inverse (shim, trackrod, pushrod)
    sheet = pin_susp.setup_sheet(corner.geometry, shim=[15, 30])
    found = pin_susp.solve_setup(corner.geometry, {"camber": -2.5, "roadwheel_angle": 0.1})

Files, the CLI, the CSV, results and poses speak mm and degrees; inside, the
model is in SI units (m, rad): a Geometry's ``hardpoints`` and a Corner's
``design_positions`` are in m (``hardpoints_mm`` reads them back in mm). The
formats and columns are documented in docs/ (geometry.md, sweep.md, results.md,
axle.md, vehicle.md, loads.md, studies.md, urdf.md).
"""

__version__ = "0.1.0"

import sys
from typing import TYPE_CHECKING

# Each public name and the submodule that defines it. They load on first use
# (PEP 562), so that `import pin_susp` or a CLI command that needs only the
# sweep does not pay for loads, sensitivities, studies and their libraries.
_EXPORTS = {
    "Axle": "subjects.axle",
    "AxleModel": "subjects.axle",
    "AxleResults": "subjects.axle",
    "load_axle": "subjects.axle",
    "Corner": "subjects.corner",
    "Results": "subjects.corner",
    "InputError": "errors",
    "PinSuspError": "errors",
    "Geometry": "model.geometry",
    "load_geometry": "model.geometry",
    "LoadCase": "analyses.loads",
    "load_cases": "analyses.loads",
    "member_forces": "analyses.loads",
    "METRICS": "columns.metrics",
    "Pose": "columns.metrics",
    "hardpoint_sensitivities": "analyses.sensitivity",
    "SetupModel": "analyses.setup",
    "apply_setup": "solve.as_set",
    "setup_sheet": "analyses.setup",
    "solve_setup": "analyses.setup",
    "Sweep": "model.sweep",
    "Target": "model.sweep",
    "load_sweep": "model.sweep",
    "Vehicle": "subjects.vehicle",
    "VehicleResults": "subjects.vehicle",
    "load_vehicle": "subjects.vehicle",
}

if TYPE_CHECKING:  # for type checkers and IDEs; at run time __getattr__ below
    from .analyses.loads import LoadCase, load_cases, member_forces
    from .analyses.sensitivity import hardpoint_sensitivities
    from .analyses.setup import SetupModel, setup_sheet, solve_setup
    from .columns.metrics import METRICS, Pose
    from .errors import InputError, PinSuspError
    from .model.geometry import Geometry, load_geometry
    from .model.sweep import Sweep, Target, load_sweep
    from .solve.as_set import apply_setup
    from .subjects.axle import Axle, AxleModel, AxleResults, load_axle
    from .subjects.corner import Corner, Results
    from .subjects.vehicle import Vehicle, VehicleResults, load_vehicle


def __getattr__(name: str):
    module = _EXPORTS.get(name)
    if module is not None:
        value = getattr(_submodule(module), name)
        globals()[name] = value  # once: later look-ups skip this function
        return value
    if name.startswith("__"):  # probes such as __wrapped__: no submodule has such a name
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
    try:  # a submodule not imported yet, as `import pin_susp` used to import them all
        return _submodule(name)
    except ModuleNotFoundError as exc:
        if exc.name != f"{__name__}.{name}":
            raise
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


def _submodule(name: str):
    # __import__ (not importlib.import_module): the import machinery's own path, which
    # `python -X importtime` reports
    __import__(f"{__name__}.{name}")
    return sys.modules[f"{__name__}.{name}"]


def __dir__() -> list[str]:
    return sorted(set(globals()) | set(_EXPORTS))


__all__ = [
    "METRICS",
    "Axle",
    "AxleModel",
    "AxleResults",
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
    "Vehicle",
    "VehicleResults",
    "load_axle",
    "load_cases",
    "member_forces",
    "load_geometry",
    "apply_setup",
    "hardpoint_sensitivities",
    "load_sweep",
    "setup_sheet",
    "solve_setup",
    "load_vehicle",
]
