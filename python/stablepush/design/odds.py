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

from typing import Callable, Optional

from stablepush.design.layouts import Design, DesignStudy
from stablepush.evaluation import Batch, Spreads, evaluate
from stablepush.runners import Runner
from stablepush.sim.engines import DEFAULT_ENGINE


def evaluate_designs(study: DesignStudy, trials: int, spreads: Spreads, top: int = 3, seed: int = 1,
                     closed_loop: bool = False, engine: str = DEFAULT_ENGINE, runner: Optional[Runner] = None,
                     progress: Optional[Callable[[Design, dict, list], None]] = None) -> None:
    """Run each of the best `top` designs of `study` through `evaluate`: `trials` worlds of
    `spreads` (the same worlds for every design, from `seed`), open or `closed_loop`, on `engine`,
    and set its `success`; then rank the study again by `success` first (study.rank, with
    `success` put first unless the rule places it). A design whose arm cannot follow its plan in
    the cell runs no trial (`success.refused` says why) and ranks below those measured.
    `progress(design, record, done)` after each trial. Ctrl-C stops the study with the designs
    measured so far (`study.interrupted`)."""
    from stablepush.sim.joint_path import CellError  # loads MuJoCo: not before the odds are asked for

    runner = runner or Runner()
    for d in study.designs[:top]:
        try:
            batch = Batch(task=d.task, plan=d.plan, spreads=spreads, seed=seed, closed_loop=closed_loop,
                          engine=engine)
        except CellError as refusal:
            d.success = {"refused": str(refusal)}
            continue
        measured = evaluate(batch, trials, runner,
                            progress=(lambda record, done, d=d: progress(d, record, done)) if progress else None)
        s = measured.summary()
        d.success = {key: s[key] for key in ("trials", "judged", "successes", "success_rate", "ci95", "causes",
                                             "crashed", "wall_s")}
        if measured.interrupted:
            study.interrupted = True
            break
    study.evaluated = {"trials": trials, "top": min(top, len(study.designs)), "seed": seed,
                       "spreads": spreads.describe(), "closed_loop": closed_loop, "engine": engine}
    if "success" not in study.rank:
        study.rank = ("success",) + tuple(study.rank)
    study.designs.sort(key=lambda d: d.key(study.rank))
