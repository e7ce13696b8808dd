"""The Python API (`import stablepush as sp`) and timed trajectories."""
import json
import math
from collections import Counter

import numpy as np
import pytest
from click.testing import CliRunner

import stablepush as sp
from stablepush.execution.world import place_features
from stablepush.frames import grasp_transform, pose_to_matrix
from stablepush_cli.main import cli

from conftest import TASKS


def test_plan_save_load_check_trajectory_figure_round_trip(tmp_path):
    task = sp.load_task(TASKS / "t-shaped.yaml")
    plan = sp.plan(task, seed=1, time_limit=2.0)
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
    first = sp.plan(task, seed=1).waypoints[1]
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
            "t = sp.load_task(sys.argv[1]); sp.plan_figure(t, sp.plan(t, seed=1)); "
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
    traj = sp.trajectory(task, sp.plan(task, seed=1), rate_hz=rate_hz)
    samples = Counter(int(step) for phase, step in zip(traj.phase, traj.step) if phase == "push")
    expected = math.ceil(task.step_time * rate_hz - 1e-9)
    assert set(samples.values()) == {expected}
    assert expected / rate_hz >= task.step_time - 1e-12 and (expected - 1) / rate_hz < task.step_time


def test_the_trajectory_puts_the_object_where_the_plan_says_at_every_push():
    """At each sample that completes push k, G's world pose and the feature's world pose of the
    object give back plan pose k: T_GO(q_k) = T_WG^-1 T_WO (docs/model.md section 1)."""
    task = sp.load_task(TASKS / "horizontal-offset-low-mu.yaml")
    plan = sp.plan(task, seed=1)
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
    traj = sp.trajectory(task, sp.plan(task, seed=1))
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
        sp.plan(task, models=[None])  # was a segmentation fault
    with pytest.raises(ValueError, match="not a model of task 't-shaped'"):
        sp.plan(task, models=other.corner_models())
    assert sp.plan(task, models=task.corner_models()).solved
