"""Each hostile input and fault of the reliability issue, one by one: the exact message or the
safe behaviour, never a crash, a hang or a file written where it should not be."""
import contextlib
import dataclasses
import json
import os
import signal
import socket
import subprocess
import sys
import textwrap
import threading
import time
from pathlib import Path

import pytest
from click.testing import CliRunner

from stablepush import _core
from stablepush.errors import ArmFault, OutputError, PlanError, TaskError
from stablepush.execution import RunOptions, TcpArm, execute_plan
from stablepush.execution.protocol import PROTOCOL, decode, encode
from stablepush.outputs import write_files
from stablepush.plan import check_plan, load_plan, plan_task
from stablepush.plan.files import plan_to_dict, read_plan
from stablepush.sim.server import SimArmServer
from stablepush.task import load_task, parse_task
from stablepush.units import pose_to_si
from stablepush_cli.main import cli

from conftest import TASKS, shipped, task_text

LOW_MU = TASKS / "horizontal-offset-low-mu.yaml"


def _edited(tmp_path, old, new, name="task.yaml"):
    text = task_text("horizontal-offset-low-mu")
    assert old in text
    path = tmp_path / name
    path.write_text(text.replace(old, new, 1))
    return path


# -- numbers at the boundary ----------------------------------------------------------------------

@pytest.mark.parametrize("old, new, says", [
    ("size: [100, 25, 25]          # mm; Al 6061 square prism",
     "size: [100, 25, 25]\n  com: [1e300, 0]", "object.com[0]: must be between -10000 and 10000, got 1e+300"),
    ("step_time: 0.1", "step_time: 1.797e308", "dynamics.step_time: must be between 0.0001 and 1000"),
    ("mu: 0.425 ", "mu: 1.797e308 ", "gripper.mu: must be between 0 and 100"),
    # A positive mu too small to mean anything underflowed the cones' rows (exit 4 from the exact re-check).
    ("mu: 0.2}\n  - {name: right", "mu: 5e-324}\n  - {name: right",
     "pushers[0].mu: must be 0 (frictionless) or at least 1e-06, got 4.94066e-324"),
    ("mu: 0.425 ", "mu: 1e-170 ", "gripper.mu: must be 0 (frictionless) or at least 1e-06, got 1e-170"),
    ("max_switches: 1", "max_switches: 2147483648", "planner.max_switches: must be an integer from 0 to 100"),
    ("max_switches: 1", "max_switches: 4294967296", "planner.max_switches: must be an integer from 0 to 100"),
    ("seed: 1", "seed: 18446744073709551616", "planner.seed: must be an integer from 0 to 4294967295"),
    ("pad_rings: 1", "pad_rings: 1000000000", "gripper.pad_rings: must be an integer from 0 to 6"),
    ("pad_rings: 1", "pad_rings: 6", "gripper.pad_rings: 2 pads of 6 rings make 254 pad points; at most 128"),
    ("mu: 0.2}\n  - {name: right", "mu: 0.2, points: 4611686018427387904}\n  - {name: right",
     "pushers[0].points: must be an integer from 2 to 20"),
    ("step_time: 0.1", "step_time: 0.1\n  friction_polygon_sides: 100000000",
     "dynamics.friction_polygon_sides: must be an integer from 3 to 64"),
    ("step: [1.0, 1.0]", "step: [1e-300, 1.0]", "planner.step[0]: must be between 0.001 and 1000"),
    ("start: [0, 0, 0]", "start: [0, 0, 1e30]", "start[2]: must be between -3600 and 3600"),
    ("time_limit: 10", "time_limit: .inf", "planner.time_limit: must be finite"),
    ("time_limit: 10", "time_limit: .nan", "planner.time_limit: must be finite"),
    ("time_limit: 10", "time_limit: 9.3e9", "planner.time_limit: must be between 1e-06 and 1e+06"),
    ("name: horizontal-offset-low-mu", "name: \"a\\0b\"", "name: must be at most 100 printable characters"),
    ("name: horizontal-offset-low-mu", "name: " + "[" * 3000 + "]" * 3000, "values nested too deeply"),
    ("name: horizontal-offset-low-mu", "name: x\n? [1, 2]\n: y", "a mapping key must be a name, got a list"),
    # A duplicate key was named without its mapping ("mass: duplicate key").
    ("  mass: 202                    # g", "  mass: 202\n  mass: 203", "object.mass: duplicate key (line 21)"),
    ("name: right", "name: right, name: again", "pushers[1].name: duplicate key"),
    # YAML 1.1 reads no/off/yes/on as booleans: the message said only "got False".
    ("name: horizontal-offset-low-mu", "name: no",
     "name: must be a non-empty string, got False: YAML read it as a boolean; put the name in quotes"),
])
def test_hostile_numbers_and_yaml_are_refused_in_one_line_naming_the_field(tmp_path, old, new, says):
    result = CliRunner().invoke(cli, ["plan", str(_edited(tmp_path, old, new)), "-o", str(tmp_path / "p.json")])
    assert result.exit_code == 2, result.output
    assert says in result.stderr and len(result.stderr.strip().splitlines()) == 1, result.stderr
    assert not (tmp_path / "p.json").exists()


def test_an_alias_bomb_is_refused_before_it_grows(tmp_path):
    bomb = "a: &a [x, x, x, x, x, x, x, x, x]\n" + "".join(
        f"{chr(98 + i)}: &{chr(98 + i)} [{', '.join(['*' + chr(97 + i)] * 9)}]\n" for i in range(8))
    path = tmp_path / "bomb.yaml"
    path.write_text(bomb + task_text("horizontal-offset-low-mu"))
    result = CliRunner().invoke(cli, ["plan", str(path)])
    assert result.exit_code == 2 and "more than 100000 values (aliases expanded)" in result.stderr


def test_yaml_1_2_numbers_are_numbers():
    text = task_text("horizontal-offset-low-mu").replace("mass: 202", "mass: 2.02e2").replace("mu: 0.2}", "mu: 2e-1}")
    task = parse_task(text)
    assert task.object.mass == 202.0 and task.pushers[0].mu == 0.2


@pytest.mark.parametrize("move, says", [
    (["1e-160", "0", "0"], "move: the motion is zero or too small"),
    (["nan", "0", "0"], "move[0]: must be finite"),
    (["1e308", "0", "0"], "move[0]: must be between -10000 and 10000"),
])
def test_check_refuses_non_finite_and_vanishing_motions(move, says):
    result = CliRunner().invoke(cli, ["check", str(LOW_MU), "--move", *move])
    assert result.exit_code == 2 and says in result.stderr


def test_check_refuses_a_pose_where_the_pads_miss_the_object():
    result = CliRunner().invoke(cli, ["check", str(LOW_MU), "--move", "1", "0", "0", "--at", "1000", "0", "0"])
    assert result.exit_code == 2 and "at: the pads are not all on the object at [1000.0, 0.0, 0.0]" in result.stderr
    assert len(result.stderr.strip().splitlines()) == 1
    assert CliRunner().invoke(cli, ["check", str(LOW_MU), "--move", "1", "0", "0", "--at", "10", "0", "0"]).exit_code == 0


def test_check_refuses_a_non_finite_pose():
    result = CliRunner().invoke(cli, ["check", str(LOW_MU), "--at", "nan", "0", "0", "--move", "1", "0", "0"])
    assert result.exit_code == 2 and "at[0]: must be finite" in result.stderr


def test_the_core_refuses_what_python_would_never_pass_instead_of_trapping():
    """The C++ guards behind the validation, in a child process: a SIGFPE there fails the test."""
    script = textwrap.dedent(f"""
        import copy
        from stablepush.task import load_task
        task = load_task({str(LOW_MU)!r})
        part = copy.copy(task.object)  # 1e302 kg: past PartSpec's own range (refused there), the core's guard behind it
        object.__setattr__(part, "mass", 1e305)
        heavy = copy.copy(task)
        object.__setattr__(heavy, "object", part)
        model, heavy = task.model, heavy.model
        for m, q, dq in ((model, (0, 0, 0), (float("nan"), 0, 0)), (model, (float("inf"), 0, 0), (1e-3, 0, 0)),
                         (model, (0, 0, 0), (1e-163, 0, 0)), (heavy, (0, 0, 0), (1e300, 0, 0))):
            try:
                m.check(q, dq, 0)
                print("accepted", q, dq)
            except ValueError as exc:
                print("refused:", exc)
    """)
    out = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, timeout=60)
    assert out.returncode == 0, out.stderr
    lines = out.stdout.splitlines()
    assert lines[:3] == ["refused: the motion dq is not finite", "refused: the pose q is not finite",
                         "refused: the motion dq is zero (or under 1e-12 m and rad)"]
    assert lines[3].startswith("refused: the motion wrench overflows"), lines[3]


def test_planner_parameters_are_refused_out_of_their_declared_range():
    task = shipped("horizontal-offset-high-mu")
    model = task.model
    def settings(time_limit=1.0, **parameters):
        return _core.PlannerSettings(start=pose_to_si(task.start), goal=pose_to_si(task.goal), step=(1e-3, 0.0175),
                                     tolerance=(1e-3, 0.0175), time_limit=time_limit, parameters=parameters)

    for name, value in (("max_switches", "4294967296"), ("max_switches", "2147483648"), ("seed", "4294967296"),
                        ("seed", "-1"), ("goal_bias", "1.5"), ("rewire_radius", "nan")):
        with pytest.raises(ValueError, match=f"planner parameter '{name}'"):
            _core.plan([model], settings(**{name: value}))
    with pytest.raises(ValueError, match="time_limit must be > 0 and at most 1e6 s"):
        _core.plan([model], settings(time_limit=9.3e9))
    for tolerance in ((0.0, 0.0175), (1e-3, 0.0), (-1e-3, 0.0175)):
        zero = _core.PlannerSettings(start=pose_to_si(task.start), goal=pose_to_si(task.goal), step=(1e-3, 0.0175),
                                     tolerance=tolerance, time_limit=1.0)
        with pytest.raises(ValueError, match="tolerance must be > 0 in length and angle"):
            _core.plan([model], zero)
    ranges = _core.TRRT_STAR_PARAMETER_RANGES
    assert ranges["seed"] == ("integer", 0.0, 4294967295.0) and ranges["max_switches"][2] == 100.0


def test_seeds_above_2_31_are_their_own_seeds():
    task = shipped("large-manipulation")  # where the seed matters (test_planner.py)
    plans = [plan_to_dict(plan_task(task, seed=s)) for s in (5, 5 + 2 ** 31, 2 ** 32 - 1)]
    assert plans[0]["stats"]["seed"] == 5 and plans[1]["stats"]["seed"] == 5 + 2 ** 31
    assert plans[0]["waypoints"] != plans[1]["waypoints"]  # not seed 5 again
    assert plan_to_dict(plan_task(task, seed=2 ** 32 - 1))["waypoints"] == plans[2]["waypoints"]  # reproducible


# -- plan files -----------------------------------------------------------------------------------

def _alternate_pushers(waypoints):
    for i, w in enumerate(waypoints):
        w["pusher"] = "left" if i % 2 else "bottom"


@pytest.fixture(scope="module")
def low_mu_plan():
    return plan_to_dict(plan_task(shipped("horizontal-offset-low-mu"), seed=1))


@pytest.mark.parametrize("edit, says", [
    (lambda p: p["waypoints"][2].update(x=float("nan")), "not valid JSON (NaN is not a number JSON allows here)"),
    (lambda p: p.update(stats=[]), "stats: must be a mapping, got a list"),
    (lambda p: p.update(stats=None), "stats: must be a mapping, got null"),
    (lambda p: p.pop("solved"), "solved: missing"),
    (lambda p: p["waypoints"][3].pop("theta"), "waypoints[3].theta: missing"),
    (lambda p: p.update(solved="no"), "solved: must be a boolean, got a string"),
    (lambda p: p["waypoints"][2].update(x=p["waypoints"][2]["x"] + 50), "waypoints[2]: a step of 5"),
    (lambda p: p["waypoints"][3].update(x=10 ** 400), "waypoints[3].x: must be a finite number"),
    (lambda p: p["waypoints"][3].update(x=1e300), "waypoints[3]: a step of more unit steps than a double holds"),
    (lambda p: p["waypoints"][2].update(x="1"), 'waypoints[2].x: must be a finite number, got "1"'),
    (lambda p: p["waypoints"].extend([p["waypoints"][-1]] * 10_001), "a plan has at most 10000"),
    # "Solved" plans that do not end at this task's goal used to run with exit 0.
    (lambda p: p.update(waypoints=p["waypoints"][:6]), "not within planner.tolerance [0.5, 0.5] of the task's goal"),
    (lambda p: p.update(waypoints=p["waypoints"][:-1]), "made for another goal, or cut short?"),
    # bottom -> left -> bottom -> left: 3 switch-overs where the plan's budget is 1 (10,000 waypoints
    # alternating pushers took minutes to turn into a trajectory).
    (lambda p: _alternate_pushers(p["waypoints"][1:5]), "switch-overs, more than the plan's max_switches (1)"),
    # Fields that contradict each other or the waypoints: `show` drew such plans as solved.
    (lambda p: p.update(outcome="unreachable"), "solved: true with outcome unreachable"),
    (lambda p: p.update(outcome="sideways"), "outcome: must be one of goal_reached,"),
    (lambda p: p["stats"].update(switches=-5), "stats.switches: must be a whole number from 0 to 10000, got -5"),
    (lambda p: p["stats"].update(seed=2 ** 40), "stats.seed: must be a whole number from 0 to 4294967295"),
    (lambda p: p["waypoints"][0].update(pusher="left"), "waypoints[0].pusher: the start has no pusher, got 'left'"),
])
def test_bad_plan_files_are_refused_before_anything_moves(tmp_path, low_mu_plan, edit, says):
    plan = json.loads(json.dumps(low_mu_plan))
    edit(plan)
    path = tmp_path / "bad.plan.json"
    path.write_text(json.dumps(plan))
    with pytest.raises(PlanError) as error:
        check_plan(shipped("horizontal-offset-low-mu"), load_plan(path), source=str(path))
    assert says in str(error.value)
    result = CliRunner().invoke(cli, ["execute", str(path), "--task", str(LOW_MU), "--arm", "127.0.0.1:9"])
    assert result.exit_code == 2 and says in result.stderr


def test_show_refuses_a_plan_called_solved_that_ends_short_of_the_goal(tmp_path, low_mu_plan):
    """A plan file whose `solved` says more than its waypoints: the start alone, called solved."""
    plan = json.loads(json.dumps(low_mu_plan))
    plan["waypoints"] = plan["waypoints"][:1]
    path = tmp_path / "start.plan.json"
    path.write_text(json.dumps(plan))
    result = CliRunner().invoke(cli, ["show", str(path), "--task", str(LOW_MU), "-o", str(tmp_path / "p.png")])
    assert result.exit_code == 2 and "not within planner.tolerance" in result.stderr, result.output
    assert not (tmp_path / "p.png").exists()


def test_a_partial_plan_one_switch_over_past_its_budget_is_drawn_and_two_are_refused(tmp_path, low_mu_plan):
    """The search extends only nodes within max_switches, so the node nearest the goal, which an
    unsolved plan ends at, may be one switch-over past it; `show` draws such a plan."""
    task = shipped("horizontal-offset-low-mu")
    plan = json.loads(json.dumps(low_mu_plan))  # bottom -> left: one switch-over
    plan.update(solved=False, outcome="time_limit", message="not solved: the time limit ran out")
    plan["stats"]["max_switches"] = 0
    path = tmp_path / "partial.plan.json"
    path.write_text(json.dumps(plan))
    check_plan(task, load_plan(path), require_solved=False)
    result = CliRunner().invoke(cli, ["show", str(path), "--task", str(LOW_MU), "-o", str(tmp_path / "p.png")])
    assert result.exit_code == 0, result.output
    _alternate_pushers(plan["waypoints"][1:4])  # bottom -> left -> bottom -> left: 3
    path.write_text(json.dumps(plan))
    with pytest.raises(PlanError, match="switch-overs, more than the plan's max_switches"):
        check_plan(task, load_plan(path), require_solved=False)


def test_a_nominal_plan_is_refused_for_the_same_task_with_an_uncertainty_box():
    """Every push is re-checked at each corner of the box: a plan made without it has pushes that
    are stable for the nominal model only (its margins are 0.1 N)."""
    nominal = plan_task(shipped("horizontal-offset-low-mu"), seed=1)
    uncertain = parse_task(task_text("horizontal-offset-low-mu") + "uncertainty: {pusher_mu: 0.15}\n")
    with pytest.raises(PlanError, match=r"changed since the plan was made \(uncertainty.pusher_mu\)"):
        check_plan(uncertain, nominal)
    with pytest.raises(PlanError, match="is not a stable push for this task"):  # the pushes, re-checked
        check_plan(uncertain, dataclasses.replace(nominal, task_identity=None))
    check_plan(uncertain, plan_task(uncertain, seed=1))


def test_deeply_nested_plan_json_is_refused(tmp_path):
    path = tmp_path / "nested.plan.json"
    path.write_text("[" * 100_000 + "]" * 100_000)
    with pytest.raises(PlanError, match="nested too deeply"):
        read_plan(path)


# -- output files ---------------------------------------------------------------------------------

def test_an_output_that_cannot_be_made_is_refused_naming_it_not_a_temporary(tmp_path, monkeypatch, low_mu_plan):
    """A directory the command may not write to is refused before any work, naming the option; a
    place where no file can be made (/proc, whatever the permissions say) or a full device after
    it, naming the option and the output, for plan files and ROS 2 bags alike (the bag's scratch
    directory was an internal error)."""
    from stablepush import outputs

    access = os.access
    with monkeypatch.context() as m:
        m.setattr(outputs.os, "access", lambda path, mode: Path(path) != tmp_path and access(path, mode))
        result = CliRunner().invoke(cli, ["plan", str(LOW_MU), "-o", str(tmp_path / "p.json")])
    assert result.exit_code == 2 and "-o " in result.stderr and "is not writable" in result.stderr, result.stderr
    if not os.path.isdir("/proc/self"):
        pytest.skip("no /proc")
    result = CliRunner().invoke(cli, ["plan", str(LOW_MU), "-o", "/proc/p.json"])
    assert result.exit_code == 2 and "error: -o /proc/p.json: cannot write (" in result.stderr, result.stderr
    if os.path.exists("/dev/full"):
        result = CliRunner().invoke(cli, ["plan", str(LOW_MU), "-o", str(tmp_path / "p.json"), "--csv", "/dev/full"])
        assert result.exit_code == 2 and "error: --csv /dev/full: cannot write (" in result.stderr, result.stderr
    plan = tmp_path / "p.plan.json"
    plan.write_text(json.dumps(low_mu_plan))
    result = CliRunner().invoke(cli, ["trajectory", str(plan), "--task", str(LOW_MU), "-o", "/proc/p.mcap"])
    assert result.exit_code == 2 and "error: -o /proc/p.mcap: cannot write the bag" in result.stderr, result.output


def test_the_default_output_comes_from_the_task_file_name_never_its_name_field(tmp_path, monkeypatch):
    path = _edited(tmp_path, "name: horizontal-offset-low-mu", "name: ../escaped", name="mine.yaml")
    work = tmp_path / "work"
    work.mkdir()
    monkeypatch.chdir(work)
    result = CliRunner().invoke(cli, ["plan", str(path), "--quiet"])
    assert result.exit_code == 0, result.output
    assert (work / "mine.plan.json").exists() and not (tmp_path / "escaped.plan.json").exists()


def test_outputs_write_through_symlinks_refuse_directories_and_keep_devices(tmp_path):
    target = tmp_path / "real.json"
    target.write_text("old")
    link = tmp_path / "link.json"
    link.symlink_to(target)
    write_files({link: "new"})
    assert link.is_symlink() and target.read_text() == "new"
    (tmp_path / "dir.json").mkdir()
    with pytest.raises(OutputError, match="not a regular file; refusing to replace it"):
        write_files({tmp_path / "dir.json": "x"})
    write_files({os.devnull: "discarded"})
    assert Path(os.devnull).is_char_device()
    with pytest.raises(OutputError, match="does not exist"):
        write_files({tmp_path / "no" / "such.json": "x"})


def _plan_and_task(tmp_path):
    task = tmp_path / "task.yaml"
    task.write_text(task_text("horizontal-offset-low-mu"))
    plan = tmp_path / "task.plan.json"
    assert CliRunner().invoke(cli, ["plan", str(task), "-o", str(plan), "--quiet"]).exit_code == 0
    return task, plan


@pytest.mark.parametrize("args, says", [
    (["plan", "{task}", "-o", "{task}"], "-o {task}: is the input TASK.yaml; refusing to write over it"),
    (["plan", "{task}", "-o", "{link}"], "-o {link}: is the input TASK.yaml; refusing to write over it"),
    (["plan", "{task}", "-o", "{dir}/a.json", "--csv", "{dir}/a.json"], "--csv {dir}/a.json: is also the output of -o"),
    (["plan", "{task}", "--csv", "{dir}/task.plan.json"], "--csv {dir}/task.plan.json: is also the output of the default -o"),
    (["show", "{plan}", "--task", "{task}", "-o", "{plan}"], "-o {plan}: the file name must end in .png, .pdf or .svg"),
    (["show", "{plan}", "--task", "{task}", "-o", "{dir}/p.jpg"], "the file name must end in .png, .pdf or .svg"),
    (["show", "{plan}", "--task", "{task}", "-o", "{dir}/p.png", "--gif", "{dir}/p.png"],
     "--gif {dir}/p.png: the file name must end in .gif"),
    (["show", "{plan}", "--task", "{task}", "-o", "{dir}/plan.png", "--gif", "{dir}/no/p.gif"],
     "--gif {dir}/no/p.gif: the directory {dir}/no does not exist"),
    (["trajectory", "{plan}", "--task", "{task}", "-o", "{dir}/task.plan.json"],
     "-o {dir}/task.plan.json: is the input PLAN.json; refusing to write over it"),
    (["cone", "{task}", "--pusher", "left", "-o", "{dir}/c.jpg"], "the file name must end in .png, .pdf or .svg"),
    (["execute", "{plan}", "--task", "{task}", "--arm", "127.0.0.1:9", "--json", "{task}"],
     "--json {task}: is the input --task; refusing to write over it"),
    (["reach", "{task}", "--x", "0:1:2", "--workers", "1", "--json", "{dir}/no/r.json"],
     "--json {dir}/no/r.json: the directory {dir}/no does not exist"),
    (["reach", "{task}", "--x", "0:1:2", "--workers", "1", "--plot", "{dir}/r.json"],
     "--plot {dir}/r.json: the file name must end in .png, .pdf or .svg"),
    (["evaluate", "{task}", "--plan", "{plan}", "--trials", "1", "--workers", "1", "--csv", "{plan}"],
     "--csv {plan}: is the input --plan; refusing to write over it"),
])
def test_an_output_over_an_input_another_output_or_unwritable_is_refused_before_any_work(tmp_path, monkeypatch, args,
                                                                                         says):
    """Each was written after the work: over the task or plan (lost without a word), over the other
    output, as PNG bytes under a .pdf name, or after a whole reach map had been planned."""
    monkeypatch.chdir(tmp_path)  # where default outputs go
    task, plan = _plan_and_task(tmp_path)
    (tmp_path / "link.yaml").symlink_to(task)
    names = {"task": task, "plan": plan, "dir": tmp_path, "link": tmp_path / "link.yaml"}
    before = {p: p.read_bytes() for p in (task, plan)}
    result = CliRunner().invoke(cli, [a.format(**names) for a in args])
    assert result.exit_code == 2, result.output
    assert says.format(**names) in result.stderr
    assert {p: p.read_bytes() for p in (task, plan)} == before
    assert not any(tmp_path.glob("*.png")) and not (tmp_path / "a.json").exists()


@pytest.mark.parametrize("args, says", [
    (["reach", str(LOW_MU), "--x", "nan:nan:1"], "expected FROM:TO:COUNT, FROM and TO from -10000 to 10000"),
    (["reach", str(LOW_MU), "--z", "0:inf:2"], "expected FROM:TO:COUNT, FROM and TO from -10000 to 10000"),
    (["check", str(LOW_MU), "--move", "1", "0", "0", "--heading-step", "5"], "--heading-step: only with --directions"),
    (["evaluate", str(LOW_MU), "--trials", "1", "--ray", "notanaddress"], "Invalid value for '--ray': expected HOST:PORT"),
    (["reach", str(LOW_MU), "--ray", ":::"], "Invalid value for '--ray': expected HOST:PORT"),
    (["bench", str(LOW_MU), "--ray", "ray://host:port"], "Invalid value for '--ray': expected HOST:PORT"),
    (["evaluate", str(LOW_MU), "--ray", "127.0.0.1:1"], "error: no Ray head answers at 127.0.0.1:1"),
    (["bench", "--checks", str(LOW_MU), "-n", "0"], "Invalid value for '-n' / '--count'"),
])
def test_options_that_cannot_apply_are_refused_as_usage_errors(args, says):
    result = CliRunner().invoke(cli, args)
    assert result.exit_code == 2 and says in result.stderr, result.output


@pytest.mark.parametrize("extra, says", [
    (["--arm", "nohostport"], "Invalid value for '--arm': expected HOST:PORT"),
    (["--arm", "127.0.0.1:99999"], "Invalid value for '--arm': expected HOST:PORT with a port from 1 to 65535"),
    (["--arm", "127.0.0.1:9", "--resume-from", "99"], "error: --resume-from: must be a step from 0 to"),
])
def test_execute_names_the_option_it_refuses(tmp_path, extra, says):
    task, plan = _plan_and_task(tmp_path)
    result = CliRunner().invoke(cli, ["execute", str(plan), "--task", str(task)] + extra)
    assert result.exit_code == 2 and says in result.stderr, result.output


def test_an_option_that_needs_another_is_named_alone(tmp_path):
    """It named --engine and --tracker-noise too, which were not given."""
    task, plan = _plan_and_task(tmp_path)
    result = CliRunner().invoke(cli, ["execute", str(plan), "--task", str(task), "--arm", "127.0.0.1:9",
                                      "--sim-mu-scale", "2"])
    assert result.exit_code == 2
    assert "error: --sim-mu-scale: only with --sim" in result.stderr, result.stderr


def test_figures_are_written_in_the_format_their_name_asks(tmp_path):
    task, plan = _plan_and_task(tmp_path)
    for suffix, magic in ((".png", b"\x89PNG"), (".pdf", b"%PDF"), (".svg", b"<?xml")):
        out = tmp_path / f"plan{suffix}"
        result = CliRunner().invoke(cli, ["show", str(plan), "--task", str(task), "-o", str(out)])
        assert result.exit_code == 0, result.output
        assert out.read_bytes().startswith(magic)


def test_an_upper_case_suffix_picks_the_format_as_a_lower_case_one(tmp_path):
    task, plan = _plan_and_task(tmp_path)
    out = tmp_path / "T.JSON"
    result = CliRunner().invoke(cli, ["trajectory", str(plan), "--task", str(task), "-o", str(out)])
    assert result.exit_code == 0, result.output
    assert json.loads(out.read_text())["columns"][0] == "t"


@pytest.mark.parametrize("args, says", [
    (["plan", str(LOW_MU), "-o", "/dev/stdout"], "solved in"),
    (["reach", str(LOW_MU), "--x", "0:1:2", "--z", "0:0:1", "--theta", "0:0:1", "--workers", "1", "--quiet",
      "--json", "/dev/stdout"], "goals reached"),
])
def test_a_file_written_to_stdout_has_the_stream_alone_and_the_summary_goes_to_stderr(args, says):
    """`reach --json /dev/stdout | jq .` failed: the summary followed the JSON on stdout."""
    run = subprocess.run([sys.executable, "-m", "stablepush_cli.main"] + args, capture_output=True, text=True,
                         timeout=120)
    assert run.returncode == 0, run.stderr
    assert json.loads(run.stdout) and says in run.stderr


def test_a_plan_written_to_dev_stdout_into_a_pipe_reaches_the_pipe():
    """/dev/stdout into a pipe resolves to no file name; it was taken for a new file and refused."""
    run = subprocess.run([sys.executable, "-m", "stablepush_cli.main", "plan", str(LOW_MU), "-o", "/dev/stdout",
                          "--quiet"], capture_output=True, text=True, timeout=120)
    assert run.returncode == 0, run.stderr
    assert json.loads(run.stdout)["format"] == "stablepush.plan/1"


def test_a_closed_output_pipe_ends_quietly_with_the_sigpipe_status():
    """`stablepush check ... | head`: the reader is gone before the first line is written."""
    child = subprocess.Popen([sys.executable, "-m", "stablepush_cli.main", "check", str(LOW_MU), "--move", "1", "0",
                              "0"], stdout=subprocess.PIPE, stderr=subprocess.PIPE)
    child.stdout.close()
    stderr = child.stderr.read().decode()
    assert child.wait(timeout=60) == 141, stderr
    assert stderr == ""


def test_outputs_respect_the_umask(tmp_path):
    old = os.umask(0o027)
    try:
        write_files({tmp_path / "a.json": "x"})
    finally:
        os.umask(old)
    assert (tmp_path / "a.json").stat().st_mode & 0o777 == 0o640


def test_a_json_and_csv_pair_stays_consistent_when_the_writer_is_killed(tmp_path):
    """A writer replaces the pair over and over; SIGTERM at random moments must never leave a
    new JSON beside an old CSV, nor a temporary file."""
    script = textwrap.dedent(f"""
        import sys
        from stablepush.outputs import write_files
        k = 0
        print("ready", flush=True)
        while True:
            k += 1
            write_files({{{str(tmp_path / 'p.json')!r}: str(k) * 20000, {str(tmp_path / 'p.csv')!r}: str(k) * 20000}})
    """)
    import random

    rng = random.Random(3)
    for _ in range(40):
        writer = subprocess.Popen([sys.executable, "-c", script], stdout=subprocess.PIPE, text=True)
        writer.stdout.readline()
        time.sleep(rng.uniform(0.0, 0.05))
        writer.send_signal(signal.SIGTERM)
        writer.wait(timeout=30)
        if (tmp_path / "p.json").exists():
            assert (tmp_path / "p.json").read_text() == (tmp_path / "p.csv").read_text()
        assert not list(tmp_path.glob(".p.*.tmp"))


# -- the arm link ---------------------------------------------------------------------------------

def _hello(scene, rate_hz=100):
    return encode({"type": "hello", "protocol": PROTOCOL, "rate_hz": rate_hz, "scene": scene})


@pytest.fixture(scope="module")
def high_mu_run():
    from stablepush.execution.world import place_features, scene_description

    task = shipped("horizontal-offset-high-mu")
    plan = check_plan(task, plan_task(task, seed=1))
    return task, plan, scene_description(task, place_features(task, plan.waypoints), task.start).as_dict()


def test_the_sim_arm_survives_hostile_clients_and_then_serves_a_good_one(high_mu_run):
    task, plan, scene = high_mu_run
    server = SimArmServer(log=lambda text: None, idle_timeout=3.0)  # longer than the 2 s a new client waits
    server.start_in_thread()
    try:
        def exchange(payload, wait=True):
            with socket.create_connection((server.host, server.port), timeout=10) as conn:
                conn.sendall(payload)
                reader = conn.makefile("rb")
                return [decode(line, "server") for line in reader] if wait else None

        replies = exchange(b"[" * 100_000 + b"\n")
        assert replies[-1]["type"] == "error" and "nested too deeply" in replies[-1]["message"]
        replies = exchange(_hello(scene, rate_hz=0))
        assert "rate_hz must be between 1 and 1000" in replies[-1]["message"]
        # 826 bytes asking for 1e9 pad rings kept the server busy 31 s, until MemoryError.
        huge = json.loads(json.dumps(scene))
        huge["gripper"]["pad_rings"] = 10 ** 9
        started = time.monotonic()
        replies = exchange(_hello(huge))
        assert "scene.gripper.pad_rings must be an integer from 0 to 6" in replies[-1]["message"]
        assert time.monotonic() - started < 2.0
        replies = exchange(b'{"type": "hello", "prot')  # half a line, then silence: dropped
        assert "no complete message from the client within 3 s" in replies[-1]["message"]
        # A session in progress: a second client is told the arm is busy.
        with socket.create_connection((server.host, server.port), timeout=30) as first:
            first.sendall(_hello(scene))
            assert decode(first.makefile("rb").readline(), "server")["type"] == "ready"
            assert "busy" in exchange(b"")[-1]["message"]
        # A client that half-closes after 20 waypoints (it kept the arm busy for about 28 s): the
        # server ends its session at the end of what it sent, so the good client below is served.
        from stablepush.execution.stream import arm_trajectory
        from stablepush.execution.world import place_features

        points = arm_trajectory(task, plan.waypoints, place_features(task, plan.waypoints), 100.0,
                                scene["gripper_pose"])[:20]
        with socket.create_connection((server.host, server.port), timeout=30) as half:
            half.sendall(_hello(scene) + b"".join(
                encode({"type": "waypoint", "seq": w.seq, "t": w.t, "step": w.step, "phase": w.phase,
                        "pose": list(w.pose)}) for w in points))
            half.shutdown(socket.SHUT_WR)
            replies = [decode(line, "server") for line in half.makefile("rb")]
            assert replies[0]["type"] == "ready" and [r["seq"] for r in replies[1:]] == list(range(20))
        time.sleep(0.2)
        report = execute_plan(task, plan, TcpArm(server.host, server.port), RunOptions(rate_hz=100.0, pace=False))
        assert report.last_confirmed_step == len(plan.waypoints) - 1 and report.final_error["distance"] < 0.5
    finally:
        server.close()


def test_the_executor_holds_its_ack_deadline_against_a_trickling_arm(high_mu_run):
    task, plan, scene = high_mu_run
    listener = socket.create_server(("127.0.0.1", 0))

    def trickle():
        conn, _ = listener.accept()
        with conn, contextlib.suppress(OSError):  # the executor hangs up when its deadline passes
            conn.makefile("rb").readline()
            for byte in encode({"type": "ready", "protocol": PROTOCOL, "arm": "x", "state": {}}):
                time.sleep(0.1)
                conn.sendall(bytes([byte]))

    threading.Thread(target=trickle, daemon=True).start()
    started = time.monotonic()
    with pytest.raises(ArmFault, match="no complete message from the arm server .* within 1 s"):
        execute_plan(task, plan, TcpArm("127.0.0.1", listener.getsockname()[1], 1.0), RunOptions(rate_hz=100.0, pace=False))
    assert time.monotonic() - started < 5.0  # the deadline plus the stop's 2 s, not the trickle's 8 s
    listener.close()


@pytest.mark.parametrize("state, says", [
    ({"ee_pose": "here"}, "state.ee_pose must be 7 finite numbers"),
    ({"ee_pose": [0, 0, 0, 1, 0, 0]}, "state.ee_pose must be 7 finite numbers"),
    ({"ee_pose": [0, 0, float("nan"), 1, 0, 0, 0]}, "not a JSON line"),
    ({"ee_pose": [0, 0, 0, 1, 0, 0, 0], "object_in_grasp": {"x": "1"}}, "object_in_grasp must hold finite numbers"),
    # Finite but absurd: 1e200 overflowed (exit 4), 100 m streamed 88,000 waypoints of approach, a
    # tracked theta of 1e17 reached the re-planner as a zero motion (exit 4, the arm never stopped).
    ({"ee_pose": [1e200, 0, 0, 1, 0, 0, 0]}, "state.ee_pose is more than 10 m from the arm's base"),
    ({"ee_pose": [100, 0, 0, 1, 0, 0, 0]}, "state.ee_pose is more than 10 m from the arm's base"),
    ({"ee_pose": [0.4, 0, 0.3, 2, 0, 0, 0]}, "state.ee_pose: the quaternion is not of unit length"),
    ({"ee_pose": [0.4, 0, 0.3, 1, 0, 0, 0], "object_in_grasp": {"x": 0, "z": 0, "theta": 1e17}},
     "object_in_grasp must have"),
    ({"ee_pose": [0.4, 0, 0.3, 1, 0, 0, 0], "contact_force": [0, 0]}, "state.contact_force must be 3 finite"),
    ({"ee_pose": [0.4, 0, 0.3, 1, 0, 0, 0], "contact_force": [0, 1e9, 0]}, "state.contact_force must be 3 finite"),
])
def test_bad_arm_states_end_in_an_arm_fault_and_a_stop(high_mu_run, state, says):
    task, plan, _ = high_mu_run
    listener = socket.create_server(("127.0.0.1", 0))
    stops = []

    def arm():
        conn, _ = listener.accept()
        with conn:
            reader = conn.makefile("rb")
            reader.readline()
            conn.sendall(json.dumps({"type": "ready", "protocol": PROTOCOL, "arm": "x", "state": state}).encode() + b"\n")
            stops.append(reader.readline())

    threading.Thread(target=arm, daemon=True).start()
    with pytest.raises(ArmFault, match=says) as fault:
        execute_plan(task, plan, TcpArm("127.0.0.1", listener.getsockname()[1], 2.0), RunOptions(rate_hz=100.0, pace=False))
    time.sleep(0.1)
    assert stops and json.loads(stops[0])["type"] == "stop"
    assert fault.value.last_confirmed_step == 0
    listener.close()


def test_a_task_error_is_a_stablepush_error_with_exit_status_2():
    from stablepush.errors import StablepushError
    from stablepush_cli.main import EXIT_STATUS

    assert issubclass(TaskError, StablepushError) and issubclass(PlanError, StablepushError)
    assert dict(EXIT_STATUS)[TaskError] == 2 and dict(EXIT_STATUS)[ArmFault] == 3


# -- the files a user names ----------------------------------------------------------------------

@pytest.mark.parametrize("kind", ["fifo", "device", "sparse"])
def test_task_and_plan_files_are_read_bounded_and_regular_only(tmp_path, kind):
    """A FIFO used to hang, /dev/zero and a 3 GB sparse file were read whole (MemoryError, exit 4)."""
    path = tmp_path / "input"
    if kind == "fifo":
        os.mkfifo(path)
    elif kind == "device":
        path = Path("/dev/zero")
    else:
        with open(path, "wb") as handle:
            handle.truncate(3 * 2**30)
    says = "larger than" if kind == "sparse" else "not a regular file"
    task = CliRunner().invoke(cli, ["plan", str(path), "-o", str(tmp_path / "p.json")])
    assert task.exit_code == 2 and says in task.stderr and len(task.stderr.strip().splitlines()) == 1, task.stderr
    plan = CliRunner().invoke(cli, ["show", str(path), "--task", str(LOW_MU), "-o", str(tmp_path / "x.png")])
    assert plan.exit_code == 2 and says in plan.stderr, plan.stderr


@pytest.mark.parametrize("name, says", [("part.3mf", "a mesh file is one of stl, obj, ply, off"),
                                        ("part.stl", "not a regular file")])
def test_mesh_files_are_read_bounded_in_known_formats(tmp_path, name, says):
    mesh = tmp_path / name
    if name.endswith(".stl"):
        os.mkfifo(mesh)
    else:
        mesh.write_bytes(b"PK\x03\x04")
    task = tmp_path / "task.yaml"
    task.write_text("object: {shape: mesh, file: " + name + ", mass: 10}\ngripper: {grip_force: 10, mu: 0.5}\n"
                    "pushers: [{name: left, at: [-20, 0], mu: 0.5}]\nstart: [0, 0, 0]\ngoal: [1, 0, 0]\n")
    result = CliRunner().invoke(cli, ["plan", str(task)])
    assert result.exit_code == 2 and "object.file" in result.stderr and says in result.stderr, result.stderr


def test_ctrl_c_ends_a_long_search_at_once_and_writes_nothing(tmp_path):
    """SIGINT 2 s into a search that cannot succeed (the T to a goal below its start: no fixture
    pushes it down, docs/reach.md) with a 20 s limit used to return only at the limit; it now
    stops within a flag check."""
    task = tmp_path / "stuck.yaml"
    text = task_text("t-shaped")
    task.write_text(text.replace("time_limit: 10", "time_limit: 20").replace(
        "goal: [25, 17.7, 0]", "goal: [0, -8, 0]"))
    assert "time_limit: 20" in task.read_text() and "goal: [0, -8, 0]" in task.read_text()
    out = tmp_path / "stuck.plan.json"
    process = subprocess.Popen([sys.executable, "-c", "from stablepush_cli.main import cli; cli()", "plan", str(task),
                                "-o", str(out)], stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    time.sleep(2.0)
    assert process.poll() is None  # still searching
    process.send_signal(signal.SIGINT)
    interrupted = time.monotonic()
    _, stderr = process.communicate(timeout=15)
    assert time.monotonic() - interrupted < 1.5, stderr
    assert process.returncode == 1 and "Aborted!" in stderr and not out.exists()


def test_a_trajectory_past_the_sample_cap_is_refused_in_bounded_time(monkeypatch, tmp_path):
    """A valid plan whose trajectory would pass the samples cap (issue 24, item 8) is refused with
    one line naming the cap and the rate, before it takes minutes and gigabytes."""
    from stablepush.execution import stream

    monkeypatch.setattr(stream, "MAX_TRAJECTORY_SAMPLES", 2000)
    task = str(TASKS / "pivoting.yaml")
    plan = tmp_path / "p.plan.json"
    assert CliRunner().invoke(cli, ["plan", task, "-o", str(plan), "--quiet"]).exit_code == 0
    result = CliRunner().invoke(cli, ["trajectory", str(plan), "--task", task, "-o", str(tmp_path / "t.csv"),
                                      "--rate", "1000"])
    assert result.exit_code == 2, result.output
    assert "2000 samples" in result.output and "1000 Hz" in result.output and "lower rate" in result.output
    assert not (tmp_path / "t.csv").exists()


def _plan_then_edit(tmp_path, edit):
    """A plan of the high-mu offset, and its task file edited afterwards by `edit` (text -> text)."""
    source = (TASKS / "horizontal-offset-high-mu.yaml").read_text()
    task = tmp_path / "task.yaml"
    task.write_text(source)
    plan = tmp_path / "task.plan.json"
    assert CliRunner().invoke(cli, ["plan", str(task), "-o", str(plan), "--quiet"]).exit_code == 0
    task.write_text(edit(source))
    return str(plan), str(task)


@pytest.mark.parametrize("edit, changed", [
    (lambda t: t.replace("goal: [20, 0, 0]", "goal: [19.5, 0, 0]"), "goal"),  # still within tolerance of the end
    (lambda t: t.replace("grip_force: 10 ", "grip_force: 10.5 "), "gripper.grip_force"),
])
def test_every_command_and_the_api_refuse_a_plan_whose_task_changed_and_name_what(tmp_path, edit, changed):
    """A user edited the task after planning: the library's check_plan refuses the plan (the rule
    is not the CLI's), so execute, show, trajectory, evaluate and the API all do, naming the field."""
    import stablepush as sp
    from stablepush.evaluation import Batch, Spreads

    plan, task = _plan_then_edit(tmp_path, edit)
    for args in (["execute", plan, "--task", task, "--sim", "--quiet"],
                 ["show", plan, "--task", task, "-o", str(tmp_path / "p.png")],
                 ["trajectory", plan, "--task", task, "-o", str(tmp_path / "t.csv")],
                 ["evaluate", task, "--plan", plan, "--trials", "1", "--quiet"]):
        result = CliRunner().invoke(cli, args)
        assert result.exit_code == 2, (args, result.output)
        assert "changed since the plan was made" in result.output and changed in result.output, result.output
    assert not (tmp_path / "p.png").exists() and not (tmp_path / "t.csv").exists()
    edited, made = load_task(task), load_plan(plan)
    for call in (lambda: sp.check_plan(edited, made), lambda: sp.trajectory(edited, made),
                 lambda: sp.plan_figure(edited, made),
                 lambda: Batch(task=edited, plan=made, spreads=Spreads())):
        with pytest.raises(PlanError, match=f"task_identity: .*changed since the plan was made .*{changed}"):
            call()
    # The pad mu edited in code, as the user study did: the same refusal.
    with pytest.raises(PlanError, match=r"changed since the plan was made \(gripper.mu\)"):
        sp.check_plan(load_task(str(TASKS / "horizontal-offset-high-mu.yaml")).with_values({"gripper.mu": 0.5}),
                      sp.plan_task(load_task(str(TASKS / "horizontal-offset-high-mu.yaml"))))


def test_a_pusher_edited_after_planning_is_named(tmp_path):
    from stablepush.plan.verify import changes_since_planned

    plan, task = _plan_then_edit(tmp_path, lambda t: t.replace("mu: 0.6", "mu: 0.61", 1))
    changes = changes_since_planned(load_task(task), load_plan(plan))
    assert changes and all(c.startswith("pushers.") and c.endswith(".mu") for c in changes), changes


def test_a_hand_edited_task_record_and_an_old_plan_file(tmp_path):
    plan, task = _plan_then_edit(tmp_path, lambda t: t)
    data = json.loads(Path(plan).read_text())
    data["task_identity"]["fields"]["goal"] = [0, 0, 0]
    Path(plan).write_text(json.dumps(data))
    with pytest.raises(PlanError, match="digest"):
        load_plan(plan)
    del data["task_identity"]  # a plan file from before the record: read as before, nothing to compare
    Path(plan).write_text(json.dumps(data))
    result = CliRunner().invoke(cli, ["show", plan, "--task", task, "-o", str(tmp_path / "p.png")])
    assert result.exit_code == 0 and "changed since" not in result.output


@pytest.mark.parametrize("key, value, says", [("min_margin", 1.0, "planner.min_margin"),
                                              ("min_hold_ratio", 5.0, "planner.min_hold_ratio")])
def test_check_plan_holds_a_plan_to_the_tasks_min_margin_and_min_hold_ratio(key, value, says):
    """Issue 24, item 4: min_margin and min_hold_ratio were not checked against a plan."""
    import dataclasses

    task = shipped("horizontal-offset-high-mu")
    plan = plan_task(task, seed=1)
    check_plan(task, plan)
    stricter = dataclasses.replace(task, planner=task.planner.replace(**{key: value}))
    with pytest.raises(PlanError, match=says):
        check_plan(stricter, plan)


HOSTILE_VALUES = [1e308, -1e308, 1e17, -1e17, 1e-300, 0.0, 50.0, "x", None, [], {}, True, float("nan")]


@pytest.mark.parametrize("seed", range(40))
def test_generated_hostile_arm_states_end_in_a_report_or_a_fault_with_a_stop(high_mu_run, seed):
    """Issue 24's arm surface, generated: an arm that answers one ack (or its ready) with a hostile
    value in ee_pose or object_in_grasp, or with a key missing, closed loop on. The run ends in a
    report or an ArmFault, and in a fault the arm is told to stop."""
    import random

    from stablepush.execution.closed_loop import ClosedLoop

    task, plan, _ = high_mu_run
    rng = random.Random(seed)
    bad_at = rng.randrange(0, 60)  # 0: the ready
    listener = socket.create_server(("127.0.0.1", 0))
    stops = []

    def state(pose, in_grasp, hostile: bool) -> dict:
        out = {"ee_pose": list(pose), "joints": [0.0] * 7, "object_in_grasp": dict(in_grasp)}
        if hostile:
            where = rng.choice(["ee_pose", "object_in_grasp", "missing"])
            if where == "ee_pose":
                out["ee_pose"][rng.randrange(7)] = rng.choice(HOSTILE_VALUES)
            elif where == "object_in_grasp":
                out["object_in_grasp"][rng.choice(["x", "z", "theta"])] = rng.choice(HOSTILE_VALUES)
            else:
                del out[rng.choice(["ee_pose", "object_in_grasp"])]
        return out

    def arm():
        conn, _ = listener.accept()
        with conn:
            reader = conn.makefile("rb")
            hello = json.loads(reader.readline())
            pose = hello["scene"]["gripper_pose"]
            x, z, theta = hello["scene"]["object_in_grasp"]
            in_grasp = {"x": x, "z": z, "theta": theta}
            conn.sendall(json.dumps({"type": "ready", "protocol": PROTOCOL, "arm": "x",
                                     "state": state(pose, in_grasp, bad_at == 0)}).encode() + b"\n")
            for line in reader:
                msg = json.loads(line)
                if msg["type"] == "stop":
                    stops.append(msg)
                    conn.sendall(json.dumps({"type": "stopped", "state": state(pose, in_grasp, False)}).encode() + b"\n")
                    return
                if msg["type"] == "bye":
                    return
                pose = msg["pose"]
                conn.sendall(json.dumps({"type": "ack", "seq": msg["seq"],
                                         "state": state(pose, in_grasp, msg["seq"] + 1 == bad_at)}).encode() + b"\n")

    threading.Thread(target=arm, daemon=True).start()
    try:
        report = execute_plan(task, plan, TcpArm("127.0.0.1", listener.getsockname()[1], 2.0), RunOptions(rate_hz=100.0, pace=False, closed_loop=ClosedLoop.for_task(task)))
        # A run that ends in a report took the hostile state in its stride: every step confirmed, the
        # arm never told to stop, and a report that strict JSON writes (no nan or inf let through).
        assert report.last_confirmed_step == report.total_steps and not stops, (report.last_confirmed_step, stops)
        json.dumps(report.as_dict(), allow_nan=False)
    except ArmFault:
        time.sleep(0.1)
        assert stops, "the arm was not told to stop"
    finally:
        listener.close()
