"""`-o OUT.parquet` writes the results as Parquet: the CSV's columns and values, blanks as
nulls, the units and sources in the schema's metadata."""

import json

import numpy as np
import pandas as pd
import pyarrow.parquet as pq
from conftest import EXAMPLES

from pin_susp.cli import main


def test_sweep_to_parquet_holds_the_csvs_values(tmp_path, capsys):
    geometry, sweep = EXAMPLES / "double_wishbone.yaml", EXAMPLES / "bump_steer.yaml"
    assert main(["sweep", str(geometry), str(sweep), "-o", str(tmp_path / "r.csv"), "-q"]) == 0
    assert main(["sweep", str(geometry), str(sweep), "-o", str(tmp_path / "r.parquet"), "-q"]) == 0
    csv = pd.read_csv(tmp_path / "r.csv", comment="#")
    table = pq.read_table(tmp_path / "r.parquet")
    frame = table.to_pandas()
    assert list(frame.columns) == list(csv.columns) and len(frame) == 41
    for name in csv.columns:  # the CSV's text round-trips to the same float64
        a, b = csv[name].to_numpy(), frame[name].to_numpy()
        if a.dtype.kind == "f":
            assert np.array_equal(a, b.astype(float), equal_nan=True), name
        else:
            assert (a == b).all(), name
    assert table.column("anti_dive").null_count == 41  # blank in the CSV
    meta = table.schema.metadata
    assert json.loads(meta[b"units"])["camber"] == "deg"
    assert json.loads(meta[b"geometry"])["source"] == str(geometry)
    assert not list(tmp_path.glob(".*"))  # no temporary file left


def test_loads_to_parquet(tmp_path):
    out = tmp_path / "forces.parquet"
    code = main(
        [
            "loads",
            str(EXAMPLES / "pushrod_rocker.yaml"),
            str(EXAMPLES / "bump_steer.yaml"),
            "--cases",
            str(EXAMPLES / "loads.yaml"),
            "-o",
            str(out),
            "-q",
        ]
    )
    assert code == 0
    frame = pd.read_parquet(out)
    assert len(frame) > 0 and "step_index" in frame.columns
