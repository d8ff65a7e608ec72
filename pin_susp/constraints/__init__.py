"""Loop closures and targets: one row kind per module, each owning all its maths.

Every row kind implements one interface (row.Row): ``residual``/``jacobian`` at one
configuration, ``fill`` (the Newton solver's fast form from frames read once) and
``fill_many`` (n configurations at once in numpy), and ``drift_many`` where it has a
second derivative. The Newton solver (solver.py) and the batched path (bulk.py) only
stack rows through it. Residuals are in metres (or radians: a held revolute joint, a
roll target); Jacobians are d(residual)/dv with v in the tangent space of the joint
configuration (``pin.integrate``).

=================  ========================================================
ball.py            BallClosure: two anchors coincide (3 rows)
distance.py        DistanceClosure: a link's ends keep their length (1 row)
point_target.py    PointTarget: a point held on a plane (1 row)
joint_target.py    JointTarget: a joint held at a value (1 row)
heave.py           HeaveTarget: an axle's mean wheel-centre height (1 row)
roll.py            RollTarget: an axle's roll angle over the track (1 row)
shim_gap.py        ShimGap: a shim stack between two faces (3 rows)
face_alignment.py  FaceAlignment: two faces kept parallel (3 rows)
rocker_turn.py     RockerTurn: a torsion bar's rocker turn (held row, statics)
bar_twist.py       BarTwist: an anti-roll bar's twist (held row, statics)
branch.py          LoopBranch, BranchGuard: each loop's assembly branch (chirality)
points.py          FramePoint, ContactPatchPoint: the points rows are written on
kinematics.py      Kinematics: Pinocchio model + data at one configuration
row.py             Row: the interface; StepFrames, ManyFrames: the frames' data
=================  ========================================================

(A MacPherson strut's point-on-line condition is no row: the strut rod is a prismatic
joint along the strut axis, closed by a ball at the top mount.)
"""

from .ball import BallClosure
from .bar_twist import BarTwist
from .branch import (
    MEASURES,
    MEASURES_MANY,
    BranchGuard,
    LoopBranch,
    alignment,
    alignment_many,
    chirality,
    chirality_many,
    pick_branch,
)
from .distance import DistanceClosure, length_rates
from .face_alignment import FaceAlignment
from .heave import HeaveTarget
from .joint_target import JointTarget
from .kinematics import WORLD, Kinematics
from .point_target import PointTarget
from .points import ContactPatchPoint, FramePoint
from .rocker_turn import RockerTurn
from .roll import RollTarget
from .row import ManyFrames, Row, StepFrames
from .shim_gap import ShimGap

__all__ = [
    "MEASURES",
    "MEASURES_MANY",
    "WORLD",
    "BallClosure",
    "BarTwist",
    "BranchGuard",
    "ContactPatchPoint",
    "DistanceClosure",
    "FaceAlignment",
    "FramePoint",
    "HeaveTarget",
    "JointTarget",
    "Kinematics",
    "LoopBranch",
    "ManyFrames",
    "PointTarget",
    "RockerTurn",
    "RollTarget",
    "Row",
    "ShimGap",
    "StepFrames",
    "alignment",
    "alignment_many",
    "chirality",
    "chirality_many",
    "length_rates",
    "pick_branch",
]
