"""Benchmarks: the stable-push test (median time per check, by contact case) and planning
(the paper's Table II: planning time over seeds, success, switch-overs, path length).

Check queries run through `StablePushModel.check_batch` (one C++ loop, no Python per check) in
batches; each batch gives a time per check, and the median over batches is reported. Planning
trials run the task with seeds seed, seed + 1, ...; the time is the core's own (model built once).
"""
from __future__ import annotations

import csv
import dataclasses
import io
import json
import time
from dataclasses import dataclass
from typing import Callable, Dict, List, Optional

import numpy as np

from stablepush.errors import RunnerError
from stablepush.outputs import write_atomically
from stablepush.plan.search import plan_task
from stablepush.runners import Runner, WorkerLost, run_all
from stablepush.task.model import Task
from stablepush.units import MM, is_integer

# Paper Table II (median planning time over 10 trials, s): this paper's planner in MATLAB on an
# i7 2.8 GHz, and the earlier complementarity-based planner (Chavan-Dafle and Rodriguez 2017).
PAPER_TABLE_II = {
    "horizontal-offset-low-mu": (2.83, 592.8),
    "pivoting": (1.6, 128.4),
    "large-manipulation": (2.54, 17684.0),
    "t-shaped": (0.82, 32657.0),
}


@dataclass
class CheckTiming:
    case: str
    median_us: float
    min_us: float
    checks: int
    feasible_fraction: float
    exact_fraction: float


def _queries(task: Task, rng: np.random.Generator, n: int, sticking: bool):
    q = np.column_stack([rng.uniform(-3, 3, n) * MM, rng.uniform(-3, 3, n) * MM, np.radians(rng.uniform(-20, 20, n))])
    if sticking:
        # Rotation about the first pad's centre: that centre sticks, every other pad point slides.
        w = np.radians(rng.uniform(0.2, 1.5, n)) * rng.choice([-1.0, 1.0], n)
        pad = np.array(task.gripper.pads[0][0]) * MM
        arm = pad[None, :] - q[:, :2]
        dq = np.column_stack([-w * arm[:, 1], w * arm[:, 0], w])
    else:
        dq = np.column_stack([rng.uniform(-1, 1, n) * MM, rng.uniform(-1, 1, n) * MM,
                              np.radians(rng.uniform(-1, 1, n))])
    return q, dq


def bench_checks(
    task: Task,
    checks: int = 200_000,
    batch: int = 2_000,
    seed: int = 0,
    progress: Optional[Callable[[int], None]] = None,
) -> Dict[str, CheckTiming]:
    """Median time per stable-push test for the all-sliding and the sticking case, cycling
    through the task's pushers: `checks` tests of each, timed in batches of up to `batch` (as
    equal as they divide, so that no short remainder weighs as much as a full batch)."""
    for name, value in (("checks", checks), ("batch", batch)):
        if not is_integer(value) or value < 1:
            raise ValueError(f"{name}: must be a whole number of at least 1, got {value!r}")
    model = task.model
    rng = np.random.default_rng(seed)
    out = {}
    batches = -(-checks // batch)
    sizes = [checks // batches + (k < checks % batches) for k in range(batches)]
    for case, sticking in (("all_sliding", False), ("sticking", True)):
        per_check: List[float] = []
        feasible, exact, done = 0, 0, 0
        for size in sizes:
            q, dq = _queries(task, rng, size, sticking)
            pusher = len(per_check) % len(task.pushers)
            start = time.perf_counter()
            f, _, e = model.check_batch(q, dq, pusher)
            per_check.append((time.perf_counter() - start) / size)
            feasible += int(f.sum())
            exact += int(e.sum())
            done += size
            if progress:
                progress(size)
        out[case] = CheckTiming(
            case=case,
            median_us=float(np.median(per_check)) * 1e6,
            min_us=float(np.min(per_check)) * 1e6,
            checks=done,
            feasible_fraction=feasible / done,
            exact_fraction=exact / done,
        )
    return out


@dataclass
class PlanningTrial:
    task: str
    seed: int
    solved: bool
    outcome: str
    planning_time_s: float
    switches: int
    pushes: int
    path_length_steps: float
    feasibility_checks: int
    nodes: int
    pusher_sequence: List[str]  # the pushers in the plan's order, one entry per contact
    min_margin: Optional[float]  # N: the least margin over the plan's pushes (None: no push)
    # The first plan of an anytime search (improve_for > 0), before the improvement; None otherwise.
    first_time_s: Optional[float] = None
    first_switches: Optional[int] = None
    first_path_length_steps: Optional[float] = None
    first_min_margin: Optional[float] = None


def planning_trial(task: Task, seed: int, time_limit: Optional[float] = None,
                   improve_for: Optional[float] = None) -> PlanningTrial:
    """One planning run of `task` with `seed` (the task's models are built on its first run and
    kept with it)."""
    plan = plan_task(task, seed=seed, time_limit=time_limit, improve_for=improve_for)
    s = plan.stats
    first = s.get("first") or {}
    return PlanningTrial(
        task=task.name, seed=seed, solved=plan.solved, outcome=plan.outcome,
        planning_time_s=s["planning_time_s"], switches=s["switches"], pushes=s["pushes"],
        path_length_steps=s["path_length_steps"], feasibility_checks=s["feasibility_checks"], nodes=s["nodes"],
        pusher_sequence=list(plan.pusher_sequence),
        min_margin=min((w.margin for w in plan.waypoints[1:] if w.margin is not None), default=None),  # each push's
        first_time_s=first.get("planning_time_s"), first_switches=first.get("switches"),
        first_path_length_steps=first.get("path_length_steps"), first_min_margin=first.get("min_margin"),
    )


def bench_planning(task: Task, trials: int, seed: int = 1, time_limit: Optional[float] = None,
                   progress: Optional[Callable[[int], None]] = None,
                   improve_for: Optional[float] = None, runner: Optional[Runner] = None) -> "list[PlanningTrial]":
    """Plan `task` with seeds seed .. seed + trials - 1 (with `improve_for`, an anytime search that
    goes on that many seconds after its first plan; the trial records both), here one after the
    other, or on `runner`'s local processes or Ray (in seed order; RunnerError when a worker is
    lost). `progress(1)` after each trial."""
    if runner is not None:
        return _bench_on_runner(PlanningJob(task, seed, time_limit, improve_for), trials, runner, progress)
    out = []
    for k in range(trials):
        out.append(planning_trial(task, seed + k, time_limit, improve_for))
        if progress is not None:
            progress(1)
    return out


@dataclass(frozen=True)
class PlanningJob:
    """A bench's planning runs of one task, as jobs for a batch runner (`stablepush.runners.run_all`):
    run k plans with seed `seed` + k."""

    task: Task
    seed: int = 1
    time_limit: Optional[float] = None
    improve_for: Optional[float] = None


def _bench_on_runner(job: "PlanningJob", trials: int, runner: Runner,
                     progress: Optional[Callable[[int], None]]) -> "list[PlanningTrial]":
    done = {}
    for k, trial in run_all(run_planning_job, job, range(trials), runner):
        if isinstance(trial, WorkerLost):
            raise RunnerError(f"{job.task.name}: planning trial {k} lost its worker ({trial.why})")
        done[k] = trial
        if progress is not None:
            progress(1)
    return [done[k] for k in sorted(done)]


def write_planning_trials(path: str, trials: "list[PlanningTrial]", summaries: "list[dict]") -> None:
    """Every trial to `path`: .json (trials and the summaries) or else CSV, one row per trial, a
    list (pusher_sequence) as JSON in its cell, since pusher names may hold any printable character."""
    records = [dataclasses.asdict(t) for t in trials]
    if path.lower().endswith(".json"):
        write_atomically(path, json.dumps({"trials": records, "summary": summaries}, indent=1) + "\n")
        return
    buffer = io.StringIO()
    writer = csv.DictWriter(buffer, fieldnames=list(records[0]), lineterminator="\n")
    writer.writeheader()
    writer.writerows({k: json.dumps(v) if isinstance(v, list) else v for k, v in r.items()} for r in records)
    write_atomically(path, buffer.getvalue())


def run_planning_job(job: PlanningJob, k: int) -> PlanningTrial:
    return planning_trial(job.task, job.seed + k, job.time_limit, job.improve_for)


def summarize_planning(trials: "list[PlanningTrial]") -> dict:
    """One Table II row: times in s over all trials (a failed trial counts its time limit)."""
    times = sorted(t.planning_time_s for t in trials)
    solved = [t for t in trials if t.solved]
    name = trials[0].task
    paper, earlier = PAPER_TABLE_II.get(name, (None, None))
    total_time = sum(t.planning_time_s for t in trials)
    return {
        "task": name,
        "trials": len(trials),
        "success_rate": len(solved) / len(trials),
        "median_time_s": float(np.median(times)),
        "p95_time_s": float(np.percentile(times, 95)),
        "min_time_s": times[0],
        "max_time_s": times[-1],
        "median_switches": float(np.median([t.switches for t in solved])) if solved else None,
        "median_path_length_steps": float(np.median([t.path_length_steps for t in solved])) if solved else None,
        "checks_per_s": sum(t.feasibility_checks for t in trials) / total_time if total_time > 0 else 0.0,
        "paper_time_s": paper,
        "earlier_planner_time_s": earlier,
        **_first_and_improved(solved),
    }


def _first_and_improved(solved: "list[PlanningTrial]") -> dict:
    """Medians of the first and the improved plans of anytime trials (empty without improve_for)."""
    anytime = [t for t in solved if t.first_time_s is not None and t.min_margin is not None]
    if not anytime:
        return {}

    def median(values):
        return float(np.median(values))

    return {
        "first_median_time_s": median([t.first_time_s for t in anytime]),
        "first_median_switches": median([t.first_switches for t in anytime]),
        "first_median_path_length_steps": median([t.first_path_length_steps for t in anytime]),
        "first_median_min_margin": median([t.first_min_margin for t in anytime]),
        "improved_median_switches": median([t.switches for t in anytime]),
        "improved_median_path_length_steps": median([t.path_length_steps for t in anytime]),
        "improved_median_min_margin": median([t.min_margin for t in anytime]),
    }

