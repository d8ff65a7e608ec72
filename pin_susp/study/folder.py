"""A study's directory (docs/studies.md): its manifest, checked before any work; the
part files, one per batch, each whole; what ``resume`` finds damaged; the tables
assembled at the end; best.yaml.
"""

from __future__ import annotations

import json
import os
from pathlib import Path

import numpy as np
import yaml

from .. import __version__
from ..errors import PinSuspError
from ..io.conventions import Output
from .spec import MANIFEST, PARTS, Study, batches
from .tasks import from_ipc
from .variants import variant_data


def _fingerprint(study: Study, steps: bool) -> dict:
    """What makes a run this study's: the files' hashes, the variants, --steps (the
    study's path is kept for information: the same file may be typed differently)."""
    out = {
        "pin_susp": __version__,
        "study": study.source,
        "study_sha256": study.sha256,
        "geometry_sha256": study.geometry_sha256,
        "sweep_sha256": study.sweep_sha256,
        "kind": study.kind,
        "variants": study.samples,
        "batches": len(batches(study)),
        "steps": steps,
    }
    if study.referenced_sha256:  # a vehicle's axle files: edited, another geometry
        out["referenced_sha256"] = study.referenced_sha256
    return out


INFORMATION = ("pin_susp", "study")  # manifest entries that do not decide sameness


def prepare(study: Study, outdir: Path, steps: bool, resume: bool) -> Path:
    """Check OUTDIR again and write its manifest; the parts' folder."""
    from ..io.atomic import write_text

    mine = check_outdir(study, outdir, steps, resume)
    manifest = outdir / MANIFEST
    for stale in (outdir / PARTS).glob(".*.tmp"):  # a part cut short by an interruption
        stale.unlink()
    try:
        (outdir / PARTS).mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise PinSuspError(f"{outdir}: cannot write here ({exc.strerror})") from None
    write_text(json.dumps(mine, indent=2) + "\n", manifest)
    return outdir / PARTS


def check_outdir(study: Study, outdir: Path, steps: bool, resume: bool) -> dict:
    """OUTDIR must be new or empty, or hold this study's unfinished run (``resume``);
    nothing is written. The manifest that the run will write."""
    from ..io.atomic import check_folder

    mine = _fingerprint(study, steps)
    check_folder(outdir)  # a name too long for the file system: one line, not a traceback
    manifest = outdir / MANIFEST
    if outdir.exists() and not outdir.is_dir():
        raise PinSuspError(f"{outdir}: exists and is not a directory")
    if outdir.exists() and any(outdir.iterdir()):
        if not manifest.is_file():
            raise PinSuspError(
                f"{outdir}: is not empty and holds no study: give a new or empty directory"
            )
        try:
            theirs = json.loads(manifest.read_text())
        except (OSError, ValueError):
            theirs = None
        if not isinstance(theirs, dict):
            raise PinSuspError(f"{manifest}: unreadable: not a study's directory")
        differs = [k for k in mine if k not in INFORMATION and theirs.get(k) != mine[k]]
        if differs == ["steps"]:
            how = "with" if theirs.get("steps") else "without"
            raise PinSuspError(
                f"{outdir}: holds a run of this study made {how} --steps: run it {how} "
                "--steps, or give a new or empty directory"
            )
        if differs == ["batches"]:  # (16 batches since issue 30; 64 before)
            raise PinSuspError(
                f"{outdir}: holds a run of this study cut into {theirs.get('batches')} batches, "
                f"where this pin_susp cuts it into {mine['batches']} (an earlier version's): "
                "it cannot be resumed; give a new or empty directory"
            )
        if differs == ["referenced_sha256"]:
            edited = [f for f, sha in mine[differs[0]].items() if theirs[differs[0]].get(f) != sha]
            raise PinSuspError(
                f"{outdir}: holds a run of this study made before {', '.join(edited)} was "
                "edited (the geometry reads it): give a new or empty directory"
            )
        if differs:
            what = theirs.get("study", "another study")
            raise PinSuspError(
                f"{outdir}: holds the data of another study ({what}; differs in "
                f"{', '.join(differs)}): give a new or empty directory"
            )
        if (outdir / "variants.parquet").exists():
            raise PinSuspError(
                f"{outdir}: this study has already finished here: give a new or empty directory"
            )
        if not resume:
            raise PinSuspError(
                f"{outdir}: holds an unfinished run of this study: --resume to finish it, or "
                "give a new or empty directory"
            )
    elif resume:
        raise PinSuspError(f"{outdir}: no unfinished run of this study to resume")
    else:
        from ..io.atomic import existing_ancestor

        folder = existing_ancestor(outdir.absolute())
        if not folder.is_dir():
            raise PinSuspError(f"{outdir}: cannot write here ({folder} is not a directory)")
        if not os.access(folder, os.W_OK | os.X_OK):
            raise PinSuspError(f"{outdir}: cannot write here (no permission in {folder})")
    return mine


def finished_batches(outdir: str | Path) -> int | None:
    """How many batches an unfinished run in ``outdir`` has written (None: no run there)."""
    outdir = Path(outdir)
    if not (outdir / MANIFEST).is_file() or (outdir / "variants.parquet").exists():
        return None
    return len(list((outdir / PARTS).glob("variants-*.parquet")))


def write_part(parts: Path, result: dict):
    """A batch's part files, each written whole; the variants' part last: its
    presence marks the batch done (a steps part without it goes). The batch's
    variants (an Arrow table), for ``assemble``."""
    i = result["index"]
    parts.mkdir(exist_ok=True)
    variants = from_ipc(result["variants"])
    try:
        if result["steps"] is not None:
            write_parquet(from_ipc(result["steps"]), parts / f"steps-{i:06d}.parquet")
        write_parquet(variants, parts / f"variants-{i:06d}.parquet")
    except BaseException:
        (parts / f"steps-{i:06d}.parquet").unlink(missing_ok=True)
        raise
    return variants


def damaged(parts: Path, i: int, ids: np.ndarray, steps: bool) -> str | None:
    """What is wrong with batch ``i``'s part files (None: nothing, or not written):
    each must read whole, its variants part holding the batch's variants."""
    import pyarrow as pa
    import pyarrow.parquet as pq

    path = parts / f"variants-{i:06d}.parquet"
    if not path.exists():
        return None
    names = [path] + [parts / f"steps-{i:06d}.parquet"] * steps
    for name in names:
        if not name.exists():
            continue  # a batch none of whose variants converged has no steps
        try:
            table = pq.read_table(name)
        except (pa.ArrowException, OSError, ValueError) as exc:
            return f"{name}: damaged ({_first_line(exc)})"
        if name == path:
            got = (
                np.sort(table.column("variant_id").to_numpy())
                if "variant_id" in (table.column_names)
                else None
            )
            if got is None or not np.array_equal(got, ids):
                return f"{name}: does not hold batch {i}'s variants"
    return None


def _first_line(exc: BaseException) -> str:
    text = str(exc).strip().splitlines()
    return text[0][:200] if text else type(exc).__name__


def write_parquet(table, path: Path) -> None:
    """A table as Parquet, whole or not at all (io.atomic.atomic_write)."""
    import pyarrow.parquet as pq

    from ..io.atomic import atomic_write

    with atomic_write(path, binary=True) as f:
        pq.write_table(table, f)


def assemble(study: Study, outdir: Path, parts: Path, n: int, steps: bool, have=None):
    """The variants' table (by variant_id) from the parts, and steps.parquet (a
    dataset: a folder of part files) moved into place. ``have``: batch → its variants
    as written in this run (not read back)."""
    import pyarrow as pa
    import pyarrow.parquet as pq

    missing = [i for i in range(n) if not (parts / f"variants-{i:06d}.parquet").is_file()]
    if missing:  # removed under a running study: never a table with holes
        raise PinSuspError(
            f"{parts}: the part files of {len(missing)} batches went missing while the study "
            "ran (removed by another program?): --resume solves them again"
        )
    tables, have = [], have or {}
    for i in range(n):
        path = parts / f"variants-{i:06d}.parquet"
        if i in have:
            tables.append(have[i])
            continue
        try:
            tables.append(pq.read_table(path))
        except (pa.ArrowException, OSError, ValueError) as exc:  # damaged while the run ran
            raise PinSuspError(
                f"{path}: damaged ({_first_line(exc)}): --resume solves its batch again"
            ) from None
    variants = pa.concat_tables(tables, promote_options="permissive").sort_by("variant_id")
    units = {v.name: "mm" for v in study.variables}
    for m, unit in study.column_units.items():
        units |= {f"{m}_{figure}": unit for figure in ("static", "min", "max") if unit}
    meta = {
        "units": json.dumps(units),
        "pin_susp": __version__,
        "study": json.dumps(_fingerprint(study, steps)),
        "variables": json.dumps([v.__dict__ for v in study.variables]),
    }
    form = Output(study.convention)
    variants = in_convention(variants, form).replace_schema_metadata(meta | form.metadata())
    if steps and any(parts.glob("steps-*.parquet")):  # (no variant solved: no steps)
        folder = outdir / "steps.parquet"
        folder.mkdir(exist_ok=True)
        for i in range(n):
            part = parts / f"steps-{i:06d}.parquet"
            if part.exists() and not form.identity:  # the parts are ISO: converted here
                write_parquet(steps_in_convention(pq.read_table(part), form), part)
            if part.exists():
                os.replace(part, folder / f"part-{i:06d}.parquet")
    return variants


STATISTICS = ("_static", "_min", "_max", "_linear")  # a variants column: a metric's


def in_convention(variants, form):
    """The variants' table in ``form``'s convention (the study's ``conventions:``): each
    metric's statistics and each variable (``d_<point>_<axis>``) by the column's sign,
    a metric's min and max swapped where the sign is −1."""
    import pyarrow as pa
    import pyarrow.compute as pc

    if form.identity:
        return variants
    from ..io.conventions import CONVENTIONS, sign

    convention = CONVENTIONS[form.convention]
    columns = {}
    for name in variants.column_names:
        column = variants.column(name)
        base = next((name.removesuffix(s) for s in STATISTICS if name.endswith(s)), name)
        base = base.removeprefix("d_")
        if not pa.types.is_floating(column.type) or sign(base, convention) == 1:
            columns[name] = column
            continue
        if name.endswith(("_min", "_max")):  # −max is the new min
            other = base + ("_max" if name.endswith("_min") else "_min")
            column = variants.column(other) if other in variants.column_names else column
        columns[name] = pc.negate(column)
    return pa.table(columns, schema=None).replace_schema_metadata(variants.schema.metadata)


def steps_in_convention(table, form):
    """A steps part (its units in the schema's ``units``) in ``form``'s convention."""
    import pyarrow as pa

    units = json.loads((table.schema.metadata or {}).get(b"units", b"{}"))
    columns = {}
    for name in table.column_names:
        column = table.column(name)
        if pa.types.is_floating(column.type):
            values = column.to_numpy(zero_copy_only=False)
            column = pa.array(form.values(name, values, units.get(name)), from_pandas=True)
        columns[name] = column
    meta = dict(table.schema.metadata or {}) | {
        k.encode(): v.encode() for k, v in form.metadata().items()
    }
    return pa.table(columns).replace_schema_metadata(meta)


def drop_parts(parts: Path) -> None:
    for p in parts.iterdir():
        p.unlink()
    parts.rmdir()


def read_steps(outdir: str | Path):
    """A finished study's steps.parquet as one pandas DataFrame."""
    import pandas as pd

    return pd.read_parquet(Path(outdir) / "steps.parquet")


def write_geometry(study: Study, deltas, path: str | Path, comment: str) -> None:
    """The study's geometry file with the deltas applied (best.yaml), whole or not at all."""
    from ..io.atomic import write_text

    data = variant_data(study.geometry_data, study.variables, deltas)
    lines = "".join(f"# {line}\n" for line in comment.splitlines())
    write_text(lines + yaml.safe_dump(data, sort_keys=False), path)
