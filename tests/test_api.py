"""The Python API (`import stablepush as sp`) and timed trajectories."""
import json
import math

import numpy as np
import pytest
from click.testing import CliRunner
from conftest import TASKS

import stablepush as sp
from stablepush.execution import place_features
from stablepush.frames import grasp_transform, pose_to_matrix
from stablepush_cli.main import cli


def test_plan_save_load_check_trajectory_figure_round_trip(tmp_path):
    task = sp.load_task(TASKS / "t-shaped.yaml")
    plan = sp.plan(task, seed=1, time_limit=2.0)
    assert isinstance(plan, sp.Plan) and plan.solved and "40 pushes" in repr(plan)
    plan.save(tmp_path / "t.plan.json", tmp_path / "t.csv")
    loaded = sp.Plan.load(tmp_path / "t.plan.json")
    assert loaded.waypoints == plan.waypoints and loaded.ends_at_goal == plan.ends_at_goal
    assert np.array_equal(loaded.poses, plan.poses) and loaded.poses.shape == (41, 3)
    assert loaded.check(task) is loaded
    traj = loaded.trajectory(task, rate_hz=50)
    assert len(traj) > 0 and traj.rate_hz == 50
    fig = loaded.figure(task)
    assert fig.axes
    with pytest.raises(sp.PlanError, match="the plan is for task 't-shaped', not 'pivoting'"):
        loaded.check(sp.load_task(TASKS / "pivoting.yaml"))
    assert sp.check(task, at=task.start, move=(1, 0, 0))["left"]["feasible"] in (True, False)
    with pytest.raises(sp.StablepushError):
        sp.load_task(tmp_path / "missing.yaml")


def test_the_trajectory_puts_the_object_where_the_plan_says_at_every_push():
    """At each sample that completes push k, G's world pose and the feature's world pose of the
    object give back plan pose k: T_GO(q_k) = T_WG^-1 T_WO (docs/model.md section 1)."""
    task = sp.load_task(TASKS / "horizontal-offset-low-mu.yaml")
    plan = sp.plan(task, seed=1)
    traj = plan.trajectory(task, rate_hz=100)
    features = place_features(task, plan.steps)
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
    traj = sp.plan(task, seed=1).trajectory(task)
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
    header, first = (tmp_path / "t.csv").read_text().splitlines()[:2]
    assert header == "t,x,y,z,qx,qy,qz,qw,vx,vy,vz,wx,wy,wz,phase,step"
    assert first.endswith(",push,1")
    out = CliRunner().invoke(cli, ["trajectory", str(plan_file), "--task", str(task), "-o", str(tmp_path / "t.json"),
                                   "--quat", "wxyz", "--rate", "50"])
    assert out.exit_code == 0, out.output
    doc = json.loads((tmp_path / "t.json").read_text())
    assert doc["columns"][4:8] == ["qw", "qx", "qy", "qz"] and doc["rate_hz"] == 50
    bad = CliRunner().invoke(cli, ["trajectory", str(plan_file), "--task", str(task), "-o", str(tmp_path / "t.txt")])
    assert bad.exit_code == 2 and "must end in .csv or .json" in bad.stderr


def test_figures_the_executor_and_trajectories_take_a_plan_or_its_waypoints():
    from stablepush import figures
    from stablepush.execution import as_steps
    from stablepush.trajectory import timed_trajectory

    task = sp.load_task(TASKS / "horizontal-offset-high-mu.yaml")
    plan = sp.plan(task, seed=1)
    assert as_steps(plan) == as_steps(plan.waypoints) == as_steps(plan.steps) == plan.steps
    assert figures.plan_figure(task, plan.waypoints).axes  # the issue's `plan_figure(task, result.waypoints)`
    assert len(timed_trajectory(task, plan)) == len(plan.trajectory(task))
