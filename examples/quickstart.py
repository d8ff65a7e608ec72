"""pin_susp from Python: load a corner, solve one pose, run a sweep, write CSV, draw
the report, read hardpoints back in mm, and sweep an axle.

Run from the repository root:  python examples/quickstart.py
"""

from pathlib import Path

import numpy as np

import pin_susp

HERE = Path(__file__).parent

# A corner from its YAML file (a dict in the same format works too).
corner = pin_susp.Corner(HERE / "double_wishbone.yaml")
print(corner)  # <Corner 'double_wishbone.yaml' 'example corner': double_wishbone, ...>
print(f"{corner.geometry.name}: {corner.model.nv} joints, mobility {corner.mobility}")

# Hardpoints: the model works in metres; hardpoints_mm gives the file's mm back.
print(f"  lower ball joint {corner.geometry.hardpoints_mm['lower_wishbone_outboard']} mm")

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

print(results)  # <Results 'bump_steer.yaml' on 'double_wishbone.yaml': 41 steps, ...>

frame = results.to_pandas()  # a DataFrame, one row per step, units in frame.attrs
print(frame[["wheel_travel", "camber", "roadwheel_angle"]].iloc[::10].to_string(index=False))

out = Path("quickstart_results.csv")
results.to_csv(out)
print(f"wrote {out}")
results.plot("quickstart_report.png")  # the report `pin-susp sweep --plot` draws
print("wrote quickstart_report.png")

# An axle: both corners on one chassis and one rack, swept in roll.
axle = pin_susp.Axle(HERE / "axle_front.yaml")
print(axle)
roll = axle.run_sweep(HERE / "roll.yaml")
print(roll)
print(
    f"at {roll['roll'][-1]:.0f} deg of roll: camber {roll['camber_left'][-1]:.3f} deg left, "
    f"{roll['camber_right'][-1]:.3f} deg right"
)
