"""Studies: many variants of one geometry through one sweep, on Dask (docs/studies.md).

A study file names a geometry, a sweep and the hardpoint coordinates that vary
(mm from design). Its variants come from a design of experiments (full
factorial, Latin hypercube, Sobol), from manufacturing tolerances (Monte
Carlo), or from an optimiser's starts (least squares to target values and
curves). They are cut into batches; each batch is one task that builds every
variant's corner (or axle) from the geometry's data and solves its sweep — no
state is shared between tasks, so a batch gives the same numbers wherever it
runs. The client writes each finished batch as its own Parquet part file
(atomically), so ``resume`` skips what is done and a lost worker costs only
its batch: Dask runs it again elsewhere.

Execution: ``scheduler=None`` runs in this process, one batch after another;
``"local"`` starts a ``LocalCluster`` on 127.0.0.1; an address
(``tcp://host:port``) uses an existing scheduler. The numbers are the same.

The modules: ``spec`` (the study file read and checked), ``data`` (variables, terms,
a task's job, the objective's residuals), ``variants`` (their table, each one built
and solved), ``derivatives`` (the exact sensitivities: the optimiser's Jacobian, the
linear prediction), ``tasks`` (one batch, one optimiser start), ``folder`` (the
directory: manifest, part files, resume), ``cluster`` (Dask), ``run`` (a run).
"""

# ruff: noqa: F401 (the package's names, importable from pin_susp.study as before)
from __future__ import annotations

from ..errors import InputError
from ..subjects.axle_file import holds_wheels
from .data import AXES, MISS, Job, Term, Variable, objective_residuals
from .derivatives import linear_prediction, objective_jacobian, sensitivities
from .folder import INFORMATION, finished_batches, read_steps, write_geometry
from .run import Outcome, best_row, curves_of, run_study
from .spec import (
    DISTRIBUTIONS,
    DOE_METHODS,
    KINDS,
    MANIFEST,
    MAX_VALUES,
    MAX_VARIANTS,
    PARTS,
    STUDY_KEYS,
    Study,
    batches,
    load_study,
)
from .summary import summary_lines
from .tasks import run_batch, run_start
from .variants import Variant, build, variant_data, variant_table

__all__ = [
    "InputError",
    "Outcome",
    "Study",
    "Variable",
    "load_study",
    "read_steps",
    "run_study",
    "variant_data",
    "variant_table",
]
