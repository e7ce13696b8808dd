"""Calibration (stablepush.calibration, `stablepush calibrate`): the posterior's arithmetic by hand,
its intervals' coverage over random worlds with synthetic probes, the probes the model chooses
(safe, informative, runnable as plans), a world that hides its friction, the calibrated task file,
and calibration from run reports. The probes on the simulated arm are in test_calibrate_sim.py."""
import json
import math

import numpy as np
import pytest
from click.testing import CliRunner

from stablepush.calibration import Belief, Calibration, CalibrationSettings, Interval, calibrate_from_runs
from stablepush.calibration.belief import expected_information, grid, split, stick_chance
from stablepush.calibration.files import calibrated_task_text
from stablepush.calibration.probes import (
    SLIP_DEG,
    SLIP_MM,
    Instrument,
    Unknowns,
    WorldGrid,
    candidates,
    probe_plan,
    probe_world,
)
from stablepush.errors import SettingError, TaskError
from stablepush.execution.world import place_features, scene_description
from stablepush.plan import Waypoint, check_plan
from stablepush.sim import WorldDeviation
from stablepush.task import load_task, parse_task
from stablepush_cli.main import cli

from conftest import TASKS


def test_one_observation_moves_the_mass_by_the_error_rate_by_hand():
    """Two values per axis, one pusher; a push stable only where the pads' mu is low. Observed to
    stick with error rate e, the low cells weigh (1 - e) each and the high ones e: the pads' low
    value has (1 - e) of the mass."""
    belief = Belief([0.2, 0.4], [[0.1, 0.3]])
    margins = np.array([[0.5, 0.5], [-0.5, -0.5]])  # [pad, pusher], N
    chance = stick_chance(margins, 0.1, 0.0)
    assert chance == pytest.approx(np.array([[0.9, 0.9], [0.1, 0.1]]))
    belief.observe(0, chance, stuck=True)
    assert np.exp(belief.pad_log_marginal()) == pytest.approx([0.9, 0.1])
    assert np.exp(belief.pusher_log_marginal(0)) == pytest.approx([0.5, 0.5])  # the pusher's mu untouched
    assert split(belief.pair_weights(0), chance) == pytest.approx(0.9 * 0.9 + 0.1 * 0.1)
    assert not belief.informative(0)


def test_a_boundary_blurs_the_verdict_by_its_margin_by_hand():
    """Blurred over 1 N: a margin of 1 N sticks with Phi(1) = 0.8413, of 0 N a coin toss, then the
    error rate: 0.02 + 0.96 x 0.8413."""
    assert stick_chance(np.array([1.0, 0.0, -1.0]), 0.02, 1.0) == pytest.approx(
        [0.02 + 0.96 * 0.841345, 0.5, 0.02 + 0.96 * 0.158655], abs=1e-6)


def test_the_pads_marginal_is_the_product_over_pushers_by_hand():
    """Pusher 0 says the pads' mu is low (e = 0.1), pusher 1 says it is high (e = 0.2): the low
    value's odds are 0.9/0.1 x 0.2/0.8 = 2.25."""
    belief = Belief([0.2, 0.4], [[0.1, 0.3], [0.1, 0.3]])
    belief.observe(0, np.array([[0.9, 0.9], [0.1, 0.1]]), stuck=True)
    belief.observe(1, np.array([[0.2, 0.2], [0.8, 0.8]]), stuck=True)
    low, high = np.exp(belief.pad_log_marginal())
    assert low / high == pytest.approx(0.9 / 0.1 * 0.2 / 0.8)


def test_a_sure_push_tells_nothing_and_an_even_one_tells_most():
    weights = np.array([[0.5, 0.5]])

    def bits(stuck_left, stuck_right):
        return expected_information(weights, stick_chance(np.array([[stuck_left, stuck_right]]), 0.05, 0.0))

    assert bits(1.0, 1.0) == pytest.approx(0.0, abs=1e-9)  # sticks in every world
    assert bits(-1.0, -1.0) == pytest.approx(0.0, abs=1e-9)
    assert bits(1.0, -1.0) > 0.5  # splits the posterior in two
    coin = expected_information(weights, np.array([[0.5, 0.5]]))
    assert coin == pytest.approx(0.0, abs=1e-9)  # a coin toss in every world tells nothing


def test_grid_spans_the_spread_and_a_frictionless_nominal_from_zero():
    assert grid(0.4, 0.5, 5) == pytest.approx((0.2, 0.3, 0.4, 0.5, 0.6))
    assert grid(0.0, 0.5, 3) == pytest.approx((0.0, 0.25, 0.5))


def _bisection_study(rng, error_rate, probes=12, size=25):
    """A random world (pads, two pushers) and `probes` synthetic probes, each a boundary line in
    (pad mu, pusher mu) through the posterior's middle at a random slope, observed with
    `error_rate`: whether the pads' and each pusher's interval holds the truth."""
    pad_axis, axes = np.array(grid(0.4, 0.5, size)), [np.array(grid(0.2, 0.5, size)), np.array(grid(0.5, 0.5, size))]
    truth = (rng.uniform(0.24, 0.56), rng.uniform(0.12, 0.28), rng.uniform(0.3, 0.7))
    belief = Belief(pad_axis, axes)
    for k in range(probes):
        i = k % 2
        a = rng.uniform(0.2, 1.0) * rng.choice([-1.0, 1.0])
        # through the posterior mean: the line a (pad / pad0) + (mu / mu0) = t
        pad_mean, mu_mean = belief.pad_interval().value, belief.pusher_interval(i).value
        t = a * pad_mean / 0.4 + mu_mean / axes[i][size // 2]
        margins = a * pad_axis[:, None] / 0.4 + axes[i][None, :] / axes[i][size // 2] - t
        truly = a * truth[0] / 0.4 + truth[1 + i] / axes[i][size // 2] > t
        observed = truly if rng.random() >= error_rate else not truly
        belief.observe(i, stick_chance(margins, error_rate, 0.0), observed)
    intervals = [belief.pad_interval(), belief.pusher_interval(0), belief.pusher_interval(1)]
    return [iv.low <= v <= iv.high for iv, v in zip(intervals, truth)]


def test_the_intervals_hold_the_truth_in_at_least_93_percent_of_random_worlds():
    """Over 300 random worlds with observations wrong 5% of the time (the rate the posterior
    assumes), each of the three 95% intervals holds the truth in at least 93% of them."""
    rng = np.random.default_rng(7)
    held = np.array([_bisection_study(rng, 0.05) for _ in range(300)])
    assert held.mean(axis=0).min() >= 0.93, held.mean(axis=0)


def test_the_probes_of_a_shipped_task_are_safe_informative_and_plans_of_their_world():
    task = load_task(TASKS / "horizontal-offset-low-mu.yaml")
    unknowns = Unknowns.of(task, 0.5, 9)
    worlds = WorldGrid(task, unknowns)
    belief = unknowns.belief()
    probes = candidates(task, worlds, belief, task.start, Instrument(pushes=4, error_rate=0.05))
    assert probes and probes[0].bits > 0.5  # one splits the grid nearly evenly
    assert sorted({p.pusher for p in probes if p.bits > 0.1}) == ["bottom", "left", "right"]
    for probe in probes[:5]:
        assert (probe.margins > 0).any() and not (probe.margins > 0).all()
        world = probe_world(task, unknowns, belief, probe)
        check_plan(world, probe_plan(world, probe))  # each push stable in the world it is planned in
        for pose in probe.poses:
            assert abs(pose[0] - task.start[0]) <= 10.0 and world.model.grasp_maintained(
                [pose[0] * 1e-3, pose[1] * 1e-3, math.radians(pose[2])])


def test_a_world_with_its_own_values_is_the_scene_of_the_task_with_them():
    """The fidelity contract is shown on scenes made from tasks: a world that sets a task's fields
    builds exactly the scene of the task that has them, so the contract holds in it."""
    task = load_task(TASKS / "horizontal-offset-low-mu.yaml")
    values = (("gripper.mu", 0.31), ("pushers.left.mu", 0.27), ("gripper.grip_force", 12.5), ("object.mass", 250.0))
    deviation = WorldDeviation(world=values)
    start = [Waypoint(*task.start)]
    given = deviation.apply(scene_description(task, place_features(task, start, True), task.start, solid=False))
    world = deviation.world_task(task)
    expected = scene_description(world, place_features(world, start, True), task.start, solid=False)
    assert given.gripper == expected.gripper and given.features == expected.features
    assert given.object.mass == pytest.approx(expected.object.mass)
    assert given.object.inertia == pytest.approx(expected.object.inertia)


def test_a_world_fixed_to_a_task_keeps_its_mu_whatever_a_probe_was_planned_for():
    """A probe is a plan of another world than the task's: a simulated world that sets only some
    mu must keep the task's others, not take the probe's."""
    task = load_task(TASKS / "horizontal-offset-low-mu.yaml")
    fixed = dict(WorldDeviation(world=(("pushers.left.mu", 0.3),)).fixed_to(task).world)
    assert fixed == {"gripper.mu": 0.425, "pushers.left.mu": 0.3, "pushers.right.mu": 0.2, "pushers.bottom.mu": 0.2}
    probe_world = task.with_values({"pushers.right.mu": 0.9, "gripper.mu": 0.6})
    start = [Waypoint(*task.start)]
    scene = WorldDeviation(world=tuple(fixed.items())).apply(
        scene_description(probe_world, place_features(probe_world, start, True), task.start, solid=False))
    assert scene.gripper.mu == 0.425 and {f.pusher: f.mu for f in scene.features}["right"] == 0.2


def test_a_world_names_fields_a_world_sets_and_the_task_has():
    with pytest.raises(SettingError, match="not a field a world sets"):
        WorldDeviation(world=(("gripper.pad_rings", 2.0),))
    with pytest.raises(SettingError, match="gripper.mu"):
        WorldDeviation(world=(("gripper.mu", -0.1),))
    task = load_task(TASKS / "horizontal-offset-low-mu.yaml")
    with pytest.raises(TaskError, match="nope"):
        WorldDeviation(world=(("pushers.nope.mu", 0.3),)).world_task(task)


def test_execute_refuses_a_world_field_the_task_has_not_before_anything_moves(tmp_path):
    plan = tmp_path / "p.json"
    task = TASKS / "pivoting.yaml"
    assert CliRunner().invoke(cli, ["plan", str(task), "-o", str(plan)]).exit_code == 0
    result = CliRunner().invoke(cli, ["execute", str(plan), "--task", str(task), "--sim", "--world",
                                      "pushers.nope.mu=0.3"])
    assert result.exit_code == 2 and "nope" in result.output
    result = CliRunner().invoke(cli, ["execute", str(plan), "--task", str(task), "--world", "gripper.mu=0.3"])
    assert result.exit_code == 2 and "--world: only with --sim" in result.output
    result = CliRunner().invoke(cli, ["execute", str(plan), "--task", str(task), "--sim", "--world", "gripper.mu"])
    assert result.exit_code == 2 and "FIELD=VALUE" in result.output


def _calibration(task, pad=(0.4, 0.38, 0.43), left=(0.21, 0.2, 0.22)):
    return Calibration(task, {"gripper.mu": Interval(*pad), "pushers.left.mu": Interval(*left)},
                       {"pushers.bottom.mu": "no safe push by bottom"}, [], "test", CalibrationSettings())


def test_the_calibrated_task_file_holds_the_estimates_and_a_box_over_the_intervals():
    task = load_task(TASKS / "horizontal-offset-low-mu.yaml")
    calibration = _calibration(task)
    text = calibrated_task_text(calibration)
    again = parse_task(text, source="calibrated.yaml")
    assert again.gripper.mu == pytest.approx(0.4)
    # left at its interval's low end: a plan stable there is stable over the whole interval
    assert again.pushers[0].mu == pytest.approx(0.2)
    assert again.pushers[1].mu == task.pushers[1].mu  # right: not estimated, kept
    # the pads' box covers their interval about the estimate
    assert again.gripper.mu * (1 - again.uncertainty["pad_mu"]) <= 0.38
    assert again.gripper.mu * (1 + again.uncertainty["pad_mu"]) >= 0.43
    assert again.uncertainty.get("pusher_mu", 0.0) == task.uncertainty.get("pusher_mu", 0.0)  # bottom: unidentified
    every = Calibration(task, {"gripper.mu": Interval(0.4, 0.38, 0.43), **{
        f"pushers.{p.name}.mu": Interval(0.2, 0.15, 0.3) for p in task.pushers}}, {}, [], "test",
        CalibrationSettings())
    assert "pusher_mu" not in every.calibrated_task().uncertainty
    assert {p.mu for p in every.calibrated_task().pushers} == {0.15}
    assert "# Paper Table II" in text  # the task file's own comments kept
    assert "pushers.bottom.mu: not identified" in text


def _report(task, steps, contacts):
    return {"task": task.name, "contacts": contacts, "steps": steps}


def test_runs_whose_pushes_slipped_bound_the_friction_from_their_reports():
    """A run of the low-mu task's drag by `left`: the pusher carries the weight by its friction
    against a push as hard as the pads' friction, so the drag is stable only where the pads' mu
    (and the pusher's) is high enough. Reported stuck, the pads' mu moves up; slipped, down."""
    task = load_task(TASKS / "horizontal-offset-low-mu.yaml")
    steps = [[0.0, 0.0, 0.0, None]] + [[float(k), -0.1 * k, 0.0, "left"] for k in range(1, 5)]
    slipped = _report(task, steps, [{"pusher": "left", "first_step": 1, "last_step": 4, "slip_mm": 0.3,
                                     "slip_deg": 0.2}])
    stuck = _report(task, steps, [{"pusher": "left", "first_step": 1, "last_step": 4, "slip_mm": 0.01,
                                   "slip_deg": 0.001}])
    settings = CalibrationSettings(grid=9)
    down = calibrate_from_runs(task, [("a.json", slipped)], settings).estimates["gripper.mu"].value
    up = calibrate_from_runs(task, [("b.json", stuck)], settings).estimates["gripper.mu"].value
    assert down < task.gripper.mu < up
    assert SLIP_MM < 0.3 and SLIP_DEG < 0.2


def test_the_same_pushes_run_again_are_one_observation_their_majority():
    """Runs of one plan make the same pushes; where the model or the simulator errs on them it errs
    every time, so 20 reports of a slipped drag narrow nothing beyond one, and one stuck report
    among three slipped ones is outvoted."""
    task = load_task(TASKS / "horizontal-offset-low-mu.yaml")
    steps = [[0.0, 0.0, 0.0, None]] + [[float(k), -0.1 * k, 0.0, "left"] for k in range(1, 5)]

    def report(slip_mm):
        return _report(task, steps, [{"pusher": "left", "first_step": 1, "last_step": 4, "slip_mm": slip_mm,
                                      "slip_deg": 0.001}])

    settings = CalibrationSettings(grid=9)
    once = calibrate_from_runs(task, [("a.json", report(0.3))], settings).estimates["gripper.mu"]
    twenty = calibrate_from_runs(task, [(f"{k}.json", report(0.3)) for k in range(20)], settings)
    assert twenty.estimates["gripper.mu"] == once and len(twenty.probes) == 20
    shifted = [[v + 0.03 * (k < 3) for k, v in enumerate(step[:3])] + step[3:] for step in steps]  # tracker noise
    outvoted = [("s.json", report(0.01))] + [(f"{k}.json", report(0.3)) for k in range(2)]
    outvoted.append(("t.json", _report(task, shifted, [{"pusher": "left", "first_step": 1, "last_step": 4,
                                                         "slip_mm": 0.3, "slip_deg": 0.001}])))
    assert calibrate_from_runs(task, outvoted, settings).estimates["gripper.mu"] == once


def test_the_pads_product_is_read_as_the_grip_force_or_the_mass_that_is_named():
    """mu, grip force and mass enter the stable-push test only as mu N / m (docs/model.md section
    7). So the slipped drag of the test above puts the grip force where it put mu, as a share of
    the task's (the margins over the grid are the same), and the mass above the task's; naming two
    leaves both unidentified, with the product in the reason."""
    task = load_task(TASKS / "horizontal-offset-low-mu.yaml")
    steps = [[0.0, 0.0, 0.0, None]] + [[float(k), -0.1 * k, 0.0, "left"] for k in range(1, 5)]
    slipped = [("a.json", _report(task, steps, [{"pusher": "left", "first_step": 1, "last_step": 4, "slip_mm": 0.3,
                                                 "slip_deg": 0.2}]))]
    mu = calibrate_from_runs(task, slipped, CalibrationSettings(grid=9)).estimates["gripper.mu"]
    by_force = calibrate_from_runs(task, slipped, CalibrationSettings(grid=9, estimate=("gripper.grip_force",)))
    force = by_force.estimates["gripper.grip_force"]
    assert "gripper.mu" not in by_force.estimates and "gripper.mu" not in by_force.unidentified
    for a, b in ((force.value, mu.value), (force.low, mu.low), (force.high, mu.high)):
        assert a / task.gripper.grip_force == pytest.approx(b / task.gripper.mu, rel=1e-9)
    mass = calibrate_from_runs(task, slipped, CalibrationSettings(grid=9, estimate=("object.mass",)))
    assert mass.estimates["object.mass"].value > task.object.mass
    both = calibrate_from_runs(task, slipped, CalibrationSettings(grid=9, estimate=("gripper.mu", "object.mass")))
    assert set(both.unidentified) >= {"gripper.mu", "object.mass"} and "gripper.mu" not in both.estimates
    assert "only through the product" in both.unidentified["gripper.mu"]
    assert both.calibrated_task().gripper.mu == task.gripper.mu  # the task's values kept


@pytest.mark.parametrize("name", ["t-shaped", "horizontal-offset-low-mu"])
def test_a_pushs_verdict_depends_on_mu_times_grip_force_over_mass_alone(name):
    """docs/model.md section 7: the pads' mu x 0.8, the grip force x 0.8 and the mass / 0.8 give
    the same verdict for every push, over random poses and moves (the margin scales with the
    product)."""
    task = load_task(TASKS / f"{name}.yaml")
    s = 0.8
    worlds = [task.with_values({"gripper.mu": task.gripper.mu * s}).model,
              task.with_values({"gripper.grip_force": task.gripper.grip_force * s}).model,
              task.with_values({"object.mass": task.object.mass / s}).model]
    rng = np.random.default_rng(3)
    flips = []
    for _ in range(150):
        q = [rng.uniform(-5e-3, 5e-3), rng.uniform(-5e-3, 5e-3), math.radians(rng.uniform(-5, 5))]
        dq = [rng.normal() * 1e-3, rng.normal() * 1e-3, math.radians(rng.normal())]
        results = [model.check_all(q, dq) for model in worlds]
        for by_mu, by_force, by_mass in zip(*results):
            assert by_mu.feasible == by_force.feasible == by_mass.feasible
            flips.append(by_mu.feasible)
            assert by_force.margin == pytest.approx(by_mu.margin, rel=1e-6, abs=1e-9)
    assert 0 < sum(flips) < len(flips)  # both verdicts occur


def test_an_interval_at_the_grids_end_is_said_to_be_there():
    """The posterior knows the task's value times 1 -+ spread only: a mass of 300 g against the
    task's 130 was estimated 186 (160 to 195 = 130 x 1.5) on the arm. Such an interval is flagged;
    one inside the grid, or down at a frictionless grid's 0, is not."""
    task = load_task(TASKS / "large-manipulation.yaml")
    settings = CalibrationSettings(estimate=("object.mass",))
    calibration = Calibration(task, {"object.mass": Interval(186.2, 159.8, 195.0),
                                     "pushers.left.mu": Interval(0.6, 0.4, 0.8),
                                     "pushers.right.mu": Interval(0.35, 0.3, 0.45)}, {}, [], "test", settings)
    assert calibration.at_grid_edge() == {"object.mass": "high", "pushers.right.mu": "low"}
    assert calibration.as_dict()["at_grid_edge"] == calibration.at_grid_edge()
    assert "    at the grid's high end (the task's value x1.5): the world may lie beyond it" in "\n".join(
        calibration.describe())
    frictionless = Calibration(task.with_values({"pushers.left.mu": 0.0}), {"pushers.left.mu": Interval(0.1, 0.0, 0.3)},
                               {}, [], "test", settings)
    assert frictionless.at_grid_edge() == {}


def test_a_calibrated_grip_force_is_written_with_its_box():
    task = load_task(TASKS / "horizontal-offset-low-mu.yaml")
    calibration = Calibration(task, {"gripper.grip_force": Interval(12.0, 11.0, 13.5)}, {}, [], "test",
                              CalibrationSettings(estimate=("gripper.grip_force",)))
    again = parse_task(calibrated_task_text(calibration), source="calibrated.yaml")
    assert again.gripper.grip_force == pytest.approx(12.0) and again.gripper.mu == task.gripper.mu
    assert "pad_mu" not in again.uncertainty
    assert again.gripper.grip_force * (1 - again.uncertainty["grip_force"]) <= 11.0
    assert again.gripper.grip_force * (1 + again.uncertainty["grip_force"]) >= 13.5


def test_a_report_without_its_steps_is_refused_naming_the_file(tmp_path):
    task = load_task(TASKS / "horizontal-offset-low-mu.yaml")
    with pytest.raises(SettingError, match="old.json.*no `steps`"):
        calibrate_from_runs(task, [("old.json", {"task": task.name, "contacts": []})])
    path = tmp_path / "bad.json"
    path.write_text(json.dumps({"x": 1}))
    result = CliRunner().invoke(cli, ["calibrate", str(TASKS / "horizontal-offset-low-mu.yaml"), "--from", str(path)])
    assert result.exit_code == 2 and "not a run report" in result.output


def test_interval_half_width_is_the_farther_end():
    assert Interval(0.5, 0.4, 0.7).half_width == pytest.approx(0.2)


def test_ctrl_c_stops_at_once_keeping_what_was_measured_and_running_nothing_more():
    from stablepush.calibration import calibrate

    task = load_task(TASKS / "horizontal-offset-low-mu.yaml")
    calls = []

    def arm_for():
        calls.append(1)
        raise KeyboardInterrupt

    calibration = calibrate(task, arm_for, CalibrationSettings(grid=9))
    assert calibration.stopped == "interrupted" and calibration.probes == [] and calibration.returned is None
    assert len(calls) == 1 and "gripper.mu" in calibration.unidentified


def test_calibration_settings_refuse_what_they_cannot_be():
    with pytest.raises(SettingError, match="max_probes"):
        CalibrationSettings(max_probes=0)
    with pytest.raises(SettingError, match="spread"):
        CalibrationSettings(spread=1.0)
    with pytest.raises(SettingError, match="target"):
        CalibrationSettings(target=(0.0, 0.1))
    for estimate in ((), ("gripper.pad_rings",), ("object.mass", "object.mass"), "gripper.mu"):
        with pytest.raises(SettingError, match="estimate"):
            CalibrationSettings(estimate=estimate)
