"""One subject (issue 25, 1): code outside the subjects' own modules never asks which
kind of subject it holds — a corner, an axle — but uses what both answer alike.

A ratchet, read from the source with ``ast``: every place a module outside
``SUBJECTS`` asks the kind, by file, must equal ``KIND_TESTS`` (today's). A new one
fails; one removed must leave the list too. The ways of asking:

- ``isinstance(x, C)`` with C a subject's class or its data's (Corner, AxleModel,
  Geometry, AxleGeometry, Results, AxleResults);
- ``hasattr``/``getattr`` of an attribute only one kind has (``geometries``,
  ``geometry``, ``axle``);
- a column only one kind's results have, tested for (``"camber_left" in columns``);
- the geometry file's ``scope`` compared (``data.get("scope") == "axle"``), or any
  value compared to ``"axle"`` or ``"corner"``;
- an axle's elements tested for (``model.axle is None``, ``axle is not None``);
- a call of ``is_axle``, ``is_axle_file`` or ``is_axle_data`` (or a definition of
  ``is_axle``);
- the number of a subject's corners compared (``len(subject.labels) > 1``): a twin
  still chosen by kind, only spelt through the labels.

``python tests/test_one_subject.py`` prints every place.
"""

from __future__ import annotations

import ast
import sys
from collections import Counter
from pathlib import Path

PACKAGE = Path(__file__).resolve().parents[1] / "pin_susp"

# The subjects' own modules: where the kinds are told apart, once.
SUBJECTS = (
    "subjects/corner.py",
    "subjects/axle.py",
    "subjects/axle_file.py",
    "subjects/vehicle_file.py",
    "subjects/subject.py",
)

KINDS = {"Corner", "AxleModel", "Geometry", "AxleGeometry", "Results", "AxleResults"}
ONE_KIND_ATTRIBUTES = {"geometries", "geometry", "axle"}
KIND_WORDS = {"axle", "corner"}

# Today's places, by file (below pin_susp/): a ratchet that only goes down.
KIND_TESTS: dict[str, int] = {}


def _names(node: ast.AST) -> set[str]:
    """The class names an isinstance's second argument gives (a tuple, a union)."""
    found = set()
    for n in ast.walk(node):
        if isinstance(n, ast.Name):
            found.add(n.id)
        elif isinstance(n, ast.Attribute):
            found.add(n.attr)
    return found


def _called(node: ast.Call) -> str | None:
    f = node.func
    return f.id if isinstance(f, ast.Name) else f.attr if isinstance(f, ast.Attribute) else None


def _is_scope(node: ast.AST) -> bool:
    """``x.get("scope")`` or ``x["scope"]``."""
    if isinstance(node, ast.Call) and _called(node) == "get" and node.args:
        a = node.args[0]
        return isinstance(a, ast.Constant) and a.value == "scope"
    if isinstance(node, ast.Subscript):
        s = node.slice
        return isinstance(s, ast.Constant) and s.value == "scope"
    return False


def _is_axle_elements(node: ast.AST) -> bool:
    """``axle`` or ``something.axle``: an axle's elements (None for two bare corners)."""
    return (isinstance(node, ast.Name) and node.id == "axle") or (
        isinstance(node, ast.Attribute) and node.attr == "axle"
    )


def _is_label_count(node: ast.AST) -> bool:
    """``len(x.labels)``."""
    return (
        isinstance(node, ast.Call)
        and _called(node) == "len"
        and len(node.args) == 1
        and isinstance(node.args[0], ast.Attribute)
        and node.args[0].attr == "labels"
    )


def kind_tests_in(tree: ast.AST) -> list[tuple[int, str]]:
    """(line, what) for every place the source asks which kind a subject is."""
    found = []
    for node in ast.walk(tree):
        if isinstance(node, ast.FunctionDef) and node.name == "is_axle":
            found.append((node.lineno, "def is_axle"))
        elif isinstance(node, ast.Call):
            name = _called(node)
            if name == "isinstance" and len(node.args) == 2 and _names(node.args[1]) & KINDS:
                found.append((node.lineno, f"isinstance(…, {ast.unparse(node.args[1])})"))
            elif name in ("hasattr", "getattr") and len(node.args) >= 2:
                a = node.args[1]
                if isinstance(a, ast.Constant) and a.value in ONE_KIND_ATTRIBUTES:
                    found.append((node.lineno, f"{name}(…, {a.value!r})"))
            elif name in ("is_axle", "is_axle_file", "is_axle_data"):
                found.append((node.lineno, f"{name}(…)"))
        elif isinstance(node, ast.Compare):
            sides = [node.left, *node.comparators]
            ops = node.ops
            if any(isinstance(op, (ast.In, ast.NotIn)) for op in ops):
                left = node.left
                if (
                    isinstance(left, ast.Constant)
                    and isinstance(left.value, str)
                    and left.value.endswith(("_left", "_right"))
                ):
                    found.append((node.lineno, f"{left.value!r} in …"))
                    continue
            if any(isinstance(op, (ast.Eq, ast.NotEq)) for op in ops):
                if any(_is_scope(s) for s in sides):
                    found.append((node.lineno, "scope =="))
                    continue
                if any(isinstance(s, ast.Constant) and s.value in KIND_WORDS for s in sides):
                    found.append((node.lineno, "== 'axle'/'corner'"))
                    continue
            if any(isinstance(op, (ast.Is, ast.IsNot)) for op in ops):
                if _is_axle_elements(node.left) and any(
                    isinstance(s, ast.Constant) and s.value is None for s in node.comparators
                ):
                    found.append((node.lineno, f"{ast.unparse(node)}"))
                    continue
            if any(_is_label_count(s) for s in sides):
                found.append((node.lineno, f"{ast.unparse(node)}"))
    return sorted(found)


def places() -> dict[str, list[tuple[int, str]]]:
    """Every place outside the subjects' modules, by file below pin_susp/."""
    out = {}
    for path in sorted(PACKAGE.rglob("*.py")):
        name = str(path.relative_to(PACKAGE))
        if name in SUBJECTS:
            continue
        found = kind_tests_in(ast.parse(path.read_text(encoding="utf-8")))
        if found:
            out[name] = found
    return out


def test_no_new_place_asks_which_kind_of_subject():
    found = Counter({name: len(lines) for name, lines in places().items()})
    grown = {n: (c, KIND_TESTS.get(n, 0)) for n, c in found.items() if c > KIND_TESTS.get(n, 0)}
    shrunk = {n: (found.get(n, 0), c) for n, c in KIND_TESTS.items() if found.get(n, 0) < c}
    assert not grown, (
        "a new place asks which kind of subject it holds (file: found, declared): give "
        f"both subjects what it needs instead (pin_susp/subject.py): {grown}\n"
        + "\n".join(f"  {n}:{line} {what}" for n in grown for line, what in places()[n])
    )
    assert not shrunk, (
        "fewer places ask the kind than KIND_TESTS declares (file: found, declared): "
        f"lower its count in tests/test_one_subject.py: {shrunk}"
    )


def test_the_walk_sees_every_way_of_asking():
    source = """
def is_axle(path): ...
a = isinstance(m, AxleModel)
b = isinstance(m, (Corner, int))
c = isinstance(m, axle.AxleGeometry | None)
d = hasattr(m, "geometries")
e = getattr(m, "axle", None)
f = "camber_left" in results.columns
g = data.get("scope") == "axle"
h = data["scope"] != "corner"
i = kind == "axle"
j = model.axle is not None
k = axle is None
l = is_axle_file(path)
m = len(subject.labels) > 1
# none of these
n = isinstance(m, dict)
o = hasattr(m, "labels")
p = "camber" in results.columns
q = data.get("version") == 1
r = model.tree is None
s = len(labels) > 1
"""
    found = kind_tests_in(ast.parse(source))
    assert [line for line, _ in found] == list(range(2, 16)), found


def test_both_subjects_answer_what_the_consumers_ask():
    """What a command asks instead of the kind: the blocks a per-corner input is in
    (loads' cases) and the columns a sweep's summary shows."""
    from pin_susp.subjects.subject import load_subject

    examples = PACKAGE.parent / "examples"
    corner = load_subject(examples / "double_wishbone.yaml")
    axle = load_subject(examples / "axle_front.yaml")
    assert corner.blocks == () and axle.blocks == ("left", "right")
    assert corner.summary_columns is None  # every metric column
    sided = [c for c in axle.summary_columns if c.endswith(tuple(map(axle.suffix, axle.labels)))]
    assert sided and len(sided) == len(set(sided))


def test_validate_sees_one_scope_of_either_subject():
    """What validate asks instead of the kind: one Scope over the labelled corners (the
    drivers: each hub z, the rack), each corner's columns from points a Dual per label
    (an axle's own added), and the engines' points in the form the subject's motion has."""
    import numpy as np

    from pin_susp.subjects.subject import load_subject
    from pin_susp.validate import Scope, scope_of

    examples = PACKAGE.parent / "examples"
    corner = load_subject(examples / "double_wishbone.yaml")
    axle = load_subject(examples / "axle_front.yaml")
    for subject, drivers in ((corner, 2), (axle, 3)):
        scope = scope_of(subject)
        assert type(scope) is Scope and scope.drivers == drivers
        by_label = subject.label_motion([subject.q_design])
        columns = subject.metric_columns_of(by_label)
        assert {f"camber{subject.suffix(label)}" for label in subject.labels} <= set(columns)
    assert "roll_center_z" in axle.metric_columns_of(axle.label_motion([axle.q_design]))
    own = corner.motion([corner.q_design])
    as_motion = corner.motion_points(corner.label_motion([corner.q_design]))
    assert own.keys() == as_motion.keys()
    assert all(np.array_equal(own[n].val, as_motion[n].val) for n in own)
    assert corner.noun == "corner" and axle.noun == "axle"


def test_a_study_asks_the_subject_not_its_kind():
    """What a study asks instead of the kind: the subject of the file's data built
    (subject.kind_of), the data a variant's points move in (an axle's mirrored right side
    written out), whether its sensitivities hold a sweep, each step's held targets."""
    import yaml

    from pin_susp.model.sweep import load_sweep
    from pin_susp.subjects.subject import kind_of

    examples = PACKAGE.parent / "examples"
    bump = load_sweep(examples / "bump_steer.yaml")
    for name, labels in (("double_wishbone.yaml", ("",)), ("axle_front.yaml", ("left", "right"))):
        data = yaml.safe_load((examples / name).read_text())
        kind = kind_of(data)
        subject = kind.build(data, name, variant=True)
        assert subject.labels == labels
        moved = kind.variant_data(data)
        assert moved is not data and moved["hardpoints"] is not data["hardpoints"]
        if subject.blocks:  # a mirrored axle: its right side's points written out
            assert "right" not in data["hardpoints"]
            assert all(moved["hardpoints"][label] for label in subject.blocks)
        else:
            assert moved == data
        if not subject.blocks:
            assert subject.sensitivities_hold(bump) and subject.held_at(bump, 0)
        else:
            assert not subject.sensitivities_hold(bump) and subject.held_at(bump, 0) is None


if __name__ == "__main__":
    for name, lines in places().items():
        print(f"{name}: {len(lines)}")
        for line, what in lines:
            print(f"    {line}: {what}")
    print(f"total: {sum(len(v) for v in places().values())}")
    sys.exit(0)
