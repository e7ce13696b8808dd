"""The odds of the best designs (`stablepush design --evaluate N`): each of the top designs' plans
run through `evaluate` in the same worlds, and the designs ranked again, by the measured success
rate first.

Every design is judged in the same N worlds (worlds.draw_world(seed, i): common random numbers, so
a difference in rate is the layouts' and not the draw's), drawn within the spreads the study is
given (Spreads.for_task: the design file's uncertainty box when it has one, else a lab's). The rate
is over N trials: designs whose Wilson intervals overlap are not told apart by it, and the ranking
then rests on the keys after `success`.
"""
from __future__ import annotations

import functools
from dataclasses import dataclass
from typing import Callable, Dict, Optional

from stablepush.design.layouts import Design, DesignStudy
from stablepush.errors import SettingError
from stablepush.evaluation import Batch, Spreads, check_predictions, evaluate
from stablepush.evaluation.batch import MAX_TRIALS
from stablepush.runners import Runner
from stablepush.sim.deviation import MAX_SEED
from stablepush.sim.engines import DEFAULT_ENGINE, ENGINES
from stablepush.units import is_integer

MAX_TOP = 100  # designs whose odds one study measures (design --evaluate-top)


@dataclass(frozen=True)
class DesignOdds:
    """How evaluate_designs measures the best `top` designs' odds: `trials` worlds of `spreads`
    each (the same worlds for every design, from `seed`), open or `closed_loop`, on `engine`, with
    `predict` model-only worlds each when given. Made with a field out of its range it raises
    SettingError naming it, as `design --evaluate` takes them."""

    trials: int
    spreads: Spreads
    top: int = 3
    seed: int = 1
    closed_loop: bool = False
    engine: str = DEFAULT_ENGINE
    # model-only worlds joined to each design's trials (evaluation.with_predictions); None: none, and
    # the designs rank by their trials' rate, else by the prediction-powered interval's low end
    predict: Optional[int] = None

    def __post_init__(self) -> None:
        for name, value, low, high in (("trials", self.trials, 1, MAX_TRIALS), ("top", self.top, 1, MAX_TOP),
                                       ("seed", self.seed, 0, MAX_SEED)):  # top past the designs: all of them
            if isinstance(value, bool) or not is_integer(value) or not low <= value <= high:
                raise SettingError(name, f"must be a whole number from {low} to {high:,}, got {value!r:.40}")
        if not isinstance(self.spreads, Spreads):
            raise SettingError("spreads", f"must be a Spreads (evaluation.Spreads.for_task), got "
                                          f"{type(self.spreads).__name__}")
        if not isinstance(self.closed_loop, bool):
            raise SettingError("closed_loop", f"must be true or false, got {self.closed_loop!r:.40}")
        if self.engine not in ENGINES:
            raise SettingError("engine", f"must be one of {', '.join(ENGINES)}, got {self.engine!r:.40}")
        if self.predict is not None:
            check_predictions(self.predict)


def evaluate_designs(study: DesignStudy, odds: DesignOdds, runner: Optional[Runner] = None,
                     progress: Optional[Callable[[Design, dict, list], None]] = None) -> None:
    """Run each of the best `odds.top` designs of `study` through `evaluate`, as `odds` says, and
    set its `success`; then rank the study again by `success` first (study.rank, with `success`
    put first unless the rule places it). A design whose arm cannot follow its plan in the cell
    runs no trial (`success.refused` says why) and ranks below those measured.
    `progress(design, record, done)` after each trial. Ctrl-C stops the study with the designs
    measured so far (`study.interrupted`); `study.evaluated["ran"]` says how many trials each of
    the top designs ran (layout -> trials). With `odds.predict`, each design's trials are joined
    with the model's verdicts on that many worlds (`success.prediction`), and `success` ranks by
    the prediction-powered interval's low end. TypeError for a study or odds that is not one,
    before any trial."""
    if not isinstance(study, DesignStudy):
        raise TypeError(f"study: expected a DesignStudy (design()'s result), got {type(study).__name__}")
    if not isinstance(odds, DesignOdds):
        raise TypeError(f"odds: expected a DesignOdds, got {type(odds).__name__}")
    from stablepush.kinematics.cell_path import CellError  # loads MuJoCo: not before the odds are asked for

    runner = runner or Runner()
    top = odds.top
    ran: Dict[str, int] = {" + ".join(d.pushers): 0 for d in study.designs[:top]}
    for d in study.designs[:top]:
        try:
            # A design without its task or plan (design() makes none) is Batch's to refuse, naming the field.
            batch = Batch(task=d.task, plan=d.plan,  # type: ignore[arg-type]  # Batch checks both at run time
                          spreads=odds.spreads, seed=odds.seed, closed_loop=odds.closed_loop, engine=odds.engine)
        except CellError as refusal:
            d.success = {"refused": str(refusal)}
            continue
        measured = evaluate(batch, odds.trials, runner,
                            progress=functools.partial(progress, d) if progress else None,  # progress(d, record, done)
                            predictions=odds.predict)
        s = measured.summary()
        d.success = {key: s[key] for key in ("trials", "judged", "successes", "success_rate", "ci95", "causes",
                                             "crashed", "wall_s")}
        if odds.predict is not None:
            d.success["prediction"] = s["prediction"]
        ran[" + ".join(d.pushers)] = s["trials"]
        if measured.interrupted:
            study.interrupted = True
            break
    study.evaluated = {"trials": odds.trials, "predictions": odds.predict, "top": min(top, len(study.designs)),
                       "seed": odds.seed,
                       "spreads": odds.spreads.describe(), "closed_loop": odds.closed_loop, "engine": odds.engine,
                       "interrupted": study.interrupted, "ran": ran}
    if "success" not in study.rank:
        study.rank = ("success",) + tuple(study.rank)
    study.designs.sort(key=lambda d: d.key(study.rank))
