"""Reliability, round four (issue 69), classes H to P: `design`'s outputs, its design file, its
verdict and its odds, the API's value types and arguments, and evaluate's --target. Each test
fails on the code before its fix. Fast: nothing here runs the simulated arm's trials."""
import math
import shutil
from pathlib import Path

import pytest
import yaml
from click.testing import CliRunner

import stablepush as sp
from stablepush import design as design_package
from stablepush.design import layouts, odds
from stablepush.errors import SettingError, StablepushError, TaskError
from stablepush.evaluation import SequentialTest, Spreads, study_trials
from stablepush.task.design_file import load_design
from stablepush_cli.main import cli

from conftest import ROOT

SIX_JOINT = ROOT / "data" / "arms" / "six-joint.urdf"
# One candidate, the high-mu offset's left face: a single layout, solved by a straight drag in
# about a second.
ONE = {
    "name": "one",
    "object": {"shape": "box", "size": [100, 25, 25], "mass": 202},
    "gripper": {"grip_force": 10, "mu": 0.425, "pad_rings": 1,
                "pads": [{"center": [0, 0], "radius": 5}, {"center": [0, 0], "radius": 5}]},
    "gravity": [0, -9.81],
    "dynamics": {"step_time": 0.1},
    "candidates": [{"name": "left", "from": [-50, -12.5], "to": [-50, 12.5], "mu": 0.6}],
    "start": [0, 0, 0],
    "goal": [20, 0, 0],
    "planner": {"time_limit": 10, "seed": 1, "max_switches": 1, "step": [1.0, 1.0], "tolerance": [0.5, 0.5]},
    "environment": {"end_on_feature": True},
}
QUICK = ["--quiet", "--reach-top", "0", "--workers", "1"]


def _design_file(tmp_path, edit=None, name="one.design.yaml") -> Path:
    data = yaml.safe_load(yaml.safe_dump(ONE))
    if edit is not None:
        edit(data)
    path = tmp_path / name
    path.write_text(yaml.safe_dump(data, sort_keys=False))
    return path


def _no_search(monkeypatch):
    monkeypatch.setattr(layouts, "run_all", lambda *a, **k: pytest.fail("the layouts were searched"))


def _design(*args):
    return CliRunner().invoke(cli, ["design", *map(str, args)])


# -- H. every output checked before the search -----------------------------------------------------

@pytest.mark.parametrize("out", ["afile/sub", "/dev/null", "/proc/self"])
def test_h_an_out_that_cannot_be_a_folder_is_refused_before_the_search(tmp_path, monkeypatch, out):
    """It exited 4 (NotADirectoryError) after the whole search, and --json was never written."""
    path = _design_file(tmp_path)
    (tmp_path / "afile").write_text("a file\n")
    monkeypatch.chdir(tmp_path)
    _no_search(monkeypatch)
    result = _design(path, *QUICK, "--out", out, "--json", tmp_path / "d.json")
    assert result.exit_code == 2, result.output
    assert result.output.startswith("error: --out") and out in result.output, result.output
    assert (tmp_path / "afile").read_text() == "a file\n"


# -- I. the folder holds this run's designs only ---------------------------------------------------

def test_i_a_second_run_into_the_same_out_leaves_none_of_the_earlier_runs_designs(tmp_path):
    """design-2.yaml of an earlier run (of two designs) stayed beside this run's one design."""
    path = _design_file(tmp_path)
    out = tmp_path / "designs"
    out.mkdir()
    earlier = "# design-2 of one.design.yaml (stablepush design): the layout bottom, each fixture where ...\nname: x\n"
    (out / "design-2.yaml").write_text(earlier)
    (out / "notes.txt").write_text("mine\n")
    result = _design(path, *QUICK, "--out", out)
    assert result.exit_code == 0, result.output
    assert sorted(p.name for p in out.iterdir()) == ["design-1.yaml", "notes.txt"]
    # None found: the earlier designs go too, so that none is taken for this run's.
    (out / "design-2.yaml").write_text(earlier)
    unreachable = _design_file(tmp_path, lambda d: d.update(goal=[-20, 0, 0]), "back.design.yaml")
    result = _design(unreachable, *QUICK, "--out", out)
    assert result.exit_code == 1, result.output
    assert sorted(p.name for p in out.iterdir()) == ["notes.txt"]


def test_i_a_file_of_the_designs_name_the_tool_did_not_write_is_refused_before_the_search(tmp_path, monkeypatch):
    path = _design_file(tmp_path)
    out = tmp_path / "designs"
    out.mkdir()
    (out / "design-3.yaml").write_text("name: my own task\n")
    _no_search(monkeypatch)
    result = _design(path, *QUICK, "--out", out)
    assert result.exit_code == 2, result.output
    assert "error: --out" in result.output and "design-3.yaml" in result.output
    assert (out / "design-3.yaml").read_text() == "name: my own task\n"


# -- J. ~ in the robot model's name ----------------------------------------------------------------

def test_j_a_robot_model_under_home_is_named_as_the_design_file_read_it(tmp_path, monkeypatch):
    """The designs named <folder>/~/arm6.urdf, and `plan` of them exited 2."""
    home = tmp_path / "home"
    home.mkdir()
    shutil.copy(SIX_JOINT, home / "arm6.urdf")
    monkeypatch.setenv("HOME", str(home))
    robot = {"model": "~/arm6.urdf", "flange": "tool0", "tcp": [0, 0, 110, 0, 180, 0]}
    path = _design_file(tmp_path, lambda d: d["environment"].update(robot=robot))
    result = _design(path, *QUICK, "--out", tmp_path / "out")
    assert result.exit_code == 0, result.output
    written = yaml.safe_load((tmp_path / "out" / "design-1.yaml").read_text())
    assert written["environment"]["robot"]["model"] == str(home / "arm6.urdf")
    planned = CliRunner().invoke(cli, ["plan", str(tmp_path / "out" / "design-1.yaml"), "-o", str(tmp_path / "p.json")])
    assert planned.exit_code == 0, planned.output


# -- K. environment.features in a design file ------------------------------------------------------

def test_k_features_in_a_design_file_are_refused_by_name(tmp_path, monkeypatch):
    """Every layout without the pusher the features named was silently "unsolved"."""
    path = _design_file(tmp_path, lambda d: d["environment"].update(features={"left": [0, 0, 300, 0]}))
    _no_search(monkeypatch)
    result = _design(path, *QUICK, "--out", tmp_path / "out")
    assert result.exit_code == 2, result.output
    assert "environment.features" in result.output and "layouts planned" not in result.output
    with pytest.raises(TaskError) as refused:
        load_design(path)
    assert refused.value.field == "environment.features"


# -- L. an arm that can follow no design -----------------------------------------------------------

def test_l_a_study_whose_arm_follows_no_design_says_so_and_fails(tmp_path):
    """It exited 0 with "best layout: left", a layout the arm cannot follow."""
    robot = {"model": str(SIX_JOINT), "flange": "tool0", "tcp": [0, 0, 110, 0, 180, 0], "base": [3000, 0, 0, 0]}
    path = _design_file(tmp_path, lambda d: d["environment"].update(robot=robot))
    result = _design(path, *QUICK, "--out", tmp_path / "out", "--json", tmp_path / "d.json")
    assert result.exit_code == 1, result.output
    assert "best layout" not in result.output
    verdict = result.output.strip().splitlines()[-1]
    assert verdict.startswith("no design is usable by this arm"), verdict
    assert yaml.safe_load((tmp_path / "d.json").read_text())["verdict"] == verdict


# -- M. the goal at the start ----------------------------------------------------------------------

def test_m_a_goal_at_the_start_is_nothing_to_plan_as_plan_says(tmp_path, monkeypatch):
    """It exited 1: "none of them has a stable push toward the goal"."""
    path = _design_file(tmp_path, lambda d: d.update(goal=[0, 0, 0]))
    _no_search(monkeypatch)
    result = _design(path, *QUICK, "--out", tmp_path / "out")
    assert result.exit_code == 2, result.output
    assert "error:" in result.output and "goal: " in result.output and "nothing to plan" in result.output
    task_file = tmp_path / "task.yaml"
    data = yaml.safe_load(path.read_text())
    data["pushers"] = data.pop("candidates")
    task_file.write_text(yaml.safe_dump(data))
    planned = CliRunner().invoke(cli, ["plan", str(task_file), "-o", str(tmp_path / "p.json")])
    assert planned.exit_code == 2
    assert planned.output.split("goal: ", 1)[1] == result.output.split("goal: ", 1)[1]


# -- N. Ctrl-C during --evaluate -------------------------------------------------------------------

class _Stopped:
    """evaluate()'s result for a batch stopped by Ctrl-C after `ran` of its trials."""

    def __init__(self, ran):
        self.interrupted = True
        self.ran = ran

    def summary(self):
        return {"trials": self.ran, "judged": self.ran, "successes": self.ran, "success_rate": 1.0,
                "ci95": [0.7, 1.0], "causes": {}, "crashed": 0, "wall_s": 1.0}


def test_n_an_evaluation_stopped_by_ctrl_c_says_how_many_trials_each_design_ran(tmp_path, monkeypatch):
    """It said "the best 2 designs, 30 trials each" where the second design had run none."""
    path = _design_file(tmp_path, lambda d: d["candidates"].append(
        {"name": "bottom", "from": [-50, -12.5], "to": [50, -12.5], "mu": 0.6}))
    task, candidates = load_design(path)

    def search(task, candidates, source=None, **kw):
        designs = []
        for name in ("left", "bottom"):
            d = layouts.Design((name,), task=layouts.layout_task(task, candidates, source), solved=True, pushes=20,
                               switches=0, margin_n=0.1, end_used=0.1, points=0, planning_time_s=0.1, tests=10,
                               features={name: [0.0, 0.0, 300.0, 0.0]})
            designs.append(d)
        return layouts.DesignStudy(candidates=["left", "bottom"], designs=designs, pruned_candidates=[],
                                   layouts_searched=2, layouts_pruned=1, rank=layouts.DEFAULT_RANK)

    monkeypatch.setattr(design_package, "design", search)
    monkeypatch.setattr(odds, "Batch", lambda **kw: kw)
    monkeypatch.setattr(odds, "evaluate", lambda batch, trials, runner, progress=None, predictions=None: _Stopped(12))
    result = _design(path, *QUICK, "--out", tmp_path / "out", "--evaluate", "30", "--evaluate-top", "2",
                     "--json", tmp_path / "d.json")
    assert result.exit_code == 130, result.output
    odds_line = next(line for line in result.output.splitlines() if line.startswith("odds:"))
    assert "30 trials each" not in odds_line, odds_line
    assert "the study stopped by Ctrl-C" in odds_line and "left ran 12 of 30" in odds_line and "bottom none" in odds_line
    evaluated = yaml.safe_load((tmp_path / "d.json").read_text())["evaluated"]
    assert evaluated["interrupted"] is True and evaluated["ran"] == {"left": 12, "bottom": 0}


# -- O. the API's value types and arguments check what the task file checks, before any work ---------

@pytest.mark.parametrize("make, field", [
    (lambda: sp.Robot(model="/no/such/arm.urdf", flange="tool0"), "environment.robot.model"),
    (lambda: sp.Robot(model=str(ROOT / "README.md"), flange="tool0"), "environment.robot.model"),
    (lambda: sp.Robot(tcp=(1e300, 0, 0, 0, 0, 0)), "environment.robot.tcp[0]"),
    (lambda: sp.Robot(tcp=(0, 0, 110, 0, 1e9, 0)), "environment.robot.tcp[4]"),
    (lambda: sp.Robot(base=(0, -1e5, 0, 0)), "environment.robot.base[1]"),
    (lambda: sp.Robot(max_joint_speed=1e9), "environment.robot.max_joint_speed"),
    (lambda: sp.Robot(flange=" "), "environment.robot.flange"),
    (lambda: sp.Cell(retract=-50), "environment.retract"),
    (lambda: sp.Cell(station_spacing=0), "environment.station_spacing"),
    (lambda: sp.Cell(lane_offset=1e9), "environment.lane_offset"),
    (lambda: sp.Cell(home=(1e9, 0, 0)), "environment.home[0]"),
    (lambda: sp.Cell(features={"left": (0, 0, 1e9, 0)}), "environment.features.left[2]"),
])
def test_o_the_cell_and_robot_values_refuse_what_the_task_file_refuses_by_field(make, field):
    """Robot(model=<missing>) reached SimulatedArm as a FileNotFoundError; Robot(tcp=(1e300, ...))
    a LinAlgError in the arm's kinematics; Cell(retract=-50) was taken."""
    with pytest.raises(TaskError) as refused:
        make()
    assert refused.value.field == field, str(refused.value)


def test_o_the_defaults_and_a_task_files_robot_still_make_values():
    assert sp.Robot() == sp.Robot() and sp.Cell().robot == sp.Robot()
    robot = sp.Robot(model=str(SIX_JOINT), flange="tool0", tcp=(0, 0, 110, 0, 180, 0))
    assert robot.model == str(SIX_JOINT)


@pytest.fixture(scope="module")
def one_study(tmp_path_factory):
    path = _design_file(tmp_path_factory.mktemp("study"))
    task, candidates = load_design(path)
    return task, candidates, str(path)


@pytest.mark.parametrize("arguments, field", [
    ({"rank": ("bogus",)}, "rank"),
    ({"rank": ("fixtures", "fixtures")}, "rank"),
    ({"rank": (["arm"],)}, "rank"),
    ({"rank": "fixtures"}, "rank"),
    ({"reach_top": -1}, "reach_top"),
    ({"max_fixtures": 0}, "max_fixtures"),
    ({"time_limit": -1.0}, "time_limit"),
    ({"check_limit": -1}, "check_limit"),
    ({"max_fixtures": 1.5}, "max_fixtures"),
])
def test_o_design_refuses_its_arguments_before_the_search(one_study, monkeypatch, arguments, field):
    """design(rank=("bogus",)) searched every layout, then raised KeyError: its search is refused
    when made."""
    task, candidates, source = one_study
    _no_search(monkeypatch)
    with pytest.raises(StablepushError) as refused:
        layouts.design(task, candidates, source=source, search=layouts.LayoutSearch(**arguments))
    assert refused.value.field == field, str(refused.value)


@pytest.mark.parametrize("arguments, field", [
    ({"trials": 0}, "trials"),
    ({"trials": -3}, "trials"),
    ({"trials": 2.5}, "trials"),
    ({"top": -1}, "top"),
    ({"top": 0}, "top"),
    ({"seed": -1}, "seed"),
    ({"engine": "bullet"}, "engine"),
    ({"spreads": {"pad_mu": 0.1}}, "spreads"),
])
def test_o_evaluate_designs_refuses_its_arguments_before_any_trial(one_study, monkeypatch, arguments, field):
    """top=-1 evaluated every design but the last; trials=0 ran none and ranked by no rate."""
    task, candidates, source = one_study
    study = layouts.DesignStudy(candidates=["left"], designs=[layouts.Design(("left",), solved=True)],
                                pruned_candidates=[], layouts_searched=1, layouts_pruned=0, rank=layouts.DEFAULT_RANK)
    monkeypatch.setattr(odds, "Batch", lambda **kw: pytest.fail("a batch was made"))
    given = {"trials": 2, "spreads": Spreads(vary={"pad_mu": 0.1}), **arguments}
    with pytest.raises(SettingError) as refused:
        odds.evaluate_designs(study, odds.DesignOdds(**given))
    assert refused.value.field == field, str(refused.value)
    assert study.evaluated is None and study.designs[0].success is None


@pytest.mark.parametrize("trials", [0, -1, 2.0, True, 10**7])
def test_o_a_study_of_no_trials_is_refused_by_evaluate_itself(trials):
    """evaluate(batch, 0) ran no trial and summed up a study of none."""
    with pytest.raises(SettingError) as refused:
        study_trials(Spreads(vary={"pad_mu": 0.1}), trials)
    assert refused.value.field == "trials"
    assert study_trials(Spreads(vary={"pad_mu": 0.1}), None) == 100


# -- P. evaluate --target names its range ----------------------------------------------------------

@pytest.mark.parametrize("target", ["0.005", "0.01"])
def test_p_a_target_inside_the_indifference_zone_names_the_options_range(target):
    """It said "indifference 0.01 must be less than the target", of a setting no option sets
    (fixed with issue 68, item 6; kept here as this class's test)."""
    result = CliRunner().invoke(cli, ["evaluate", str(ROOT / "data" / "tasks" / "horizontal-offset-high-mu.yaml"),
                                      "--target", target, "--quiet"])
    assert result.exit_code == 2, result.output
    assert result.output.startswith("error: --target: must lie strictly between 0.01 and 1"), result.output
    assert "indifference 0.01 must be less" not in result.output
    assert math.isclose(0.01, SequentialTest(0.5).indifference)

