"""A plan's measured success rate over many perturbed worlds (`stablepush evaluate`): the worlds
(worlds.py), the batch that runs one trial per world (batch.py) where `stablepush.runners`
says: here, on local processes or on Ray, and the sequential decision that may stop it early
(sequential.py)."""
from stablepush.evaluation.batch import (
    Batch,
    Evaluation,
    decision_state,
    evaluate,
    run_trial,
    study_trials,
    wilson_interval,
    write_evaluation,
)
from stablepush.evaluation.sequential import SequentialTest
from stablepush.evaluation.worlds import VARY_KEYS, Spreads, TrialWorld, draw_world, robust_task

__all__ = ["Batch", "Evaluation", "SequentialTest", "Spreads", "TrialWorld", "VARY_KEYS", "decision_state",
           "draw_world", "evaluate", "robust_task", "run_trial", "study_trials", "wilson_interval", "write_evaluation"]
