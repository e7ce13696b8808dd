"""Help for the mistakes people make: each gets the stated message."""
import numpy as np
import pytest
from click.testing import CliRunner

from stablepush.task import parse_task
from stablepush_cli.main import cli

from conftest import task_text


def _write(tmp_path, text, name="mine.yaml"):
    path = tmp_path / name
    path.write_text(text)
    return path


def test_name_is_optional_and_defaults_to_the_file_stem(tmp_path):
    text = task_text("horizontal-offset-high-mu").replace("name: horizontal-offset-high-mu\n", "")
    path = _write(tmp_path, text, "my-part.yaml")
    result = CliRunner().invoke(cli, ["plan", str(path), "-o", str(tmp_path / "p.json")])
    assert result.exit_code == 0 and result.output.startswith("my-part: solved"), result.output
    assert parse_task(text).name == "task"


def test_a_task_written_in_metres_is_warned_about_and_refused_plainly(tmp_path):
    text = (task_text("horizontal-offset-low-mu").replace("size: [100, 25, 25]", "size: [0.1, 0.025, 0.025]")
            .replace("pads:\n    - {center: [0, 0], radius: 5}\n    - {center: [0, 0], radius: 5}",
                     "pads:\n    - {center: [0, 0], radius: 0.01}\n    - {center: [0, 0], radius: 0.01}")
            .replace("{name: left,   from: [-50, -12.5], to: [-50, 12.5], mu: 0.2}",
                     "{name: left,   from: [-0.05, -0.0125], to: [-0.05, 0.0125], mu: 0.2}")
            .replace("{name: right,  from: [50, -12.5],  to: [50, 12.5],  mu: 0.2}",
                     "{name: right,  from: [0.05, -0.0125],  to: [0.05, 0.0125],  mu: 0.2}")
            .replace("{name: bottom, from: [-10, -12.5], to: [10, -12.5], mu: 0.2}",
                     "{name: bottom, from: [-0.01, -0.0125], to: [0.01, -0.0125], mu: 0.2}")
            .replace("goal: [20, 0, 0]", "goal: [0.02, 0, 0]"))
    result = CliRunner().invoke(cli, ["plan", str(_write(tmp_path, text))])
    assert result.exit_code == 2
    lines = result.stderr.strip().splitlines()
    assert "warning:" in lines[0] and "object: 0.1 mm across; written in metres? Task files use mm" in lines[0]
    assert lines[-1].startswith("error:") and "already within planner.tolerance" in lines[-1]
    assert "nothing to plan" in lines[-1]


@pytest.mark.parametrize("old, new, says", [
    ("mass: 202 ", "mass: 202000 ", "object.mass: 202000 g (over 50 kg); task files use grams"),
    ("grip_force: 10 ", "grip_force: 1000 ", "gripper.grip_force: 1000 N per pad (over 500 N)"),
    ("mu: 0.425 ", "mu: 42.5 ", "gripper.mu: 42.5; a friction coefficient over 3 is unusual"),
    ("gravity: [0, -9.81]", "gravity: [0, -98.1]", "gravity: |g| = 98.1 m/s^2, neither 0"),
    # A mass written in kg (0.045 for a 45 g part) in the 62.5 cm^3 prism: 0.00072 g/cm^3.
    ("mass: 202 ", "mass: 0.045 ", "object.mass: 0.045 g in 62.5 cm^3 is 0.00072 g/cm^3, lighter than air; written in kg?"),
])
def test_implausible_magnitudes_are_warned_about_naming_the_field(old, new, says):
    text = task_text("horizontal-offset-low-mu")
    assert old in text
    task = parse_task(text.replace(old, new, 1))
    assert any(says in w for w in task.warnings), task.warnings
    assert parse_task(text).warnings == ()


def test_a_pusher_a_hair_off_its_edge_is_snapped_and_one_far_off_gets_its_true_distance():
    near = task_text("horizontal-offset-low-mu").replace("from: [-50, -12.5], to: [-50, 12.5]",
                                                         "from: [-49.99, -12.5], to: [-49.99, 12.5]")
    task = parse_task(near)
    assert task.pushers[0].a == (-50.0, -12.5) and task.pushers[0].b == (-50.0, 12.5)
    assert any("pushers[0]: 0.01 mm off the object's edge from [-50.0, -12.5] to [-50.0, 12.5] mm" in w
               or "pushers[0]: 0.01 mm off the object's edge from [-50.0, 12.5] to [-50.0, -12.5] mm" in w
               for w in task.warnings), task.warnings
    far = task_text("horizontal-offset-low-mu").replace("from: [-50, -12.5], to: [-50, 12.5]",
                                                        "from: [-40, -12.5], to: [-40, 12.5]")
    with pytest.raises(Exception, match="its farther end is 10 mm from the nearest edge"):
        parse_task(far)


def test_show_draws_an_unsolved_plan_marked_as_such_and_point_pushers(tmp_path):
    from matplotlib.text import Annotation

    from stablepush.plan import Plan, Waypoint
    from stablepush.viz import figures

    from conftest import TASKS, task_with

    task = TASKS / "horizontal-offset-low-mu.yaml"
    plan = tmp_path / "part.json"
    # Without a switch-over the goal is out of reach (the drag needs the lift first): never solved.
    args = ["plan", str(task), "--max-switches", "0", "--time-limit", "0.05", "-o", str(plan)]
    assert CliRunner().invoke(cli, args).exit_code == 1
    result = CliRunner().invoke(cli, ["show", str(plan), "--task", str(task), "-o", str(tmp_path / "p.png")])
    assert result.exit_code == 0 and (tmp_path / "p.png").stat().st_size > 0, result.output
    # A point pusher is a dot; the object's x axis an arrow (its orientation).
    pegs = task_with("horizontal-offset-low-mu", lambda d: d.update(
        gravity=[0, 0], pushers=[{"name": "tip", "at": [-50, 0], "mu": 0.6}]))
    partial = Plan(task=pegs.name, solved=False, outcome="time_limit", message="", stats={},
                   waypoints=[Waypoint(0, 0, 0), Waypoint(1, 0, 30, pusher="tip")])
    fig = figures.plan_figure(pegs, partial)
    first, last = fig.axes[0], fig.axes[1]
    assert any(line.get_marker() == "o" for line in first.get_lines())
    # The orientation arrow runs along O's x axis: from the pose's (x, z), turned by its theta.
    size = 0.3 * max(max(abs(v) for v in p) for p in pegs.vertices)
    for ax, (x, z, theta) in ((first, (0, 0, 0)), (last, (1, 0, 30))):
        arrows = [t for t in ax.texts if isinstance(t, Annotation) and t.arrow_patch is not None]
        assert len(arrows) == 1
        c, s = np.cos(np.radians(theta)), np.sin(np.radians(theta))
        assert np.allclose(arrows[0].xyann, (x, z)) and np.allclose(arrows[0].xy, (x + c * size, z - s * size))
    assert fig.axes[1].get_title().startswith("end")


def test_a_centre_of_mass_outside_the_outlines_hull_is_warned_about_naming_it():
    text = task_text("horizontal-offset-low-mu")
    outside = parse_task(text.replace("mass: 202 ", "com: [0, 100]\n  mass: 202 ", 1))
    assert [w for w in outside.warnings if w.startswith("object.com: [0.0, 100.0] mm lies 87.5 mm outside")]
    assert parse_task(text.replace("mass: 202 ", "com: [50, -12.5]\n  mass: 202 ", 1)).warnings == ()  # a corner
    # An L's centre of mass may lie off its outline, in the notch: inside the hull, no warning.
    ell = parse_task("object: {shape: polygon, mass: 50, com: [20, 20], polygon: [[0, 0], [40, 0], [40, 15], "
                     "[15, 15], [15, 40], [0, 40]]}\ngripper: {grip_force: 10, mu: 0.5}\n"
                     "pushers: [{name: left, from: [0, 30], to: [0, 40], mu: 0.5}]\nstart: [-7.5, -30, 0]\n"
                     "goal: [-7.5, -25, 0]\n")
    assert not [w for w in ell.warnings if "object.com" in w], ell.warnings
