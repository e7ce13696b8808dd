"""`stablepush evaluate`."""
from __future__ import annotations

import os
import sys
from dataclasses import dataclass
from typing import Optional

import click

from stablepush.errors import OutputError, SettingError
from stablepush.sim import DEFAULT_ENGINE, ENGINES
from stablepush_cli.common import (
    EXIT_INTERNAL,
    EXIT_NOT_SOLVED,
    check_named_outputs,
    fail,
    given,
    landings_bar,
    load_plan_and_task,
    load_task_file,
    say_beside,
)
from stablepush_cli.groups import (
    RobotChoice,
    RunnerChoice,
    StudyOutputs,
    TrialRun,
    WorldSpreads,
    option_group,
    robot_choice,
    runner_choice,
    video_request,
)
from stablepush_cli.options import (
    Finite,
    Whole,
    check_video,
    parse_vary,
    video_settings_need,
)


@dataclass(frozen=True)
class EvaluatedPlan:
    """TASK.yaml, --plan, --robust: the plan evaluated, the one given or one planned here (robust:
    to the worlds)."""

    task_file: str
    plan_file: Optional[str]
    robust: bool


@dataclass(frozen=True)
class StudyTrials:
    """--trials, --target, --confidence, --seed, --predict: how many trials run (a count, or until
    the sequential test of --target decides), the seed their worlds are drawn from, and how many
    model-only worlds join them (None: none)."""

    trials: Optional[int]
    target: Optional[float]
    confidence: float
    seed: int
    predict: Optional[int] = None


@click.command()
@option_group(
    "source", EvaluatedPlan,
    click.argument("task_file", metavar="TASK.yaml", type=click.Path(dir_okay=False)),
    click.option("--plan", "plan_file", metavar="PLAN.json", type=click.Path(dir_okay=False), default=None,
                 help="The plan to evaluate (checked against the task). Default: plan once from the task."),
    click.option("--robust", is_flag=True,
                 help="Plan robust to the worlds: the task's uncertainty box widened to the --vary spreads, so "
                      "every push is stable for every multiplier they draw (docs/model.md section 7). Corrections "
                      "keep the box. Not with --plan."))
@option_group(
    "count", StudyTrials,
    click.option("--trials", default=None, type=Whole(min=1, max=1_000_000),
                 help="Number of trials (worlds)  [default: 100]. With --target, the most to run  [default: the "
                      "most trials the test is expected to take at any success rate, a cap it decides within "
                      "(docs/evaluate.md)]."),
    click.option("--target", "target", default=None, type=Finite(min=0, max=1, min_open=True, max_open=True),
                 metavar="RATE", help="Decide whether the plan lands at least RATE of the time (e.g. 0.99), and "
                                      "stop as soon as the evidence does: a sequential probability ratio test, valid "
                                      "however early it stops (docs/evaluate.md); with --predict, a "
                                      "prediction-powered test by betting, as valid. A rate one point below RATE is "
                                      "called above with probability at most 1 - --confidence, and one at RATE "
                                      "below likewise; so RATE lies strictly between 0.01 and 1."),
    click.option("--confidence", default=0.95, show_default=True,
                 type=Finite(min=0.5, max=1, min_open=True, max_open=True),
                 metavar="C", help="With --target: the decision's confidence."),
    click.option("--seed", default=1, show_default=True, type=Whole(min=0, max=2**32 - 1),
                 help="Trial i's world depends on (seed, i) alone: the same seed gives the same worlds and "
                      "outcomes, serially, on workers or on Ray."),
    click.option("--predict", default=None, type=Whole(min=1), metavar="N",
                 help="Also ask the plan's model for its verdict on N model-only worlds of the same spreads (each "
                      "push stable, the release held, the end within the tolerance; about 0.1 ms a world) and on "
                      "each trial's world, and join them to the trials by prediction-powered inference: the summary "
                      "adds the model's agreement with the simulator and an interval that holds whatever that "
                      "agreement (docs/evaluate.md, 'Odds from predictions'). With --target, the decision uses "
                      "them too (a prediction-powered test: the same error rates, often fewer trials). Without "
                      "--target the trials are the same with or without it. At most 10,000,000."))
@option_group(
    "worlds", WorldSpreads,
    click.option("--vary", "vary", multiple=True, callback=parse_vary, metavar="KEY=FRACTION",
              help="Multiply the task's KEY (pad_mu, pusher_mu, grip_force or mass) in each world by a factor drawn "
                   "uniformly within 1 +- FRACTION. Repeatable; `--vary none` varies nothing. Default: the task's "
                   "uncertainty box, else pad_mu and pusher_mu 0.1, grip_force 0.05, mass 0.02, with "
                   "--feature-error 0.2 0.2 (docs/evaluate.md, 'The worlds')."),
    click.option("--feature-error", nargs=2, type=Finite(min=0), default=None, metavar="MM DEG",
                 help="Place each feature off by up to MM in x and z and DEG about y (uniform). Default: 0.2 0.2 "
                      "without --vary, else 0 0."),
    click.option("--tracker-noise", nargs=2, type=Finite(min=0), default=(0.0, 0.0), metavar="MM DEG",
                 help="Standard deviations of the tracker's noise on the pose in the grasp."))
@option_group(
    "run", TrialRun,
    click.option("--closed-loop", is_flag=True, help="Run each trial closed loop (re-plan from the tracked pose)."),
    click.option("--guard/--no-guard", "guarded", default=True, show_default=True,
                 help="Find each feature by touch at the end of its approach (as `execute --guard`)."),
    click.option("--engine", default=DEFAULT_ENGINE, show_default=True, type=click.Choice(ENGINES),
                 help="The simulated arm's physics engine."),
    click.option("--success-tolerance", nargs=2, type=Finite(min=0, min_open=True), default=None, metavar="MM DEG",
                 help="A trial lands when the object comes to rest within MM (x and z) and DEG of the goal in the "
                      "grasp, as `execute` judges a run (default: the task's planner.tolerance)."))
@runner_choice("the trials")
@option_group(
    "outputs", StudyOutputs,
    click.option("--json", "json_path", type=click.Path(dir_okay=False), default=None,
                 help="Write the summary and every trial as JSON."),
    click.option("--csv", "csv_path", type=click.Path(dir_okay=False), default=None, help="Write one trial a row."),
    click.option("--plot", "png_path", type=click.Path(dir_okay=False), default=None,
                 help="Draw the goal error's CDF against the tolerance, and success over the varied parameters "
                      "(PNG, PDF or SVG, as the name ends)."),
    video_request(
        "--video-failed",
        click.option("--video-failed", "video_path", type=click.Path(file_okay=False), default=None, metavar="DIR",
                     help="Draw each failed trial's run as a video, DIR/trial-<i>.mp4 (made if missing; as `execute "
                          "--video` draws it, in the trial's own world), named in the trial's record (--json, "
                          "--csv).")))
@click.option("--quiet", is_flag=True, help="No progress bar.")
@robot_choice
def evaluate(source: EvaluatedPlan, count: StudyTrials, worlds: WorldSpreads, run: TrialRun, where: RunnerChoice,
             outputs: StudyOutputs, quiet: bool, robot: RobotChoice) -> None:
    """Measure how often a plan lands: run it in TRIALS simulated worlds that differ from its model.

    Each trial's world multiplies the task's parameters named by --vary by factors drawn within the
    given spreads (default: the task's uncertainty box, else a lab's: see --vary), moves each
    feature by up to --feature-error and adds --tracker-noise; the plan runs there on the simulated
    arm (open loop, or --closed-loop) and lands, as `execute` judges a run, when the object comes
    to rest after the release within the task's tolerance of the goal (or --success-tolerance).
    The summary gives the success rate with its Wilson 95% interval, the goal error's percentiles
    and the causes of the misses. Spreads that vary nothing make one world: one trial runs, and no
    interval is given. A trial that crashes (an internal error) is recorded (cause `crash`), left
    out of the rate, and the batch goes on, to exit 4; Ctrl-C stops it and keeps the trials done.

    \b
    Exit status: 0 done (whatever the success rate), 1 no plan found, 2 bad input (a --tracker-noise
    the guard cannot tell a touch from: at most 0.125 mm and 0.125 deg, or --no-guard), 4 a trial
    crashed (the trials are summarized and written, each crash with its error), 130 stopped by
    Ctrl-C (the trials done are summarized and written).

    \b
    Examples:
      stablepush evaluate data/tasks/t-shaped.yaml --trials 100   # a lab's spreads, judged by the task's tolerance
      stablepush evaluate data/tasks/pivoting.yaml --trials 200 --vary pad_mu=0.15 --vary pusher_mu=0.15 \\
          --vary grip_force=0.1 --vary mass=0.05 --feature-error 0.5 0.5 --json piv.eval.json --plot piv.png
      stablepush evaluate data/tasks/t-shaped.yaml --trials 1000 --closed-loop --vary pad_mu=0.15 --ray
      stablepush evaluate data/tasks/t-shaped.yaml --trials 100 --robust --vary pad_mu=0.15 --vary pusher_mu=0.15
      stablepush evaluate data/tasks/t-shaped.yaml --trials 20 --vary pad_mu=0.3 --video-failed t-failed
    """
    test = _test(count.target, count.confidence)
    video = outputs.video
    video_dir = video.path
    if video_dir:  # before the trials load MuJoCo: the renderer needs MUJOCO_GL=osmesa from the start
        check_video("--video-failed", os.path.join(video_dir, "trial-0.mp4"), video.fps, video.size)
    else:
        video_settings_need("--video-failed")
    from stablepush.evaluation import Batch, decision_state, decision_test, study_trials, write_evaluation
    from stablepush.evaluation import evaluate as run_evaluation
    from stablepush.outputs import FIGURE_SUFFIXES, require_suffix
    from stablepush.runners import default_workers

    require_suffix("--plot", outputs.png_path, FIGURE_SUFFIXES)
    check_named_outputs(outputs.named(), {"TASK.yaml": source.task_file, "--plan": source.plan_file})
    say = say_beside(*outputs.given())

    runner = where.runner(default=default_workers())
    _check_before_trials(count, worlds, run)
    task, plan, spreads = _study(source, worlds)
    task = robot.on(task)
    if video_dir:
        from stablepush.sim import video_directory

        try:
            video_dir = video_directory(video_dir)
        except OutputError as exc:
            fail(f"--video-failed {exc}")
    try:
        batch = Batch(task=task, plan=plan, spreads=spreads, seed=count.seed, closed_loop=run.closed_loop,
                      guarded=run.guarded, engine=run.engine, tolerance=run.success_tolerance, video_dir=video_dir,
                      video_fps=video.fps, video_size=video.size)
    except SettingError as exc:  # the tracker's noise, past what the guard can tell a touch from
        fail(f"--{exc.field.replace('_', '-')}: {exc.reason}")
    for warning in batch.warnings():
        click.echo(f"warning: {warning}", err=True)
    trials = count.trials
    if test is not None and trials is not None and test.cap_warning(trials):
        click.echo(f"warning: --trials {trials}: {test.cap_warning(trials)}", err=True)
    trials = study_trials(spreads, trials, test)  # as evaluate() runs them: the bar and the header say so too
    if not quiet:
        box = ", ".join(f"{key} +-{fraction:.0%}" for key, fraction in task.uncertainty.items())
        click.echo(f"{task.name}: {spreads.describe()}", err=True)
        click.echo(f"{task.name}: {'up to ' if test else ''}{trials} trials, "
                   f"{'closed' if run.closed_loop else 'open'} loop"
                   f"{'' if run.guarded else ', approaches not guarded'} on {run.engine}, "
                   f"on {runner.describe(trials)}" + (f"; the plan is robust to {box}" if box else ""), err=True)
    verdicts = _model_only(batch, count.predict, quiet)
    decider = decision_test(test, verdicts)  # with --predict, the prediction-powered test evaluate() decides by
    with landings_bar(quiet, trials) as landed:
        result = run_evaluation(batch, trials, runner, (lambda record, done: landed(
            done, suffix=f"; {decision_state(decider, done)}" if decider else "")) if landed else None, test=test,
            predictions=verdicts)
    write_evaluation(result, outputs.json_path, outputs.csv_path, outputs.png_path)
    s = result.summary()
    if not s["trials"]:
        click.echo("interrupted before any trial finished" if s["interrupted"] else "no trial finished", err=True)
        sys.exit(130 if s["interrupted"] else EXIT_NOT_SOLVED)
    for line in result.describe(written=outputs.given()):
        say(line)
    if s["crashed"]:  # internal errors: no rate stands for the trials asked for
        click.echo(f"error: {s['crashed']} of {s['trials']} trials crashed (internal errors, a bug; each trial's "
                   f"error is in its record): the success rate is over the {s['judged']} that did not", err=True)
        sys.exit(EXIT_INTERNAL)
    if s["interrupted"]:
        sys.exit(130)


def _check_before_trials(count: StudyTrials, worlds: WorldSpreads, run: TrialRun) -> None:
    """Refuse, before a plan is searched for, a tracker noise the guard cannot tell a touch from
    (Batch refuses it as well) and a count of predictions out of range."""
    option = "--tracker-noise"
    try:
        if run.guarded:
            from stablepush.execution import GuardedApproach

            GuardedApproach.for_tracker_noise(*worlds.tracker_noise)
        if count.predict is not None:
            from stablepush.evaluation import check_predictions

            option = "--predict"
            check_predictions(count.predict)
    except SettingError as exc:
        fail(f"{option}: {exc.reason}")


def _study(source: EvaluatedPlan, worlds: WorldSpreads):
    """The task, the plan to evaluate (the one given, else planned here) and the worlds' spreads."""
    task_file, plan_file, robust = source.task_file, source.plan_file, source.robust
    if robust and plan_file:
        fail("--robust plans from the task; a plan given with --plan is evaluated as it is")
    if plan_file:
        task, plan = load_plan_and_task(plan_file, task_file)
    else:
        task = load_task_file(task_file)
    spreads = worlds.spreads(task)
    if not plan_file:
        task, plan = _plan_for(task, spreads, robust)
    return task, plan, spreads


def _plan_for(task, spreads, robust: bool):
    """The task to evaluate (robust: its box widened to the spreads) and its plan; exit 1 when none
    is found."""
    from stablepush.evaluation import robust_task
    from stablepush.plan import plan_task

    if robust:
        try:
            task = robust_task(task, spreads)
        except SettingError as exc:
            fail(f"--robust: {exc.reason}")
    plan = plan_task(task)
    if not plan.solved:
        click.echo(f"{task.name}{' (robust)' if robust else ''}: {plan.message}", err=True)
        sys.exit(EXIT_NOT_SOLVED)
    return task, plan


def _model_only(batch, predict: Optional[int], quiet: bool):
    """The model's verdicts on `predict` model-only worlds (None without --predict), made before the
    trials: evaluate() joins them to the trials, and a --target decision uses them."""
    from stablepush.evaluation import model_only_verdicts

    if predict is None:
        return None
    if not quiet:
        click.echo(f"predicting {predict:,} model-only worlds", err=True)
    return model_only_verdicts(batch, predict)  # its count was checked before the trials


def _test(target, confidence: float):
    """The sequential test --target asks for (None without it)."""
    from stablepush.evaluation import SequentialTest

    if target is None:
        if given("confidence"):
            fail("--confidence: only with --target")
        return None
    try:
        return SequentialTest(target, confidence)
    except SettingError as exc:
        fail(f"--{exc.field}: {exc.reason}")
