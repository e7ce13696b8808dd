"""A plan's measured success rate over many perturbed worlds (`stablepush evaluate`): the worlds
(worlds.py), the batch that runs one trial per world (batch.py), and where a batch of jobs runs:
here, on local processes or on Ray (runners.py, which `stablepush bench` uses too)."""
from stablepush.evaluation.batch import (
    Batch,
    Evaluation,
    default_workers,
    evaluate,
    run_trial,
    wilson_interval,
    write_evaluation,
)
from stablepush.evaluation.runners import Runner, WorkerLost, run_all
from stablepush.evaluation.worlds import VARY_KEYS, Spreads, TrialWorld, draw_world

__all__ = ["Batch", "Evaluation", "Runner", "Spreads", "TrialWorld", "VARY_KEYS", "default_workers", "draw_world",
           "evaluate", "run_all", "run_trial", "WorkerLost", "wilson_interval", "write_evaluation"]
