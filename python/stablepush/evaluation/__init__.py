"""A plan's measured success rate over many perturbed worlds (`stablepush evaluate`): the worlds
(worlds.py) and the batch that runs one trial per world, here, on local processes or on Ray
(batch.py)."""
from stablepush.evaluation.batch import (
    Batch,
    Evaluation,
    Runner,
    default_workers,
    evaluate,
    run_trial,
    wilson_interval,
    write_evaluation,
)
from stablepush.evaluation.worlds import VARY_KEYS, Spreads, TrialWorld, draw_world

__all__ = ["Batch", "Evaluation", "Runner", "Spreads", "TrialWorld", "VARY_KEYS", "default_workers", "draw_world",
           "evaluate", "run_trial", "wilson_interval", "write_evaluation"]
