"""The CSV writer (export): both text styles give back every float64 bit for bit, the
file's layout holds (comments, an unquoted header, True/False, blank undefined cells,
names quoted only where CSV needs it, \\n), a stream of chunks writes the same bytes as
the whole table at once (CSV and Parquet), and a failure leaves no file."""

import csv
import io

import numpy as np
import pandas as pd
import pyarrow.parquet as pq
import pytest
from conftest import EXAMPLES

from pin_susp.io import atomic, tables
from pin_susp.model.sweep import load_sweep
from pin_susp.subjects.corner import Results

EDGE = [
    0.0,
    -0.0,
    1e-05,
    1e-07,
    1.5e-06,
    100.0,
    -3.0,
    0.1,
    1 / 3,
    1e15,
    1e16,
    1e22,
    123456789.0,
    2.0**53,
    2.0**53 + 2,
    1e300,
    -1e-300,
    1.7976931348623157e308,
    2.2250738585072014e-308,  # the least normal
    1e-310,  # subnormal
    5e-324,  # the least subnormal
    float("nan"),
    float("inf"),
    -float("inf"),
]
NAMES = ["plain", "a,b", 'say "hi"', "two\nlines", "ü case", "", "True"]
META = {"geometry": ("g.yaml", "ab12"), "sweep": ("s.yaml", None)}


def edge_results(rows: int = 60, seed: int = 0) -> Results:
    """Every kind of column and value a results table holds, and some it should not."""
    rng = np.random.default_rng(seed)
    any_bits = rng.integers(0, 2**64, rows, dtype=np.uint64).view(np.float64)
    columns = {
        "step_index": np.arange(rows),
        "solver_converged": np.arange(rows) % 3 != 1,
        "load_case": np.array([NAMES[i % len(NAMES)] for i in range(rows)], dtype=object),
        "edge": np.resize(np.array(EDGE), rows),
        "any_bits": any_bits,  # every exponent, NaN among them now and then
        "whole": rng.integers(-5000, 5000, rows).astype(float) * np.resize([1.0, -1.0], rows),
        "zeros": np.resize([0.0, -0.0], rows),  # the same value, not the same bits
        "fixed": np.full(rows, 100.0),  # a fixed point of the chassis
        "fixed_negative_zero": np.full(rows, -0.0),
        "fixed_tiny": np.full(rows, 1e-310),
        "undefined": np.full(rows, np.nan),
        "solver_iterations": rng.integers(0, 7, rows),
        "last": rng.normal(size=rows) * 10.0 ** rng.integers(-8, 8, rows),
    }
    units = dict.fromkeys(columns, "") | {"edge": "mm", "last": "N·m"}
    return Results(columns, units, META)


@pytest.fixture(params=["repr", "fast"])
def style(request, monkeypatch):
    """Each text style in turn: FAST_CELLS moved so that any table has it."""
    monkeypatch.setattr(tables, "FAST_CELLS", 10**18 if request.param == "repr" else 0)
    return request.param


def parsed(path) -> tuple[list, list, list]:
    """The file read with the csv module: comment lines, the header, the rows (strings)."""
    with open(path, encoding="utf-8", newline="") as f:
        text = f.read()
    lines = text.split("\n")
    comments = [line for line in lines if line.startswith("#")]
    body = text[sum(len(c) + 1 for c in comments) :]
    rows = list(csv.reader(io.StringIO(body, newline="")))
    return comments, rows[0], rows[1:]


def same_bits(a, b) -> bool:
    a, b = np.asarray(a, float), np.asarray(b, float)
    nan = np.isnan(a)
    return bool((nan == np.isnan(b)).all() and (a.view(np.uint64) == b.view(np.uint64))[~nan].all())


def check_cells(results: Results, path) -> None:
    """Every cell against the value it was written from (float(): bit for bit)."""
    comments, header, rows = parsed(path)
    assert header == list(results.columns)
    assert len(rows) == len(results[header[0]]) and all(len(r) == len(header) for r in rows)
    for j, name in enumerate(header):
        cells = [r[j] for r in rows]
        values = np.asarray(results.columns[name])
        if values.dtype.kind == "f":
            assert "nan" not in {c.lower() for c in cells}, name
            back = [np.nan if c == "" else float(c) for c in cells]
            assert all((c == "") == np.isnan(v) for c, v in zip(cells, values, strict=True))
            assert same_bits(back, values), name
        elif values.dtype.kind == "b":
            assert cells == ["True" if v else "False" for v in values], name
        elif values.dtype.kind in "iu":
            assert [int(c) for c in cells] == values.tolist(), name
            assert all(c.lstrip("-").isdigit() for c in cells), name
        else:
            assert cells == values.tolist(), name


def test_every_cell_reads_back_as_written(tmp_path, style):
    results = edge_results()
    tables.write_csv(results, tmp_path / "r.csv")
    check_cells(results, tmp_path / "r.csv")


def test_pandas_reads_back_the_same_float64s(tmp_path, style):
    results = edge_results(200, seed=1)
    tables.write_csv(results, tmp_path / "r.csv")
    frame = pd.read_csv(tmp_path / "r.csv", comment="#")
    for name, values in results.columns.items():
        values = np.asarray(values)
        if values.dtype.kind == "f":  # a float column stays float, even all whole numbers
            assert frame[name].dtype == np.float64, name
            assert same_bits(frame[name].to_numpy(), values), name
    assert frame["load_case"].fillna("").tolist() == results["load_case"].tolist()
    assert frame["solver_converged"].tolist() == results["solver_converged"].tolist()


def test_the_layout_of_a_small_table(tmp_path, style):
    columns = {
        "step_index": np.array([0, 1]),
        "solver_converged": np.array([True, False]),
        "x": np.array([1e-05, -0.0]),
        "y": np.array([np.nan, 100.0]),
        "load_case": np.array(["a,b", "c"], dtype=object),
    }
    units = {"step_index": "", "solver_converged": "", "x": "mm", "y": "deg", "load_case": ""}
    tables.write_csv(Results(columns, units, META), tmp_path / "r.csv")
    x0 = "1e-05" if style == "repr" else "0.00001"  # the one cell the two styles differ in
    assert (tmp_path / "r.csv").read_bytes().decode() == (
        f"# pin_susp {tables.__version__}\n"
        "# geometry: g.yaml sha256=ab12\n"
        "# sweep: s.yaml\n"
        '# units: {"step_index": "", "solver_converged": "", "x": "mm", "y": "deg", '
        '"load_case": ""}\n'
        "step_index,solver_converged,x,y,load_case\n"
        f'0,True,{x0},,"a,b"\n'
        "1,False,-0.0,100.0,c\n"
    )


def test_the_fast_style_writes_whole_numbers_and_exponents_as_floats(tmp_path, style):
    values = np.array([100.0, -0.0, 0.0, 1e15, 1e22, 123456789.0, 2.5, 1e-7, 1e-05])
    columns = {"step_index": np.arange(len(values)), "v": values}
    tables.write_csv(Results(columns, {"step_index": "", "v": ""}, META), tmp_path / "r.csv")
    _, _, rows = parsed(tmp_path / "r.csv")
    cells = [r[1] for r in rows]
    assert same_bits([float(c) for c in cells], values)
    for cell in cells:  # never a bare integer: a reader sees a float
        assert "." in cell or "e" in cell, cell
    if style == "fast":
        assert cells[:3] == ["100.0", "-0.0", "0.0"] and cells[-1] == "0.00001"


@pytest.mark.parametrize("rows", [1, 5])
def test_a_table_of_fixed_values_only(tmp_path, style, rows):
    """Every column the same all along (each formatted once in the fast style)."""
    columns = {"a": np.full(rows, 2.0), "b": np.full(rows, np.nan), "c": np.full(rows, -0.0)}
    results = Results(columns, dict.fromkeys(columns, ""), META)
    tables.write_csv(results, tmp_path / "r.csv")
    check_cells(results, tmp_path / "r.csv")
    assert (tmp_path / "r.csv").read_text().endswith("a,b,c\n" + "2.0,,-0.0\n" * rows)


@pytest.fixture(scope="module")
def sweep_results(corner):
    return corner.run_sweep(load_sweep(EXAMPLES / "bump_steer.yaml"))


def test_the_example_sweep_parses_the_same_on_both_sides_of_the_threshold(
    tmp_path, monkeypatch, sweep_results
):
    rows, columns = len(sweep_results), len(sweep_results.columns)
    texts = {}
    for cells, name in ((rows * columns + 1, "below"), (rows * columns, "at")):
        monkeypatch.setattr(tables, "FAST_CELLS", cells)
        tables.write_csv(sweep_results, tmp_path / f"{name}.csv")
        texts[name] = (tmp_path / f"{name}.csv").read_text()
        check_cells(sweep_results, tmp_path / f"{name}.csv")
    assert texts["below"] != texts["at"]  # two styles...
    below = pd.read_csv(tmp_path / "below.csv", comment="#")
    at = pd.read_csv(tmp_path / "at.csv", comment="#")
    assert list(below.dtypes) == list(at.dtypes)  # ...the same table read back
    for name in sweep_results.columns:
        a, b = below[name].to_numpy(), at[name].to_numpy()
        if a.dtype.kind == "f":
            assert same_bits(a, b) and same_bits(a, sweep_results[name]), name
        else:
            assert (a == b).all(), name
    assert below["anti_dive"].isna().all()  # undefined on this axle: blank cells


def test_the_threshold_counts_cells():
    assert tables.fast_style(1, tables.FAST_CELLS)
    assert not tables.fast_style(1, tables.FAST_CELLS - 1)
    assert tables.fast_style(2001, 86) and not tables.fast_style(41, 86)


def test_csv_text_is_the_files_text(tmp_path, style, sweep_results):
    tables.write_csv(sweep_results, tmp_path / "r.csv")
    assert tables.csv_text(sweep_results).encode() == (tmp_path / "r.csv").read_bytes()


def chunks(results: Results, sizes) -> list[Results]:
    out, start = [], 0
    for size in sizes:
        part = {k: v[start : start + size] for k, v in results.columns.items()}
        out.append(Results(part, results.units, results.meta))
        start += size
    assert start == len(results)
    return out


@pytest.mark.parametrize("sizes", [[60], [1] * 60, [7] * 8 + [4], [0, 13, 0, 40, 7]])
def test_a_stream_writes_the_bytes_of_the_whole_table(tmp_path, style, monkeypatch, sizes):
    monkeypatch.setattr(tables, "_BLOCK_ROWS", 9)  # chunks cut across the fast style's blocks
    results = edge_results()
    tables.write_csv(results, tmp_path / "whole.csv")
    names = list(results.columns)
    with tables.CsvStream(tmp_path / "s.csv", results.units, META, names, len(results)) as out:
        for part in chunks(results, sizes):
            out.write(part)
    assert (tmp_path / "s.csv").read_bytes() == (tmp_path / "whole.csv").read_bytes()
    assert out.rows == len(results)


def test_the_stream_takes_its_style_from_the_total_rows(tmp_path, monkeypatch):
    monkeypatch.setattr(tables, "FAST_CELLS", 60 * 13)  # edge_results: 13 columns
    results = edge_results()
    names = list(results.columns)
    for total, cell in ((60, "0.00001"), (59, "1e-05")):
        with tables.CsvStream(tmp_path / "s.csv", results.units, META, names, total) as out:
            for part in chunks(results, [10] * 6):  # every chunk below the threshold
                out.write(part)
        _, _, rows = parsed(tmp_path / "s.csv")
        assert rows[2][3] == cell  # edge[2] = 1e-05


@pytest.mark.parametrize("sizes", [[60], [1] * 60, [3, 4, 0, 20, 33], [14, 14, 32]])
def test_a_parquet_stream_writes_the_bytes_of_the_whole_table(tmp_path, monkeypatch, sizes):
    monkeypatch.setattr(tables, "ROW_GROUP", 7)
    results = edge_results()
    tables.write_parquet(results, tmp_path / "whole.parquet")
    names = list(results.columns)
    with tables.ParquetStream(tmp_path / "s.parquet", results.units, META, names) as out:
        for part in chunks(results, sizes):
            out.write(part)
    assert (tmp_path / "s.parquet").read_bytes() == (tmp_path / "whole.parquet").read_bytes()
    read = pq.ParquetFile(tmp_path / "s.parquet")
    assert read.metadata.num_row_groups == 9  # 60 rows in groups of 7
    table = read.read()
    for name, values in results.columns.items():
        back = table.column(name).to_numpy(zero_copy_only=False)
        if np.asarray(values).dtype.kind == "f":
            assert table.column(name).null_count == np.isnan(values).sum()
            assert same_bits(back.astype(float), values), name
        else:
            assert back.tolist() == np.asarray(values).tolist(), name


def test_write_parquet_is_pyarrows_own_table_written_whole(tmp_path, sweep_results):
    """The same bytes as pyarrow's write_table of the table with the schema's metadata,
    below a row group's rows."""
    import pyarrow as pa

    tables.write_parquet(sweep_results, tmp_path / "r.parquet")
    columns = {k: tables.arrow_column(v) for k, v in sweep_results.columns.items()}
    meta = tables.parquet_metadata(sweep_results.units, sweep_results.meta)
    pq.write_table(pa.table(columns).replace_schema_metadata(meta), tmp_path / "own.parquet")
    assert (tmp_path / "r.parquet").read_bytes() == (tmp_path / "own.parquet").read_bytes()
    assert (
        pq.read_schema(tmp_path / "r.parquet").metadata[b"pin_susp"] == tables.__version__.encode()
    )


@pytest.mark.parametrize("stream", [tables.CsvStream, tables.ParquetStream])
@pytest.mark.parametrize("failure", [RuntimeError, KeyboardInterrupt])
def test_a_failure_inside_a_stream_leaves_no_file(tmp_path, style, monkeypatch, stream, failure):
    monkeypatch.setattr(tables, "ROW_GROUP", 7)  # the Parquet writer is open when it fails
    results = edge_results()
    names = list(results.columns)
    (tmp_path / "old.out").write_text("before")
    for path in (tmp_path / "new.out", tmp_path / "old.out"):
        with pytest.raises(failure):
            with stream(path, results.units, META, names, len(results)) as out:
                for part in chunks(results, [30, 30]):
                    out.write(part)
                    raise failure("part-way")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["old.out"]  # no temporary either
    assert (tmp_path / "old.out").read_text() == "before"


def test_streams_inside_all_or_none_appear_together_or_not_at_all(tmp_path, style):
    results = edge_results()
    names = list(results.columns)
    with pytest.raises(RuntimeError):
        with atomic.all_or_none():
            for stream, name in ((tables.CsvStream, "r.csv"), (tables.ParquetStream, "r.pq")):
                with stream(tmp_path / name, results.units, META, names, len(results)) as out:
                    out.write(results)
            raise RuntimeError("after both were complete")
    assert list(tmp_path.iterdir()) == []
    with atomic.all_or_none():
        with tables.CsvStream(tmp_path / "r.csv", results.units, META, names, 60) as out:
            out.write(results)
        assert list(tmp_path.iterdir()) != [] and not (tmp_path / "r.csv").exists()
    assert [p.name for p in tmp_path.iterdir()] == ["r.csv"]


def test_a_chunk_with_other_columns_is_refused_and_leaves_no_file(tmp_path):
    results = edge_results()
    names = list(results.columns)
    other = Results({k: v for k, v in results.columns.items() if k != "edge"}, {}, META)
    with pytest.raises(ValueError, match="edge"):
        with tables.CsvStream(tmp_path / "r.csv", results.units, META, names, 60) as out:
            out.write(other)
    assert list(tmp_path.iterdir()) == []


def test_a_parquet_stream_of_many_small_chunks_still_writes_the_same_bytes(tmp_path, monkeypatch):
    """Pages of a row group fill at the same rows however the chunks cut them."""
    monkeypatch.setattr(tables, "ROW_GROUP", 150_000)
    rng = np.random.default_rng(2)
    n = 200_000  # a first group of more than a page (1 MB) per column, then the rest
    columns = {
        "step_index": np.arange(n),
        "x": rng.normal(size=n),
        "y": np.where(rng.random(n) < 0.1, np.nan, rng.normal(size=n)),
    }
    results = Results(columns, dict.fromkeys(columns, "mm"), META)
    tables.write_parquet(results, tmp_path / "whole.parquet")
    with tables.ParquetStream(tmp_path / "s.parquet", results.units, META, list(columns)) as out:
        for part in chunks(results, [101] * (n // 101) + [n % 101]):
            out.write(part)
    assert (tmp_path / "s.parquet").read_bytes() == (tmp_path / "whole.parquet").read_bytes()


@pytest.mark.parametrize("nan_null", [False, True])
def test_arrow_arrays_from_numpys_buffers_are_pyarrows_own(nan_null):
    # the compiled style's arrays are built on numpy's buffers (no Python conversion:
    # pyarrow's imports pandas); each equals pyarrow's own conversion of the column
    import pyarrow as pa

    columns = edge_results(61).columns
    for name in ("edge", "any_bits", "undefined", "fixed_tiny", "solver_converged", "step_index"):
        for values in (columns[name], columns[name][1::3], columns[name][:0]):
            ours = tables._arrow_from_numpy(values, pa, nan_null=nan_null)
            theirs = pa.array(values, from_pandas=nan_null)
            assert ours.type == theirs.type and ours.null_count == theirs.null_count, name
            nulls = ours.is_null().to_pylist()
            assert nulls == theirs.is_null().to_pylist(), name
            a, b = (x.to_numpy(zero_copy_only=False) for x in (ours, theirs))
            if values.dtype.kind == "f":  # bit for bit (-0.0, NaN)
                assert same_bits(a, b), name
            else:
                assert ours.equals(theirs) and list(a) == list(values), name
    swapped = columns["any_bits"].astype(">f8")  # another byte order: the same values
    ours = tables._arrow_from_numpy(swapped, pa, nan_null=nan_null)
    assert same_bits(ours.to_numpy(zero_copy_only=False), columns["any_bits"])
    texts = [n for n in NAMES] + ["", "ü"]
    assert tables._text_array(texts, pa).to_pylist() == texts
    assert [s.as_py() for s in tables._texts(texts, pa)] == texts


def test_the_kernels_by_name_write_what_pyarrow_compute_writes(tmp_path, monkeypatch):
    # tables._Kernels calls pyarrow's kernels by name; pyarrow.compute's own functions
    # (its fallback) must give the same bytes on every kind of value
    import pyarrow.compute

    monkeypatch.setattr(tables, "FAST_CELLS", 0)
    results = edge_results()
    tables._compute()
    assert isinstance(tables._KERNELS[0], tables._Kernels)
    ours = tables.csv_text(results)
    monkeypatch.setattr(tables, "_KERNELS", [pyarrow.compute])
    assert tables.csv_text(results) == ours
    tables.write_csv(results, tmp_path / "out.csv")
    check_cells(results, tmp_path / "out.csv")


def test_the_repr_styles_cells_are_numpys_str_of_each_value():
    # a float64 cell is Python's repr; numpy's str (the style's text before) must agree
    # on every kind of value, every exponent among them; NaN an empty cell
    columns = edge_results(400, seed=1).columns
    for name in ("edge", "any_bits", "whole", "zeros", "fixed_tiny", "last", "undefined"):
        values = columns[name]
        expected = values.astype(str)
        expected[np.isnan(values)] = ""
        assert tables._column_cells(values) == expected.tolist(), name
    for name in ("step_index", "solver_iterations"):
        assert tables._column_cells(columns[name]) == columns[name].astype(str).tolist()
    single = np.array([0.1, 1e-05, np.nan], dtype=np.float32)  # its own shortest text
    assert tables._column_cells(single) == ["0.1", "1e-05", ""]
