"""The Python API (`import stablepush as sp`) and timed trajectories."""
import dataclasses
import json
import math
import os
import re
import subprocess
from collections import Counter

import numpy as np
import pytest
from click.testing import CliRunner

import stablepush as sp
from stablepush.execution.world import place_features
from stablepush.frames import grasp_transform, pose_to_matrix
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
    expected = math.ceil(task.step_time * rate_hz - 1e-9)
    assert set(samples.values()) == {expected}
    assert expected / rate_hz >= task.step_time - 1e-12 and (expected - 1) / rate_hz < task.step_time


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
    assert all(pushes.count(k) == round(task.step_time * 100) for k in done)


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


def test_plan_refuses_models_that_are_not_the_tasks():
    import stablepush as sp

    task, other = sp.load_task(TASKS / "t-shaped.yaml"), sp.load_task(TASKS / "pivoting.yaml")
    with pytest.raises(TypeError, match=r"models\[0\]: expected a StablePushModel"):
        sp.plan_task(task, models=[None])  # was a segmentation fault
    with pytest.raises(ValueError, match="not one of the corner_models.. of task 't-shaped'"):
        sp.plan_task(task, models=other.corner_models())
    assert sp.plan_task(task, models=task.corner_models()).solved


def test_the_planning_subpackage_keeps_its_dotted_path():
    """`sp.plan_task` plans; `stablepush.plan` stays the subpackage the docs name
    (stablepush.plan.reach.reach_map, stablepush.plan.load_plan)."""
    import stablepush.plan as planning
    import stablepush.plan.reach

    assert stablepush.plan.reach.reach_map is not None and planning.load_plan is sp.load_plan
    assert sp.plan_task is planning.plan_task


def test_check_answers_for_the_task_given_and_plan_takes_only_its_own_corner_models():
    """check() builds the task's own models (robust with an uncertainty box); plan_task's `models`
    must be the task's corner models: another task's friction, or the nominal model of a task
    with a box, would answer for another task."""
    high, low = sp.load_task(TASKS / "horizontal-offset-high-mu.yaml"), sp.load_task(TASKS / "horizontal-offset-low-mu.yaml")
    with pytest.raises(TypeError):
        sp.check(high, at=(0, 0, 0), move=(1, 0, 0), model=low.build_model())
    with pytest.raises(ValueError, match=r"models\[0\]: not one of the corner_models.. of task 'horizontal-offset-high"):
        sp.plan_task(high, models=low.corner_models(), time_limit=0.3)
    robust = sp.load_task(TASKS / "more" / "large-manipulation-robust.yaml")
    with pytest.raises(ValueError, match="uncertainty box"):
        sp.plan_task(robust, models=[robust.build_model()], time_limit=0.3)
    with pytest.raises(ValueError, match="1 model"):
        sp.plan_task(robust, models=robust.corner_models()[:1], time_limit=0.3)
    assert sp.plan_task(robust, models=robust.corner_models()[::-1]).solved  # any order
    base = sp.load_task(TASKS / "large-manipulation.yaml")
    edits = {"com": dict(com=(30.0, -5.0)), "step_time": dict(step_time=0.5), "pushes": dict(pushes="by_moving_pusher"),
             "pad_rings": dict(pad_rings=3), "pads": dict(pads=(((5.0, 0.0), 5.0), ((5.0, 0.0), 5.0)))}
    for name, edit in edits.items():
        with pytest.raises(ValueError, match="not one of the corner_models"):
            sp.plan_task(base, models=dataclasses.replace(base, **edit).corner_models(), time_limit=0.3)
    frictionless = dataclasses.replace(base, mu=0.0, uncertainty={"pad_mu": 0.2})
    frictionless.check_models(frictionless.corner_models())
    elsewhere = dataclasses.replace(base, goal=(5.0, 0.0, 0.0))  # a model does not depend on the goal
    elsewhere.check_models(base.corner_models())
    dataclasses.replace(base, mass=round(base.mass)).check_models(base.corner_models())  # 130 is 130.0
    moving = dataclasses.replace(base, pushes="by_moving_pusher")  # no feature, so no start's turn in it
    dataclasses.replace(moving, start=(0.0, 0.0, 10.0)).check_models(moving.corner_models())
    arrays = dataclasses.replace(base, com=np.array([0.0, -5.0]))
    arrays.check_models(arrays.corner_models())


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
        sp.plan_task(task, min_transit_hold=math.nan)
    with pytest.raises(sp.TaskError, match="start_pusher: no pusher named 'nope'"):
        sp.plan_task(task, start_pusher="nope")


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
