"""Help for the mistakes people make: each gets the stated message."""
import numpy as np
import pytest
from click.testing import CliRunner

from stablepush.errors import TaskError
from stablepush.task import parse_task
from stablepush_cli.main import cli

from conftest import ROOT, TASKS, shipped, task_text


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
    import dataclasses

    from matplotlib.text import Annotation

    from stablepush.plan import plan_task
    from stablepush.viz import figures

    from conftest import TASKS, task_with

    task = TASKS / "horizontal-offset-low-mu.yaml"
    plan = tmp_path / "part.json"
    # Without a switch-over the goal is out of reach (the drag needs the lift first): never solved.
    args = ["plan", str(task), "--max-switches", "0", "--time-limit", "0.05", "-o", str(plan)]
    assert CliRunner().invoke(cli, args).exit_code == 1
    result = CliRunner().invoke(cli, ["show", str(plan), "--task", str(task), "-o", str(tmp_path / "p.png")])
    assert result.exit_code == 0 and (tmp_path / "p.png").stat().st_size > 0, result.output
    # A point pusher is a dot; the object's x axis an arrow (its orientation). The partial plan is
    # a real plan's first pushes: plan_figure draws only a plan of the task (check_plan).
    pegs = task_with("horizontal-offset-low-mu", lambda d: d.update(
        gravity=[0, 0], pushers=[{"name": "tip", "at": [-50, 0], "mu": 0.6}], goal=[3, 0, 10]))
    solved = plan_task(pegs)
    partial = dataclasses.replace(solved, solved=False, outcome="time_limit", waypoints=solved.waypoints[:8])
    end = partial.waypoints[-1].pose
    assert abs(end[2]) > 5  # turned enough for the arrow's direction to tell
    fig = figures.plan_figure(pegs, partial)
    snapshots = [ax for ax in fig.axes if ax.get_title()]
    first, last = snapshots[0], snapshots[-1]
    assert any(line.get_marker() == "o" for line in first.get_lines())
    # The orientation arrow runs along O's x axis: from the pose's (x, z), turned by its theta.
    size = 0.3 * max(max(abs(v) for v in p) for p in pegs.object.vertices)
    for ax, (x, z, theta) in ((first, (0, 0, 0)), (last, end)):
        arrows = [t for t in ax.texts if isinstance(t, Annotation) and t.arrow_patch is not None]
        assert len(arrows) == 1
        c, s = np.cos(np.radians(theta)), np.sin(np.radians(theta))
        assert np.allclose(arrows[0].xyann, (x, z)) and np.allclose(arrows[0].xy, (x + c * size, z - s * size))
    assert last.get_title().startswith("end")


def test_a_goal_the_pads_cannot_hold_is_told_at_load_with_what_to_change():
    """At the high-mu offset's goal the pads hold 0.91 times the weight whichever pusher pushes
    last: released there, it moves. Its shipped task ends the run on the feature, so no warning."""
    assert not any("hold" in w for w in shipped("horizontal-offset-high-mu").warnings)
    released = parse_task(task_text("horizontal-offset-high-mu").replace("end_on_feature: true", "end_on_feature: false"))
    (warning,) = [w for w in released.warnings if w.startswith("goal:")]
    assert "the pads alone hold only 0.91 times the object's weight at the goal" in warning
    # 11.1 N holds the weight at the goal; 14.8 N holds it through the release (the arm's
    # acceleration as it backs off, anywhere within the tolerance: task/release.py).
    assert "moved_on_release" in warning and "gripper.grip_force 14.8 N or more" in warning
    assert "environment.end_on_feature: true" in warning
    # Gripped 14.8 N, they hold it (hold_ratio is linear in the grip force): no warning.
    firm = parse_task(task_text("horizontal-offset-high-mu").replace("end_on_feature: true", "end_on_feature: false")
                      .replace("grip_force: 10 ", "grip_force: 14.8 "))
    assert min(firm.goal_hold_ratios().values()) >= 1.0 and not any(w.startswith("goal:") for w in firm.warnings)
    # The bottom feature turned 90 deg in the world: with its gravity the pads hold the goal (4.29
    # times the weight), with the side pushers' not; min_hold_ratio: 1 is the cure, and once given,
    # nothing is left to say.
    turned_text = task_text("horizontal-offset-high-mu").replace(
        "end_on_feature: true", "end_on_feature: false") + "  features:\n    bottom: [400, 150, 300, 90]\n"
    turned = parse_task(turned_text)
    assert turned.goal_hold_ratios()["bottom"] > 4.0 and turned.goal_hold_ratios()["left"] < 1.0
    (warning,) = [w for w in turned.warnings if w.startswith("goal:")]
    assert warning.startswith("goal: the pads alone hold the object at the goal only when the last push is by bottom")
    assert "a plan that ends with left, right" in warning and "planner.min_hold_ratio: 1" in warning
    asked = parse_task(turned_text.replace("tolerance: [0.5, 0.5]", "tolerance: [0.5, 0.5]\n  min_hold_ratio: 1"))
    assert not any(w.startswith("goal:") for w in asked.warnings)
    # Pads without friction hold nothing, and no grip force helps (the fuzz campaign's mu 0).
    frictionless = parse_task(task_text("horizontal-offset-high-mu").replace("end_on_feature: true", "end_on_feature: false")
                              .replace("mu: 0.425", "mu: 0"))
    assert any("no grip force does: the pads hold nothing with gripper.mu 0" in w for w in frictionless.warnings)
    with pytest.raises(TaskError, match="environment.end_on_feature: must be true or false"):
        parse_task(task_text("horizontal-offset-high-mu").replace("end_on_feature: true", "end_on_feature: 1"))


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


@pytest.mark.parametrize("old, new, says", [
    ("goal: [20, 0, 0]", "goal: [20, 0, 0.26]", "goal[2]: 0.26 deg; written in radians? (0.26 rad is 14.9 deg; task "
                                                "files use degrees)"),
    ("start: [0, 0, 0]", "start: [0, 0, 1.5708]", "start[2]: 1.5708 deg; written in radians? (1.5708 rad is 90 deg"),
    # 0.4 rad is no round angle, but 0.4 deg is within the task's 0.5 deg tolerance of no turn at all
    ("goal: [20, 0, 0]", "goal: [20, 0, -0.4]", "goal[2]: -0.4 deg; written in radians? (-0.4 rad is -22.9 deg"),
])
def test_an_angle_written_in_radians_is_warned_about_naming_the_field(old, new, says):
    text = task_text("horizontal-offset-low-mu")
    assert old in text
    warnings = parse_task(text.replace(old, new, 1)).warnings
    assert [w for w in warnings if says in w], warnings


@pytest.mark.parametrize("theta", [0, 1, 2.5, 0.75, -1.5, 7.5, 15, -20, 360])
def test_an_angle_meant_in_degrees_is_not_taken_for_radians(theta):
    """Whole degrees, angles past 2 pi, and fractions that are no round angle in radians and lie beyond
    the tolerance (0.75 rad is 43 deg; 2.5 rad 143 deg; 1.5 rad 86 deg)."""
    text = task_text("horizontal-offset-low-mu").replace("goal: [20, 0, 0]", f"goal: [20, 0, {theta}]", 1)
    assert not [w for w in parse_task(text).warnings if "radians" in w]


def test_lengths_in_metres_are_named_where_accepted_and_where_refused():
    from stablepush.errors import TaskError

    from conftest import task_with

    def in_metres(d):
        d["gripper"]["pads"][0]["radius"] = 0.05
        d["environment"] = {**d.get("environment", {}), "retract": 0.02, "home": [0.45, 0, 0.3],
                            "features": {"left": [0.4, 0, 0.3, 0]}}

    warnings = task_with("horizontal-offset-low-mu", in_metres).warnings
    text = task_text("horizontal-offset-low-mu")
    for says in ["gripper.pads[0].radius: 0.05 mm; written in metres? task files use mm (0.05 m is 50 mm)",
                 "environment.retract: 0.02 mm; written in metres? task files use mm (0.02 m is 20 mm)",
                 "environment.home: [0.45, 0, 0.3] mm; written in metres? task files use mm ([0.45, 0, 0.3] m is "
                 "[450, 0, 300] mm)",
                 "environment.features.left: [0.4, 0, 0.3] mm; written in metres? task files use mm ([0.4, 0, 0.3] m "
                 "is [400, 0, 300] mm)"]:
        assert says in warnings, warnings
    assert not [w for w in parse_task(text).warnings if "metres" in w]
    with pytest.raises(TaskError) as error:  # a pusher in metres on an object in mm is far off its edge
        parse_task(text.replace("from: [-50, -12.5], to: [-50, 12.5]", "from: [-0.05, -0.0125], to: [-0.05, 0.0125]"))
    assert error.value.field == "pushers[0]"
    assert error.value.reason.endswith("; written in metres? task files use mm ([[-0.05, -0.0125], [-0.05, 0.0125]] "
                                       "m is [[-50, -12.5], [-50, 12.5]] mm)"), error.value.reason


def test_a_robots_tcp_or_base_in_metres_and_radians_is_refused_naming_the_option_or_field(tmp_path):
    """A user's UR-style TCP, 0.15 m out and pitched -pi/2, written as in their URDF: taken in mm and
    deg it put G 0.15 mm from the flange, and the cell check refused the plan for a link in the
    floor. The option, or the task file's field, is named with the unit it takes; the values as
    the hint reads them pass the check."""
    from stablepush.task import Robot, robot_with, with_robot

    urdf = str(ROOT / "data" / "arms" / "six-joint.urdf")
    with pytest.raises(TaskError) as error:
        robot_with(Robot(), urdf, "tool0", [0, 0, 0.15, 0, -1.5708, 0])
    assert error.value.field == "--tcp"
    assert error.value.reason == ("0 0 0.15 0 -1.5708 0: written in metres? (0.15 m is 150 mm); written in radians? "
                                  "(-1.5708 rad is -90 deg); --tcp takes mm and deg")
    with pytest.raises(TaskError, match=r"^--base: 0.4 0 0 1.5708: written in metres\? \(0.4 m is 400 mm\); "
                                        r"written in radians\? \(1.5708 rad is 90 deg\)"):
        with_robot(shipped("horizontal-offset-low-mu"), base=[0.4, 0, 0, 1.5708])
    text = task_text("horizontal-offset-low-mu") + (f"  robot: {{model: {urdf}, flange: tool0, "
                                                    f"tcp: [0, 0, 0.15, 0, -1.5708, 0]}}\n")
    with pytest.raises(TaskError) as error:
        parse_task(text)
    assert error.value.field == "environment.robot.tcp" and "environment.robot.tcp takes mm and deg" in error.value.reason
    # Whole degrees, mm, the origin, and the shipped arm's TCP are what they say.
    for tcp in ([0, 0, 110, 0, 180, 0], [0, 0, 0, 0, 0, 0], [0, 0, 150, 0, -90, 0], [0.5, 0, 150, 0, 1.5, 0]):
        robot_with(Robot(), urdf, "tool0", tcp)
    # The cure, followed: the plan that the TCP in metres and radians ran into the floor, the arm follows.
    plan = tmp_path / "p.json"
    runner = CliRunner()
    assert runner.invoke(cli, ["plan", str(TASKS / "horizontal-offset-low-mu.yaml"), "-o", str(plan)]).exit_code == 0
    arm = ["--task", str(TASKS / "horizontal-offset-low-mu.yaml"), "--robot", urdf, "--flange", "tool0", "--tcp"]
    slipped = runner.invoke(cli, ["check-cell", str(plan), *arm, "0", "0", "0.15", "0", "-1.5708", "0"])
    assert slipped.exit_code == 2 and "--tcp: 0 0 0.15 0 -1.5708 0: written in metres?" in slipped.output
    assert runner.invoke(cli, ["check-cell", str(plan), *arm, "0", "0", "150", "0", "-90", "0"]).exit_code == 0


def test_a_goal_no_push_from_the_start_moves_the_object_toward_is_named_when_the_search_fails():
    """The only pusher presses on the left end (+x); the goal lies 20 mm to -x. The search spends its
    time and used to blame the time limit alone."""
    from stablepush.plan import SearchRules, plan_task

    from conftest import task_with

    task = task_with("horizontal-offset-high-mu", lambda d: d.update(
        pushers=[p for p in d["pushers"] if p["name"] == "left"], goal=[-20, 0, 0]))
    plan = plan_task(task, time_limit=0.3)
    assert plan.outcome == "time_limit"
    assert plan.message.endswith(
        "; the goal lies at dx -20 mm, dz 0 mm, dtheta 0 deg from the start, and no stable push from there moves "
        "the object along -x (none): a plan must go around, if any can (each pusher's stable pushes from the "
        "start: stable_directions)"), plan.message
    assert "the goal lies" not in plan_task(task, time_limit=0.3, rules=SearchRules(explain=False)).message
