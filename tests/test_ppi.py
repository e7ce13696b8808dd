"""The model's verdict on a world (evaluation.prediction) and the prediction-powered rate
(evaluation.ppi): checked against the model rebuilt for each world, hand-counted tables, and
thousands of synthetic studies with predictors of every quality."""
import numpy as np
import pytest

from stablepush.evaluation.ppi import clopper_pearson, prediction_powered_rate
from stablepush.evaluation.prediction import PlanInWorlds, agreement, predicted_multipliers
from stablepush.evaluation.worlds import VARY_KEYS, Spreads
from stablepush.plan import plan_task
from stablepush.pose import Tolerance
from stablepush.task import load_task
from stablepush.task.model import UNCERTAIN
from stablepush.units import pose_to_si

from conftest import TASKS

SPREADS = Spreads(vary={"pad_mu": 0.3, "pusher_mu": 0.3, "grip_force": 0.1, "mass": 0.05})


def test_a_worlds_model_is_the_task_rebuilt_with_its_values():
    task = load_task(TASKS / "horizontal-offset-low-mu.yaml")
    model = task.model.in_world(1.2, 0.9, 1.05)
    rebuilt = task.with_values({"gripper.mu": task.gripper.mu * 1.2, "gripper.grip_force": task.gripper.grip_force * 0.9,
                                "object.mass": task.object.mass * 1.05}).model
    rng = np.random.default_rng(3)
    for _ in range(50):
        q = pose_to_si(tuple(rng.uniform(-5, 5, 2)) + (float(rng.uniform(-20, 20)),))
        dq = tuple(rng.uniform(-1, 1, 3) * (1e-3, 1e-3, 0.02))
        for p in range(len(task.pushers)):
            a, b = model.check(q, dq, p), rebuilt.check(q, dq, p)
            assert (a.feasible, a.margin) == pytest.approx((b.feasible, b.margin), abs=1e-12)
        assert model.hold_ratio(q, 0) == pytest.approx(rebuilt.hold_ratio(q, 0), rel=1e-12)
    with pytest.raises(ValueError, match="scales"):
        task.model.in_world(0.0, 1.0, 1.0)


def test_the_verdict_is_the_plan_rechecked_in_each_worlds_own_model():
    task = load_task(TASKS / "horizontal-offset-low-mu.yaml")
    plan = plan_task(task, seed=1)
    judge = PlanInWorlds(task, plan, Tolerance(0.5, 0.5))
    worlds = predicted_multipliers(7, 40, SPREADS)
    lands = judge.predict_multipliers(worlds)
    assert 0 < lands.sum() < len(lands)  # +-30% mu: some worlds hold every push, some do not
    for row, said in zip(worlds, lands):
        m = dict(zip(VARY_KEYS, row))
        pusher_mu = np.floor(m["pusher_mu"] / 1e-3 + 1e-9) * 1e-3
        world = task.with_values({"gripper.mu": task.gripper.mu * m["pad_mu"],
                                  "gripper.grip_force": task.gripper.grip_force * m["grip_force"],
                                  "object.mass": task.object.mass * m["mass"],
                                  **{UNCERTAIN["pusher_mu"].replace("*", p.name): p.mu * pusher_mu
                                     for p in task.pushers}})
        stable = all(world.model.check(pose_to_si(a.pose), tuple(np.subtract(pose_to_si(b.pose), pose_to_si(a.pose))),
                                       world.pusher_index(b.pushed_by)).feasible
                     for a, b in zip(plan.waypoints, plan.waypoints[1:]))
        held = task.environment.end_on_feature or world.model.hold_ratio(
            pose_to_si(plan.waypoints[-1].pose), world.pusher_index(plan.waypoints[-1].pushed_by)) >= 1.0
        assert said == (stable and held)


def test_the_model_only_worlds_are_drawn_within_the_spreads_and_reproduce_with_the_seed():
    worlds = predicted_multipliers(3, 5000, SPREADS)
    assert worlds.shape == (5000, len(VARY_KEYS))
    spread = np.array([SPREADS.vary[k] for k in VARY_KEYS])
    assert np.all(np.abs(worlds - 1.0) <= spread) and np.all(np.abs(worlds - 1.0).max(axis=0) > 0.95 * spread)
    assert np.array_equal(worlds, predicted_multipliers(3, 5000, SPREADS))
    assert not np.array_equal(worlds, predicted_multipliers(4, 5000, SPREADS))


def test_the_confusion_table_and_the_rate_on_a_hand_counted_study():
    landed = [True] * 8 + [False] * 2
    predicted = [True] * 7 + [False] + [True, False]  # 7 agree lands, 1 said miss but landed, 1 said land but missed
    assert agreement(predicted, landed) == {"lands_landed": 7, "lands_missed": 1, "misses_landed": 1,
                                            "misses_missed": 1}
    rate = prediction_powered_rate(landed, predicted, [True] * 750 + [False] * 250)
    # pi = 0.75, a = 7/8, b = 1/2
    assert rate.estimate == pytest.approx(0.75 * 7 / 8 + 0.25 * 0.5)
    assert rate.low < rate.estimate < rate.high
    assert rate.predicted_rate == 0.75 and rate.trials == 10 and rate.predictions == 1000


def test_clopper_pearson_matches_the_binomial_tail():
    from scipy.stats import binom

    low, high = clopper_pearson(7, 20, 0.05)
    assert binom.sf(6, 20, low) == pytest.approx(0.025) and binom.cdf(7, 20, high) == pytest.approx(0.025)
    assert clopper_pearson(0, 0, 0.05) == (0.0, 1.0)


PREDICTORS = {
    "exact": lambda y, rng: y,
    "noisy": lambda y, rng: y ^ (rng.random(y.size) < 0.1),
    "biased toward landing": lambda y, rng: y | (rng.random(y.size) < 0.5),
    "always wrong": lambda y, rng: ~y,
}


@pytest.mark.parametrize("predictor", PREDICTORS)
def test_the_95_percent_interval_holds_the_rate_in_95_percent_of_studies_whatever_the_predictor(predictor):
    rng = np.random.default_rng(11)
    held = studies = 0
    for rate in (0.99, 0.9, 0.6):
        for _ in range(500):
            y = rng.random(100) < rate
            unlabelled = rng.random(5000) < rate
            f = PREDICTORS[predictor](y, rng)
            f_unlabelled = PREDICTORS[predictor](unlabelled, rng)
            result = prediction_powered_rate(y, f, f_unlabelled)
            held += result.low <= rate <= result.high
            studies += 1
    assert held / studies >= 0.95, (predictor, held, studies)


def test_a_good_model_narrows_the_interval_of_a_plan_that_misses_often():
    rng = np.random.default_rng(5)
    y = rng.random(100) < 0.8
    predicted = y ^ (rng.random(100) < 0.02)
    unlabelled = rng.random(100_000) < 0.8
    unlabelled_f = unlabelled ^ (rng.random(100_000) < 0.02)
    rate = prediction_powered_rate(y, predicted, unlabelled_f)
    plain = clopper_pearson(int(y.sum()), y.size, 0.05)
    assert rate.high - rate.low < plain[1] - plain[0]
    assert rate.low <= plain[1] and plain[0] <= rate.high


def test_evaluate_predict_joins_the_models_verdicts_to_the_same_trials(tmp_path):
    import json

    from click.testing import CliRunner

    from stablepush_cli.main import cli

    args = ["evaluate", str(TASKS / "horizontal-offset-low-mu.yaml"), "--trials", "2", "--vary", "pad_mu=0.35",
            "--vary", "pusher_mu=0.35", "--workers", "1", "--quiet"]
    plain = CliRunner().invoke(cli, [*args, "--json", str(tmp_path / "plain.json")])
    predicted = CliRunner().invoke(cli, [*args, "--predict", "300", "--json", str(tmp_path / "predicted.json")])
    assert plain.exit_code == predicted.exit_code == 0, predicted.output
    assert "model-only worlds" in predicted.output and "the model agreed with" in predicted.output
    without, joined = (json.loads((tmp_path / f"{name}.json").read_text()) for name in ("plain", "predicted"))
    assert [t["success"] for t in without["trials"]] == [t["success"] for t in joined["trials"]]
    assert all(isinstance(t["predicted"]["lands"], bool) for t in joined["trials"])
    p = joined["summary"]["prediction"]
    assert p["predictions"] == 300 and p["trials"] == 2 and sum(p["agreement"].values()) == 2
    assert p["interval"][0] <= p["estimate"] <= p["interval"][1]
    assert without["summary"]["prediction"] is None


def test_evaluate_refuses_a_count_of_predictions_before_any_trial():
    from click.testing import CliRunner

    from stablepush_cli.main import cli

    result = CliRunner().invoke(cli, ["evaluate", str(TASKS / "pivoting.yaml"), "--predict", "20000000"])
    assert result.exit_code == 2 and "--predict: must be a whole number from 1 to 10,000,000" in result.output
    assert "trials" not in result.output.split("--predict")[0]
