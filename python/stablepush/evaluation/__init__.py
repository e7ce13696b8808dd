"""A plan's measured success rate over many perturbed worlds (`stablepush evaluate`): the worlds
(worlds.py), the batch that runs one trial per world (batch.py) where `stablepush.runners`
says: here, on local processes or on Ray, the sequential decision that may stop it early
(sequential.py), and the model's verdict on a world (prediction.py) that joins many model-only
worlds to the trials (ppi.py)."""
from stablepush.evaluation.batch import (
    MAX_PREDICTIONS,
    Batch,
    Evaluation,
    check_predictions,
    decision_state,
    decision_test,
    evaluate,
    model_only_verdicts,
    run_trial,
    study_trials,
    wilson_interval,
    with_predictions,
    write_evaluation,
)
from stablepush.evaluation.ppi import PredictedRate, prediction_powered_rate
from stablepush.evaluation.prediction import PlanInWorlds, Prediction, predicted_multipliers
from stablepush.evaluation.sequential import PredictionPoweredTest, SequentialTest
from stablepush.evaluation.worlds import VARY_KEYS, Spreads, TrialWorld, draw_world, robust_task

__all__ = ["Batch", "Evaluation", "MAX_PREDICTIONS", "PlanInWorlds", "PredictedRate", "Prediction",
           "PredictionPoweredTest", "SequentialTest", "Spreads", "TrialWorld", "VARY_KEYS", "check_predictions",
           "decision_state", "decision_test", "draw_world", "evaluate", "model_only_verdicts", "predicted_multipliers",
           "prediction_powered_rate", "robust_task", "run_trial", "study_trials", "wilson_interval", "with_predictions",
           "write_evaluation"]
