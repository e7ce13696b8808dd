"""`stablepush design`: fixture layouts from candidates. Every design it reports plans again from
its own task file and each push of the plan agrees with the independent LP (tests/independent_lp.py);
on generated parts, grips and goals too; a regrasp no layout can do is said to be so, with the
reason; the shipped offset's design is at least as good as the task's own layout by the ranking;
the best designs' measured odds rank them, and their task files land the same trials."""
import math
from pathlib import Path

import numpy as np
import pytest
import yaml
from click.testing import CliRunner

import stablepush as sp
from stablepush.design import (
    DEFAULT_RANK,
    Design,
    DesignOdds,
    LayoutSearch,
    design,
    design_task,
    evaluate_designs,
    layout_task,
    layouts,
    measure_layout,
    parse_rank,
)
from stablepush.errors import SettingError, TaskError
from stablepush.evaluation import Batch, Spreads, evaluate
from stablepush.runners import Runner
from stablepush.task.design_file import load_design
from stablepush.units import pose_to_si
from stablepush_cli.main import cli

from conftest import ROOT, TASKS
from independent_lp import IndependentModel

DESIGN = ROOT / "data" / "designs" / "offset-low-mu.design.yaml"
BAND_N = 1e-6  # N: pushes this close to their cone's boundary are not compared with the LP


def _agrees_with_the_independent_lp(task, plan) -> None:
    reference = IndependentModel(task)
    model = task.model
    for w0, w1 in zip(plan.waypoints, plan.waypoints[1:]):
        q0, q1 = pose_to_si(w0.pose), pose_to_si(w1.pose)
        dq = tuple(b - a for a, b in zip(q0, q1))
        index = task.pusher_index(w1.pusher)
        if abs(model.check(q0, dq, index).margin) <= BAND_N:
            continue
        assert reference.stable(q0, dq, index)[0], (w0.pose, w1.pose, w1.pusher)


def _replanned_and_verified(task_mapping: dict, source) -> None:
    """The design's task file as written, planned again and every push checked by the LP."""
    task = sp.parse_task(yaml.safe_dump(task_mapping), str(source))
    plan = sp.plan_task(task, time_limit=2)
    assert plan.solved, plan.message
    sp.check_plan(task, plan)
    _agrees_with_the_independent_lp(task, plan)


def test_candidates_are_the_sections_edges_and_points_beside_its_convex_corners():
    task, candidates = load_design(DESIGN)
    names = [c["name"] for c in candidates]
    assert names[:4] == ["edge0", "edge1", "edge2", "edge3"] and len(names) == 4 + 8
    corner = next(c for c in candidates if c["name"] == "corner0b")  # 1 mm from (-50, -12.5) toward (50, -12.5)
    assert corner["at"] == pytest.approx([-49.0, -12.5]) and corner["mu"] == 0.2
    assert "pushers" not in task


@pytest.mark.slow
def test_the_offset_design_is_at_least_as_good_as_the_tasks_own_layout_and_verifies(tmp_path):
    task, candidates = load_design(DESIGN)
    study = design(task, candidates, source=str(DESIGN), search=LayoutSearch(time_limit=2.0, reach_top=0),
                   runner=Runner(workers=2))
    assert study.designs, study.verdict
    own_task = yaml.safe_load((TASKS / "horizontal-offset-low-mu.yaml").read_text())
    own = measure_layout(task, own_task["pushers"], str(DESIGN), time_limit=2.0)
    assert own.solved and study.designs[0].key(DEFAULT_RANK) <= own.key(DEFAULT_RANK), (study.designs[0], own)
    for d in study.designs:
        _replanned_and_verified(design_task(task, candidates, d), DESIGN)


def _generated_design(rng) -> dict:
    """A convex part (4-6 corners, 50-120 mm), gripped at its middle by two small pads, a goal a few
    mm and degrees away; every edge and corner of it a candidate."""
    n = int(rng.integers(4, 7))
    # spread round the origin (every gap under half a turn), so the part holds the pads' centre
    angles = (np.arange(n) + rng.uniform(-0.3, 0.3, n)) * 2 * math.pi / n
    radius = rng.uniform(25, 60)
    polygon = [[round(float(radius * rng.uniform(0.8, 1.0) * math.cos(a)), 3),
                round(float(radius * rng.uniform(0.8, 1.0) * math.sin(a)), 3)] for a in angles]
    return {
        "name": "generated",
        "object": {"shape": "polygon", "polygon": polygon, "thickness": 20, "mass": float(rng.uniform(80, 300))},
        "gripper": {"grip_force": float(rng.uniform(8, 20)), "mu": float(rng.uniform(0.4, 0.8)),
                    "pads": [{"center": [0, 0], "radius": 5}, {"center": [0, 0], "radius": 5}]},
        "gravity": [0, -9.81],
        "candidates": {"mu": float(rng.uniform(0.3, 0.8))},
        "start": [0, 0, 0],
        "goal": [round(float(rng.uniform(-8, 8)), 2), round(float(rng.uniform(-5, 5)), 2),
                 round(float(rng.uniform(-15, 15)), 1)],
        "planner": {"tolerance": [1, 1]},
    }


@pytest.mark.parametrize("seed", [3, 8, 21])
def test_every_design_of_a_generated_part_plans_and_verifies(tmp_path, seed):
    rng = np.random.default_rng(seed)
    path = tmp_path / "generated.design.yaml"
    path.write_text(yaml.safe_dump(_generated_design(rng)))
    try:
        task, candidates = load_design(path)
    except TaskError as exc:  # a draw whose goal leaves the pads off the part: refused by name, as a task is
        assert exc.field.startswith(("goal", "object")), exc
        return
    study = design(task, candidates, source=str(path), search=LayoutSearch(max_fixtures=1, time_limit=0.5, reach_top=0))
    if not study.designs:
        assert study.verdict.startswith("no layout of the candidates can do it: "), study.verdict
        return
    for d in study.designs:
        assert d.solved and d.margin_n >= 0 and len(d.features) == len(d.pushers)
        assert d.points == sum(1 for name in d.features if name.startswith("corner")) and 0 <= d.end_used <= 1
        _replanned_and_verified(design_task(task, candidates, d), path)


def test_a_regrasp_no_layout_can_do_is_said_so_with_the_reason(tmp_path):
    data = yaml.safe_load(DESIGN.read_text())
    data["candidates"] = [{"name": "right", "from": [50, -12.5], "to": [50, 12.5], "mu": 0.2}]
    path = tmp_path / "right-only.design.yaml"
    path.write_text(yaml.safe_dump(data))
    result = CliRunner().invoke(cli, ["design", str(path), "--quiet", "--json", str(tmp_path / "d.json")])
    assert result.exit_code == 1, result.output
    assert ("no layout of the candidates can do it: none of them (right) has a stable push from the start toward "
            "the goal") in result.output
    assert yaml.safe_load((tmp_path / "d.json").read_text())["designs"] == []


def test_the_design_command_writes_task_files_that_plan_unchanged(tmp_path):
    data = yaml.safe_load(DESIGN.read_text())
    data["candidates"] = [{"name": "left", "from": [-50, -12.5], "to": [-50, 12.5], "mu": 0.2},
                          {"name": "bottom", "from": [-50, -12.5], "to": [50, -12.5], "mu": 0.2}]
    (tmp_path / "arms").mkdir()
    (tmp_path / "arms" / "six.urdf").write_text((ROOT / "data" / "arms" / "six-joint.urdf").read_text())
    # named relative to the design file: the task files written one folder down still find it
    data["environment"]["robot"] = {"model": "arms/six.urdf", "flange": "tool0", "tcp": [0, 0, 110, 0, 180, 0]}
    path = tmp_path / "two.design.yaml"
    path.write_text(yaml.safe_dump(data))
    out = tmp_path / "designs"
    runner = CliRunner()
    result = runner.invoke(cli, ["design", str(path), "--quiet", "--out", str(out), "--json", str(tmp_path / "d.json"),
                                 "--reach-top", "1", "--plot", str(tmp_path / "top.png")])
    assert result.exit_code == 0, result.output
    report = yaml.safe_load((tmp_path / "d.json").read_text())
    best = report["designs"][0]
    assert best["pushers"] == ["left", "bottom"] and best["reach"] is not None
    assert best["arm"]["follows"] is True and "the arm follows it" in result.output  # the task names its arm
    assert (tmp_path / "top.png").stat().st_size > 1000
    assert Path(best["task_file"]) == out / "design-1.yaml"
    planned = runner.invoke(cli, ["plan", best["task_file"], "-o", str(tmp_path / "p.json")])
    assert planned.exit_code == 0, planned.output
    features = yaml.safe_load(Path(best["task_file"]).read_text())["environment"]["features"]
    assert set(features) == {"left", "bottom"}


@pytest.mark.parametrize("text, field", [
    ("pushers: []\ncandidates: {mu: 0.2}", "pushers"),
    ("", "candidates"),
    ("candidates: {mu: -1}", "candidates.mu"),
    ("candidates: []", "candidates"),
    ("candidates: [{name: nowhere, at: [500, 0], mu: 0.2}]", "pushers[0]"),
])
def test_a_bad_design_file_is_refused_naming_the_field(tmp_path, text, field):
    data = yaml.safe_load(DESIGN.read_text())
    data.pop("candidates")
    data.update(yaml.safe_load(text) or {})
    path = tmp_path / "bad.design.yaml"
    path.write_text(yaml.safe_dump(data))
    with pytest.raises(TaskError) as refused:
        load_design(path)
    assert f": {field}" in str(refused.value), str(refused.value)


def test_the_rank_puts_the_arm_first_then_fixtures_point_pushers_and_the_plans_end_and_measured_odds_first():
    follows = Design(("a", "b"), solved=True, pushes=9, switches=1, margin_n=0.1, features={"a": [], "b": []},
                     arm={"follows": True})
    cannot = Design(("c",), solved=True, pushes=3, switches=0, margin_n=2.0, features={"c": []},
                    arm={"follows": False, "reason": "joint 2 at its limit"})
    assert follows.key(DEFAULT_RANK) < cannot.key(DEFAULT_RANK)  # fewer fixtures, but the arm cannot follow it
    follows.success = {"success_rate": 0.6, "successes": 6, "judged": 10, "ci95": [0.31, 0.83]}
    cannot.success = {"success_rate": 0.9, "successes": 9, "judged": 10, "ci95": [0.6, 0.98]}
    not_measured = Design(("d",), solved=True, pushes=1, switches=0, margin_n=5.0, features={"d": []})
    rank = ("success",) + DEFAULT_RANK
    assert sorted([not_measured, follows, cannot], key=lambda d: d.key(rank)) == [cannot, follows, not_measured]
    assert parse_rank("margin, success", measured=True) == ("margin", "success")
    # Among layouts of as many fixtures, one that leans on a point pusher ranks below one that does
    # not, whatever its margin (a point pusher's push is robust to nothing, docs/planner.md); then
    # the plan that ends nearer its goal first (an open-loop run lands where it ends plus its drift).
    inside = Design(("e",), solved=True, pushes=5, switches=0, margin_n=0.1, features={"e": []}, end_used=0.0,
                    points=0)
    nearer_edge = Design(("f",), solved=True, pushes=5, switches=0, margin_n=3.0, features={"f": []},
                         end_used=0.6, points=0)
    on_a_point = Design(("g",), solved=True, pushes=5, switches=0, margin_n=3.0, features={"g": []}, end_used=0.0,
                        points=1)
    two_fixtures = Design(("h", "i"), solved=True, pushes=5, switches=0, margin_n=3.0, features={"h": [], "i": []},
                          end_used=0.0, points=0)
    assert (sorted([two_fixtures, on_a_point, nearer_edge, inside], key=lambda d: d.key(DEFAULT_RANK))
            == [inside, nearer_edge, on_a_point, two_fixtures])
    for text in ("success", "margin,margin", "speed"):
        with pytest.raises(TaskError, match="rank"):
            parse_rank(text)
    # Two layouts tied on every other key rank by their searches' stable-push tests, a count, not by
    # how long the searches took on a machine that may have been busy.
    slow_few = Design(("j",), solved=True, pushes=5, switches=0, margin_n=0.1, features={"j": []}, end_used=0.0,
                      points=0, planning_time_s=0.9, tests=100)
    fast_many = Design(("k",), solved=True, pushes=5, switches=0, margin_n=0.1, features={"k": []}, end_used=0.0,
                       points=0, planning_time_s=0.1, tests=5000)
    assert sorted([fast_many, slow_few], key=lambda d: d.key(DEFAULT_RANK)) == [slow_few, fast_many]
    assert sorted([slow_few, fast_many], key=lambda d: d.key(parse_rank("time"))) == [fast_many, slow_few]


@pytest.mark.parametrize("path", sorted((ROOT / "data" / "designs").glob("*.design.yaml")), ids=lambda p: p.stem)
def test_every_shipped_design_file_loads_and_keeps_its_tasks_regrasp(path):
    task, candidates = load_design(path)
    assert candidates and "pushers" not in task
    twin = TASKS / f"{task['name']}.yaml"
    assert twin.exists(), twin
    own = yaml.safe_load(twin.read_text())
    for key in ("object", "gripper", "gravity", "start", "goal"):
        assert task[key] == own[key], key


def _pivot_design():
    """The shipped pivot with its pushers taken away: its edges and corners are the candidates."""
    path = TASKS / "pivoting.yaml"
    data = yaml.safe_load(path.read_text())
    mu = min(p["mu"] for p in data.pop("pushers"))
    data["environment"].pop("features", None)
    data["candidates"] = {"mu": mu}
    return data, path


def _pivot_study(tmp_path):
    """The pivot's design file written to tmp_path and its one-fixture layouts searched on 2 workers:
    (path, task, candidates, runner, study)."""
    data, _ = _pivot_design()
    path = tmp_path / "pivot.design.yaml"
    path.write_text(yaml.safe_dump(data))
    task, candidates = load_design(path)
    runner = Runner(workers=2)
    study = design(task, candidates, source=str(path), search=LayoutSearch(max_fixtures=1, time_limit=1.0, reach_top=0),
                   runner=runner)
    return path, task, candidates, runner, study


@pytest.mark.slow
def test_evaluate_ranks_the_best_designs_by_their_odds_in_the_same_worlds(tmp_path):
    path, task, candidates, runner, study = _pivot_study(tmp_path)
    assert len(study.designs) > 3, study.verdict
    spreads = Spreads.for_task(layout_task(task, candidates, str(path)), {"pad_mu": 0.3, "pusher_mu": 0.3})
    evaluate_designs(study, DesignOdds(3, spreads, top=3, seed=5), runner=runner)
    assert study.rank[0] == "success" and study.evaluated["trials"] == 3
    measured = [d for d in study.designs if d.success is not None]
    assert study.designs[:3] == measured and all(d.success["trials"] == 3 for d in measured)
    assert [d.key(study.rank) for d in study.designs] == sorted(d.key(study.rank) for d in study.designs)
    # The best design's task file, as written, run in the same worlds: the same trials land.
    best = study.designs[0]
    written = sp.parse_task(yaml.safe_dump(design_task(task, candidates, best, str(path))), str(path))
    again = evaluate(Batch(task=written, plan=best.plan, spreads=spreads, seed=5), 3, runner).summary()
    assert again["successes"] == best.success["successes"]


def test_with_predictions_the_designs_rank_by_the_low_end_of_their_prediction_powered_interval(tmp_path):
    path, task, candidates, runner, study = _pivot_study(tmp_path)
    spreads = Spreads.for_task(layout_task(task, candidates, str(path)), {"pad_mu": 0.3, "pusher_mu": 0.3})
    evaluate_designs(study, DesignOdds(2, spreads, top=2, seed=5, predict=500), runner=runner)
    measured = study.designs[:2]
    assert all(d.success["prediction"]["predictions"] == 500 and d.success["prediction"]["trials"] == 2
               for d in measured)
    lows = [d.success["prediction"]["interval"][0] for d in measured]
    assert lows == sorted(lows, reverse=True)
    assert "with 500 predictions" in measured[0].odds() and study.evaluated["predictions"] == 500
    assert "model-only worlds" in study.describe_odds()
    with pytest.raises(SettingError, match="predict"):
        DesignOdds(2, spreads, predict=0)


@pytest.mark.parametrize("args, says", [
    (["--vary", "pad_mu=0.2"], "--vary: only with --evaluate N"),
    (["--closed-loop"], "--closed-loop: only with --evaluate N"),
    (["--rank", "success,margin"], "rank"),
    (["--evaluate", "2", "--vary", "pad_mu=2"], "--vary"),
    (["--evaluate", "2", "--feature-error", "1e9", "0"], "--feature-error"),
    (["--predict", "100"], "--predict: only with --evaluate N"),
    (["--evaluate", "2", "--predict", "20000000"], "--predict: must be a whole number from 1 to 10,000,000"),
])
def test_the_odds_options_are_refused_before_the_search(tmp_path, args, says):
    result = CliRunner().invoke(cli, ["design", str(DESIGN), "--quiet", "--out", str(tmp_path / "d"), *args])
    assert result.exit_code == 2, result.output
    assert says in result.output and "layouts planned" not in result.output



def test_the_design_command_says_how_many_layouts_gave_no_plan_and_why_grouped(tmp_path, monkeypatch):
    data = yaml.safe_load(DESIGN.read_text())
    data["candidates"] = [{"name": "left", "from": [-50, -12.5], "to": [-50, 12.5], "mu": 0.2},
                          {"name": "right", "from": [50, 12.5], "to": [50, -12.5], "mu": 0.2},
                          {"name": "top", "from": [50, 12.5], "to": [-50, 12.5], "mu": 0.2}]
    path = tmp_path / "three.design.yaml"
    path.write_text(yaml.safe_dump(data))
    whole = layouts.layout_task

    def refused_without_top(task, pushers, source=None):  # one worker: this process plans every layout
        if len(pushers) < 3 and "top" not in [p["name"] for p in pushers]:
            raise TaskError("goal", "refused without top")
        return whole(task, pushers, source)

    monkeypatch.setattr(layouts, "layout_task", refused_without_top)
    result = CliRunner().invoke(cli, ["design", str(path), "--quiet", "--time-limit", "0.5", "--reach-top", "0",
                                      "--workers", "1", "--json", str(tmp_path / "d.json")])
    assert result.exit_code == 1, result.output
    assert "of the 3 layouts planned, 0 solved and 3 gave no plan:" in result.output
    assert "  2: the layout's task was refused (left, left + right); e.g. left: goal: refused without top" in (
        result.output)
    assert "  1: the search ended before the goal (its check limit or its time ran out), the best partial path " in (
        result.output)
    groups = yaml.safe_load((tmp_path / "d.json").read_text())["no_plan"]
    assert [(g["outcome"], g["layouts"], g["pushers"]) for g in groups] == [
        ("refused", 2, [["left"], ["left", "right"]]), ("time_limit", 1, [["left", "top"]])]
    assert groups[0]["end_steps"] is None and groups[1]["end_steps"][0] > 0


def test_the_design_files_keep_the_design_files_comments_and_mean_the_design_task(tmp_path):
    from stablepush.design import DesignStudy, design_files

    robot = (ROOT / "data" / "arms" / "six-joint.urdf").read_text()
    (tmp_path / "arms").mkdir()
    (tmp_path / "arms" / "six.urdf").write_text(robot)
    text = DESIGN.read_text().replace("  end_on_feature: true\n", (
        "  end_on_feature: true\n"
        "  robot:\n"
        "    model: arms/six.urdf   # named from the design file's folder\n"
        "    flange: tool0\n"
        "    tcp: [0, 0, 110, 0, 180, 0]\n"))
    assert text != DESIGN.read_text()
    path = tmp_path / "offset.design.yaml"
    path.write_text(text)
    task, candidates = load_design(path)
    d = Design(("edge0", "edge3"), solved=True, features={"edge0": [1.5, 0.0, 300.0, 0.0], "edge3": [0.0, 150.0, 300.0, 0]})
    study = DesignStudy(candidates=[c["name"] for c in candidates], designs=[d], pruned_candidates=[],
                        layouts_searched=1, layouts_pruned=0, rank=DEFAULT_RANK)
    written = design_files(study, task, candidates, tmp_path / "designs", str(path))[d.task_file]
    assert yaml.safe_load(written) == design_task(task, candidates, d, str(path))
    lines = written.splitlines()
    assert lines[0].startswith("# design-1 of offset.design.yaml (stablepush design): the layout edge0 + edge3")
    about_candidates = text.split("\ncandidates:")[0].rsplit("step_time: 0.1\n", 1)[1].splitlines()
    kept = [line for line in text.splitlines() if "#" in line and line not in about_candidates and "model:" not in line]
    assert len(kept) > 20 and all(line in lines for line in kept), [line for line in kept if line not in lines]
    assert "  # At the goal the pads alone hold 0.91 times the prism's weight (the grip of the paper's example" in lines
    assert any(line.startswith(f"    model: {tmp_path / 'arms' / 'six.urdf'} ")  # edited, its comment kept
               and line.endswith(" # named from the design file's folder") for line in lines)
    assert about_candidates and not set(about_candidates) & set(lines)  # the candidates' comment goes with them
