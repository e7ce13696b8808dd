"""The sequential decision of `evaluate --target` (stablepush.evaluation.sequential): its error
rates on synthetic Bernoulli streams (no simulator), that a study stops once it decides, and that
the test sees the trials in the order of their numbers, whatever order they finish in."""
import re

import numpy as np
import pytest
from click.testing import CliRunner

import stablepush.evaluation.batch as batch_mod
from stablepush.evaluation import PredictionPoweredTest, SequentialTest, decision_state, evaluate
from stablepush.runners import Runner
from stablepush_cli.main import cli

from conftest import TASKS


def _studies(test, rate, studies=10_000, cap=20_000, seed=2026):
    rng = np.random.default_rng(seed)
    return [test.first_decision(rng.random(cap) < rate) for _ in range(studies)]


def test_a_rate_one_point_below_the_target_is_called_above_in_under_5_percent_of_10000_studies():
    results = _studies(SequentialTest(0.99, confidence=0.95), 0.98)
    above = sum(verdict == "above" for verdict, _ in results)
    assert above / len(results) < 0.05, above
    assert sum(verdict == "undecided" for verdict, _ in results) == 0


def test_a_rate_of_99_9_percent_is_called_above_within_a_few_hundred_trials_in_most_studies():
    results = _studies(SequentialTest(0.99, confidence=0.95), 0.999)
    quick = [n for verdict, n in results if verdict == "above" and n <= 400]
    assert len(quick) / len(results) > 0.9, len(quick)


def test_a_rate_at_the_target_is_called_below_in_under_5_percent_of_studies():
    results = _studies(SequentialTest(0.99, confidence=0.95), 0.99)
    assert sum(verdict == "below" for verdict, _ in results) / len(results) < 0.05


@pytest.mark.parametrize("settings, says", [({"target": 1.0}, "target: must lie strictly between 0 and 1"),
                                            ({"target": 0.9, "confidence": 0.4}, "confidence: must lie"),
                                            ({"target": 0.005}, "target: must lie strictly between 0.01 and 1")])
def test_settings_out_of_range_are_refused_by_name(settings, says):
    with pytest.raises(ValueError, match=says):
        SequentialTest(**settings)


def _synthetic(rate, seed=7):
    """A run_trial whose trial i lands as a seeded coin of `rate` decides, without a simulator."""
    def run_trial(batch, i):
        landed = bool(np.random.default_rng([seed, i]).random() < rate)
        return {"trial": i, "world": {"feature_offsets": {}}, "success": landed, "cause": None if landed else "drift",
                "goal_error": {"x": 0.0, "z": 0.0, "theta": 0.0, "distance": 0.0}, "final_error": None,
                "replans": 0, "sim_time_s": 1.0, "wall_s": 0.0, "verdict": "", "error": None}
    return run_trial


def test_a_study_stops_once_the_test_decides_and_says_how(monkeypatch):
    from test_evaluate import _batch

    monkeypatch.setattr(batch_mod, "run_trial", _synthetic(0.999))
    test = SequentialTest(0.99)
    result = evaluate(_batch(), 5000, Runner(workers=1), test=test)
    decision = result.summary()["decision"]
    outcomes = [t["success"] for t in result.trials]
    assert decision["decision"] == "above" and decision["trials"] == len(result.trials) < 5000
    assert test.first_decision(outcomes) == ("above", decision["trials"])
    assert any(line.startswith("decision: above: it lands at least 99.0%") for line in result.describe())


def test_the_test_takes_the_trials_in_the_order_of_their_numbers():
    """Failures that finish first (say they are quicker) must not decide the study early: trial 0
    lands, trials 1-5 fail; fed 1-5 first, the test waits for trial 0 and decides on 0-5 alone."""
    test = SequentialTest(0.99, confidence=0.9)
    decision = batch_mod._Decision(test)
    records = [{"trial": i, "success": i == 0} for i in range(6)]
    said = [decision.add(r) for r in records[1:] + records[:1]]
    assert said[:-1] == [False] * 5 and said[-1] is True
    assert decision.as_dict()["trials"] == test.first_decision([r["success"] for r in records])[1]


def test_confidence_alone_is_refused():
    result = CliRunner().invoke(cli, ["evaluate", str(TASKS / "pivoting.yaml"), "--confidence", "0.9", "--quiet"])
    assert result.exit_code == 2 and "--confidence: only with --target" in result.output


def test_a_target_inside_the_indifference_zone_is_refused_naming_the_options_range():
    result = CliRunner().invoke(cli, ["evaluate", str(TASKS / "pivoting.yaml"), "--target", "0.005", "--quiet"])
    assert result.exit_code == 2, result.output
    assert ("error: --target: must lie strictly between 0.01 and 1 (the test weighs the target against a rate 0.01 "
            "below it, its indifference zone), got 0.005") in result.output


def test_without_trials_a_target_of_99_percent_is_decided_above_when_every_trial_lands(monkeypatch):
    """296 landings in a row decide `above` at 0.99; the cap of 100 trials the command had left
    such a study undecided."""
    monkeypatch.setattr(batch_mod, "run_trial", _synthetic(1.0))
    result = CliRunner().invoke(cli, ["evaluate", str(TASKS / "more/tilted-gravity.yaml"), "--target", "0.99",
                                      "--workers", "1"])
    assert result.exit_code == 0, result.output
    assert "up to 1276 trials" in result.output
    assert ("decision: above: it lands at least 99.0% of the time (95% confidence, Wald's SPRT), after the first 296 "
            "trials (296 landed)") in result.output


def test_the_apis_evaluate_takes_the_tests_default_cap_too(monkeypatch):
    from test_evaluate import _batch

    monkeypatch.setattr(batch_mod, "run_trial", _synthetic(1.0))
    result = evaluate(_batch(), runner=Runner(workers=1), test=SequentialTest(0.99))
    d = result.summary()["decision"]
    assert (d["decision"], d["trials"], d["successes"], result.requested) == ("above", 296, 296, 1276)


@pytest.mark.parametrize("rate, decided", [(0.999, 0.99), (0.99, 0.75), (0.98, 0.75), (0.97, 0.99)])
def test_the_default_cap_decides_most_studies_at_the_edges_of_the_indifference_zone_and_nearly_all_outside(
        rate, decided):
    test = SequentialTest(0.99)
    cap = test.default_cap()
    assert cap == 1276 and test.to_decide(0, 0, "above") == 296
    results = _studies(test, rate, studies=4000, cap=cap)
    assert sum(verdict != "undecided" for verdict, _ in results) / len(results) > decided


def test_a_cap_the_test_cannot_decide_above_within_is_warned_of(monkeypatch):
    monkeypatch.setattr(batch_mod, "run_trial", _synthetic(1.0))
    result = CliRunner().invoke(cli, ["evaluate", str(TASKS / "more/tilted-gravity.yaml"), "--target", "0.99",
                                      "--trials", "100", "--workers", "1", "--quiet"])
    assert result.exit_code == 0, result.output
    assert ("warning: --trials 100: the test cannot decide above within 100 trials: a plan that lands every time "
            "needs 296 (the default cap is 1276)") in result.output


def test_the_progress_line_shows_where_the_test_stands_on_the_trials_in_their_order(monkeypatch):
    test = SequentialTest(0.99)
    assert test.state(0, 0) == "log LR +0.00 in (-3.00, +3.00): 296 more landings decide above, 5 misses below"
    done = [{"trial": i, "success": True} for i in (0, 1, 3)]  # trial 3 waits for trial 2, not yet finished
    assert decision_state(test, done) == test.state(2, 2)
    assert "294 more landings decide above" in decision_state(test, done)
    assert decision_state(test, [{"trial": i, "success": True} for i in range(296)]) == "decided above (log LR +3.01)"

    import stablepush_cli.common as common

    class Bar:
        labels = []

        def update(self, n):
            self.labels.append(self.label)

        def render_finish(self):
            pass

    monkeypatch.setattr(common, "progressbar", lambda quiet, **options: Bar())
    monkeypatch.setattr(batch_mod, "run_trial", _synthetic(1.0))
    result = CliRunner().invoke(cli, ["evaluate", str(TASKS / "more/tilted-gravity.yaml"), "--target", "0.99",
                                      "--trials", "3", "--workers", "1"])
    assert result.exit_code == 0, result.output
    assert Bar.labels[-1] == f"landed 3/3 (100%); {test.state(3, 3)}", Bar.labels


# The prediction-powered test (sequential.PredictionPoweredTest): each trial carries the model's verdict
# on its world, and the model's verdicts on 100,000 model-only worlds give pi_hat.
PREDICTORS = {  # the model's verdict from the trial's outcome, and pi = P(verdict lands) at a rate r
    "exact": (lambda y, rng: y, lambda r: r),
    "noisy (10% flipped)": (lambda y, rng: y ^ (rng.random(y.size) < 0.1), lambda r: 0.9 * r + 0.1 * (1 - r)),
    "biased toward landing": (lambda y, rng: y | (rng.random(y.size) < 0.5), lambda r: r + 0.5 * (1 - r)),
    "pessimistic (a fifth of landings called misses)": (lambda y, rng: y & (rng.random(y.size) >= 0.2),
                                                         lambda r: 0.8 * r),
    "always wrong": (lambda y, rng: ~y, lambda r: 1 - r),
}


def _powered_studies(predictor, rate, studies=2000, target=0.99, predictions=100_000, seed=2026):
    """`studies` synthetic studies at `rate`, capped at the Wald test's default cap: each its
    trials' outcomes, the model's verdicts on them, and its own draw of the model-only verdicts."""
    verdict, pi = PREDICTORS[predictor]
    wald = SequentialTest(target)
    cap = wald.default_cap()
    rng = np.random.default_rng(seed)
    out = []
    for _ in range(studies):
        y = rng.random(cap) < rate
        test = PredictionPoweredTest(target, predictions, int(rng.binomial(predictions, pi(rate))))
        out.append((test.first_decision(y, verdict(y, rng)), wald.first_decision(y)))
    return out


def test_the_powered_tests_wealth_after_two_trials_is_the_equation_by_hand():
    """target 0.9, indifference 0.1 (p0 = 0.8), 100 model-only worlds all predicted to land (pi_hat = 1,
    pi_low = 0.0025^(1/100), Clopper-Pearson at delta = 0.1 x 0.05). Trial 1 (landed, said lands):
    no trial before, so a = b = the pooled prior 1/2, lambda = 0, Z = 1; the bets' prior is one trial
    at 0.85, variance 0.85 x 0.15, so b = 0.05 / (0.1275 + 0.0025) both ways. Trial 2 (missed, said
    misses): pooled (1 + 1/2) / 2 = 3/4, a = (1 + 3/4) / 2, b = 3/4, lambda = 1/8, Z = 0 + 1/8 (1 - 0);
    the plug-in bet on `above` is past the largest, 0.9 / (m - min Z), and is cut to it."""
    test = PredictionPoweredTest(0.9, 100, 100, confidence=0.95, indifference=0.1)
    above, below = test.betting_log_wealth([True, False], [True, False])
    bet = 0.05 / 0.13
    assert above[0] == pytest.approx(np.log(1 + bet * (1 - 0.8)), rel=1e-12)
    assert below[0] == pytest.approx(np.log(1 + bet * (0.9 - 1)), rel=1e-12)
    lam, z, pi_low = 0.125, 0.125, 0.0025 ** (1 / 100)
    m_above, m_below = 0.8 + lam * (1 - pi_low), 0.9  # pi_high = pi_hat = 1
    mean = (0.85 + 1) / 2
    variance = (0.85 * 0.15 + 0.85 ** 2 + 1) / 2 - mean ** 2
    bet_above = (mean - m_above) / (variance + (mean - m_above) ** 2)  # 1.41: past the largest bet,
    assert bet_above > 0.9 / (m_above + lam * (1 - 1.0))  # c / (m - min Z), min Z = -lambda (1 - pi_hat)
    bet_above = 0.9 / m_above
    bet_below = 0.0  # the mean, 0.925, is above m' = 0.9: no bet on `below`
    assert above[1] - above[0] == pytest.approx(np.log(1 + bet_above * (z - m_above)), rel=1e-12)
    assert below[1] - below[0] == pytest.approx(np.log(1 + bet_below * (m_below - z)), abs=1e-15)
    assert test.bounds == pytest.approx((np.log(1 / 0.045), np.log(1 / 0.045)))
    # the test decides by half of that wealth and half Wald's likelihood ratio of 0.9 against 0.8
    ratio = np.cumsum([np.log(0.9 / 0.8), np.log(0.1 / 0.2)])
    mixed_above, mixed_below = test.log_wealth([True, False], [True, False])
    assert np.exp(mixed_above) == pytest.approx(0.5 * np.exp(above) + 0.5 * np.exp(ratio), rel=1e-12)
    assert np.exp(mixed_below) == pytest.approx(0.5 * np.exp(below) + 0.5 * np.exp(-ratio), rel=1e-12)


def test_an_exact_model_makes_a_foreseen_miss_no_evidence_against_the_plan():
    """After trials under both verdicts have shown the model right, a miss it foresaw moves `above`'s
    wealth less than a miss it did not: Z = Y - lambda (F - pi_hat) is near pi_hat."""
    test = PredictionPoweredTest(0.99, 100_000, 99_000)
    y = [True] * 100 + [False] + [True] * 100
    foreseen = test.betting_log_wealth(y + [False], y + [False])
    unforeseen = test.betting_log_wealth(y + [False], y + [True])
    lost, lost_unforeseen = foreseen[0][-2] - foreseen[0][-1], unforeseen[0][-2] - unforeseen[0][-1]
    assert 0 < lost < lost_unforeseen / 2, (lost, lost_unforeseen)


@pytest.mark.parametrize("predictor", PREDICTORS)
def test_the_powered_tests_error_rates_stay_within_alpha_and_beta_whatever_the_model(predictor):
    """At p0 = 0.98 `above` is wrong, at p1 = 0.99 `below` is: each in at most 5% of 2,000 studies
    (3 binomial standard errors of slack: 0.05 + 3 x 0.0049)."""
    for rate, wrong in ((0.98, "above"), (0.99, "below")):
        results = _powered_studies(predictor, rate, seed=int(rate * 1000))
        said = sum(verdict == wrong for (verdict, _), _wald in results)
        assert said / len(results) <= 0.05 + 3 * np.sqrt(0.05 * 0.95 / len(results)), (predictor, rate, said)


@pytest.mark.parametrize("predictor", ["exact", "always wrong", "pessimistic (a fifth of landings called misses)"])
def test_a_plan_that_lands_99_9_percent_is_called_above_well_before_walds_296_trials(predictor):
    results = _powered_studies(predictor, 0.999, studies=1000)
    powered = [(verdict, n) for (verdict, n), _wald in results]
    assert sum(verdict == "above" for verdict, _ in powered) / len(powered) > 0.99
    assert np.median([n for _, n in powered]) <= 0.75 * np.median([n for _, (_, n) in results]) == 0.75 * 296


def test_at_the_target_with_a_useless_model_the_test_is_nearly_as_decisive_as_walds():
    """The bets alone leave most studies of a plan that lands 99% of the time undecided when the
    model is always wrong (about 60%, against Wald's 20%); holding half the wealth in Wald's ratio
    keeps within 15 points of Wald's."""
    results = _powered_studies("always wrong", 0.99, studies=500)
    ours = sum(verdict == "undecided" for (verdict, _), _wald in results) / len(results)
    walds = sum(verdict == "undecided" for _ours, (verdict, _) in results) / len(results)
    assert ours <= walds + 0.15, (ours, walds)


def test_with_an_exact_model_the_edges_of_the_indifference_zone_are_decided_the_right_way():
    for rate, right in ((0.995, "above"), (0.98, "below")):
        results = _powered_studies("exact", rate, studies=500)
        assert sum(verdict == right for (verdict, _), _wald in results) / len(results) > 0.9, rate


@pytest.mark.parametrize("settings, says", [({"predictions": 0}, "predictions: must be a whole number"),
                                            ({"predicted_landings": 11}, "predicted_landings: must be a whole number "
                                                                         "from 0 to 10"),
                                            ({"target": 1.0}, "target: must lie strictly between 0 and 1")])
def test_the_powered_tests_settings_out_of_range_are_refused_by_name(settings, says):
    with pytest.raises(ValueError, match=says):
        PredictionPoweredTest(**{"target": 0.99, "predictions": 10, "predicted_landings": 5, **settings})


def test_evaluate_with_predictions_decides_by_the_powered_test_and_says_so(monkeypatch):
    from test_evaluate import _batch

    monkeypatch.setattr(batch_mod, "run_trial", _synthetic(1.0))
    batch = _batch()
    result = evaluate(batch, runner=Runner(workers=1), test=SequentialTest(0.99), predictions=2000)
    d = result.summary()["decision"]
    assert d["method"] == "prediction-powered test by betting" and d["predictions"] == 2000
    assert d["decision"] == "above" and d["trials"] == len(result.trials) < 296
    verdicts = batch_mod.model_only_verdicts(batch, 2000)
    test = PredictionPoweredTest.of(SequentialTest(0.99), verdicts)
    assert test.first_decision([t["success"] for t in result.trials],
                               [t["predicted"]["lands"] for t in result.trials]) == ("above", d["trials"])
    assert result.prediction is not None and result.prediction.predictions == 2000
    assert decision_state(test, result.trials).startswith("decided above (log wealth above +3.1")
    assert decision_state(test, result.trials[:3]).startswith("log wealth above ")


def test_evaluate_target_with_predict_decides_by_the_powered_test(monkeypatch):
    monkeypatch.setattr(batch_mod, "run_trial", _synthetic(1.0))
    result = CliRunner().invoke(cli, ["evaluate", str(TASKS / "more/tilted-gravity.yaml"), "--target", "0.99",
                                      "--predict", "1000", "--workers", "1", "--quiet"])
    assert result.exit_code == 0, result.output
    decided = re.search(r"\(95% confidence, prediction-powered test by betting\), after the first (\d+) trials",
                        result.output)
    assert decided is not None and int(decided.group(1)) < 296, result.output  # Wald's: 296
