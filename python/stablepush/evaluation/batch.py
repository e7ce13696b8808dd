"""A plan's success rate over many perturbed worlds (`stablepush evaluate`).

Each trial runs the plan on a simulated arm of its own (`stablepush.sim`, in the worker's process,
over the arm protocol on a loopback port) in the world `worlds.draw_world(seed, i)` draws, and
records where the object ended against the goal. Trials are independent: they run one after the
other, on local worker processes, or on Ray (`stablepush.runners`), and a trial's outcome depends on
(seed, i) alone, so all three give the same trials. With `Batch.video_dir`, a failed trial's run,
kept in memory while it runs, is drawn into a video in the worker after its verdict
(`stablepush.sim.mujoco.video`), which changes no outcome.

The summary's `ci95` is the Wilson score interval of the success rate (scipy's `binomtest`).
Units: mm and deg as in plan files; times in s.
"""
from __future__ import annotations

import dataclasses
import os
import time
import traceback
from dataclasses import dataclass
from typing import Any, Callable, Dict, List, Optional, Sequence, Tuple, Union

import numpy as np

from stablepush.errors import SettingError
from stablepush.evaluation.ppi import PredictedRate, prediction_powered_rate
from stablepush.evaluation.prediction import PlanInWorlds, predicted_multipliers
from stablepush.evaluation.sequential import PredictionPoweredTest, SequentialTest
from stablepush.evaluation.worlds import VARY_KEYS, Spreads, TrialWorld, draw_world
from stablepush.execution.bags import RunRecording
from stablepush.execution.closed_loop import ClosedLoop
from stablepush.execution.executor import RunOptions, execution_warnings
from stablepush.execution.guard import GuardedApproach
from stablepush.execution.run import run_plan
from stablepush.execution.verdict import success_tolerance
from stablepush.plan.plan import Plan
from stablepush.plan.verify import check_plan
from stablepush.pose import Pose, Tolerance
from stablepush.runners import Runner, WorkerLost, run_all, this_node
from stablepush.sim.deviation import MAX_SEED, WorldDeviation
from stablepush.sim.local_arm import SimulatedArm
from stablepush.sim.mujoco.video import check_fps, check_size
from stablepush.task.model import Task
from stablepush.units import is_integer

RATE_HZ = 100.0  # waypoints per second of robot time, as `execute`'s default
PERCENTILES = (50, 90, 95, 99)
EDGE = 0.9  # of the success tolerance: an open-loop plan ending this far out is warned of
DEFAULT_TRIALS = 100  # a study's trials when none are named and no sequential test sets the cap
MAX_TRIALS = 1_000_000  # a study's, as `evaluate --trials` takes
MAX_PREDICTIONS = 10_000_000  # model-only worlds, as `evaluate --predict` takes (about 100 us each)


@dataclass(frozen=True)
class Batch:
    """What every trial shares: the task, its plan, the spreads of the worlds, open or closed
    loop, guarded approaches or not (stablepush.execution.guard), the engine and the success
    tolerance (mm, deg; None: the task's planner.tolerance, as `execute` judges a run)."""

    task: Task
    plan: Plan
    spreads: Spreads
    seed: int = 1
    closed_loop: bool = False
    guarded: bool = True
    engine: str = "mujoco"
    tolerance: Optional[Tuple[float, float]] = None
    # Where each failed trial's video goes (`trial-<i>.mp4`; None: no videos), and how it is drawn
    # (stablepush.sim.mujoco.video). Drawn after the trial's verdict, so the outcomes do not depend on them.
    video_dir: Optional[str] = None
    video_fps: float = 25.0
    video_size: Tuple[int, int] = (640, 480)

    def __post_init__(self):
        # Refused here, before any trial runs, rather than once per trial as a crash: a plan not of
        # the task, a tolerance out of range, a robot that cannot carry the jaws (RobotError) or a
        # plan it cannot follow in its cell (CellError).
        for name, kind in (("task", Task), ("plan", Plan), ("spreads", Spreads)):
            if not isinstance(getattr(self, name), kind):
                raise TypeError(f"Batch.{name} must be a {kind.__name__}, got {type(getattr(self, name)).__name__}")
        if isinstance(self.seed, bool) or not is_integer(self.seed) or not 0 <= self.seed <= MAX_SEED:
            raise SettingError("seed", f"must be a whole number from 0 to {MAX_SEED}, got {self.seed!r:.40}")
        for name in ("closed_loop", "guarded"):
            if not isinstance(getattr(self, name), bool):
                raise TypeError(f"Batch.{name} must be True or False, got {getattr(self, name)!r:.40}")
        check_fps(self.video_fps)
        check_size(self.video_size)
        check_plan(self.task, self.plan)
        success_tolerance(self.task, self.tolerance)
        guard_of(self)  # a tracker noise the guard cannot tell a touch from: SettingError (tracker_noise)
        SimulatedArm(self.engine, robot=self.task.environment.robot).check_cell(self.task, self.plan, RATE_HZ)

    @property
    def success_tolerance(self) -> Tolerance:
        """The Tolerance a trial is judged with: the batch's, else the task's."""
        return success_tolerance(self.task, self.tolerance)

    def warnings(self) -> List[str]:
        """What makes the trials miss whatever their worlds (legal, but probably not meant), one
        line each: the executor's cell differing from the task's model (execution_warnings), and,
        open loop, a plan that ends outside the success tolerance of the goal, which a trial then
        lands only where the world's own error happens to make up the difference, or within it but
        at its edge (EDGE of it or more in some coordinate), where any drift of a real push misses."""
        out = execution_warnings(self.task)
        tol = self.success_tolerance
        end, goal = self.plan.waypoints[-1].pose, self.task.goal
        dx, dz, dtheta = Pose.of(end).minus(goal)
        mm, deg = max(abs(dx), abs(dz)), abs(dtheta)
        others = "let the last pusher go on toward the goal pose (planner.finish_steps: 1) or run the closed loop"
        tol0, tol1 = tol
        if not self.closed_loop and not tol.within(end, goal):
            out.append(f"the plan ends {mm:.2f} mm / {deg:.2f} deg from the goal (the larger of x and z; theta), "
                       f"outside the success tolerance {tol0:g} mm / {tol1:g} deg: an "
                       f"open-loop trial lands only where its world's error happens to make up the difference. "
                       f"To land, plan to the tolerance (planner.tolerance: [{tol0:g}, "
                       f"{tol1:g}]), {others}")
        elif not self.closed_loop and tol.used(end, goal) >= EDGE:
            out.append(f"the plan ends {mm:.2f} mm / {deg:.2f} deg from the goal (the larger of x and z; theta), at "
                       f"the edge of the success tolerance {tol0:g} mm / {tol1:g} deg: an "
                       f"open-loop trial that drifts outward at all misses. To leave it room, plan to less "
                       f"(planner.tolerance: [{tol0 / 2:g}, {tol1 / 2:g}]), {others}")
        return out

    def world(self, trial: int) -> TrialWorld:
        return draw_world(self.seed, trial, self.spreads, self.task.pusher_names)


def deviation_of(batch: Batch, world: TrialWorld) -> WorldDeviation:
    """The simulated arm's deviation for one trial's world."""
    m = world.multipliers
    return WorldDeviation(pad_mu_scale=m["pad_mu"], pusher_mu_scale=m["pusher_mu"], grip_scale=m["grip_force"],
                          mass_scale=m["mass"], tracker_noise_mm=batch.spreads.tracker_noise[0],
                          tracker_noise_deg=batch.spreads.tracker_noise[1], seed=world.tracker_seed,
                          feature_offsets=tuple((k, *v) for k, v in world.feature_offsets.items()))


def guard_of(batch: Batch) -> Optional[GuardedApproach]:
    """The guarded approach the trials run with (None: not guarded), its touch clear of the
    tracker's noise."""
    return GuardedApproach.for_tracker_noise(*batch.spreads.tracker_noise) if batch.guarded else None


def run_trial(batch: Batch, trial: int) -> dict:
    """Run trial `trial` and return its record. A trial whose arm faults is recorded with cause
    `arm_fault` (a miss), one that raises anything else as `crash` (`error` says what: an internal
    error, not a miss; Evaluation.summary leaves it out of the rate); neither ends the batch; `node`
    says where it ran (stablepush.runners.this_node). With `batch.video_dir`, the run is recorded in
    memory and, when the trial failed, drawn into video_dir/trial-<i>.mp4 (`video`: its path; None
    for a trial that landed, or when it could not be drawn, `video_error` then says why)."""
    world = batch.world(trial)
    started = time.perf_counter()
    record: Dict[str, Any] = {"trial": trial, "world": world.as_dict()}
    # Made before the run, so that a trial that crashes part-way still has what it ran to draw.
    recording = RunRecording() if batch.video_dir else None
    try:
        loop = ClosedLoop.for_task(batch.task) if batch.closed_loop else None
        options = RunOptions(rate_hz=RATE_HZ, closed_loop=loop, guard=guard_of(batch),
                             success_tolerance=batch.tolerance)
        arm = SimulatedArm(batch.engine, deviation_of(batch, world), robot=batch.task.environment.robot)
        run = run_plan(batch.task, batch.plan, arm, options, recording=recording)
        if run.fault is not None:  # the simulated arm failed (a simulator blow-up, an unreachable pose): stopped
            record.update(_not_run("arm_fault", str(run.fault)))
        else:
            report = run.report_or_fault()  # no fault: its report
            record.update(final_error=report.final_error, goal_error=report.goal_error,
                          replans=sum(1 for r in report.replans if r.solved), success=bool(report.success),
                          cause=report.verdict.cause if report.verdict else None,
                          verdict=report.verdict.detail if report.verdict else None,
                          sim_time_s=report.waypoints / RATE_HZ, error=None,
                          simulated_geometry=report.simulated_geometry,
                          # corrections whose search the wall-time guard stopped: this trial may differ elsewhere
                          wall_guard=sum(1 for r in report.replans if r.guard_fired))
    except Exception as exc:  # noqa: BLE001 - a crashed trial is a result, not the end of the batch
        last = traceback.extract_tb(exc.__traceback__)[-1]
        where = f"{os.path.basename(last.filename)}:{last.lineno}"
        record.update(_not_run("crash", f"{type(exc).__name__}: {exc} ({where})"))
    record["wall_s"] = time.perf_counter() - started
    record["node"] = this_node()
    if batch.video_dir:
        assert recording is not None, "made above for a batch with a video_dir"
        record["video"] = None if record["success"] else _failed_trial_video(batch, trial, world, recording, record)
    return record


def _failed_trial_video(batch: Batch, trial: int, world: TrialWorld, recording: RunRecording, record: dict):
    """Draw a failed trial's recorded run in its own world (features where this trial put them)
    into video_dir/trial-<i>.mp4 and return the path; None, with `video_error` in the record, when
    it cannot be drawn (no waypoint was acknowledged, say). Never raises: the trial's record stands."""
    from stablepush.sim.mujoco.video import VideoLook, render_run, run_scene

    assert batch.video_dir is not None, "asked only of a batch with a video_dir"
    path = os.path.join(batch.video_dir, f"trial-{trial}.mp4")
    try:
        scene = deviation_of(batch, world).apply(run_scene(batch.task, batch.plan, batch.closed_loop))
        render_run(path, batch.task, scene, recording.samples, look=VideoLook(batch.video_fps, batch.video_size))
    except Exception as exc:  # noqa: BLE001 - a video that cannot be drawn does not change the trial
        record["video_error"] = f"{type(exc).__name__}: {' '.join(str(exc).split())[:300]}"
        return None
    return path


def _not_run(cause: str, error: str) -> dict:
    """A trial record's outcome fields when the run did not end: an arm fault or a crash."""
    return {"final_error": None, "goal_error": None, "replans": 0, "success": False, "cause": cause, "verdict": None,
            "sim_time_s": 0.0, "error": error}


def crashed(record: dict) -> bool:
    """Whether a trial's record is of a crash (an internal error, or a lost worker): not a miss."""
    return record.get("cause") == "crash"


def _crashed(batch: Batch, trial: int, why: str) -> dict:
    return {"trial": trial, "world": batch.world(trial).as_dict(), **_not_run("crash", why), "wall_s": 0.0,
            "node": None}  # where it was lost is not known


def study_trials(spreads: Spreads, trials: Optional[int] = None, test: Optional[SequentialTest] = None) -> int:
    """The trials a study runs (at most, with a `test`): `trials` when given, else the test's
    default cap (SequentialTest.default_cap: one it decides within), else DEFAULT_TRIALS; one where
    every world is the model's own (Spreads.trials_to_run). SettingError for `trials` that is not a
    whole number from 1 to MAX_TRIALS: a study of none would rate nothing."""
    if trials is not None and (isinstance(trials, bool) or not is_integer(trials) or not 1 <= trials <= MAX_TRIALS):
        raise SettingError("trials", f"must be a whole number from 1 to {MAX_TRIALS:,}, got {trials!r:.40}")
    if trials is None:
        trials = test.default_cap() if test is not None else DEFAULT_TRIALS
    return spreads.trials_to_run(trials)


# A count of model-only worlds to predict, or the model's verdicts on them already (model_only_verdicts)
ModelOnly = Union[int, np.ndarray]
AnyTest = Union[SequentialTest, PredictionPoweredTest]


def evaluate(batch: Batch, trials: Optional[int] = None, runner: Runner = Runner(),
             progress: Optional[Callable[[dict, List[dict]], None]] = None,
             test: Optional[SequentialTest] = None, predictions: Optional[ModelOnly] = None) -> "Evaluation":
    """Run trials 0 .. trials-1 of `batch` on `runner` (None: study_trials' default);
    `progress(record, done)` after each. Ctrl-C (KeyboardInterrupt) stops the batch and keeps the
    trials done (`interrupted`). When every world is the model's own (Spreads.one_world) one trial
    says all there is: it alone runs, and the summary gives no interval. With a sequential `test`
    (sequential.py), `trials` is a cap: the study stops once the test decides. It is asked after
    each trial in the order of the trials' numbers (a trial that finishes early on another worker
    waits for those before it), since a test asked in the order trials happen to finish could be
    swayed by how long each kind takes; decision_state(test, done) is where it stands.

    With `predictions` (a count of model-only worlds, or the model's verdicts on them from
    model_only_verdicts), the model predicts those worlds before the trials, each finished trial
    gets its own world's verdict (`predicted`), and the evaluation is returned joined with them
    (with_predictions); a `test` then decides by the prediction-powered test of its settings
    (decision_test), whose decision the evaluation's `decision` names (`method`)."""
    if not isinstance(batch, Batch):
        raise TypeError(f"batch must be a Batch, got {type(batch).__name__}")
    if not isinstance(runner, Runner):
        raise TypeError(f"runner must be a Runner (stablepush.runners.Runner), got {type(runner).__name__}")
    if test is not None and not isinstance(test, SequentialTest):
        raise TypeError(f"test must be a SequentialTest or None, got {type(test).__name__}")
    verdicts = None if predictions is None else model_only_verdicts(batch, predictions)
    judge = None if verdicts is None else _judge(batch)
    trials = study_trials(batch.spreads, trials, test)
    source = run_all(run_trial, batch, range(trials), runner)
    started = time.perf_counter()
    done: List[dict] = []
    interrupted = False
    decision = _Decision(decision_test(test, verdicts))
    try:
        for i, record in source:
            if isinstance(record, WorkerLost):
                record = _crashed(batch, i, record.why)
            if judge is not None:  # microseconds: the model's verdict on the trial's own world
                record = {**record, "predicted": judge.predict(batch.world(i)).as_dict()}
            done.append(record)
            if progress is not None:
                progress(record, done)
            if decision.add(record):
                break
    except KeyboardInterrupt:
        interrupted = True
    finally:
        close = getattr(source, "close", None)
        if close is not None:
            close()
    done.sort(key=lambda r: r["trial"])
    evaluation = Evaluation(batch=batch, trials=done, wall_s=time.perf_counter() - started,
                            runner=runner.describe(trials), requested=trials, interrupted=interrupted,
                            decision=decision.as_dict())
    return evaluation if verdicts is None or not done else with_predictions(evaluation, verdicts)


def check_predictions(predictions: int) -> int:
    """`predictions`, a count of model-only worlds; SettingError unless a whole number from 1 to
    MAX_PREDICTIONS (asked before the trials run, by whoever will join predictions to them)."""
    if isinstance(predictions, bool) or not is_integer(predictions) or not 1 <= predictions <= MAX_PREDICTIONS:
        raise SettingError("predict", f"must be a whole number from 1 to {MAX_PREDICTIONS:,}, got {predictions!r:.40}")
    return predictions


def _judge(batch: Batch) -> PlanInWorlds:
    return PlanInWorlds(batch.task, batch.plan, batch.success_tolerance, batch.closed_loop)


def model_only_verdicts(batch: Batch, predictions: ModelOnly) -> np.ndarray:
    """The model's verdicts (a bool array) on `predictions` model-only worlds of the batch's spreads
    (prediction.predicted_multipliers); verdicts already made (an array) are returned as they are.
    SettingError for a count that is not a whole number from 1 to MAX_PREDICTIONS."""
    if isinstance(predictions, np.ndarray):
        if predictions.ndim != 1 or predictions.size == 0:
            raise ValueError(f"model-only verdicts must be a non-empty 1-d array, got shape {predictions.shape}")
        return predictions.astype(bool)
    check_predictions(predictions)
    return _judge(batch).predict_multipliers(predicted_multipliers(batch.seed, predictions, batch.spreads))


def decision_test(test: Optional[SequentialTest], verdicts: Optional[np.ndarray] = None) -> Optional[AnyTest]:
    """The test a study decides with: with the model's `verdicts` on model-only worlds, the
    prediction-powered test of `test`'s settings (sequential.PredictionPoweredTest), else `test`."""
    if test is None or verdicts is None:
        return test
    return PredictionPoweredTest.of(test, verdicts)


def with_predictions(evaluation: "Evaluation", predictions: ModelOnly) -> "Evaluation":
    """`evaluation` with the model's verdict on each trial's world (each record's `predicted`; one
    it has is kept) and its success rate from `predictions` model-only worlds of the same spreads
    (a count, or the verdicts model_only_verdicts made) joined with the trials by
    prediction-powered inference (ppi.prediction_powered_rate; the crashed trials left out, as
    from the rate). SettingError for a count of predictions that is not a whole number from 1 to
    MAX_PREDICTIONS."""
    batch = evaluation.batch
    verdicts = model_only_verdicts(batch, predictions)
    judge = _judge(batch)
    trials = [t if "predicted" in t else {**t, "predicted": judge.predict(batch.world(t["trial"])).as_dict()}
              for t in evaluation.trials]
    judged = [t for t in trials if not crashed(t)]
    rate = prediction_powered_rate([bool(t["success"]) for t in judged], [t["predicted"]["lands"] for t in judged],
                                   verdicts)
    return dataclasses.replace(evaluation, trials=trials, prediction=rate)


def decision_state(test: AnyTest, done: Sequence[dict]) -> str:
    """Where `test` (as decision_test gives it: the prediction-powered test reads each record's
    `predicted`) stands on the trial records `done` (finished in any order), as evaluate() feeds
    it: the trials in the order of their numbers up to the first not yet finished, in words
    (the test's state), for a progress line."""
    decision = _Decision(test)
    for record in sorted(done, key=lambda r: r["trial"]):
        if decision.add(record):
            break
    if isinstance(test, PredictionPoweredTest):
        return test.state(decision.landed, decision.predicted)
    return test.state(decision.successes, decision.judged)


class _Decision:
    """A sequential test fed the trials in the order of their numbers."""

    def __init__(self, test: Optional[AnyTest]):
        self.test = test
        # (landed, the model's verdict on its world; None without predictions); None: a crashed trial, passed over
        self.waiting: Dict[int, Optional[Tuple[bool, Optional[bool]]]] = {}
        self.next = self.successes = self.judged = 0
        self.landed: List[bool] = []
        self.predicted: List[bool] = []
        self.verdict: Optional[str] = None

    def add(self, record: dict) -> bool:
        """Take a finished trial; whether the test has decided."""
        if self.test is None or self.verdict is not None:
            return self.verdict is not None
        powered = isinstance(self.test, PredictionPoweredTest)
        # A crashed trial is no evidence either way (an internal error, not a miss): it is passed over.
        self.waiting[record["trial"]] = None if crashed(record) else (
            bool(record["success"]), bool(record["predicted"]["lands"]) if powered else None)
        while self.next in self.waiting and self.verdict is None:
            trial = self.waiting.pop(self.next)
            self.next += 1
            if trial is not None:
                landed, predicted = trial
                self.judged += 1
                self.successes += landed
                self.landed.append(landed)
                if isinstance(self.test, PredictionPoweredTest):
                    self.predicted.append(bool(predicted))
                    self.verdict = self.test.decide(self.landed, self.predicted)
                else:
                    self.verdict = self.test.decide(self.successes, self.judged)
        return self.verdict is not None

    def as_dict(self) -> Optional[dict]:
        if self.test is None:
            return None
        return {**self.test.as_dict(), "decision": self.verdict or "undecided", "trials": self.judged,
                "successes": self.successes}


@dataclass(frozen=True)
class Evaluation:
    batch: Batch
    trials: List[dict]
    wall_s: float
    runner: str
    requested: int
    interrupted: bool = False
    decision: Optional[dict] = None  # the sequential test's: its settings, decision, and the trials it took
    prediction: Optional[PredictedRate] = None  # the rate with the model's verdicts (with_predictions)

    def summary(self) -> dict:
        """Counts, the success rate with its Wilson 95% interval, goal-error percentiles (mm and
        |deg|, over the trials that ran to the end), the causes of the misses, and the speed:
        robot time simulated per wall second. A crashed trial (an internal error) is neither a
        landing nor a miss: the rate and its interval are over the trials that did not crash
        (`judged`), and the crashed ones are counted (`crashed`) and listed (`crashed_trials`)."""
        n = len(self.trials)
        crashes = [t["trial"] for t in self.trials if crashed(t)]
        judged = n - len(crashes)
        successes = sum(1 for t in self.trials if t["success"])
        ran = [t for t in self.trials if t["goal_error"] is not None]
        distance = np.array([t["goal_error"]["distance"] for t in ran])
        angle = np.array([abs(t["goal_error"]["theta"]) for t in ran])
        causes: Dict[str, int] = {}
        for t in self.trials:
            if not t["success"] and not crashed(t):
                causes[str(t["cause"])] = causes.get(str(t["cause"]), 0) + 1
        robot_time = sum(t["sim_time_s"] for t in self.trials)
        nodes: Dict[str, int] = {}  # where the trials ran; a trial whose worker was lost has no node (None)
        for t in self.trials:
            if t.get("node") is not None:
                nodes[t["node"]] = nodes.get(t["node"], 0) + 1
        return {
            "task": self.batch.task.name, "trials": n, "requested": self.requested, "interrupted": self.interrupted,
            "judged": judged, "successes": successes, "success_rate": successes / judged if judged else None,
            # one world: every trial would be this one, so a rate over them says nothing more
            "ci95": None if not judged or self.batch.spreads.one_world else list(wilson_interval(successes, judged)),
            "tolerance": self.batch.success_tolerance.as_list(), "one_world": self.batch.spreads.one_world,
            "closed_loop": self.batch.closed_loop, "guarded": self.batch.guarded,
            "engine": self.batch.engine, "seed": self.batch.seed,
            "simulated_geometry": next((t["simulated_geometry"] for t in self.trials if t.get("simulated_geometry")),
                                       None),
            "plan_uncertainty": dict(self.batch.task.uncertainty),
            "vary": dict(self.batch.spreads.vary), "feature_error": list(self.batch.spreads.feature_error),
            "tracker_noise": list(self.batch.spreads.tracker_noise),
            "goal_error_mm": _percentiles(distance), "goal_error_deg": _percentiles(angle),
            "causes": causes, "crashed": len(crashes), "crashed_trials": crashes,
            "wall_s": self.wall_s, "runner": self.runner, "nodes": dict(sorted(nodes.items())),
            "robot_time_s": robot_time, "real_time_factor": robot_time / self.wall_s if self.wall_s > 0 else None,
            "decision": self.decision,
            "prediction": self.prediction.as_dict() if self.prediction is not None else None,
            # trials a correction's search was stopped by its wall-time guard in, not by its count of
            # tests: their outcome may depend on the machine's load (docs/evaluate.md)
            "wall_guard_trials": [t["trial"] for t in self.trials if t.get("wall_guard")],
        }

    def as_dict(self) -> dict:
        return {"summary": self.summary(), "trials": self.trials}

    def describe(self, written: Sequence[str] = ()) -> List[str]:
        """The summary in lines, as `stablepush evaluate` prints them: the success rate with its
        interval, the goal error, the causes of the misses, the speed, the files `written`, and the
        trials' videos."""
        s = self.summary()
        tol = s["tolerance"]
        within = f"within {tol[0]:g} mm (x and z) and {tol[1]:g} deg"
        if not s["judged"]:
            lines = [f"{s['task']}: no trial ran to a verdict: {'the' if s['trials'] == 1 else 'every'} trial crashed"]
        elif s["one_world"]:
            lines = [f"{s['task']}: one world, the model's own (nothing varies): "
                     f"{'landed' if s['successes'] else 'missed'} {within}; one trial, so no interval"]
        else:
            low, high = s["ci95"]
            lines = [f"{s['task']}: landed {s['successes']} of {s['judged']} trials {within}: {s['success_rate']:.1%} "
                     f"(95% CI {low:.1%}-{high:.1%})" + (f"; interrupted after {s['trials']} of {s['requested']}"
                                                         if s["interrupted"] else "")]
        if s["simulated_geometry"]:
            lines.append(f"simulated as: {s['simulated_geometry']}")
        if s["goal_error_mm"]:
            mm, deg = s["goal_error_mm"], s["goal_error_deg"]
            lines.append(f"goal error: median {mm['p50']:.3f} mm / {deg['p50']:.3f} deg, "
                         f"p95 {mm['p95']:.3f} mm / {deg['p95']:.3f} deg")
        if self.prediction is not None:
            lines.append(self.prediction.describe())
        if s["decision"] is not None:
            d = s["decision"]
            said = {"above": "it lands at least", "below": "it lands less than",
                    "undecided": "undecided whether it lands at least"}[d["decision"]]
            lines.append(f"decision: {d['decision']}: {said} {d['target']:.1%} of the time ({d['confidence']:.0%} "
                         f"confidence, {d['method']}), after the first {d['trials']} trials ({d['successes']} landed)")
        if s["causes"]:
            lines.append("misses: " + ", ".join(f"{cause} {count}" for cause, count in sorted(s["causes"].items())))
        if s["crashed"]:
            first = next(t for t in self.trials if crashed(t))
            lines.append(f"crashed: {s['crashed']} of {s['trials']} trials (internal errors, not misses: left out of "
                         f"the rate; each trial's `error` says what), the first, trial {first['trial']}: "
                         f"{first['error']}")
        if s["wall_guard_trials"]:
            guarded = s["wall_guard_trials"]
            lines.append(f"warning: in {len(guarded)} trial(s) ({', '.join(map(str, guarded[:10]))}) a correction's "
                         f"search ran into its wall-time guard before its count of tests: those outcomes may differ "
                         f"on a less loaded machine (run fewer workers)")
        over = f" over {len(s['nodes'])} nodes" if len(s["nodes"]) > 1 else ""
        lines.append(f"{s['wall_s']:.1f} s on {s['runner']}{over}: {s['robot_time_s']:.0f} s of robot time, "
                     f"{s['real_time_factor']:.2f}x real time")
        if written:
            lines.append(f"written: {', '.join(written)}")
        return lines + self._video_lines()

    def _video_lines(self) -> List[str]:
        if not self.batch.video_dir:
            return []
        videos = sum(1 for t in self.trials if t.get("video"))
        failed = sum(1 for t in self.trials if not t["success"])
        return ([f"videos of {videos} of the {failed} failed trial(s) written to {self.batch.video_dir}"]
                + [f"  trial {t['trial']}: no video ({t['video_error']})" for t in self.trials if t.get("video_error")])

    def rows(self) -> Tuple[List[str], List[list]]:
        """The trials as CSV columns and rows (one trial a row)."""
        offsets = sorted({k for t in self.trials for k in t["world"]["feature_offsets"]})
        errors = (("goal_error", "goal"), ("final_error", "final"))  # record field, column prefix
        header = (["trial", "success", "cause"] + list(VARY_KEYS)
                  + [f"{name}_{c}" for name in offsets for c in ("dx_mm", "dz_mm", "dtheta_deg")]
                  + [f"{short}_{c}" for _, short in errors for c in ("x_mm", "z_mm", "theta_deg", "distance_mm")]
                  + ["replans", "sim_time_s", "wall_s", "verdict", "error", "node"]
                  + (["video", "video_error"] if self.batch.video_dir else [])
                  + (["predicted_lands", "predicted_least_margin_n"] if self.prediction is not None else []))
        rows = []
        for t in self.trials:
            w = t["world"]
            rows.append([t["trial"], t["success"], t["cause"] or ""] + [w[k] for k in VARY_KEYS]
                        + [v for name in offsets for v in w["feature_offsets"].get(name, ("", "", ""))]
                        + [(t[which] or {}).get(c, "") for which, _ in errors for c in ("x", "z", "theta", "distance")]
                        + [t["replans"], t["sim_time_s"], t["wall_s"], t["verdict"] or "", t["error"] or "",
                           t.get("node") or ""]
                        + ([t.get("video") or "", t.get("video_error") or ""] if self.batch.video_dir else [])
                        + ([t["predicted"]["lands"], t["predicted"]["least_margin"]]
                           if self.prediction is not None else []))
        return header, rows


def wilson_interval(successes: int, n: int, confidence: float = 0.95) -> Tuple[float, float]:
    """The Wilson score interval of a success rate (scipy)."""
    from scipy.stats import binomtest

    ci = binomtest(successes, n).proportion_ci(confidence_level=confidence, method="wilson")
    return float(ci.low), float(ci.high)


def _percentiles(values: np.ndarray) -> Optional[Dict[str, float]]:
    if values.size == 0:
        return None
    return {f"p{p}": float(np.percentile(values, p)) for p in PERCENTILES} | {"max": float(values.max())}


def write_evaluation(evaluation: Evaluation, json_path: Optional[str] = None, csv_path: Optional[str] = None,
                     png_path: Optional[str] = None) -> None:
    """Write the evaluation: JSON (`summary` and `trials`), CSV (one trial a row), the figure as PNG
    (`stablepush.viz.figures.evaluation_figure`); each file atomically."""
    import csv
    import io
    import json

    from stablepush.outputs import write_atomically

    if json_path is not None:
        write_atomically(json_path, json.dumps(evaluation.as_dict(), indent=1) + "\n")
    if csv_path is not None:
        header, rows = evaluation.rows()
        buffer = io.StringIO()
        writer = csv.writer(buffer, lineterminator="\n")
        writer.writerow(header)
        writer.writerows(rows)
        write_atomically(csv_path, buffer.getvalue())
    if png_path is not None:
        from stablepush.viz.figures import evaluation_figure, save_figure

        save_figure(evaluation_figure(evaluation.summary(), evaluation.trials), png_path)
