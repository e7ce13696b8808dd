"""The sequential decision of `evaluate --target` (stablepush.evaluation.sequential): its error
rates on synthetic Bernoulli streams (no simulator), that a study stops once it decides, and that
the test sees the trials in the order of their numbers, whatever order they finish in."""
import numpy as np
import pytest
from click.testing import CliRunner

import stablepush.evaluation.batch as batch_mod
from stablepush.evaluation import SequentialTest, decision_state, evaluate
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
