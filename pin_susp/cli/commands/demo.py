"""`pin-susp demo`: the embedded example corner through a bump + steer sweep, its inputs,
results, report, drawing, 3D replay and URDF written into one folder."""

from __future__ import annotations

from ...errors import PinSuspError
from ..options import check_outputs, output_arguments, output_form
from ..report import Digest, progress_bar, report_failures, summary, warn_transmission

DESCRIPTION = (
    "Solve the embedded example corner (the test corner of open-kinematics "
    "0.4) through a combined bump+steer sweep and write into DIR: demo_geometry.yaml and "
    "demo_sweep.yaml (the inputs, to edit and rerun), demo_results.csv (every column), "
    "demo_report.png (the standard kinematics plots), demo_drawing.png (front and side "
    "view), demo_replay.html (the 3D replay, opens in a browser with no server) and "
    "demo_corner.urdf (the URDF with its loop closures)."
)


def arguments(parser) -> None:
    parser.add_argument(
        "-o",
        "--output",
        default="pin_susp_demo",
        metavar="DIR",
        help="output folder (default: ./pin_susp_demo)",
    )
    output_arguments(parser)


def run(args) -> int:
    import hashlib
    from dataclasses import replace
    from importlib import resources

    import yaml

    from ...io.atomic import all_or_none, check_folder, write_text
    from ...io.tables import csv_text
    from ...model.geometry import load_geometry
    from ...model.sweep import load_sweep
    from ...subjects.corner import Corner

    if str(args.output).strip() == "":
        raise PinSuspError(f"{args.output!r}: the demo writes several files: give a folder")
    out = check_folder(args.output)
    if out.exists() and not out.is_dir():
        raise PinSuspError(f"{args.output!r}: the demo writes several files: give a folder")
    data = resources.files("pin_susp") / "data"
    inputs = {name: (data / name).read_text() for name in ("demo_geometry.yaml", "demo_sweep.yaml")}
    geometry_path, sweep_path = out / "demo_geometry.yaml", out / "demo_sweep.yaml"
    files = {
        "results": out / "demo_results.csv",
        "plots": out / "demo_report.png",
        "drawing": out / "demo_drawing.png",
        "3D replay": out / "demo_replay.html",
        "URDF": out / "demo_corner.urdf",
    }
    check_outputs(args, geometry_path, sweep_path, *files.values())
    # read from the text, named as the copies written beside the results
    geometry, sweep = (
        replace(
            load(yaml.safe_load(inputs[path.name])),
            source=str(path),
            sha256=hashlib.sha256(inputs[path.name].encode()).hexdigest(),
        )
        for load, path in ((load_geometry, geometry_path), (load_sweep, sweep_path))
    )
    corner = Corner(geometry)
    results = corner.run_sweep(sweep, progress=progress_bar(sweep.steps, False))
    digest = Digest.of(results)
    warn_transmission(digest)
    with all_or_none():
        for name, text in inputs.items():
            write_text(text, out / name)
        write_text(corner.urdf, files["URDF"])
        text = csv_text(results)  # the report's: ISO, mm
        form = output_form(args)
        write_text(text if form.identity else csv_text(results, form), files["results"])
        _demo_pictures(corner, results, files, text)
    print(f"pin_susp demo: {corner.geometry.name}, {sweep.steps}-step bump + steer sweep")
    summary(digest, files["results"])
    for what, path in [("geometry", geometry_path), ("sweep", sweep_path), *files.items()]:
        print(f"  {what:<10} {path}")
    print(
        f"open {files['3D replay']} in a browser to see the corner move; "
        f"{files['plots']} has the standard plots"
    )
    return report_failures(digest)


def _demo_pictures(corner, results, files, csv: str) -> None:
    import contextlib
    import io

    from ...io.atomic import write_text
    from ...plots import ResultsFile, report_figure, save_figure
    from ...viz.drawing import drawing_figure
    from ...viz.scene import CornerScene

    written = ResultsFile(files["results"], raw=csv.encode())
    save_figure(report_figure([written]), files["plots"])
    save_figure(drawing_figure(corner), files["drawing"])
    with contextlib.redirect_stdout(io.StringIO()):  # meshcat announces its server
        scene = CornerScene(corner)
    try:
        scene.animate(list(results.meta["q"]))
        write_text(scene.html(), files["3D replay"])
    finally:
        scene.close()
