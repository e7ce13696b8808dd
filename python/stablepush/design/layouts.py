"""Where should the fixtures go: from a part, a grasp, a start and a goal to a ranked set of
fixture layouts, each a complete task with a verified plan (`stablepush design`).

A design file is a task file whose `candidates` stand in for its `pushers` (design_file.load_design):
every edge and convex corner of the part's section, or pushers listed. A layout is a set of at
most `max_fixtures` candidates. The search
1. prunes every candidate whose cone holds no stable push, from the start, that brings the object
   nearer the goal (mechanics.stable_directions, distances in unit steps): a layout none of whose
   candidates can make such a first push is not planned (a plan that must first push away from
   the goal is lost to this; the count is reported);
2. plans every other layout (plan_task with the task's seed, time limit and uncertainty box: a
   robust plan where the task has one) and checks the plan against its task (check_plan);
3. measures each solved layout: pushes, switch-overs, the point pushers it uses, how far from the
   goal its plan ends, planning time, the least margin of its pushes over the uncertainty box
   (verify.plan_margin), where each fixture stands in the world at the start
   (execution.world.place_features: the task's environment.features), and, where the task names
   its arm (environment.robot), whether the arm can follow the plan (kinematics.cell_path);
4. ranks them (RANK_KEYS, `rank`), keeps the best of each set of fixtures its plan uses, then
   for the best `reach_top` a small reach map around the goal (REACH_CELLS cells, REACH_SPAN
   tolerances either side in x and z): the share of nearby goals the layout also reaches, and
   ranks again;
5. optionally (odds.evaluate_designs) runs the best designs' plans through `evaluate` and ranks
   them by their measured success rate first.
Layouts run on a `runners.Runner` (here, local processes or Ray), each deterministic for the seed.
"""
from __future__ import annotations

import itertools
import math
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Callable, Dict, List, Optional, Sequence, Tuple, Union

from stablepush.design.folder import DESIGN_HEADER, DESIGN_NAME
from stablepush.errors import PadFaceError, SettingError, TaskError
from stablepush.execution.world import place_features
from stablepush.frames import angle_about_y
from stablepush.plan import check_plan, plan_task
from stablepush.plan.plan import Plan
from stablepush.plan.reach import ReachGrid, reach_map
from stablepush.plan.search import require_goal_apart
from stablepush.plan.verify import plan_margin
from stablepush.runners import Runner, WorkerLost, run_all
from stablepush.task.fields import planner_integer, planner_limit
from stablepush.task.mechanics import stable_directions
from stablepush.task.model import Robot, Task
from stablepush.task.schema import parse_task
from stablepush.task.task_text import commented_task, with_files_named_absolutely
from stablepush.units import is_integer

# What a layout is ranked by, each best first: the key, and +1 where less is better, -1 more.
# `arm`: 0 where the task's arm follows the plan, 1 where it cannot (no arm named: not a key);
# `points`: the point pushers the plan uses (a point pusher's stable push cannot be robust to the
# pads' mu, the grip or the mass, docs/planner.md, so its margin is the model's alone);
# `end`: how far from the goal the plan ends, its largest coordinate over the tolerance (0 at the
# goal, 1 at the tolerance's edge): an open-loop run lands where the plan ends plus its drift;
# `success`: the rate measured by odds.evaluate_designs (not measured: ranks last).
RANK_KEYS: Dict[str, int] = {"arm": 1, "fixtures": 1, "points": 1, "end": 1, "switches": 1, "margin": -1,
                             "pushes": 1, "reach": -1, "tests": 1, "time": 1, "success": -1}
# Last, the search's effort in stable-push tests, a count: planning `time` would rank two layouts
# otherwise tied by how busy the machine was (it stays a key a rule may name).
DEFAULT_RANK = ("arm", "fixtures", "points", "end", "switches", "margin", "pushes", "reach", "tests")
REACH_CELLS = 3  # per axis (x and z) of the reach map around the goal
MAX_REACH_TOP = 100  # the best designs given a reach map (design --reach-top)
REACH_SPAN = 2.0  # planner.tolerance either side of the goal
# Every search of a design is bounded by stable-push tests, a count, so that the same design file
# gives the same designs on any machine under any load; the time limits are guards past them.
LAYOUT_CHECKS = 2_000_000  # a layout's search: about 2 s of a line-pusher task's on 2 cores of 2026
REACH_CHECKS = 200_000  # a cell of the reach map around the goal
REACH_TIME_LIMIT = 30.0  # s: the reach cells' guard
# Why a planned layout gave no plan, by its `outcome` (the plan's PlanOutcome, or the two of the
# design search's own), in words; an outcome not listed is named as it is.
NO_PLAN_REASONS: Dict[str, str] = {
    "time_limit": "the search ended before the goal (its check limit or its time ran out)",
    "goal_over_switch_limit": "the goal reached only with more switch-overs than planner.max_switches",
    "invalid_start": "the pads do not hold the object at the start",
    "unreachable": "the goal is out of the layout's reach",
    "refused": "the layout's task was refused",
    "worker_lost": "the worker planning it was lost",
}
NO_PLAN_EXAMPLE = ("refused", "unreachable", "worker_lost")  # whose words need a layout's own reason beside them


def parse_rank(text: str, measured: bool = False) -> Tuple[str, ...]:
    """A ranking rule: keys of RANK_KEYS, comma-separated, most important first, each at most
    once; `success` only where the designs' odds are `measured` (odds.evaluate_designs)."""
    return _rank_keys(tuple(k.strip() for k in text.split(",") if k.strip()), repr(text), measured)


def _rank_keys(keys: Tuple[Any, ...], given: str, measured: bool) -> Tuple[str, ...]:
    """`keys` as a ranking rule (parse_rank's), TaskError otherwise; `given`: the rule as given."""
    unknown = [k for k in keys if not isinstance(k, str) or k not in RANK_KEYS]
    if not keys or unknown or len(set(keys)) < len(keys):
        raise TaskError("rank", f"keys from {', '.join(RANK_KEYS)}, comma-separated, each once, got {given:.80}")
    if "success" in keys and not measured:
        raise TaskError("rank", "`success` is measured by evaluating the designs (--evaluate N); without it "
                                "no design has a success rate to rank by")
    return keys


@dataclass(eq=False)  # a design is the one result it is: compared, hashed and found in lists by identity
class Design:
    """One layout: its pushers (candidate names), the task made of them, and what was measured."""

    pushers: Tuple[str, ...]
    task: Optional[Task] = None
    solved: bool = False
    reason: str = ""
    outcome: Optional[str] = None  # unsolved: a key of NO_PLAN_REASONS (the plan's outcome, refused, worker_lost)
    end_steps: Optional[float] = None  # unsolved: how far from the goal the search's best path ended (unit steps)
    pushes: Optional[int] = None
    switches: Optional[int] = None
    end_used: Optional[float] = None  # the plan's end's largest offset from the goal over the tolerance (1: its edge)
    points: Optional[int] = None  # point pushers the plan uses
    planning_time_s: Optional[float] = None
    tests: Optional[int] = None  # the stable-push tests its search made
    margin_n: Optional[float] = None
    reach: Optional[float] = None  # share of the goals around the goal it also reaches (None: not measured)
    features: Dict[str, List[float]] = field(default_factory=dict)  # pusher -> [x, y, z mm, theta deg]
    # Whether the task's arm (environment.robot, when it names one) can follow the plan in the cell
    # (joint_path: follows, or the first sample it cannot and why); None: no arm named.
    arm: Optional[Dict[str, Any]] = None
    task_file: Optional[str] = None
    plan: Optional[Plan] = field(default=None, repr=False)
    # The plan's measured odds (odds.evaluate_designs): trials, successes, success_rate with its ci95,
    # the misses' causes; or `refused` where the arm cannot follow it. None: not evaluated.
    success: Optional[Dict[str, Any]] = None

    @property
    def fixtures(self) -> int:
        """The fixtures the layout needs: the pushers its plan uses (those of a task's own layout
        that the plan leaves alone need not be built)."""
        return len(self.features) if self.solved else len(self.pushers)

    def key(self, rank: Sequence[str]) -> tuple:
        values = {"arm": None if self.arm is None else int(not self.arm["follows"]), "fixtures": self.fixtures,
                  "points": self.points, "end": self.end_used, "switches": self.switches, "margin": self.margin_n,
                  "pushes": self.pushes, "reach": self.reach, "tests": self.tests, "time": self.planning_time_s,
                  "success": self._success_value()}
        ranked = tuple(math.inf if (value := values[k]) is None else RANK_KEYS[k] * value for k in rank)
        return (not self.solved, *ranked)

    def _success_value(self) -> Optional[float]:
        """What `success` ranks by: the prediction-powered interval's low end where the odds were
        measured with predictions, else the trials' success rate."""
        measured = self.success or {}
        predicted = measured.get("prediction")
        return predicted["interval"][0] if predicted else measured.get("success_rate")

    def odds(self) -> str:
        """The measured odds in words (", landed 19 of 20 trials (76%-99%)"), or why none were
        measured; "" where the design was not evaluated."""
        if self.success is None:
            return ""
        if "refused" in self.success:
            return f", not evaluated: {self.success['refused']}"
        s, ci = self.success, self.success["ci95"]
        interval = f" ({ci[0]:.0%}-{ci[1]:.0%})" if ci else ""
        predicted = s.get("prediction")
        if predicted:
            low, high = predicted["interval"]
            interval += f", {low:.0%}-{high:.0%} with {predicted['predictions']:,} predictions"
        return f", landed {s['successes']} of {s['judged']} trials{interval}"

    def as_dict(self) -> Dict[str, Any]:
        return {"pushers": list(self.pushers), "fixtures": self.fixtures, "solved": self.solved,
                "reason": self.reason or None, "outcome": self.outcome, "end_steps": self.end_steps,
                "pushes": self.pushes, "switches": self.switches, "end_used": self.end_used, "points": self.points,
                "planning_time_s": self.planning_time_s, "tests": self.tests,
                "margin_n": self.margin_n, "reach": self.reach, "features": self.features, "arm": self.arm,
                "success": self.success, "task_file": self.task_file}


@dataclass
class DesignStudy:
    """The search's result: the designs, best first (solved ones), and what was not planned."""

    candidates: List[str]
    designs: List[Design]
    pruned_candidates: List[str]
    layouts_searched: int
    layouts_pruned: int
    rank: Tuple[str, ...]
    failed: List[Design] = field(default_factory=list)  # planned, not solved
    evaluated: Optional[Dict[str, Any]] = None  # how the odds were measured (odds.evaluate_designs); None: not
    interrupted: bool = False  # the odds' trials stopped by Ctrl-C

    @property
    def usable(self) -> List[Design]:
        """The designs the task's arm can follow (every design where the task names no arm)."""
        return [d for d in self.designs if d.arm is None or d.arm["follows"]]

    @property
    def verdict(self) -> str:
        """One line: the best design, or why there is none (none solved; or none the arm can follow,
        when the ranking's best is one it cannot)."""
        if self.designs and not self.usable:
            first = self.designs[0]
            assert first.arm is not None, "a design the arm cannot follow was checked against it"
            many = f"any of the {len(self.designs)} designs" if len(self.designs) > 1 else "the one design"
            return (f"no design is usable by this arm: it cannot follow the plan of {many} (e.g. "
                    f"{' + '.join(first.pushers)}: {first.arm['reason']})")
        if self.designs:
            best = self.designs[0]
            return (f"best layout: {' + '.join(best.pushers)} ({best.pushes} pushes, {best.switches} switch-overs, "
                    f"margin {best.margin_n:.3f} N{best.odds()})")
        if not self.layouts_searched:
            return (f"no layout of the candidates can do it: none of them ({', '.join(self.pruned_candidates)}) has a "
                    f"stable push from the start toward the goal")
        return (f"no layout of the candidates can do it: {self.layouts_searched} layouts planned, none solved "
                f"(e.g. {' + '.join(self.failed[0].pushers)}: {self.failed[0].reason})")

    def no_plan(self) -> List[Dict[str, Any]]:
        """The layouts planned that gave no plan, grouped by why (their `outcome`), the largest group
        first: the outcome, why in words (NO_PLAN_REASONS), how many layouts and which, the span of
        unit steps from the goal their searches' best paths ended at (None where none was
        searched), and one layout's own reason as an example."""
        groups: Dict[str, List[Design]] = {}
        for d in self.failed:
            groups.setdefault(d.outcome or "unknown", []).append(d)
        out = []
        for outcome, designs in sorted(groups.items(), key=lambda g: (-len(g[1]), g[0])):
            ends = [d.end_steps for d in designs if d.end_steps is not None]
            out.append({"outcome": outcome, "why": NO_PLAN_REASONS.get(outcome, outcome), "layouts": len(designs),
                        "pushers": [list(d.pushers) for d in designs],
                        "end_steps": [min(ends), max(ends)] if ends else None,
                        "example": {"pushers": list(designs[0].pushers), "reason": designs[0].reason}})
        return out

    def describe_no_plan(self) -> List[str]:
        """How many layouts were planned and solved, and why the others gave no plan (no_plan), in
        lines: the count first, then a line a group with up to three of its layouts."""
        if not self.layouts_searched:
            return []
        solved = self.layouts_searched - len(self.failed)
        lines = [f"of the {self.layouts_searched} layouts planned, {solved} solved and {len(self.failed)} gave no "
                 f"plan" + (":" if self.failed else "")]
        for g in self.no_plan():
            ends = g["end_steps"]
            span = "" if ends is None else (f", the best partial path{'s' if g['layouts'] > 1 else ''} "
                                            f"{ends[0]:.1f}{'' if ends[1] == ends[0] else f'-{ends[1]:.1f}'} unit "
                                            f"steps from it")
            named = ", ".join(" + ".join(p) for p in g["pushers"][:3]) + (", ..." if g["layouts"] > 3 else "")
            example = g["example"]
            for_one = (f"; e.g. {' + '.join(example['pushers'])}: {example['reason']}"
                       if g["outcome"] in NO_PLAN_EXAMPLE else "")
            lines.append(f"  {g['layouts']}: {g['why']}{span} ({named}){for_one}")
        return lines

    def describe_odds(self) -> Optional[str]:
        """How the odds were measured, in a line (None: they were not): the designs, the trials and
        the worlds; where a design ran fewer trials than asked (the study stopped by Ctrl-C, its
        arm refused, one world), how many each ran."""
        e = self.evaluated
        if e is None:
            return None
        which = "the best design" if e["top"] == 1 else f"the best {e['top']} designs"
        worlds = (f"in the same worlds ({e['spreads']}; seed {e['seed']}, {'closed' if e['closed_loop'] else 'open'} "
                  f"loop on {e['engine']})")
        if e.get("predictions"):
            worlds += (f", with {e['predictions']:,} model-only worlds each (ranked by the prediction-powered "
                       f"interval's low end)")
        ran = e.get("ran", {})
        if not self.interrupted and all(n == e["trials"] for n in ran.values()):
            return f"odds: {which}, {e['trials']} trials each {worlds}"
        each = ", ".join(f"{layout} ran {n} of {e['trials']}" if n else f"{layout} none" for layout, n in ran.items())
        return (f"odds: {which}, {e['trials']} trials asked of each {worlds}; "
                f"{'the study stopped by Ctrl-C: ' if self.interrupted else ''}{each}")

    def as_dict(self) -> Dict[str, Any]:
        return {"candidates": self.candidates, "pruned_candidates": self.pruned_candidates,
                "layouts_searched": self.layouts_searched, "layouts_pruned": self.layouts_pruned,
                "no_plan": self.no_plan(),
                "rank": list(self.rank), "verdict": self.verdict, "evaluated": self.evaluated,
                "interrupted": self.interrupted, "designs": [d.as_dict() for d in self.designs],
                "unsolved": [d.as_dict() for d in self.failed]}


@dataclass(frozen=True)
class _Job:
    """What every layout's planning shares (sent once per worker)."""

    task: Dict[str, Any]
    candidates: Tuple[Dict[str, Any], ...]
    source: Optional[str]
    layouts: Tuple[Tuple[int, ...], ...]
    time_limit: Optional[float]
    check_limit: int = LAYOUT_CHECKS


def layout_task(task: Dict[str, Any], pushers: Sequence[Dict[str, Any]], source: Optional[str] = None) -> Task:
    """The task of one layout: the design's task with these pushers."""
    return parse_task({**task, "pushers": [dict(p) for p in pushers]}, source)


@dataclass(frozen=True)
class LayoutSearch:
    """How design() searches: the layouts of at most `max_fixtures` candidates, each planned within
    `check_limit` stable-push tests (0: no count; then `time_limit` s, None: the task's
    planner.time_limit, which is otherwise only a guard), the solved ones ranked by `rank` (keys of
    RANK_KEYS; `success` may be among them: evaluate_designs measures it), the best `reach_top`
    given a reach map around the goal. Made with a field out of its range it raises TaskError or
    SettingError naming it, as `stablepush design` takes them."""

    max_fixtures: int = 2
    rank: Tuple[str, ...] = DEFAULT_RANK
    reach_top: int = 3
    time_limit: Optional[float] = None
    check_limit: int = LAYOUT_CHECKS

    def __post_init__(self) -> None:
        max_fixtures, reach_top, rank = self.max_fixtures, self.reach_top, self.rank
        if isinstance(max_fixtures, bool) or not is_integer(max_fixtures) or max_fixtures < 1:
            raise SettingError("max_fixtures", f"must be a whole number from 1 up, got {max_fixtures!r:.40}")
        if isinstance(reach_top, bool) or not is_integer(reach_top) or not 0 <= reach_top <= MAX_REACH_TOP:
            raise SettingError("reach_top", f"must be a whole number from 0 to {MAX_REACH_TOP}, got {reach_top!r:.40}")
        if self.time_limit is not None:
            planner_limit("time_limit", self.time_limit)
        if isinstance(rank, str) or not isinstance(rank, (tuple, list)):
            raise TaskError("rank", f"a sequence of keys from {', '.join(RANK_KEYS)}, got {rank!r:.80}")
        object.__setattr__(self, "rank", _rank_keys(tuple(rank), repr(tuple(rank)), measured=True))
        object.__setattr__(self, "check_limit", planner_integer("check_limit", "check_limit", self.check_limit))


def design(task: Dict[str, Any], candidates: Sequence[Dict[str, Any]], source: Optional[str] = None,
           search: Optional[LayoutSearch] = None, runner: Optional[Runner] = None,
           progress: Optional[Callable[[Design], None]] = None) -> DesignStudy:
    """Search the layouts of `candidates` (design_file.load_design) as `search` says (None:
    LayoutSearch()), and rank the solved ones. `progress(design)` after each layout is planned.
    TypeError for a search, runner or progress that is not one."""
    search = LayoutSearch() if search is None else search
    if not isinstance(search, LayoutSearch):
        raise TypeError(f"search: expected a LayoutSearch, got {type(search).__name__}")
    if runner is not None and not isinstance(runner, Runner):
        raise TypeError(f"runner: expected a Runner, got {type(runner).__name__}")
    if progress is not None and not callable(progress):
        raise TypeError(f"progress: expected a function, got {type(progress).__name__}")
    rank, reach_top, check_limit = search.rank, search.reach_top, search.check_limit
    if not isinstance(task, dict):
        raise TypeError(f"task must be a design file's task mapping (design_file.load_design), got "
                        f"{type(task).__name__}")
    if not isinstance(candidates, (list, tuple)) or not all(isinstance(c, dict) for c in candidates):
        raise TypeError(f"candidates must be a list of pusher entries (design_file.load_design), got "
                        f"{candidates!r:.60}")
    max_fixtures = min(search.max_fixtures, len(candidates))
    everything = layout_task(task, candidates, source)  # every candidate checked once, on the part
    require_goal_apart(everything)  # else every candidate would be pruned as making no push toward the goal
    toward = _pushers_toward_goal(everything)
    useful = [i for i, c in enumerate(candidates) if c["name"] in toward]
    layouts = [combo for size in range(1, max_fixtures + 1)
               for combo in itertools.combinations(range(len(candidates)), size) if set(combo) & set(useful)]
    total = sum(math.comb(len(candidates), k) for k in range(1, max_fixtures + 1))
    job = _Job(task, tuple(candidates), source, tuple(layouts), search.time_limit, check_limit)
    runner = runner or Runner()
    results: List[Design] = []
    for i, result in run_all(_plan_layout, job, range(len(layouts)), runner):
        if isinstance(result, WorkerLost):
            result = Design(tuple(candidates[k]["name"] for k in layouts[i]), reason=f"worker lost: {result.why}",
                            outcome="worker_lost")
        results.append(result)
        if progress is not None:
            progress(result)
    results.sort(key=lambda d: d.pushers)  # in the layouts' order, whichever worker finished first
    solved = _distinct(sorted((d for d in results if d.solved), key=lambda d: d.key(rank)))
    for d in solved[:reach_top]:
        assert d.task is not None, "a solved design has its task"
        d.reach = _reach_near_goal(d.task, runner)
    solved.sort(key=lambda d: d.key(rank))
    return DesignStudy(candidates=[c["name"] for c in candidates], designs=solved,
                       pruned_candidates=[c["name"] for i, c in enumerate(candidates) if i not in useful],
                       layouts_searched=len(layouts), layouts_pruned=total - len(layouts), rank=tuple(rank),
                       failed=[d for d in results if not d.solved])


def _distinct(ranked: List[Design]) -> List[Design]:
    """One design per set of fixtures its plan uses, the smallest layout of it (a layout whose
    plan leaves one of its pushers alone is the smaller layout again), in ranked order."""
    best: Dict[frozenset, Design] = {}
    for d in ranked:
        used = frozenset(d.features)
        if used not in best or len(d.pushers) < len(best[used].pushers):
            best[used] = d
    return [d for d in ranked if best[frozenset(d.features)] is d]


def _pushers_toward_goal(task: Task) -> set:
    """The pushers with a stable push from the start that brings the object nearer the goal (in
    unit steps), in the task's uncertainty box when it has one (one stable_directions for all)."""
    unit = (*(task.planner.step[0],) * 2, task.planner.step[1])
    to_goal = [(g - s) / u for g, s, u in zip(task.goal, task.start, unit)]
    pushes = stable_directions(task, task.start)["pushers"]
    return {name for name, moves in pushes.items()
            if any(sum(m / u * t for m, u, t in zip(push["move"], unit, to_goal)) > 0 for push in moves)}


def _plan_layout(job: _Job, i: int) -> Design:
    return measure_layout(job.task, [job.candidates[k] for k in job.layouts[i]], job.source, job.time_limit,
                          job.check_limit)


def measure_layout(task: Dict[str, Any], pushers: Sequence[Dict[str, Any]], source: Optional[str] = None,
                   time_limit: Optional[float] = None, check_limit: int = LAYOUT_CHECKS) -> Design:
    """One layout planned (within `check_limit` stable-push tests, 0: none, and `time_limit` s, None:
    the task's) and checked, with what the
    ranking reads: pushes, switch-overs, planning time, the least margin and the fixtures' places.
    A task's own pushers measured so can be ranked among the designs."""
    d = Design(tuple(p["name"] for p in pushers))
    try:
        d.task = layout_task(task, pushers, source)
    except TaskError as exc:  # the goal's grasp or the part's checks refuse it with these pushers
        d.reason, d.outcome = str(exc), "refused"
        return d
    try:
        plan = plan_task(d.task, time_limit=time_limit, check_limit=check_limit or None)
    except PadFaceError as exc:  # its path takes a mesh part's pads off the faces the model takes
        d.reason, d.outcome = str(exc), "refused"
        return d
    d.planning_time_s, d.tests = plan.stats.get("planning_time_s"), plan.stats.get("feasibility_checks")
    if not plan.solved:
        d.reason = plan.message or "not solved within the time limit"
        d.outcome = plan.outcome
        if plan.outcome == "time_limit":  # its best partial path; other outcomes' paths are not partial
            d.end_steps = plan.stats.get("goal_distance_steps")
        return d
    d.plan = plan = check_plan(d.task, plan)
    d.solved = True
    d.pushes = len(plan.waypoints) - 1
    d.switches = max(0, len(plan.pusher_sequence) - 1)
    d.margin_n = plan_margin(d.task, plan)
    end = plan.waypoints[-1].pose
    d.end_used = d.task.tolerance.used(end, d.task.goal)
    for name, feature in place_features(d.task, list(plan.waypoints)).items():
        T = feature.object_pose
        d.features[name] = [float(T[0, 3] * 1e3), float(T[1, 3] * 1e3), float(T[2, 3] * 1e3),
                            math.degrees(angle_about_y(T[:3, :3]))]
    d.points = sum(1 for p in d.task.pushers if p.is_point and p.name in d.features)
    if d.task.environment.robot != Robot():
        d.arm = _arm_follows(d.task, plan)
    return d


def _arm_follows(task: Task, plan) -> Dict[str, Any]:
    """The cell check of the task's arm on the plan (kinematics.cell_path), as its JSON verdict."""
    from stablepush.kinematics.cell_path import CellError, joint_path

    try:
        return joint_path(task, plan).verdict()
    except CellError as refusal:
        return refusal.verdict()


def _reach_near_goal(task: Task, runner: Runner) -> float:
    """The share of goals on a REACH_CELLS x REACH_CELLS grid around the goal (REACH_SPAN
    tolerances either side in x and z, the goal's theta) that the layout also reaches."""
    tol = task.planner.tolerance[0] * REACH_SPAN
    gx, gz, gt = task.goal
    grid = ReachGrid((gx - tol, gx + tol, REACH_CELLS), (gz - tol, gz + tol, REACH_CELLS), (gt, gt, 1))
    cells = reach_map(task, grid, seed=task.planner.seed, time_limit=REACH_TIME_LIMIT, check_limit=REACH_CHECKS,
                      runner=runner).cells
    return sum(1 for c in cells if c["solved"]) / len(cells)


def design_task(task: Dict[str, Any], candidates: Sequence[Dict[str, Any]], d: Design,
                source: Optional[str] = None) -> Dict[str, Any]:
    """A design as a complete task in the task file's form: the design file's task with the
    layout's pushers, and environment.features where its plan puts each fixture (what `plan`,
    `execute` and `evaluate` take unchanged). The files the design file `source` names (a mesh, a
    robot model) are named by the absolute paths its task read them from, so the task file reads
    the same files anywhere (a model `~/arm.urdf` is the home folder's, as the design file read it)."""
    by_name = {c["name"]: c for c in candidates}
    environment = dict(task.get("environment") or {})
    environment["features"] = {name: [round(v, 6) for v in pose] for name, pose in d.features.items()}
    out = {**task, "pushers": [dict(by_name[name]) for name in d.pushers], "environment": environment}
    read = d.task if d.task is not None else layout_task(task, [by_name[name] for name in d.pushers], source)
    return with_files_named_absolutely(out, read)


def designs_folder(design_file: str) -> Path:
    """Where a design file's designs go by default: NAME.designs/ beside NAME.design.yaml."""
    path = Path(design_file)
    stem = path.name[:-len(".design.yaml")] if path.name.endswith(".design.yaml") else path.stem
    return path.parent / f"{stem}.designs"


def design_files(study: DesignStudy, task: Dict[str, Any], candidates: Sequence[Dict[str, Any]], folder: Path,
                 source: Optional[str] = None) -> Dict[Union[str, Path], str]:
    """Each design as a task file, `folder`/design-<rank>.yaml (its `task_file` set): path -> YAML,
    with the design file `source`'s comments where they apply (task.task_text.commented_task)."""
    try:
        text = Path(source).read_text(encoding="utf-8") if source is not None else None
    except (OSError, UnicodeError):  # read once already (design_file.load_design); without it, no comments
        text = None
    files: Dict[Union[str, Path], str] = {}  # as write_designs takes them (each key a str)
    for k, d in enumerate(study.designs, start=1):
        d.task_file = str(Path(folder) / DESIGN_NAME.format(rank=k))
        header = (DESIGN_HEADER.format(rank=k, source=Path(source).name if source else "a design")
                  + f"the layout {' + '.join(d.pushers)}, each fixture where its plan puts it (environment.features)\n")
        files[d.task_file] = commented_task(text, design_task(task, candidates, d, source), header)
    return files
