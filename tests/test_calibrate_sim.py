"""Calibration on the simulated arm in a world that hides its friction (`calibrate --sim --world`):
the intervals hold the world's mu, the calibrated task file plans, and the command's outputs."""
import json

import pytest
from click.testing import CliRunner

from stablepush.calibration import CalibrationSettings, calibrate
from stablepush.sim import SimulatedArm, WorldDeviation
from stablepush.task import load_task
from stablepush_cli.main import cli

from conftest import TASKS

HIDDEN = (("gripper.mu", 0.34), ("pushers.left.mu", 0.24), ("pushers.right.mu", 0.2), ("pushers.bottom.mu", 0.17))


def test_the_intervals_hold_a_hidden_worlds_mu_and_the_object_goes_back_to_the_start():
    task = load_task(TASKS / "horizontal-offset-low-mu.yaml")
    world = WorldDeviation(world=HIDDEN)
    truth = world.world_task(task)
    calibration = calibrate(task, lambda: SimulatedArm("mujoco", world, robot=task.environment.robot),
                            CalibrationSettings())
    assert 1 <= len(calibration.probes) <= 12
    assert "gripper.mu" in calibration.estimates
    for name, interval in calibration.estimates.items():
        assert interval.low <= truth.value(name) <= interval.high, (name, interval)
    assert calibration.returned is not None and calibration.returned["outcome"] == "landed"
    # the pads' mu, which every probe tells of, is narrowed to under half of what was unknown (the task's
    # mu -+ the spread); the 7% the calibration aims for is not reached in 12 probes here (+-21%)
    pad, settings = calibration.estimates["gripper.mu"], CalibrationSettings()
    assert pad.high - pad.low <= 0.5 * 2 * settings.spread * task.value("gripper.mu")


def test_calibrate_writes_a_task_plan_takes_and_the_estimates_as_json(tmp_path):
    out, report = tmp_path / "cal.yaml", tmp_path / "cal.json"
    world = [w for name, value in HIDDEN for w in ("--world", f"{name}={value}")]
    result = CliRunner().invoke(cli, ["calibrate", str(TASKS / "horizontal-offset-low-mu.yaml"), "--sim", *world,
                                      "--max-probes", "4", "--no-return", "-o", str(out), "--json", str(report)])
    assert result.exit_code == 0, result.output
    assert "probe 1: " in result.output and "gripper.mu: " in result.output
    data = json.loads(report.read_text())
    assert set(data["estimates"]) | set(data["unidentified"]) == {"gripper.mu", "pushers.left.mu",
                                                                    "pushers.right.mu", "pushers.bottom.mu"}
    assert len(data["probes"]) == 4 and all(p["outcome"] in ("stuck", "slipped") for p in data["probes"])
    planned = CliRunner().invoke(cli, ["plan", str(out), "-o", str(tmp_path / "p.json")])
    assert planned.exit_code in (0, 1), planned.output  # a task plan reads (solved or not)
    assert "uncertainty" in out.read_text()


@pytest.mark.parametrize("args, says", [
    (["--world", "gripper.pad_rings=2"], "not a field a world sets"),
    (["--world", "pushers.nope.mu=0.2"], "nope"),
])
def test_calibrate_refuses_a_world_it_cannot_make_before_any_probe(args, says):
    result = CliRunner().invoke(cli, ["calibrate", str(TASKS / "pivoting.yaml"), "--sim", *args])
    assert result.exit_code == 2 and says in result.output, result.output


def test_sim_arm_refuses_a_world_field_before_it_listens():
    result = CliRunner().invoke(cli, ["sim-arm", "--port", "0", "--world", "gripper.grip=3"])
    assert result.exit_code == 2 and "not a field a world sets" in result.output


def test_a_runs_report_holds_its_steps_and_calibrate_learns_from_it(tmp_path):
    task_file = str(TASKS / "horizontal-offset-low-mu.yaml")
    plan, report = tmp_path / "p.json", tmp_path / "run.json"
    assert CliRunner().invoke(cli, ["plan", task_file, "-o", str(plan)]).exit_code == 0
    ran = CliRunner().invoke(cli, ["execute", str(plan), "--task", task_file, "--sim", "--world", "gripper.mu=0.3",
                                   "--json", str(report)])
    assert ran.exit_code in (0, 5), ran.output
    data = json.loads(report.read_text())
    waypoints = json.loads(plan.read_text())["waypoints"]
    assert [step[3] for step in data["steps"]] == [w.get("pusher") for w in waypoints]
    assert data["steps"][-1][:3] == pytest.approx([waypoints[-1][k] for k in ("x", "z", "theta")])
    learned = CliRunner().invoke(cli, ["calibrate", task_file, "--from", str(report), "--json",
                                       str(tmp_path / "cal.json")])
    assert learned.exit_code == 0, learned.output
    assert "gripper.mu" in json.loads((tmp_path / "cal.json").read_text())["estimates"]


def test_calibrate_estimates_a_hidden_grip_force_when_asked_and_writes_it(tmp_path):
    """The world grips with 13 N where the task says 10, its pads' mu as the task's: with
    --estimate gripper.grip_force the probes read the pads' product as the grip force, and its
    interval holds the world's."""
    out, report = tmp_path / "cal.yaml", tmp_path / "cal.json"
    result = CliRunner().invoke(cli, ["calibrate", str(TASKS / "horizontal-offset-low-mu.yaml"), "--sim", "--world",
                                      "gripper.grip_force=13", "--estimate", "gripper.grip_force", "--max-probes", "8",
                                      "--no-return", "--quiet", "-o", str(out), "--json", str(report)])
    assert result.exit_code == 0, result.output
    data = json.loads(report.read_text())
    force = data["estimates"]["gripper.grip_force"]
    assert force["low"] <= 13.0 <= force["high"] and force["value"] > 10.0, force
    assert "gripper.mu" not in data["estimates"] and "gripper.mu" not in data["unidentified"]
    calibrated = load_task(out)
    assert calibrated.gripper.grip_force == pytest.approx(force["value"], rel=1e-3)
    assert calibrated.uncertainty["grip_force"] > 0.0
