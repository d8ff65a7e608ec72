"""pin_susp from Python: load a corner, solve one pose, run a sweep, write CSV.

Run from the repository root:  python examples/quickstart.py
"""

from pathlib import Path

import numpy as np

import pin_susp

HERE = Path(__file__).parent

# A corner from its YAML file (a dict in the same format works too).
corner = pin_susp.Corner(HERE / "double_wishbone.yaml")
print(f"{corner.geometry.name}: {corner.model.nv} joints, mobility {corner.mobility}")

# One pose: 25 mm of bump with the rack 5 mm to the left. Values in mm,
# relative to the design position unless mode="absolute".
pose = corner.solve_pose(
    [
        pin_susp.Target("wheel_center", "z", 25.0),
        pin_susp.Target("trackrod_inboard", "y", 5.0),
    ]
)
print(f"converged in {pose.iterations} iterations, residual {pose.max_residual:.1e} mm")
for name in ("camber", "roadwheel_angle", "caster", "kpi"):
    print(f"  {name:16s} {pose.metrics[name]:9.4f} deg")
print(f"  wheel centre     {np.round(pose.points['wheel_center'], 3)} mm")

# A sweep: one row per step, every metric and point as numpy columns.
results = corner.run_sweep(HERE / "bump_steer.yaml")
travel, camber = results["wheel_travel"], results["camber"]
print(
    f"sweep of {len(results)} steps: camber {camber[0]:.3f} deg at {travel[0]:.0f} mm "
    f"to {camber[-1]:.3f} deg at {travel[-1]:.0f} mm"
)

out = Path("quickstart_results.csv")
results.to_csv(out)
print(f"wrote {out}")
