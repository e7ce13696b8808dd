"""Every bad task is refused through the CLI with exit status 2 and one message naming the field."""
import subprocess
import sys

import pytest
import yaml
from click.testing import CliRunner

from stablepush.errors import TaskError
from stablepush_cli.main import cli

from conftest import TASKS, task_text, task_with

BASE = yaml.safe_load(task_text("horizontal-offset-low-mu"))


def edited(edit):
    data = yaml.safe_load(task_text("horizontal-offset-low-mu"))
    edit(data)
    return yaml.safe_dump(data)


def run_check(tmp_path, text):
    path = tmp_path / "task.yaml"
    path.write_text(text)
    result = CliRunner().invoke(cli, ["check", str(path), "--move", "1", "0", "0"])
    return result


def _set(path, value):
    def edit(d):
        *parents, last = path
        for key in parents:
            d = d[key]
        d[last] = value

    return edit


def _delete(path):
    def edit(d):
        *parents, last = path
        for key in parents:
            d = d[key]
        del d[last]

    return edit


BAD = [
    ("missing key", _delete(["object", "mass"]), "object.mass", "missing"),
    ("missing top key", _delete(["goal"]), "goal", "missing"),
    ("unknown key", _set(["object", "colour"], "red"), "object.colour", "unknown key"),
    ("unknown top key", _set(["speed"], 3), "speed", "unknown key"),
    ("wrong type", _set(["gripper", "grip_force"], "strong"), "gripper.grip_force", "must be a number"),
    ("bool as number", _set(["object", "mass"], True), "object.mass", "must be a number"),
    ("wrong length", _set(["start"], [0, 0]), "start", "list of 3"),
    ("negative mass", _set(["object", "mass"], -1), "object.mass", "between 0.001 and 1e+07, got -1"),
    ("zero mass", _set(["object", "mass"], 0), "object.mass", "between 0.001 and 1e+07, got 0"),
    ("zero grip force", _set(["gripper", "grip_force"], 0), "gripper.grip_force", "between 1e-06 and 100000, got 0"),
    ("zero size", _set(["object", "size"], [100, 0, 25]), "object.size[1]", "between 0.01 and 10000, got 0"),
    ("negative pad mu", _set(["gripper", "mu"], -0.1), "gripper.mu", "between 0 and 100, got -0.1"),
    ("negative pusher mu", lambda d: d["pushers"][1].update(mu=-0.5), "pushers[1].mu", "between 0 and 100, got -0.5"),
    ("unknown shape", _set(["object", "shape"], "sphere"), "object.shape", "box, polygon or mesh"),
    ("duplicate pusher", lambda d: d["pushers"][1].update(name="left"), "pushers[1].name", "duplicate"),
    (
        "pusher off boundary",
        lambda d: d["pushers"][0].update({"from": [-40, -12.5], "to": [-40, 12.5]}),
        "pushers[0]",
        "not on the object's boundary",
    ),
    (
        "point pusher on vertex",
        lambda d: d["pushers"].append({"name": "corner", "at": [50, 12.5], "mu": 0.3}),
        "pushers[3]",
        "vertex",
    ),
    ("pad outside at start", _set(["start"], [0, 10, 0]), "start", "does not lie inside"),
    ("pad outside at goal", _set(["goal"], [60, 0, 0]), "goal", "does not lie inside"),
    (
        "bad pad radius",
        _set(["gripper", "pads"], [{"center": [0, 0], "radius": -5}]),
        "gripper.pads[0].radius",
        "between 0.01 and 10000, got -5",
    ),
    (
        "pad radius in metres",
        _set(["gripper", "pads"], [{"center": [0, 0], "radius": 0.006}]),
        "gripper.pads[0].radius",
        "between 0.01 and 10000, got 0.006; written in metres? task files use mm (0.006 m is 6 mm)",
    ),
    ("size in metres", _set(["object", "size"], [0.1, 0.025, 0.005]), "object.size[2]",
     "got 0.005; written in metres? task files use mm (0.005 m is 5 mm)"),
    ("retract in metres", _set(["environment"], {"retract": 0.005}), "environment.retract",
     "got 0.005; written in metres? task files use mm (0.005 m is 5 mm)"),
    (
        "negative step time",
        _set(["dynamics", "step_time"], -0.1),
        "dynamics.step_time",
        "between 0.0001 and 1000, got -0.1",
    ),
    ("planner unknown", _set(["planner", "speed"], 1), "planner.speed", "unknown key"),
    ("planner seed", _set(["planner", "seed"], -3), "planner.seed", "an integer from 0 to 4294967295, got -3"),
    (
        "self-intersecting polygon",
        lambda d: d.update(
            object={"shape": "polygon", "polygon": [[-50, -12.5], [50, 12.5], [50, -12.5], [-50, 12.5]], "mass": 100}
        ),
        "object.polygon",
        "self-intersecting",
    ),
    (
        "degenerate polygon",
        lambda d: d.update(object={"shape": "polygon", "polygon": [[-50, 0], [0, 0], [50, 0]], "mass": 100}),
        "object.polygon",
        "degenerate",
    ),
    (
        "repeated vertex",
        lambda d: d.update(
            object={"shape": "polygon", "polygon": [[-50, -12.5], [-50, -12.5], [50, -12.5], [50, 12.5]], "mass": 100}
        ),
        "object.polygon",
        "coincide",
    ),
]


@pytest.mark.parametrize("label,edit,field,reason", BAD, ids=[b[0] for b in BAD])
def test_bad_task_is_refused_naming_the_field(tmp_path, label, edit, field, reason):
    result = run_check(tmp_path, edited(edit))
    assert result.exit_code == 2, result.output
    message = result.stderr.strip()
    assert message.count("\n") == 0, message
    assert f"{field}:" in message and reason in message, message
    assert "Traceback" not in result.output
    if reason == "unknown key":
        allowed = message.split("allowed here: ", 1)[1].rstrip(")").split(", ")
        assert len(allowed) == len(set(allowed)), message


@pytest.mark.parametrize(
    "text,reason",
    [
        ("name: x\nname: y\n", "duplicate key"),
        ("object: [unclosed\n", "not valid YAML (expected ',' or ']', but got '<stream end>' at line 2, column 1)"),
        ("", "empty"),
        ("- just\n- a list\n", "must be a mapping"),
        (task_text("t-shaped") + "environment:\n", "environment: must be a mapping, got null"),
        (task_text("horizontal-offset-low-mu").replace("mass: 202", "mass: .nan"), "finite"),
        (task_text("horizontal-offset-low-mu").replace("mass: 202", "mass: .inf"), "finite"),
    ],
)
def test_bad_yaml_is_refused(tmp_path, text, reason):
    result = run_check(tmp_path, text)
    assert result.exit_code == 2 and reason in result.stderr, result.stderr


def test_unreadable_file_is_refused(tmp_path):
    result = CliRunner().invoke(cli, ["check", str(tmp_path / "missing.yaml"), "--move", "1", "0", "0"])
    assert result.exit_code == 2 and "cannot read the task file (No such file or directory)" in result.stderr
    assert "Errno" not in result.stderr and "FileNotFoundError" not in result.stderr


def test_no_traceback_from_the_installed_command(tmp_path):
    path = tmp_path / "bad.yaml"
    path.write_text(edited(_set(["object", "mass"], -1)))
    proc = subprocess.run([sys.executable, "-m", "stablepush_cli.main", "check", str(path), "--move", "1", "0", "0"],
                          capture_output=True, text=True)
    assert proc.returncode == 2 and "Traceback" not in proc.stderr and "object.mass" in proc.stderr


def test_check_json_output_keys():
    import json

    result = CliRunner().invoke(cli, ["check", str(TASKS / "pivoting.yaml"), "--move", "0", "0", "1", "--json"])
    assert result.exit_code == 0, result.output
    data = json.loads(result.stdout)
    assert set(data) == {"left", "right", "bottom"}
    for entry in data.values():
        assert {"feasible", "case", "margin"} <= set(entry)
        assert entry["case"] == "sticking"
    assert data["left"]["feasible"] is True


def test_check_one_pusher_and_unknown_pusher():
    ok = CliRunner().invoke(cli, ["check", str(TASKS / "horizontal-offset-high-mu.yaml"), "--move", "1", "0", "0", "--pusher", "left"])
    assert ok.exit_code == 0 and ok.stdout.startswith("left") and "stable" in ok.stdout
    bad = CliRunner().invoke(cli, ["check", str(TASKS / "horizontal-offset-high-mu.yaml"), "--move", "1", "0", "0", "--pusher", "nope"])
    assert bad.exit_code == 2 and "no pusher named 'nope'" in bad.stderr


def test_every_shipped_task_loads(tasks_dir):
    from stablepush.task import load_task

    names = sorted(p.stem for p in tasks_dir.glob("*.yaml"))
    assert names == ["horizontal-offset-high-mu", "horizontal-offset-low-mu", "large-manipulation", "pivoting", "t-shaped"]
    for name in names:
        task = load_task(tasks_dir / f"{name}.yaml")
        assert task.model.grasp_maintained((0, 0, 0))


def test_too_many_pushers_is_refused():
    def many(d):
        d["pushers"] = [{"name": f"p{i}", "from": [-50, -12.5], "to": [-50, 12.5], "mu": 0.2} for i in range(33)]

    with pytest.raises(TaskError) as err:
        task_with("horizontal-offset-low-mu", many)
    assert err.value.field == "pushers" and "at most 32" in err.value.reason


STRAIGHT_VERTICES = """
name: straight
object:
  shape: polygon
  polygon: [[-30, -10], [0, -10], [30, -10], [30, 10], [0, 25], [-30, 10], [-30, 0]]
  mass: 50
gripper: {grip_force: 10, mu: 0.5}
gravity: [0, -9.81]
pushers:
  - {name: bottom, from: [-20, -10], to: [20, -10], mu: 0.5}
  - {name: pin, at: [0, -10], mu: 0.5}
  - {name: side, at: [-30, 0], mu: 0.5}
start: [0, 0, 0]
goal: [0, 3, 0]
"""


def test_a_polygons_straight_vertices_are_no_corners():
    """(0, -10) and (-30, 0) lie on straight edges of the outline, as CAD outlines have them: a
    segment pusher across one and point pushers at them were refused as off the boundary or 'on a
    vertex, where its normal is ambiguous'."""
    from stablepush.task import parse_task
    from stablepush.task.parts import outline_corners

    task = parse_task(STRAIGHT_VERTICES)
    assert len(task.object.vertices) == 7  # as written: plans of the task keep its identity
    assert outline_corners(task.object.vertices) == ((-30, -10), (30, -10), (30, 10), (0, 25), (-30, 10))
    normals = [tuple(round(c, 12) for c in p.inward_normal) for p in task.model.pushers]
    assert normals == [(0.0, 1.0), (0.0, 1.0), (1.0, 0.0)]
    corner = STRAIGHT_VERTICES.replace("{name: side, at: [-30, 0], mu: 0.5}", "{name: side, at: [30, 10], mu: 0.5}")
    with pytest.raises(TaskError, match="sits on a vertex of the object"):
        parse_task(corner)


def test_straight_vertices_are_dropped_only_within_the_tolerance_of_the_edge_they_make():
    """Each vertex of the run must lie within 1e-6 mm of the segment between the run's corners, not
    only of its neighbours': a bottom edge bowed by 4.5e-4 mm over 946 vertices 0.1 mm apart is no
    straight edge, though each vertex is straight between its neighbours; nor is a fold back."""
    from stablepush.task.parts import ON_BOUNDARY, outline_corners

    bowed = [(0.1 * i, -2e-7 * (0.1 * i) ** 2) for i in range(946)] + [(94.5, 10.0), (0.0, 10.0)]
    kept = outline_corners(bowed)
    dropped = set(bowed) - set(kept)
    for v in dropped:  # every dropped vertex lies on the outline that is left, to ON_BOUNDARY
        assert min(_distance_to_segment(v, a, b) for a, b in zip(kept, kept[1:] + kept[:1])) <= ON_BOUNDARY
    assert outline_corners([(0, 0), (8, 0), (2, 0), (10, 0), (10, 5), (0, 5)]) == (
        (0, 0), (8, 0), (2, 0), (10, 0), (10, 5), (0, 5))


def _distance_to_segment(p, a, b):
    import math

    dx, dz = b[0] - a[0], b[1] - a[1]
    t = max(0.0, min(1.0, ((p[0] - a[0]) * dx + (p[1] - a[1]) * dz) / (dx * dx + dz * dz)))
    return math.hypot(p[0] - a[0] - t * dx, p[1] - a[1] - t * dz)
