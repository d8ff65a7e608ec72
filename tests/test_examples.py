"""The example scripts run as they are."""

import subprocess
import sys

from conftest import EXAMPLES


def test_quickstart_runs(tmp_path):
    proc = subprocess.run(
        [sys.executable, str(EXAMPLES / "quickstart.py")],
        cwd=tmp_path,
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert proc.returncode == 0, proc.stderr
    assert "sweep of 41 steps" in proc.stdout
    assert (tmp_path / "quickstart_results.csv").exists()
    assert (tmp_path / "quickstart_report.png").read_bytes().startswith(b"\x89PNG")
    assert "<Corner 'double_wishbone.yaml'" in proc.stdout
    assert "lower ball joint [  0. 900. 200.] mm" in proc.stdout
    assert "<AxleResults 'roll.yaml' on 'axle_front.yaml': 31 steps, 31 converged" in proc.stdout
