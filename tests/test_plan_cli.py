"""`stablepush plan` and `stablepush bench` as a user runs them: files, exit codes, messages."""
import csv
import json
import subprocess
import sys

import yaml

from conftest import TASKS, task_text

LOW_MU = str(TASKS / "horizontal-offset-low-mu.yaml")


def run(*args, cwd=None):
    return subprocess.run([sys.executable, "-m", "stablepush_cli.main", *args], capture_output=True, text=True, cwd=cwd)


def test_plan_writes_json_and_csv(tmp_path):
    out, table = tmp_path / "p.json", tmp_path / "p.csv"
    r = run("plan", LOW_MU, "-o", str(out), "--csv", str(table), "--seed", "2")
    assert r.returncode == 0, r.stderr
    assert "solved" in r.stdout and "bottom -> left" in r.stdout
    plan = json.loads(out.read_text())
    assert plan["format"] == "stablepush.plan/1" and plan["task"] == "horizontal-offset-low-mu"
    assert plan["solved"] is True and plan["stats"]["seed"] == 2
    for key in ("planning_time_s", "iterations", "nodes", "feasibility_checks", "switches"):
        assert key in plan["stats"]
    first, second = plan["waypoints"][0], plan["waypoints"][1]
    assert first == {"x": 0.0, "z": 0.0, "theta": 0.0, "pusher": None, "margin": None, "margin_per_normal": None, "case": None,
                     "pusher_in_gripper": None}
    assert second["pusher"] == "bottom" and second["margin"] > 0
    contact = second["pusher_in_gripper"]
    assert set(contact) == {"from", "to", "normal"} and abs(contact["normal"][1]) > 0.99  # bottom faces up
    rows = list(csv.DictReader(table.open()))
    assert list(rows[0])[:5] == ["step", "x", "z", "theta", "pusher"]
    assert len(rows) == len(plan["waypoints"])
    assert [float(rows[-1][k]) for k in ("x", "z", "theta")] == [plan["waypoints"][-1][k] for k in ("x", "z", "theta")]
    assert not [p for p in tmp_path.iterdir() if p.name.endswith(".tmp")]  # atomic writes leave nothing behind


def test_same_seed_same_file(tmp_path):
    a, b = tmp_path / "a.json", tmp_path / "b.json"
    assert run("plan", LOW_MU, "-o", str(a), "--seed", "4").returncode == 0
    assert run("plan", LOW_MU, "-o", str(b), "--seed", "4").returncode == 0
    wa, wb = json.loads(a.read_text())["waypoints"], json.loads(b.read_text())["waypoints"]
    assert wa == wb


def test_unsolved_plan_exits_1_and_still_writes_the_partial_plan(tmp_path):
    out, table = tmp_path / "p.json", tmp_path / "p.csv"
    r = run("plan", LOW_MU, "-o", str(out), "--csv", str(table), "--max-switches", "0", "--time-limit", "0.2")
    assert r.returncode == 1
    assert "not solved" in r.stderr and "time limit" in r.stderr
    assert f"partial plan written to {out} and {table}" in r.stderr and table.exists()
    plan = json.loads(out.read_text())
    assert plan["solved"] is False and plan["outcome"] in ("time_limit", "goal_over_switch_limit")
    assert len(plan["waypoints"]) >= 1


def test_plan_refuses_a_bad_planner_key(tmp_path):
    data = yaml.safe_load(task_text("horizontal-offset-low-mu"))
    data["planner"]["goal_bias"] = 1.5
    bad = tmp_path / "bad.yaml"
    bad.write_text(yaml.safe_dump(data))
    r = run("plan", str(bad), "-o", str(tmp_path / "p.json"))
    assert r.returncode == 2 and "planner.goal_bias" in r.stderr
    data["planner"].pop("goal_bias")
    data["planner"]["temperature"] = 1
    bad.write_text(yaml.safe_dump(data))
    r = run("plan", str(bad), "-o", str(tmp_path / "p.json"))
    assert r.returncode == 2 and "planner.temperature" in r.stderr and "unknown key" in r.stderr
    assert not (tmp_path / "p.json").exists()


def test_bench_prints_table_ii_and_writes_trials(tmp_path):
    out = tmp_path / "bench.csv"
    r = run("bench", LOW_MU, str(TASKS / "pivoting.yaml"), "--trials", "2", "--out", str(out))
    assert r.returncode == 0, r.stderr
    lines = r.stdout.splitlines()
    assert lines[0].split()[:3] == ["task", "success", "median"]
    low = next(line for line in lines if line.startswith("horizontal-offset-low-mu"))
    assert "100%" in low and "2.83" in low and "592.8" in low  # the paper's times beside ours
    rows = list(csv.DictReader(out.open()))
    assert len(rows) == 4 and {r["seed"] for r in rows} == {"1", "2"}
    js = tmp_path / "bench.json"
    assert run("bench", LOW_MU, "--trials", "1", "--out", str(js)).returncode == 0
    assert json.loads(js.read_text())["summary"][0]["task"] == "horizontal-offset-low-mu"


def test_check_directions_lists_stable_pushes_and_their_reach(tmp_path):
    """`check --directions`: each pusher's stable unit pushes (a point pusher: one elevation per
    heading) and the largest component along each sense; --json holds the same; exactly one of
    --move and --directions."""
    pegs = str(TASKS / "more" / "cube-pegs.yaml")
    result = run("check", pegs, "--at", "7.2445", "-6.1356", "19.543", "--directions")
    assert result.returncode == 0, result.stderr
    assert "peg-left: 12" in result.stdout and "peg-bottom: 3" in result.stdout
    assert "-x +0.051" in result.stdout
    result = run("check", pegs, "--directions", "--json", "--pusher", "peg-bottom", "--heading-step", "5")
    found = json.loads(result.stdout)
    assert list(found["pushers"]) == ["peg-bottom"] and found["unit_step"] == [1.0, 1.0]
    assert set(found["largest"]) == {"+x", "-x", "+z", "-z", "+theta", "-theta"}
    headings = [p["heading"] for p in found["pushers"]["peg-bottom"]]
    assert headings and all(h % 5 == 0 for h in headings) and len(set(headings)) == len(headings)
    for args in ((), ("--move", "1", "0", "0", "--directions")):
        result = run("check", LOW_MU, *args)
        assert result.returncode == 2 and "--move DX DZ DTH, or --directions" in result.stderr
    for step in ("0", "0.01"):  # 0.01 deg: 36,000 headings, minutes and gigabytes
        result = run("check", LOW_MU, "--directions", "--heading-step", step)
        assert result.returncode == 2 and "--heading-step" in result.stderr and "0.5" in result.stderr


def test_every_number_option_refuses_nan_and_infinity():
    """Every ranged float option of every command names itself and refuses nan, inf and -inf
    before a command runs (click's own FloatRange lets nan through its bounds: `evaluate
    --success-tolerance nan nan` ran trials and called every one a miss). `check --at/--move` are
    plain floats that the library refuses in one "error:" line (test_reliability.py)."""
    import click

    from stablepush_cli.main import cli

    options = [(name, param) for name, command in cli.commands.items() for param in command.params
               if isinstance(param.type, click.FloatRange)]
    assert len(options) >= 18
    for name, param in options:
        ctx = click.Context(cli.commands[name])
        for text in ("nan", "inf", "-inf"):
            try:
                param.type.convert(text, param, ctx)
            except click.BadParameter:
                continue
            raise AssertionError(f"{name} {param.opts[0]} took {text}")
    result = run("evaluate", LOW_MU, "--success-tolerance", "nan", "0.5")
    assert result.returncode == 2 and "--success-tolerance" in result.stderr and "finite" in result.stderr


def test_planner_options_out_of_the_planners_ranges_are_refused_naming_the_option():
    """The library would refuse them too, but naming the task's field (`max_switches:`), not the
    option that was typed."""
    for option, value in (("--max-switches", "101"), ("--seed", str(2**32)), ("--time-limit", "1e9")):
        for command in ("plan", "reach", "bench"):
            if option == "--max-switches" and command != "plan":
                continue
            r = run(command, LOW_MU, option, value)
            assert r.returncode == 2 and f"Invalid value for '{option}'" in r.stderr, (command, option, r.stderr)


def _on_a_terminal(*args, cwd=None) -> str:
    """What `stablepush ARGS` writes to stderr when stderr is a terminal (a pseudo-terminal)."""
    import os
    import pty

    main, other = pty.openpty()
    process = subprocess.Popen([sys.executable, "-m", "stablepush_cli.main", *args], stdout=subprocess.DEVNULL,
                               stderr=other, cwd=cwd)
    os.close(other)
    seen = b""
    while True:
        try:
            chunk = os.read(main, 4096)
        except OSError:  # the child closed the terminal's other end
            break
        if not chunk:
            break
        seen += chunk
    process.wait(timeout=60)
    os.close(main)
    return seen.decode(errors="replace")


def test_a_long_search_shows_one_bar_on_a_terminal_and_none_in_a_pipe(tmp_path):
    """A search that the time limit ends (the only pusher presses on the left end, the goal lies to
    -x): `plan` showed nothing for the whole time limit; now a bar of the time spent, on a
    terminal. In a pipe the output is the result alone."""
    data = yaml.safe_load(task_text("horizontal-offset-high-mu"))
    data.update(pushers=[p for p in data["pushers"] if p["name"] == "left"], goal=[-20, 0, 0])
    task = tmp_path / "back.yaml"
    task.write_text(yaml.safe_dump(data))
    args = ("plan", str(task), "-o", str(tmp_path / "p.json"), "--time-limit", "2")
    piped = run(*args)
    assert piped.returncode == 1 and "searching" not in piped.stderr, piped.stderr
    shown = _on_a_terminal(*args)
    assert "horizontal-offset-high-mu: searching (time limit 2 s)" in shown and "not solved" in shown, shown
    assert "searching" not in _on_a_terminal(*args, "--quiet")


OPTIONAL = ("mujoco", "pydrake", "ray", "rosbags", "imageio_ffmpeg")  # stablepush.extras.EXTRAS' packages


def _without(packages, *args, cwd=None):
    """`stablepush ARGS` in a Python where `packages` cannot be imported, as where the extras that
    bring them were not installed."""
    code = (f"import sys\nfor name in {list(packages)!r}: sys.modules[name] = None\n"
            "from stablepush_cli.main import main\nsys.argv = ['stablepush'] + sys.argv[1:]\nmain()")
    return subprocess.run([sys.executable, "-c", code, *args], capture_output=True, text=True, cwd=cwd)


def test_planning_needs_no_optional_part_and_a_command_that_needs_one_names_it(tmp_path):
    """pip install stablepush plans, checks, draws and exports CSV/JSON; the simulators, Ray, ROS
    bags and video are extras, and a command that needs a missing one says which (exit 2)."""
    plan, csv_path, png = tmp_path / "p.json", tmp_path / "t.csv", tmp_path / "p.png"
    for args in (("plan", LOW_MU, "-o", str(plan)), ("check", LOW_MU, "--move", "1", "0", "0"),
                 ("show", str(plan), "--task", LOW_MU, "-o", str(png)),
                 ("trajectory", str(plan), "--task", LOW_MU, "-o", str(csv_path))):
        r = _without(OPTIONAL, *args)
        assert r.returncode == 0, (args, r.stderr)
    assert png.stat().st_size > 0 and csv_path.stat().st_size > 0
    for missing, args, extra in (
            ("mujoco", ("execute", str(plan), "--task", LOW_MU, "--sim", "--quiet"), "sim"),
            ("rosbags", ("trajectory", str(plan), "--task", LOW_MU, "-o", str(tmp_path / "t.mcap")), "ros"),
            ("pydrake", ("execute", str(plan), "--task", LOW_MU, "--sim", "--engine", "drake", "--quiet"), "drake")):
        r = _without([missing], *args)
        assert r.returncode == 2, (missing, r.stderr)
        assert f"pip install 'stablepush[{extra}]'" in r.stderr and "Traceback" not in r.stderr, r.stderr
