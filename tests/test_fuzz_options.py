"""Options fuzzed: `evaluate`, `reach`, `trajectory`, `execute` and `design` run through click's CliRunner with
options drawn at random (a fixed seed; the cases are generated each run, not replayed from a list)
from values that are legal, at the edges of their ranges, or hostile (NaN, infinities, -0,
negative, huge, another script's digits, empty, a trailing slash, the wrong kind). Every case must
end in an exit status other than 4 (an internal error) with no traceback: each refusal is the
library's StablepushError or click's usage error.

Kept fast (some seconds): the trials of `evaluate` draw their worlds and land without a
simulation, `execute`'s simulated arm refuses to build its world (a fault, exit 3, after every
option has been taken), `reach` searches for at most 0.01 s a cell on this process, and `design`
mostly 0.05 s a layout of two candidates."""
import random
import shlex

import pytest
import yaml
from click.testing import CliRunner

import stablepush as sp
from stablepush.evaluation import batch as batch_mod
from stablepush.execution.arm import ArmError
from stablepush_cli.main import cli

from conftest import TASKS, shipped

SEEDS = (2026, 7)
CASES_PER_COMMAND = 60
HIGH_MU = TASKS / "horizontal-offset-high-mu.yaml"

# Numbers a command may take (edges and magnitudes included), and ones it must refuse; each value is
# drawn from the first with probability LEGAL, so that most cases get past their parsing.
NUMBERS = ["0", "-0", "0.5", "1", "0.1", "0.125", "0.2", "2", "1e-3", "1e-9", "100", "1e3", "1e308", "3.5", "0.9"]
HOSTILE = ["-1", "-1e308", "1e400", "nan", "inf", "-inf", "0x10", "٣", "３", "", " ", "abc", "18446744073709551616"]
WHOLES = ["0", "1", "2", "3", "1000", "4294967295"]
HOSTILE_WHOLES = ["-1", "1.5", "1e3", "٢", "", "x", "4294967296"]
LEGAL = 0.75


def _number(rng):
    return rng.choice(NUMBERS if rng.random() < LEGAL else HOSTILE)


def _whole(rng):
    return rng.choice(WHOLES if rng.random() < LEGAL else HOSTILE_WHOLES)


def _output(rng, tmp_path, suffixes):
    if rng.random() < 0.5:  # a file it may write
        return str(tmp_path / f"out{rng.randrange(1000)}{suffixes[0]}")
    name = rng.choice(["out", "x.y", "", "nodir/out", ".", "..", "out/", "dir", "TASK", "PLAN"])
    suffix = rng.choice(list(suffixes) + ["", "/", ".txt"])
    return {"TASK": str(tmp_path / "task.yaml"), "PLAN": str(tmp_path / "task.plan.json"),
            "dir": str(tmp_path)}.get(name, str(tmp_path / (name + suffix)) if name else "")


def _axis(rng):
    return rng.choice(["-1:1:2", "0:0:1", "1:1:2", "0:1:0", "0:1:1", "nan:1:2", "0:inf:2", "0:1", "a:b:c", "0:1:٢",
                       "-1e5:1:2", "0:1:100000", "", "::", "0:1:2:3", "-0:-0:1"])


def _evaluate(rng, tmp_path):
    args = ["evaluate", str(tmp_path / "task.yaml"), "--quiet"]
    if rng.random() < 0.7:
        args += ["--plan", str(tmp_path / "task.plan.json")]
    args += ["--trials", rng.choice(["1", "2", "3", "0", "-1", "٣", "x", "1e2"])]
    options = {
        "--seed": lambda: [_whole(rng)],
        "--vary": lambda: [f"{rng.choice(['pad_mu', 'pusher_mu', 'grip_force', 'mass', 'heat', '', 'none'])}="
                           f"{_number(rng)}"],
        "--feature-error": lambda: [_number(rng), _number(rng)],
        "--tracker-noise": lambda: [_number(rng), _number(rng)],
        "--success-tolerance": lambda: [_number(rng), _number(rng)],
        "--target": lambda: [_number(rng)],
        "--confidence": lambda: [_number(rng)],
        "--workers": lambda: [rng.choice(["1", "0", "-2", "x", "٢", ""])],
        "--ray": lambda: [rng.choice(["127.0.0.1:1", "notanaddress", ":::", "host:0", "127.0.0.1:٦٣٧٩"])],
        "--json": lambda: [_output(rng, tmp_path, [".json"])],
        "--csv": lambda: [_output(rng, tmp_path, [".csv"])],
        "--engine": lambda: [rng.choice(["mujoco", "drake", "bullet", ""])],
        "--robust": lambda: [],
        "--closed-loop": lambda: [],
        "--no-guard": lambda: [],
    }
    return args + _some(rng, options)


def _reach(rng, tmp_path):
    args = ["reach", str(tmp_path / "task.yaml"), "--quiet", "--workers", "1"]
    options = {
        "--x": lambda: [_axis(rng)],
        "--z": lambda: [_axis(rng)],
        "--theta": lambda: [_axis(rng)],
        "--time-limit": lambda: [rng.choice(["0.01", "0", "-1", "nan", "inf", "1e-7", "1e-6", "٠.١", "", "x"])],
        "--seed": lambda: [_whole(rng)],
        "--json": lambda: [_output(rng, tmp_path, [".json"])],
        "--plot": lambda: [_output(rng, tmp_path, [".png", ".svg", ".jpg"])],
        "--ray": lambda: [rng.choice(["127.0.0.1:1", "notanaddress", "ray://", "[::1]:x"])],
    }
    args += _some(rng, options)
    return args if "--time-limit" in args else args + ["--time-limit", "0.01"]


def _trajectory(rng, tmp_path):
    args = ["trajectory", str(tmp_path / "task.plan.json"), "--task", str(tmp_path / "task.yaml")]
    args += ["-o", _output(rng, tmp_path, [".csv", ".json", ".mcap", ".MCAP"])]
    options = {
        "--rate": lambda: [rng.choice(["100", "1000", "1001", "7", _number(rng)])],
        "--quat": lambda: [rng.choice(["xyzw", "wxyz", "abcd", ""])],
        "--joints": lambda: [],
        "--stamp": lambda: [rng.choice(["0", "-1", "1764600000.5", "2026-12-01T15:00:00Z", "2026-12-01T15:00:00",
                                        "1e30", "nan", "٣", ""])],
    }
    return args + _some(rng, options)


def _execute(rng, tmp_path):
    args = ["execute", str(tmp_path / "task.plan.json"), "--task", str(tmp_path / "task.yaml"), "--quiet"]
    args += rng.choice([["--sim"], ["--sim"], ["--sim"], ["--arm", "127.0.0.1:1"], ["--arm", "x:٣"], []])
    options = {
        "--rate": lambda: [rng.choice(["100", "50", _number(rng)])],
        "--resume-from": lambda: [rng.choice(["19", "20", "21", _whole(rng)])],
        "--ack-timeout": lambda: [_number(rng)],
        "--json": lambda: [_output(rng, tmp_path, [".json"])],
        "--record": lambda: [_output(rng, tmp_path, [".mcap"])],
        "--success-tolerance": lambda: [_number(rng), _number(rng)],
        "--sim-mu-scale": lambda: [_number(rng)],
        "--tracker-noise": lambda: [_number(rng), _number(rng)],
        "--replan-threshold": lambda: [_number(rng), _number(rng)],
        "--final-tolerance": lambda: [_number(rng), _number(rng)],
        "--engine": lambda: [rng.choice(["mujoco", "drake", "x"])],
        "--closed-loop": lambda: [],
        "--no-guard": lambda: [],
        "--no-pace": lambda: [],
    }
    return args + _some(rng, options)


def _design(rng, tmp_path):
    args = ["design", str(tmp_path / "two.design.yaml"), "--quiet"]
    options = {
        "--max-fixtures": lambda: [_whole(rng)],
        "--rank": lambda: [rng.choice(["margin", "success", "arm,fixtures", "margin,margin", "speed", "", ",",
                                       "success,margin", "time,reach,pushes"])],
        "--reach-top": lambda: [rng.choice(["0", "1", "-1", "x", "٢", "101", ""])],
        "--evaluate": lambda: [rng.choice(["1", "2", "0", "-1", "٣", "x", "1e2", "100001"])],
        "--evaluate-top": lambda: [rng.choice(["1", "3", "0", "101", "x"])],
        "--vary": lambda: [f"{rng.choice(['pad_mu', 'mass', 'heat', '', 'none'])}={_number(rng)}"],
        "--feature-error": lambda: [_number(rng), _number(rng)],
        "--seed": lambda: [_whole(rng)],
        "--engine": lambda: [rng.choice(["mujoco", "drake", "bullet", ""])],
        "--closed-loop": lambda: [],
        "--out": lambda: [_output(rng, tmp_path, [""])],
        "--json": lambda: [_output(rng, tmp_path, [".json"])],
        "--plot": lambda: [_output(rng, tmp_path, [".png", ".svg", ".jpg"])],
        "--workers": lambda: [rng.choice(["1", "0", "-2", "x", "٢", ""])],
        "--ray": lambda: [rng.choice(["127.0.0.1:1", "notanaddress", "ray://"])],
    }
    args += _some(rng, options)
    time_limit = ["--time-limit", rng.choice(["0.05", "0", "-1", "nan", "inf", "1e-7", "٠.١", "", "x"])]
    return args + (time_limit if rng.random() < 0.3 else ["--time-limit", "0.05"]) + (
        [] if "--workers" in args else ["--workers", "1"]) + ([] if "--reach-top" in args else ["--reach-top", "0"])


def _some(rng, options):
    out = []
    for name in rng.sample(sorted(options), rng.randint(0, min(4, len(options)))):
        out += [name, *options[name]()]
    return out


class _NoWorld:
    """The simulated arm, refusing to build its world: a run faults at its hello (exit 3) once every
    option has been taken, without a simulation."""

    def __init__(self, engine="mujoco", deviation=None, log=None, robot=None):
        self.engine, self.deviation, self.connected = engine, deviation, False

    name = "fuzz arm"

    def check_cell(self, task, plan, rate_hz):
        return None

    def hello(self, scene, rate_hz, resume):
        raise ArmError("fuzz: no world is built here")

    def move(self, waypoint):
        raise ArmError("fuzz: no world is built here")

    def stop(self):
        return None

    def close(self):
        return None


def _landed(batch, trial):
    """A trial that draws its world as run_trial does, and lands, without a simulation."""
    return {"trial": trial, "world": batch.world(trial).as_dict(), "goal_error": None, "final_error": None,
            "replans": 0, "sim_time_s": 1.0, "wall_s": 0.0, "verdict": None, "error": None, "success": True,
            "cause": None}


@pytest.mark.parametrize("seed", SEEDS)
def test_fuzzed_options_never_end_in_an_internal_error(tmp_path, monkeypatch, seed):
    import stablepush.sim.local_arm as local_arm

    monkeypatch.setattr(batch_mod, "run_trial", _landed)
    monkeypatch.setattr(local_arm, "SimulatedArm", _NoWorld)
    monkeypatch.chdir(tmp_path)
    (tmp_path / "task.yaml").write_text(HIGH_MU.read_text())
    sp.save_plan(sp.plan_task(shipped("horizontal-offset-high-mu")), str(tmp_path / "task.plan.json"))
    design = yaml.safe_load(HIGH_MU.read_text())
    design["candidates"] = [p for p in design.pop("pushers") if p["name"] in ("left", "bottom")]
    (tmp_path / "two.design.yaml").write_text(yaml.safe_dump(design))
    rng = random.Random(seed)
    statuses = {}
    for make in (_evaluate, _reach, _trajectory, _execute, _design):
        for _ in range(CASES_PER_COMMAND):
            args = make(rng, tmp_path)
            result = CliRunner().invoke(cli, args)
            case = shlex.join(args)
            assert result.exit_code in (0, 1, 2, 3, 5), (case, result.output)
            assert "internal error" not in result.output and "Traceback" not in result.output, (case, result.output)
            assert result.exception is None or isinstance(result.exception, SystemExit), (case, result.exception)
            statuses[result.exit_code] = statuses.get(result.exit_code, 0) + 1
    assert statuses.get(2, 0) < sum(statuses.values())  # not every case refused: some ran
