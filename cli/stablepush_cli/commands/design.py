"""`stablepush design`."""
from __future__ import annotations

import json
import sys
from dataclasses import dataclass
from pathlib import Path
from typing import Optional

import click

from stablepush.sim import DEFAULT_ENGINE, ENGINES
from stablepush_cli.common import (
    EXIT_INTERNAL,
    EXIT_NOT_SOLVED,
    check_named_outputs,
    fail,
    given,
    landings_bar,
    progressbar,
    say_beside,
)
from stablepush_cli.groups import RunnerChoice, TrialRun, WorldSpreads, option_group, runner_choice
from stablepush_cli.options import (
    TIME_LIMIT,
    Finite,
    Whole,
    parse_vary,
)

ODDS_OPTIONS = ("evaluate_top", "vary", "feature_error", "closed_loop", "engine", "seed", "predict")


@dataclass(frozen=True)
class LayoutChoice:
    """--max-fixtures, --rank, --checks, --time-limit, --reach-top: how the layouts are searched."""

    max_fixtures: int
    rank_text: Optional[str]
    check_limit: int
    time_limit: float
    reach_top: int

    def search(self, measured: bool):
        """The search (stablepush.design.LayoutSearch); `measured`: the designs' odds are (--evaluate),
        so the rule may rank by success."""
        from stablepush.design import DEFAULT_RANK, LayoutSearch, parse_rank

        rank = parse_rank(self.rank_text, measured=measured) if self.rank_text is not None else DEFAULT_RANK
        return LayoutSearch(max_fixtures=self.max_fixtures, rank=rank, reach_top=self.reach_top,
                            time_limit=self.time_limit, check_limit=self.check_limit)


@dataclass(frozen=True)
class OddsChoice:
    """--evaluate, --evaluate-top, --vary, --feature-error, --closed-loop, --engine, --seed,
    --predict: the odds of the best designs, measured in the same worlds (`trials` None: not
    measured), with model-only worlds joined to their trials (`predict` None: none)."""

    trials: Optional[int]
    evaluate_top: int
    worlds: WorldSpreads
    run: TrialRun
    seed: int
    predict: Optional[int] = None


@click.command()
@click.argument("design_file", metavar="DESIGN.yaml", type=click.Path(dir_okay=False))
@option_group(
    "layouts", LayoutChoice,
    click.option("--max-fixtures", default=2, show_default=True, type=Whole(min=1, max=4), metavar="K",
                 help="Layouts of 1 to K fixtures."),
    click.option("--rank", "rank_text", default=None, metavar="KEYS",
                 help="The ranking rule: keys, most important first, from arm (the task's arm follows the plan "
                      "first), fixtures, points (point pushers used), end (the plan's end's offset from the goal "
                      "over the tolerance), switches, pushes (less first), margin, reach (more first), tests (the "
                      "search's stable-push tests), time (planning time: depends on the machine's load) and success "
                      "(with --evaluate). Default: arm,fixtures,points,end,switches,margin,pushes,reach,tests; with "
                      "--evaluate, success first unless the rule places it."),
    click.option("--checks", "check_limit", default=2_000_000, show_default=True, type=Whole(min=0, max=10**15),
                 metavar="N", help="Stable-push tests each layout's search may make: a count, so the same design "
                                   "file gives the same designs on any machine under any load (0: --time-limit "
                                   "alone)."),
    click.option("--time-limit", default=30.0, show_default=True, type=TIME_LIMIT, metavar="S",
                 help="Each layout's search time, a guard past --checks (the task's planner.time_limit is not used: "
                      "there are many layouts)."),
    click.option("--reach-top", default=3, show_default=True, type=Whole(min=0, max=100), metavar="N",
                 help="The best N designs get a 3x3 reach map around the goal (2 tolerances either side in x and "
                      "z), and are ranked again with it."))
@option_group(
    "odds", OddsChoice,
    click.option("--evaluate", "trials", default=None, type=Whole(min=1, max=100_000), metavar="N",
                 help="Run each of the best --evaluate-top designs' plans through `evaluate`, N trials each in the "
                      "same worlds, and rank them by their measured success rate first."),
    click.option("--evaluate-top", default=3, show_default=True, type=Whole(min=1, max=100), metavar="K",
                 help="With --evaluate: how many of the best designs to evaluate."),
    option_group(
        "worlds", WorldSpreads,
        click.option("--vary", "vary", multiple=True, callback=parse_vary, metavar="KEY=FRACTION",
                     help="With --evaluate: the worlds' spreads, as `evaluate --vary` (default: the design file's "
                          "uncertainty box, else a lab's)."),
        click.option("--feature-error", nargs=2, type=Finite(min=0), default=None, metavar="MM DEG",
                     help="With --evaluate: place each fixture off by up to MM and DEG, as `evaluate "
                          "--feature-error`.")),
    option_group(
        "run", TrialRun,
        click.option("--closed-loop", is_flag=True, help="With --evaluate: run the trials closed loop."),
        click.option("--engine", default=DEFAULT_ENGINE, show_default=True, type=click.Choice(ENGINES),
                     help="With --evaluate: the simulated arm's physics engine.")),
    click.option("--seed", default=1, show_default=True, type=Whole(min=0, max=2**32 - 1),
                 help="With --evaluate: the worlds' seed (every design runs in the same worlds)."),
    click.option("--predict", default=None, type=Whole(min=1), metavar="M",
                 help="With --evaluate: join M model-only worlds to each design's trials, as `evaluate --predict`, "
                      "and rank the designs by the low end of that interval instead of their trials' rate. At most "
                      "10,000,000."))
@click.option("--out", "out_dir", default=None, type=click.Path(file_okay=False), metavar="DIR",
              help="Where each design's task file goes (design-1.yaml is the best). Default: NAME.designs/ beside "
                   "the design file NAME.design.yaml. The folder then holds this run's designs only: the designs an "
                   "earlier run wrote there are replaced or removed; a design-N.yaml this tool did not write is "
                   "refused before the search; other files are left alone.")
@click.option("--json", "json_path", type=click.Path(dir_okay=False), default=None,
              help="Write the ranked designs (`designs`, best first, each with its `task_file`), the unsolved "
                   "layouts (`unsolved`, and grouped by why: `no_plan`) and the verdict.")
@click.option("--plot", "png_path", type=click.Path(dir_okay=False), default=None,
              help="Draw the best three layouts side by side (PNG, PDF or SVG).")
@runner_choice("the layouts' plans")
@click.option("--quiet", is_flag=True, help="No progress bar.")
def design(design_file: str, layouts: LayoutChoice, odds: OddsChoice, out_dir, json_path, png_path,
           where: RunnerChoice, quiet: bool) -> None:
    """Find where the fixtures should go: rank layouts of candidate pushers by their plans.

    DESIGN.yaml is a task file whose `candidates` stand in for its `pushers`: `candidates: {mu:
    0.5}` makes every edge of the part's section a segment pusher and puts two point pushers
    beside every convex corner, with that mu; a list of pusher entries gives them. Each layout of
    up to --max-fixtures candidates whose pushers can push the object toward the goal from the
    start is planned (robust where the task has an uncertainty box) and checked; the solved ones
    are ranked (--rank) and written as complete task files, with the features where the plan puts
    them (environment.features), that `plan`, `execute` and `evaluate` take unchanged. With
    --evaluate N, the best designs' plans each run N trials in the same simulated worlds, and the
    designs are ranked by their measured success rate first. Exit 1 when no layout of the
    candidates can do the regrasp, with the reason, or when the task's arm (environment.robot) can
    follow none of the designs (they are written all the same).

    \b
    Exit status: 0 designs found, 1 none (or none the arm can follow), 2 bad input, 4 an
    evaluation trial crashed (an internal error; everything is written), 130 the evaluation
    stopped by Ctrl-C (the designs measured so far are ranked and written).

    \b
    Examples:
      stablepush design data/designs/offset-low-mu.design.yaml --json offset.designs.json
      stablepush plan data/designs/offset-low-mu.designs/design-1.yaml -o best.plan.json
      stablepush design data/designs/offset-low-mu.design.yaml --evaluate 20 --vary pad_mu=0.2
      stablepush design data/designs/offset-low-mu.design.yaml --evaluate 20 --predict 100000
    """
    from stablepush.design import (
        DesignOdds,
        check_designs_folder,
        design_files,
        designs_folder,
        evaluate_designs,
        write_designs,
    )
    from stablepush.design import design as search
    from stablepush.outputs import FIGURE_SUFFIXES, require_suffix
    from stablepush.runners import default_workers
    from stablepush.task import load_design

    layout_search = layouts.search(measured=odds.trials is not None)
    out = Path(out_dir) if out_dir is not None else designs_folder(design_file)
    require_suffix("--plot", png_path, FIGURE_SUFFIXES)
    check_named_outputs({"--json": json_path, "--plot": png_path}, {"DESIGN.yaml": design_file})
    check_designs_folder(out, "--out")
    task, candidates = load_design(design_file)
    spreads = _spreads(task, candidates, design_file, odds)
    runner = where.runner(default=default_workers())
    bar = progressbar(quiet, length=None, label="layouts planned", show_pos=True)
    try:
        study = search(task, candidates, source=design_file, search=layout_search, runner=runner,
                       progress=(lambda d: bar.update(1)) if bar else None)
    finally:
        if bar is not None:
            bar.render_finish()
    if spreads is not None and odds.trials is not None and study.designs:
        measure = DesignOdds(odds.trials, spreads, top=odds.evaluate_top, seed=odds.seed,
                             closed_loop=odds.run.closed_loop, engine=odds.run.engine, predict=odds.predict)
        with landings_bar(quiet, odds.trials * min(odds.evaluate_top, len(study.designs))) as landed:
            ranked = list(study.designs)
            evaluate_designs(study, measure, runner=runner,
                             progress=(lambda d, record, done: landed(done, f"design {ranked.index(d) + 1}: "))
                             if landed else None)
    files = design_files(study, task, candidates, out, design_file)
    if json_path is not None:
        files[json_path] = json.dumps(study.as_dict(), indent=1) + "\n"
    write_designs(files, out)
    if png_path is not None and study.designs:
        from stablepush.viz import layouts_figure, save_figure

        top = [{"task": d.task, "rank": k, "label": _figures(d)} for k, d in enumerate(study.designs[:3], start=1)]
        best = study.designs[0].task
        assert best is not None, "a solved design has its task"
        save_figure(layouts_figure(top, f"{best.name}: the best layouts"), png_path)
    say = say_beside(json_path, png_path)
    say(f"{len(candidates)} candidates, {study.layouts_searched} layouts planned, {study.layouts_pruned} pruned "
        f"(no stable push toward the goal from the start: {', '.join(study.pruned_candidates) or 'none'})")
    for line in study.describe_no_plan():
        say(line)
    for k, d in enumerate(study.designs, start=1):
        reach = f", reach near the goal {d.reach:.0%}" if d.reach is not None else ""
        arm = "" if d.arm is None else (", the arm follows it" if d.arm["follows"] else
                                        f", the arm cannot follow it ({d.arm['reason']})")
        say(f"{k}. {_figures(d)}{reach}{arm}{d.odds()}, planned in {d.planning_time_s:.3f} s -> {d.task_file}")
    if study.evaluated is not None:
        say(study.describe_odds())
    say(study.verdict)
    if not study.usable:
        raise SystemExit(EXIT_NOT_SOLVED)
    crashed = sum(d.success.get("crashed", 0) for d in study.designs if d.success)
    if crashed:
        click.echo(f"error: {crashed} evaluation trials crashed (internal errors, a bug): each design's rate is "
                   f"over the trials that did not", err=True)
        sys.exit(EXIT_INTERNAL)
    if study.interrupted:
        sys.exit(130)


def _spreads(task, candidates, design_file: str, odds: OddsChoice):
    """The worlds --evaluate draws (None without it): the design's spreads, checked before the search."""
    from stablepush.design import layout_task

    if odds.trials is None:
        named = [name for name in ODDS_OPTIONS if given(name)]
        if named:
            fail(f"--{named[0].replace('_', '-')}: only with --evaluate N")
        return None
    if odds.predict is not None:
        from stablepush.errors import SettingError
        from stablepush.evaluation import check_predictions

        try:
            check_predictions(odds.predict)
        except SettingError as exc:
            fail(f"--predict: {exc.reason}")
    return odds.worlds.spreads(layout_task(task, candidates, design_file))


def _figures(d) -> str:
    return f"{' + '.join(d.pushers)}: {d.pushes} pushes, {d.switches} switch-overs, margin {d.margin_n:.3f} N"
