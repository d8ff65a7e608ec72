"""Results as tables: CSV (:func:`write_csv`, :func:`csv_text`) or Parquet
(:func:`write_parquet`), whole, or a chunk of rows at a time through
:class:`CsvStream` and :class:`ParquetStream` (the same bytes, memory bounded by
a chunk); every file through io.atomic's atomic_write. The CSV's cells are repr's
shortest round-trip text (small tables) or pyarrow.compute's (from FAST_CELLS
cells), both reading back to the same float64.
"""

from __future__ import annotations

import json
import sys
from contextlib import ExitStack
from pathlib import Path

import numpy as np

from .. import __version__
from .atomic import atomic_write
from .conventions import ISO_MM, Output


def format_cell(value) -> str:
    """Full precision (repr); an undefined value (NaN) is an empty cell."""
    if isinstance(value, bool | np.bool_):
        return "True" if value else "False"
    if isinstance(value, int | np.integer):
        return str(int(value))
    if isinstance(value, str):  # a name (a load case's): quoted as CSV quotes
        quote = any(c in value for c in ',"\n\r')
        return '"' + value.replace('"', '""') + '"' if quote else value
    x = float(value)
    return "" if np.isnan(x) else repr(x)


# -- CSV ---------------------------------------------------------------------------------
#
# Two text styles for the same values, one per file. Each float cell is the shortest text
# that parses back to the same float64, so either style round-trips exactly:
# - the repr style (numpy's str, = repr: ``1e-05``, ``100.0``), for small tables;
# - the compiled style (pyarrow's cast to string: ``0.00001``, ``1e+15``; a whole number
#   in fixed notation keeps ``.0`` so that a reader still sees a float: ``100.0``,
#   ``-0.0``), six to ten times faster, for tables large enough to pay for importing
#   pyarrow and pyarrow.compute (~0.1 s): FAST_CELLS cells (rows × columns) or more,
#   1 000 rows of the 86-column corner table (benchmarks/bench_writer.py measures where
#   the two meet: 500 to 1 000 rows of it). One thread: pyarrow lets go of the GIL, but
#   two threads were no faster on the two-CPU machine measured.
# Flags are True/False, integers integers, an undefined value (NaN) an empty cell, a name
# quoted only where CSV needs it, lines end with \n.

FAST_CELLS = 86_000
_BLOCK_ROWS = 16_384  # rows formatted at once by the compiled style (bounded memory)


def csv_header(units: dict, meta: dict, names, output: Output = ISO_MM) -> str:
    """The ``#`` comment lines (version, sources, the output's convention and units
    unless ISO in mm, units) and the header row; ``units``: the Results' (ISO, mm)."""
    lines = [f"# pin_susp {__version__}"]
    for what in ("geometry", "sweep"):
        source, sha = meta[what]
        lines.append(f"# {what}: {source}" + (f" sha256={sha}" if sha else ""))
    if output.header():
        lines.append(output.header())
    lines.append("# units: " + json.dumps(output.column_units(units)))
    lines.append(",".join(names))
    return "\n".join(lines) + "\n"


def fast_style(rows: int, columns: int) -> bool:
    """Whether a table of this size is written in the compiled style."""
    return rows * columns >= FAST_CELLS


def csv_text(results, output: Output = ISO_MM) -> str:
    """Results as CSV text: ``#`` comment lines, one header row, one row per step;
    ``output``: the sign convention and units (io.conventions)."""
    names = list(results.columns)
    columns = _chunk_columns(results, names, output, results.units)
    head = csv_header(results.units, results.meta, names, output)
    if not fast_style(_rows(results), len(names)):
        return head + _repr_rows(columns)
    return head + b"".join(_fast_rows(columns)).decode()


def write_csv(results, path: str | Path, output: Output = ISO_MM) -> None:
    """Results as a CSV file (the text of csv_text), whole or not at all."""
    names = list(results.columns)
    with CsvStream(path, results.units, results.meta, names, _rows(results), output) as out:
        out.write(results)


def _rows(results) -> int:
    return len(next(iter(results.columns.values()), ()))


class _Stream:
    """A file written a chunk of rows at a time through atomic_write (whole or not at
    all); ``names``: its columns, in order."""

    def __init__(self, path, columns_order, units: dict, output: Output):
        self.path = path
        self.names = list(columns_order)
        self.units = units  # the Results' (ISO, mm): what ``output`` converts from
        self.output = output
        self.rows = 0
        self._stack = None
        self._file = None

    def _open(self):
        stack = ExitStack()
        self._file = stack.enter_context(atomic_write(self.path, binary=True))
        self._stack = stack
        return self._file


class CsvStream(_Stream):
    """A CSV file written a chunk of rows at a time, whole or not at all::

        with CsvStream(path, results.units, results.meta, names, total_rows) as out:
            for chunk in chunks:  # Results (or anything with .columns), these names
                out.write(chunk)

    The file is the one write_csv makes of all the rows at once, byte for byte: the
    text style follows from ``total_rows``, the rows the file is to hold (one style
    per file, however the chunks come). It is written to a temporary file beside
    ``path`` and renamed into place on a normal exit (inside all_or_none: with the
    others); an exception or interrupt leaves neither.
    """

    def __init__(
        self, path, units: dict, meta: dict, columns_order, total_rows: int, output=ISO_MM
    ):
        super().__init__(path, columns_order, units, output)
        self.head = csv_header(units, meta, self.names, output)
        self.fast = fast_style(total_rows, len(self.names))

    def __enter__(self):
        head = self._open()
        try:
            head.write(self.head.encode())
        except BaseException:  # the file (or its temporary) is left as atomic_write leaves it
            self._stack.__exit__(*sys.exc_info())
            raise
        return self

    def write(self, results) -> None:
        """Append the rows of a chunk (its columns: this file's, in any order)."""
        columns = _chunk_columns(results, self.names, self.output, self.units)
        if self.fast:
            for part in _fast_rows(columns):
                self._file.write(part)
        else:
            self._file.write(_repr_rows(columns).encode())
        self.rows += len(columns[0]) if columns else 0

    def __exit__(self, *exc):
        self._file = None
        return self._stack.__exit__(*exc)


def _chunk_columns(results, names: list, output: Output = ISO_MM, units=None) -> list:
    """The chunk's columns in the file's order, in the output's convention and units."""
    if set(results.columns) != set(names):
        odd = sorted(set(results.columns) ^ set(names))
        raise ValueError(f"a chunk's columns differ from the file's: {odd}")
    units = units or {}
    return [np.asarray(output.values(n, results.columns[n], units.get(n))) for n in names]


def _repr_rows(columns: list) -> str:
    """The rows in the repr style, a column formatted at a time."""
    cells = [_column_cells(c) for c in columns]
    return "".join(",".join(row) + "\n" for row in zip(*cells, strict=True))


def _column_cells(values) -> list[str]:
    """format_cell for a whole column at once: a column of numbers or flags in one call.
    A float64's text is Python's repr (numpy's str of a float64 is the same shortest
    round-trip text, at 2.5 times the cost); another float's, numpy's str."""
    v = np.asarray(values)
    if v.dtype.kind == "b":
        return np.where(v, "True", "False").tolist()
    if v.dtype.kind in "iu":
        return list(map(str, v.tolist()))
    if v.dtype == np.float64:
        text = list(map(float.__repr__, v.tolist()))
        for i in np.flatnonzero(np.isnan(v)).tolist():
            text[i] = ""
        return text
    if v.dtype.kind == "f":
        text = v.astype(str)
        text[np.isnan(v)] = ""
        return text.tolist()
    return [format_cell(x) for x in v]  # names and mixed columns, one by one


def _fast_rows(columns: list):
    """The rows in the compiled style, as buffers to write in order: a block of rows at
    a time, each made when the one before is written (the memory stays bounded)."""
    rows = len(columns[0]) if columns else 0
    for i in range(0, rows, _BLOCK_ROWS):
        yield _arrow_rows([c[i : i + _BLOCK_ROWS] for c in columns])


def _arrow_rows(columns: list):
    """Rows of CSV text (a pyarrow buffer: cells joined by commas, each row ending in \n).

    Every float column's values are formatted in one call, end to end; a column whose
    every value is the same (a fixed point of the chassis) by its one value. Every
    Arrow value is made from numpy's buffers (``_arrow_from_numpy``, ``_texts``), none
    from a Python object: pyarrow converts those through a check that imports pandas
    (~0.2 s, the whole of a mid-length sweep's writing)."""
    import pyarrow as pa

    pc = _compute()
    rows = len(columns[0])
    cells: list = [None] * len(columns)
    where = []  # the float columns
    for i, v in enumerate(columns):
        kind = v.dtype.kind
        if kind == "f":
            where.append(i)
        elif kind == "b":
            cells[i] = pc.if_else(_arrow_from_numpy(v, pa), *_texts(["True", "False"], pa))
        elif kind in "iu":
            cells[i] = pc.cast(_arrow_from_numpy(v, pa), pa.string())
        else:  # names and mixed columns, one by one
            cells[i] = _text_array([format_cell(x) for x in v], pa)
    if where:
        floats = np.array([columns[i] for i in where], dtype=float)  # a column a row
        bits = floats.view(np.uint64)
        same = (bits == bits[:, :1]).all(axis=1)  # by bits: -0.0 is not 0.0
        values = np.concatenate([floats[~same].ravel(), floats[same, 0]])
        text = pc.cast(_arrow_from_numpy(values, pa, nan_null=True), pa.string())
        whole = np.isfinite(values) & (values == np.trunc(values))
        care = whole | np.isnan(values)  # the cells _float_cells changes
        varying = np.array(where)[~same]
        cut = len(varying) * rows
        changed = care[:cut].reshape(len(varying), rows).any(axis=1)
        for k, i in enumerate(varying):
            part = text.slice(k * rows, rows)
            cells[i] = (
                _float_cells(part, whole[k * rows : (k + 1) * rows], pa, pc) if changed[k] else part
            )
        tail = _float_cells(text.slice(cut), whole[cut:], pa, pc).to_pylist()
        for k, i in enumerate(np.array(where)[same]):
            cells[i] = tail[k]
    parts = []  # the columns' cells; neighbouring fixed cells as one text
    for c in cells:
        if isinstance(c, str) and parts and isinstance(parts[-1], str):
            parts[-1] += "," + c
        else:
            parts.append(c)
    if isinstance(parts[-1], str):
        parts[-1] += "\n"
    else:
        parts[-1] = pc.binary_join_element_wise(parts[-1], *_texts(["\n", ""], pa))
    if isinstance(parts[0], str) and len(parts) == 1:  # every column the same all along
        parts = [pa.repeat(_texts(parts, pa)[0], rows)]
    fixed = iter(_texts([c for c in parts if isinstance(c, str)] + [","], pa))
    args = [next(fixed) if isinstance(c, str) else c for c in parts]
    joined = pc.binary_join_element_wise(*args, next(fixed))
    offsets = np.frombuffer(joined.buffers()[1], np.int32, len(joined) + 1, 4 * joined.offset)
    return joined.buffers()[2][offsets[0] : offsets[-1]]


def _float_cells(text, whole: np.ndarray, pa, pc):
    """pyarrow's text of floats (its shortest round-trip text) as cells: an undefined
    value (NaN, a null) is an empty cell; a whole number (``whole``) in fixed notation
    gets ``.0`` (``100.0``, ``-0.0``: a reader still sees a float)."""
    if whole.any():
        plain = pc.and_(_arrow_from_numpy(whole, pa), pc.invert(pc.match_substring(text, "e")))
        point, empty = _texts([".0", ""], pa)  # plain: not 1e+16
        text = pc.if_else(plain, pc.binary_join_element_wise(text, point, empty), text)
    return pc.fill_null(text, _texts([""], pa)[0]) if text.null_count else text


class _Kernels:
    """The pyarrow.compute functions the compiled style calls, by the same names, each
    pyarrow's own kernel called by name (``call_function``) from pyarrow._compute, the
    module pyarrow.compute wraps: without the Python wrapper pyarrow.compute makes for
    each of its functions as it is imported (~25 ms, a third of what pyarrow costs a
    mid-length sweep: benchmarks/bench_cli.py). Every argument is an Arrow value."""

    def __init__(self, kernels):
        self._call = kernels.call_function
        self._cast = kernels.CastOptions.safe
        self._match = kernels.MatchSubstringOptions

    def cast(self, values, target):
        return self._call("cast", [values], self._cast(target))

    def if_else(self, condition, left, right):
        return self._call("if_else", [condition, left, right])

    def binary_join_element_wise(self, *strings):  # the last: the separator
        return self._call("binary_join_element_wise", list(strings))

    def and_(self, left, right):
        return self._call("and", [left, right])

    def invert(self, values):
        return self._call("invert", [values])

    def match_substring(self, values, pattern: str):
        return self._call("match_substring", [values], self._match(pattern))

    def fill_null(self, values, fill):
        return self._call("coalesce", [values, fill])


_KERNELS = []


def _compute():
    """_Kernels on pyarrow._compute, once; pyarrow.compute itself (the same names) where
    a pyarrow has not that module's names."""
    if not _KERNELS:
        try:
            from pyarrow import _compute as kernels

            _KERNELS.append(_Kernels(kernels))
        except (ImportError, AttributeError):
            import pyarrow.compute

            _KERNELS.append(pyarrow.compute)
    return _KERNELS[0]


def _arrow_from_numpy(values: np.ndarray, pa, nan_null: bool = False):
    """A numpy column (flags, integers or floats) as an Arrow array on its own buffers:
    ``pa.array(values, from_pandas=nan_null)``'s array (an undefined value, NaN, a null
    where ``nan_null``) without its check of pandas' types, which imports pandas."""
    v = np.ascontiguousarray(values)
    if not v.dtype.isnative:  # Arrow's buffers are little-endian, as the machine's
        v = v.astype(v.dtype.newbyteorder("="))
    n = len(v)
    if v.dtype.kind == "b":
        return pa.Array.from_buffers(pa.bool_(), n, [None, _bits(v, pa)])
    valid, nulls = None, 0
    if nan_null and v.dtype.kind == "f":
        defined = ~np.isnan(v)
        nulls = n - int(np.count_nonzero(defined))
        valid = _bits(defined, pa) if nulls else None
    return pa.Array.from_buffers(pa.from_numpy_dtype(v.dtype), n, [valid, pa.py_buffer(v)], nulls)


def _bits(flags: np.ndarray, pa):
    """Flags as Arrow's bitmap (least significant bit first)."""
    return pa.py_buffer(np.packbits(flags, bitorder="little"))


def _text_array(texts: list[str], pa):
    """Python strings as an Arrow string array on one buffer (no Python conversion)."""
    data = [t.encode() for t in texts]
    offsets = np.concatenate([[0], np.cumsum([len(d) for d in data])]).astype(np.int32)
    joined = pa.py_buffer(b"".join(data))
    return pa.StringArray.from_buffers(len(data), pa.py_buffer(offsets), joined)


def _texts(texts: list[str], pa) -> list:
    """Python strings as Arrow string scalars (``_text_array``'s)."""
    array = _text_array(texts, pa)
    return [array[i] for i in range(len(texts))]


# -- Parquet -----------------------------------------------------------------------------

ROW_GROUP = 65_536  # rows per Parquet row group: what a ParquetStream holds at most


def write_parquet(results, path: str | Path, output: Output = ISO_MM) -> None:
    """Results as a Parquet file (pyarrow), whole or not at all: the CSV's columns, an
    undefined value (a blank CSV cell) as a null, the units, the sources and the
    pin_susp version in the schema's metadata; row groups of ROW_GROUP rows."""
    names = list(results.columns)
    with ParquetStream(path, results.units, results.meta, names, None, output) as out:
        out.write(results)


def parquet_metadata(units: dict, meta: dict, output: Output = ISO_MM) -> dict:
    """The schema's metadata: pin_susp's version, the units, the sources; unless ISO in
    mm, the convention and units (``convention``, ``output_units``)."""
    out = {"pin_susp": __version__, "units": json.dumps(output.column_units(units))}
    for what in ("geometry", "sweep"):
        source, sha = meta[what]
        out[what] = json.dumps({"source": str(source), "sha256": sha})
    out.update(output.metadata())
    return out


class ParquetStream(_Stream):
    """A Parquet file written a chunk of rows at a time, whole or not at all (as
    CsvStream): rows are held until a row group of ROW_GROUP is full, so the file is
    the one write_parquet makes of all the rows at once, byte for byte. ``total_rows``
    is accepted for CsvStream's signature; Parquet does not need it."""

    def __init__(
        self, path, units: dict, meta: dict, columns_order, total_rows=None, output=ISO_MM
    ):
        super().__init__(path, columns_order, units, output)
        self.metadata = parquet_metadata(units, meta, output)
        self._held = []  # tables not yet written: fewer than ROW_GROUP rows in all
        self._held_rows = 0
        self._schema = None
        self._writer = None

    def __enter__(self):
        import pyarrow.parquet  # noqa: F401  (before the file appears: an import error leaves none)

        self._open()
        return self

    def write(self, results) -> None:
        """Append the rows of a chunk (its columns: this file's, in any order)."""
        import pyarrow as pa

        columns = _chunk_columns(results, self.names, self.output, self.units)
        table = pa.table({n: arrow_column(c) for n, c in zip(self.names, columns, strict=True)})
        table = table.replace_schema_metadata(self.metadata)
        if self._schema is None:
            self._schema = table.schema
        elif not table.schema.equals(self._schema):
            table = table.cast(self._schema)
        self._held.append(table)
        self._held_rows += len(table)
        self.rows += len(table)
        if self._held_rows >= ROW_GROUP:
            held = pa.concat_tables(self._held)
            while len(held) >= ROW_GROUP:
                self._group(held.slice(0, ROW_GROUP))
                held = held.slice(ROW_GROUP)
            self._held, self._held_rows = [held], len(held)

    def _group(self, table) -> None:
        """One row group, from one layout of the rows however the chunks cut them."""
        import pyarrow.parquet as pq

        if self._writer is None:
            self._writer = pq.ParquetWriter(self._file, self._schema)
        self._writer.write_table(table.combine_chunks(), row_group_size=ROW_GROUP)

    def __exit__(self, kind, exc, tb):
        if kind is not None:  # no file: the temporary goes
            if self._writer is not None:
                try:
                    self._writer.close()
                except Exception:
                    pass
            return self._stack.__exit__(kind, exc, tb)
        with self._stack:  # an error finishing the file also leaves none
            import pyarrow as pa

            if self._schema is None:  # no chunk came: the columns, without rows or types
                self._schema = pa.schema([(n, pa.null()) for n in self.names], self.metadata)
            if self._held_rows or self._writer is None:
                held = self._held or [self._schema.empty_table()]
                self._group(pa.concat_tables(held))
            self._writer.close()
        return False


def arrow_column(values):
    """A column for Arrow (Parquet): an undefined value (NaN, a blank CSV cell) is null;
    numbers and flags on numpy's buffers (``_arrow_from_numpy``: no pandas imported)."""
    import pyarrow as pa

    values = np.asarray(values)
    if values.dtype.kind in "biuf":
        return _arrow_from_numpy(values, pa, nan_null=values.dtype.kind == "f")
    return pa.array(values, from_pandas=values.dtype.kind == "f")


def arrow_columns(results) -> dict:
    """Every column of results for Arrow, in the CSV's order (arrow_column)."""
    return {name: arrow_column(values) for name, values in results.columns.items()}


def results_frame(results):
    """Results as a pandas DataFrame, one row per step (units in ``.attrs['units']``)."""
    import pandas as pd

    frame = pd.DataFrame({k: np.asarray(v) for k, v in results.columns.items()})
    frame.attrs["units"] = {k: u for k, u in results.units.items() if u}
    return frame


def is_parquet(path: str | Path) -> bool:
    """Whether an output is to be Parquet: its name ends .parquet, in any case
    (X.PARQUET, x.Parquet); anything else is CSV."""
    return Path(path).suffix.lower() == ".parquet"
