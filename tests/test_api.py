"""The Python API (`import stablepush as sp`) and timed trajectories."""
import copy
import dataclasses
import json
import math
import os
import pickle
import re
import subprocess
from collections import Counter

import numpy as np
import pytest
from click.testing import CliRunner

import stablepush as sp
from stablepush.execution.world import place_features
from stablepush.frames import grasp_transform, pose_to_matrix
from stablepush.plan import SearchRules
from stablepush.task.model import PLANNER_DEFAULTS, PlannerSettings
from stablepush_cli.main import cli

from conftest import TASKS


def test_plan_save_load_check_trajectory_figure_round_trip(tmp_path):
    task = sp.load_task(TASKS / "t-shaped.yaml")
    plan = sp.plan_task(task, seed=1, time_limit=2.0)
    assert isinstance(plan, sp.Plan) and plan.solved and "40 pushes" in repr(plan)
    sp.save_plan(plan, tmp_path / "t.plan.json", tmp_path / "t.csv")
    loaded = sp.load_plan(tmp_path / "t.plan.json")
    assert loaded.waypoints == plan.waypoints and loaded.ends_at_goal == plan.ends_at_goal
    assert np.array_equal(loaded.poses, plan.poses) and loaded.poses.shape == (41, 3)
    assert sp.check_plan(task, loaded) is loaded
    traj = sp.trajectory(task, loaded, rate_hz=50)
    assert len(traj) > 0 and traj.rate_hz == 50
    assert sp.plan_figure(task, loaded).axes
    with pytest.raises(sp.PlanError, match="the plan is for task 't-shaped', not 'pivoting'"):
        sp.check_plan(sp.load_task(TASKS / "pivoting.yaml"), loaded)
    with pytest.raises(sp.StablepushError):
        sp.load_task(tmp_path / "missing.yaml")


def test_check_says_a_pusher_pushes_and_never_pulls():
    """The plan's first push is stable for its pusher; the same pusher moving the object the
    opposite way would have to pull it, which no contact can (its cone holds no such wrench)."""
    task = sp.load_task(TASKS / "t-shaped.yaml")
    first = sp.plan_task(task, seed=1).waypoints[1]
    move = tuple(b - a for a, b in zip(first.pose, task.start))
    forward = tuple(-d for d in move)
    assert sp.check(task, at=task.start, move=forward)[first.pusher]["feasible"] is True
    backward = sp.check(task, at=task.start, move=move, pusher=first.pusher)[first.pusher]
    assert backward["feasible"] is False and backward["margin"] < 0


def test_the_package_leaves_the_plotting_backend_alone():
    """Drawing a figure neither needs pyplot nor switches the caller's backend, and `import
    stablepush` does not load matplotlib at all."""
    import subprocess
    import sys

    code = ("import sys, matplotlib; matplotlib.use('svg'); import stablepush as sp; "
            "assert 'matplotlib.pyplot' not in sys.modules; "
            "t = sp.load_task(sys.argv[1]); sp.plan_figure(t, sp.plan_task(t, seed=1)); "
            "assert matplotlib.get_backend() == 'svg', matplotlib.get_backend(); "
            "assert 'matplotlib.pyplot' not in sys.modules")
    done = subprocess.run([sys.executable, "-c", code, str(TASKS / "pivoting.yaml")], capture_output=True, text=True)
    assert done.returncode == 0, done.stderr
    bare = subprocess.run([sys.executable, "-c", "import sys, stablepush; assert 'matplotlib' not in sys.modules"],
                          capture_output=True, text=True)
    assert bare.returncode == 0, bare.stderr


@pytest.mark.parametrize("rate_hz", [100.0, 30.0, 25.0, 15.0, 7.0])
def test_each_push_lasts_the_models_step_time_or_the_next_whole_period_never_less(rate_hz):
    """The stability test assumed each push takes dynamics.step_time (0.1 s here); a stream at a
    rate that does not divide it must not push faster than that (at 25 Hz, 3 samples, not 2)."""
    task = sp.load_task(TASKS / "horizontal-offset-low-mu.yaml")
    traj = sp.trajectory(task, sp.plan_task(task, seed=1), rate_hz=rate_hz)
    samples = Counter(int(step) for phase, step in zip(traj.phase, traj.step) if phase == "push")
    expected = math.ceil(task.dynamics.step_time * rate_hz - 1e-9)
    assert set(samples.values()) == {expected}
    assert expected / rate_hz >= task.dynamics.step_time - 1e-12 and (expected - 1) / rate_hz < task.dynamics.step_time


def test_the_trajectory_puts_the_object_where_the_plan_says_at_every_push():
    """At each sample that completes push k, G's world pose and the feature's world pose of the
    object give back plan pose k: T_GO(q_k) = T_WG^-1 T_WO (docs/model.md section 1)."""
    task = sp.load_task(TASKS / "horizontal-offset-low-mu.yaml")
    plan = sp.plan_task(task, seed=1)
    traj = sp.trajectory(task, plan, rate_hz=100)
    features = place_features(task, plan.waypoints)
    done = {}
    for i in range(len(traj)):
        if traj.phase[i] == "push":
            done[int(traj.step[i])] = i  # the last push sample of each step completes it
    assert sorted(done) == list(range(1, len(plan.waypoints)))
    for k, i in done.items():
        w = plan.waypoints[k]
        T_WG = pose_to_matrix([*traj.position[i], *traj.quaternion_wxyz[i]])
        T_GO = np.linalg.inv(T_WG) @ features[w.pusher].object_pose
        assert np.allclose(T_GO, grasp_transform((w.x, w.z, w.theta)), atol=1e-9)
    # One unit push lasts dynamics.step_time.
    pushes = [int(s) for s, p in zip(traj.step, traj.phase) if p == "push"]
    assert all(pushes.count(k) == round(task.dynamics.step_time * 100) for k in done)


def test_velocities_match_the_motion():
    """Pivoting: G turns about y by the plan's 1 deg per 0.1 s push while the object rests on its
    feature, so |omega| = 0.1745 rad/s about y; and the velocities integrate to the positions."""
    task = sp.load_task(TASKS / "pivoting.yaml")
    traj = sp.trajectory(task, sp.plan_task(task, seed=1))
    steady = [i for i in range(1, len(traj) - 1) if traj.phase[i] == "push" and traj.phase[i - 1] == "push"
              and 2 <= traj.step[i] <= 80]
    w = traj.angular_velocity[steady]
    assert np.allclose(np.abs(w[:, 1]), math.radians(1.0) / 0.1, rtol=1e-6)
    assert np.allclose(w[:, [0, 2]], 0.0, atol=1e-9)
    p = traj.position
    assert np.allclose(p[1:] - p[:-1], traj.linear_velocity[1:] / traj.rate_hz, atol=1e-12)
    assert np.allclose(np.linalg.norm(traj.quaternion_wxyz, axis=1), 1.0)


def test_trajectory_command_writes_csv_and_json_in_either_quaternion_order(tmp_path):
    task = TASKS / "horizontal-offset-high-mu.yaml"
    plan_file = tmp_path / "p.plan.json"
    assert CliRunner().invoke(cli, ["plan", str(task), "-o", str(plan_file), "--quiet"]).exit_code == 0
    out = CliRunner().invoke(cli, ["trajectory", str(plan_file), "--task", str(task), "-o", str(tmp_path / "t.csv")])
    assert out.exit_code == 0, out.output
    header, *rows = (tmp_path / "t.csv").read_text().splitlines()
    assert header == "t,x,y,z,qx,qy,qz,qw,vx,vy,vz,wx,wy,wz,phase,step"
    # The run starts 1 mm back from its first feature and approaches it at 2 mm/s (the guarded approach).
    approach = [row for row in rows[:60] if row.endswith(",approach,0")]
    assert rows[0].endswith(",approach,0") and len(approach) == 51 and rows[51].endswith(",push,1")
    assert float(rows[0].split(",")[8]) == pytest.approx(-0.002, rel=0.05)  # vx, m/s
    out = CliRunner().invoke(cli, ["trajectory", str(plan_file), "--task", str(task), "-o", str(tmp_path / "t.json"),
                                   "--quat", "wxyz", "--rate", "50"])
    assert out.exit_code == 0, out.output
    doc = json.loads((tmp_path / "t.json").read_text())
    assert doc["columns"][4:8] == ["qw", "qx", "qy", "qz"] and doc["rate_hz"] == 50
    bad = CliRunner().invoke(cli, ["trajectory", str(plan_file), "--task", str(task), "-o", str(tmp_path / "t.txt")])
    assert bad.exit_code == 2 and "must end in .csv, .json or .mcap" in bad.stderr
    bad = CliRunner().invoke(cli, ["trajectory", str(plan_file), "--task", str(task), "-o", str(tmp_path / "t.mcap"),
                                   "--quat", "wxyz"])
    assert bad.exit_code == 2 and "--quat wxyz" in bad.stderr and not (tmp_path / "t.mcap").exists()


def test_the_planning_subpackage_keeps_its_dotted_path():
    """`sp.plan_task` plans; `stablepush.plan` stays the subpackage the docs name
    (stablepush.plan.reach.reach_map, stablepush.plan.load_plan)."""
    import stablepush.plan as planning
    import stablepush.plan.reach

    assert stablepush.plan.reach.reach_map is not None and planning.load_plan is sp.load_plan
    assert sp.plan_task is planning.plan_task


def test_a_task_builds_its_models_once_and_a_task_made_from_it_builds_its_own():
    """Task.model and Task.corner_models are built on first use and kept; a Task made from it
    (with_values, dataclasses.replace of a group) has its own, built from its own values; check
    and plan_task answer in the task's own models and take none from elsewhere."""
    base = sp.load_task(TASKS / "large-manipulation.yaml")
    assert base.model is base.model and base.corner_models is base.corner_models
    assert base.corner_models == (base.model,)  # no box: the nominal model alone
    robust = sp.load_task(TASKS / "more" / "large-manipulation-robust.yaml")
    assert len(robust.corner_models) == 4 and robust.model not in robust.corner_models
    assert all(m is t.model for m, t in zip(robust.corner_models, robust.corner_tasks))
    heavy = base.with_values({"object.mass": 2 * base.object.mass})
    assert heavy.model is not base.model
    assert heavy.model.body.mass == pytest.approx(2 * base.model.body.mass) and base.object.mass == 130.0
    edits = {"object": (dict(com=(30.0, -5.0)), lambda m: tuple(m.body.com) == pytest.approx((0.030, -0.005))),
             "gripper": (dict(pad_rings=3), lambda m: len(m.gripper.point_positions) == 2 * 37),
             "dynamics": (dict(pushes="by_moving_pusher"), lambda m: m.gravity_frame.name == "gripper")}
    for group, (change, holds) in edits.items():
        edited = dataclasses.replace(base, **{group: dataclasses.replace(getattr(base, group), **change)})
        assert holds(edited.model) and not holds(base.model), group
    high, low = sp.load_task(TASKS / "horizontal-offset-high-mu.yaml"), sp.load_task(TASKS / "horizontal-offset-low-mu.yaml")
    assert sp.check(high, at=(0, 0, 0), move=(1, 0, 0), pusher="left")["left"]["feasible"]
    assert not sp.check(low, at=(0, 0, 0), move=(1, 0, 0), pusher="left")["left"]["feasible"]
    with pytest.raises(TypeError):
        sp.plan_task(high, models=low.corner_models)  # a task plans in its own models, and no others


@pytest.mark.parametrize("copy_of", [lambda t: pickle.loads(pickle.dumps(t)), copy.deepcopy, copy.copy],
                         ids=["pickle", "deepcopy", "copy"])
def test_a_pickled_or_copied_task_leaves_its_models_behind_and_builds_equal_ones(copy_of):
    """Ray sends Tasks to its workers pickled: the models (which do not pickle) stay behind, and
    the copy builds its own from the same values."""
    task = sp.load_task(TASKS / "more" / "large-manipulation-robust.yaml")
    task.model, task.corner_models  # built, so that there is something to leave behind
    again = copy_of(task)
    assert again == task and not {"model", "corner_models", "corner_tasks"} & set(vars(again))
    q, dq = (0.0, 0.0, 0.0), (1e-3, 0.0, 0.0)
    for mine, theirs in zip((again.model, *again.corner_models), (task.model, *task.corner_models)):
        assert mine is not theirs and mine.body.mass == theirs.body.mass
        assert mine.check(q, dq, 0).margin == theirs.check(q, dq, 0).margin


@pytest.mark.parametrize("path, value", [("gripper.mu", 0.3), ("gripper.grip_force", 12.5), ("object.mass", 90.0),
                                         ("pushers.under-web.mu", 0.35)])
def test_each_value_path_reads_and_writes_its_quantity(path, value):
    task = sp.load_task(TASKS / "t-shaped.yaml")
    group, _, name = path.partition(".")
    held = task.pushers[task.pusher_index("under-web")].mu if group == "pushers" else getattr(getattr(task, group), name)
    assert task.value(path) == held != value
    changed = task.with_values({path: value})
    assert changed.value(path) == value and task.value(path) == held  # a new Task; the first one is as it was
    assert [changed.value(p) for p in ("gripper.mu", "gripper.grip_force", "object.mass") if p != path] == \
        [task.value(p) for p in ("gripper.mu", "gripper.grip_force", "object.mass") if p != path]


def test_a_new_mass_scales_a_given_inertia_with_it():
    mesh = sp.load_task(TASKS / "more" / "l-bracket-mesh.yaml")  # a mesh part: its inertia is given
    heavier = mesh.with_values({"object.mass": 3 * mesh.object.mass})
    assert heavier.object.inertia == pytest.approx(3 * mesh.object.inertia, rel=1e-15)
    plain = sp.load_task(TASKS / "t-shaped.yaml")
    assert plain.with_values({"object.mass": 90.0}).object.inertia is None  # the uniform prism's, from the mass


@pytest.mark.parametrize("values, error, says", [
    ({"gripper.pads": 0.1}, sp.TaskError, "gripper.pads: not a value of a task (gripper.mu, "),
    ({"mu": 0.1}, sp.TaskError, "mu: not a value of a task"),
    ({"pushers.nobody.mu": 0.1}, sp.TaskError, "pushers.nobody.mu: no pusher named 'nobody' (the task has left, "),
    ({"gripper.mu": -0.1}, sp.TaskError, "gripper.mu: must be between 0 and 100, got -0.1"),
    ({"gripper.grip_force": 0.0}, sp.TaskError, "gripper.grip_force: must be between 1e-06 and 100000, got 0"),
    ({"object.mass": 1e9}, sp.TaskError, "object.mass: must be between 0.001 and 1e+07, got 1e+09"),
    ({"pushers.left.mu": math.inf}, sp.TaskError, "pushers.left.mu: must be finite"),
    ({"gripper.mu": "0.3"}, TypeError, "gripper.mu must be a number"),
    ([("gripper.mu", 0.3)], TypeError, "takes a mapping"),
])
def test_an_unknown_path_or_a_value_out_of_range_is_refused_by_name(values, error, says):
    task = sp.load_task(TASKS / "t-shaped.yaml")
    with pytest.raises(error, match=re.escape(says)):
        task.with_values(values)
    if "not a value" in says or "no pusher" in says:
        with pytest.raises(error, match=re.escape(says)):
            task.value(next(iter(values)))


def test_a_task_written_in_code_plans_like_the_file():
    """parse_task takes the mapping a task file holds; a Task made directly gets the planner's
    defaults; a path handed to parse_task is pointed to load_task."""
    import yaml

    path = TASKS / "horizontal-offset-high-mu.yaml"
    from_file = sp.load_task(path)
    from_mapping = sp.parse_task(yaml.safe_load(path.read_text()), str(path))
    assert from_mapping == from_file
    bare = dataclasses.replace(from_file, planner={"tolerance": [0.5, 0.5]})  # a mapping in the file's form
    assert bare.planner == PlannerSettings(tolerance=(0.5, 0.5))
    assert bare.planner.as_dict() == {**PLANNER_DEFAULTS, "tolerance": [0.5, 0.5]}
    assert sp.plan_task(bare, seed=1).waypoints == sp.plan_task(from_file, seed=1).waypoints
    with pytest.raises(sp.TaskError, match="load_task"):
        sp.parse_task(str(path))
    assert sp.parse_task(path.read_bytes(), str(path)) == from_file
    defaults = sp.load_task(TASKS / "more" / "wedge-heel.yaml")  # its file leaves tolerance to the default
    with pytest.raises(dataclasses.FrozenInstanceError):  # one task's settings cannot change another's
        defaults.planner.tolerance = (5.0, 5.0)
    assert defaults.planner.tolerance == (1.0, 1.0) and PLANNER_DEFAULTS["tolerance"] == [1.0, 1.0]


def test_a_goal_with_no_grasp_is_unreachable_at_once():
    """A goal edited in code past the object's end (load_task refuses such a file) is decided
    before the search, not searched for the whole time limit."""
    task = dataclasses.replace(sp.load_task(TASKS / "horizontal-offset-high-mu.yaml"), goal=(200.0, 0.0, 0.0))
    plan = sp.plan_task(task, time_limit=5.0)
    assert plan.outcome == "unreachable" and "no grasp there" in plan.message
    assert sp.PlanOutcome(plan.outcome) is sp.PlanOutcome.unreachable
    assert plan.stats["planning_time_s"] < 1.0


def test_numpy_numbers_are_numbers(tmp_path):
    task = sp.load_task(TASKS / "horizontal-offset-high-mu.yaml")
    assert sp.plan_task(task, seed=np.int64(1), time_limit=np.float32(2)).solved
    assert sp.check(task, at=np.zeros(3, int), move=np.array([1, 0, 0]))["left"]["feasible"]
    plan = sp.plan_task(task, seed=1)
    assert len(sp.trajectory(task, plan, rate_hz=np.float32(100))) == len(sp.trajectory(task, plan))
    moved = dataclasses.replace(plan, waypoints=[sp.Waypoint(np.float64(0.0), np.int64(0), 0)] + plan.waypoints[1:])
    sp.save_plan(moved, tmp_path / "p.plan.json")
    assert sp.load_plan(tmp_path / "p.plan.json").waypoints == plan.waypoints
    with pytest.raises(sp.TaskError, match="seed"):
        sp.plan_task(task, seed=np.bool_(True))
    with pytest.raises(sp.TaskError, match="seed: must be an integer"):
        sp.plan_task(task, seed=np.timedelta64(1, "s"))  # numpy registers it as an integer
    with pytest.raises(sp.TaskError, match=r"at\[0\]: must be a number"):
        sp.check(task, at=(np.timedelta64(1, "s"), 0, 0), move=(1, 0, 0))


def test_what_save_plan_writes_load_plan_reads(tmp_path):
    """A plan load_plan would refuse is refused when made (Waypoint: a NaN pose or margin) or when
    written (the rest), naming the field, and check_plan names a malformed plan's field rather than
    failing inside."""
    task = sp.load_task(TASKS / "horizontal-offset-high-mu.yaml")
    plan = sp.plan_task(task, seed=1)
    w = plan.waypoints
    with pytest.raises(sp.PlanError, match=r"waypoint\.x: must be a finite number, got NaN"):
        sp.Waypoint(math.nan, 0, 0)
    with pytest.raises(sp.PlanError, match="final_hold"):
        sp.save_plan(dataclasses.replace(plan, final_hold_ratio=math.nan), tmp_path / "a.json")
    assert not (tmp_path / "a.json").exists()
    with pytest.raises(sp.PlanError, match="stats: holds a number that is not finite"):
        sp.save_plan(dataclasses.replace(plan, stats={**plan.stats, "goal_distance_steps": math.nan}), tmp_path / "a.json")
    with pytest.raises(sp.OutputError, match="overwrite the plan file"):
        sp.save_plan(plan, tmp_path / "same.json", tmp_path / "same.json")
    sp.save_plan(plan, "/dev/null", "/dev/null")  # a stream may be named twice
    fifo = tmp_path / "fifo"
    os.mkfifo(fifo)
    reader = subprocess.Popen(["cat", str(fifo)], stdout=subprocess.PIPE, text=True)
    sp.save_plan(plan, fifo, fifo)
    both = reader.communicate(timeout=30)[0]
    assert '"format": "stablepush.plan/1"' in both and "step,x,z,theta" in both  # the JSON, then the CSV
    for field, value in (("margin", 10**400), ("margin", math.nan), ("pusher", 5)):
        with pytest.raises(sp.PlanError, match=rf"waypoint\.{field}: must be"):
            dataclasses.replace(w[1], **{field: value})
    with pytest.raises(sp.PlanError, match=r"waypoints\[1\]: must be a Waypoint"):
        sp.check_plan(task, dataclasses.replace(plan, waypoints=[w[0], (1.0, 0.0, 0.0)] + w[2:]))
    with pytest.raises(sp.PlanError, match="stats"):
        sp.check_plan(task, dataclasses.replace(plan, stats=None))
    with pytest.raises(sp.PlanError, match="task"):
        sp.check_plan(task, dataclasses.replace(plan, task=None))
    empty = {"format": "stablepush.plan/1", "task": "t", "solved": True, "stats": {}, "waypoints": []}
    (tmp_path / "empty.json").write_text(json.dumps(empty))
    with pytest.raises(sp.PlanError, match="waypoints: empty"):
        sp.load_plan(tmp_path / "empty.json")


def test_a_path_where_a_task_or_plan_goes_is_named():
    task = sp.load_task(TASKS / "horizontal-offset-high-mu.yaml")
    plan = sp.plan_task(task, seed=1)
    calls = [("sp.load_task(path)", lambda: sp.plan_task("t.yaml")),
             ("sp.load_task(path)", lambda: sp.check("t.yaml", (0, 0, 0), (1, 0, 0))),
             ("sp.load_plan(path)", lambda: sp.check_plan(task, "p.json")),
             ("expected a Plan, got dict", lambda: sp.save_plan({}, "x.json")),
             ("expected a Task, got NoneType", lambda: sp.trajectory(None, plan))]
    for words, call in calls:
        with pytest.raises(TypeError, match=re.escape(words)):
            call()
    with pytest.raises(sp.TaskError, match="min_transit_hold"):
        sp.plan_task(task, rules=SearchRules(min_transit_hold=math.nan))
    with pytest.raises(sp.TaskError, match="start_pusher: no pusher named 'nope'"):
        sp.plan_task(task, rules=SearchRules(start_pusher="nope"))


def test_the_gripper_quaternion_stream_is_continuous_past_half_a_turn():
    """A plan that turns the object 200 deg: each sample's quaternion is in the hemisphere of the
    one before (no jump to the other sign), and the first has w >= 0."""
    task = sp.load_task(TASKS / "pivoting.yaml")
    turned = dataclasses.replace(task, goal=(0.0, 0.0, 200.0), planner=task.planner.replace(step=[1.0, 5.0]))
    traj = sp.trajectory(turned, sp.plan_task(turned, seed=1))
    q = traj.quaternion_wxyz
    assert q[0, 0] >= 0 and (np.sum(q[1:] * q[:-1], axis=1) > 0.99).all()
    assert q[:, 0].min() < -0.1  # past 180 deg, the stream's w has turned negative, as continuity asks


def test_trajectory_names_bags_ros_can_read_and_warns_of_another_cell(tmp_path):
    """A bag's name must end in a lower-case .mcap after a name (rosbag2's readers take the format
    from it); a plan made by_moving_pusher is exported with the executor's warning that its cell
    pushes against fixed features."""
    import yaml

    task = TASKS / "horizontal-offset-high-mu.yaml"
    plan_file = tmp_path / "p.plan.json"
    assert CliRunner().invoke(cli, ["plan", str(task), "-o", str(plan_file), "--quiet"]).exit_code == 0
    for name in ("UP.MCAP", ".mcap"):
        out = CliRunner().invoke(cli, ["trajectory", str(plan_file), "--task", str(task), "-o", str(tmp_path / name)])
        assert out.exit_code == 2 and name in out.stderr and not (tmp_path / name).exists(), out.output
    data = yaml.safe_load(task.read_text())
    data["dynamics"]["pushes"] = "by_moving_pusher"
    moving = tmp_path / "moving.yaml"
    moving.write_text(yaml.safe_dump(data))
    assert CliRunner().invoke(cli, ["plan", str(moving), "-o", str(plan_file), "--quiet"]).exit_code == 0
    out = CliRunner().invoke(cli, ["trajectory", str(plan_file), "--task", str(moving), "-o", str(tmp_path / "m.csv")])
    assert out.exit_code == 0 and "warning:" in out.stderr and "another cell" in out.stderr, out.output


def test_show_puts_its_figure_beside_the_plan_under_the_plans_own_name(tmp_path):
    task = TASKS / "horizontal-offset-high-mu.yaml"
    for name, figure in (("t.plan.json", "t.png"), ("run.2.json", "run.2.png"), ("run.3.json", "run.3.png")):
        assert CliRunner().invoke(cli, ["plan", str(task), "-o", str(tmp_path / name), "--quiet"]).exit_code == 0
        out = CliRunner().invoke(cli, ["show", str(tmp_path / name), "--task", str(task)])
        assert out.exit_code == 0 and (tmp_path / figure).exists(), out.output
