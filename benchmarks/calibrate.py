"""Calibration in worlds that hide their friction (issue targets: each identifiable mu's interval
holds the truth in >= 95% of worlds, its estimate within 7% (pads) and 10% (features), in <= 12
probes and 5 minutes): each task in --worlds hidden worlds whose pads' and features' mu are each the
task's times a factor drawn uniformly from 1 -+ --off, independently; `calibrate` on the simulated
arm in that world (`--world` with every mu set); then the task's nominal plan and the calibrated
task's plan, each run open loop in the same world.

    python3 benchmarks/calibrate.py [--tasks low-mu t-shaped ...] [--generated 3] [--worlds 4] [--seed 1]
                                    [--off 0.4] [--engine mujoco] [--workers 2 | --ray [ADDRESS]] [--md OUT.md]
                                    [--estimate gripper.grip_force]
    python3 benchmarks/calibrate.py --agreement 200 [--seed 1]
    python3 benchmarks/calibrate.py --runs 20 [--tasks ...] [--worlds 2]

World w of task t depends only on (--seed, t, w). --agreement N runs N random probes (random safe
starts, directions and worlds) and tabulates the contact's measured slip against the model's
verdict in the world itself: how often the simulator and the model agree on a probe, the number
the posterior's error rate stands for, and where the slip threshold (probes.SLIP_MM) falls.
--runs N runs each task's nominal plan N times in each hidden world (tracker noise 0.02 mm / 0.02
deg, its own seed each) and calibrates from those reports alone (`calibrate --from`), after one
run and after all N.
"""
from __future__ import annotations

import argparse
import dataclasses
import json
import sys
import time
from pathlib import Path

import numpy as np
import yaml
from evaluate_tasks import add_runner_options, runner_of
from generated_task_odds import generate_task, goal_for
from shipped import TASKS

from stablepush.calibration import PAD_PRODUCT, CalibrationSettings, calibrate, calibrate_from_runs
from stablepush.calibration.belief import Belief
from stablepush.calibration.probes import Unknowns, WorldGrid, candidates, probe_plan, probe_world, stuck
from stablepush.execution import RunOptions, run_plan
from stablepush.plan import plan_task
from stablepush.runners import WorkerLost, run_all
from stablepush.sim import SimulatedArm, WorldDeviation
from stablepush.task import parse_task
from stablepush.units import pose_to_si

SHIPPED = ("horizontal-offset-low-mu", "horizontal-offset-high-mu", "t-shaped", "pivoting")


def hidden_world(task, seed: int, t: int, w: int, off: float, pads: str = "gripper.mu") -> WorldDeviation:
    """World w of task t: the pads' quantity `pads` and every pusher's mu, each the task's times
    its own factor from 1 -+ off."""
    rng = np.random.default_rng([seed, t, w])
    fields = [pads] + [f"pushers.{p.name}.mu" for p in task.pushers]
    return WorldDeviation(world=tuple((name, task.value(name) * float(rng.uniform(1 - off, 1 + off)))
                                      for name in fields))


def _lands(task, world: WorldDeviation, engine: str):
    """Whether the task's plan (seed 1) lands open loop in `world`; None when it has no plan."""
    plan = plan_task(task, seed=1)
    if not plan.solved:
        return None
    run = run_plan(task, plan, SimulatedArm(engine, world, robot=task.environment.robot), RunOptions())
    return bool(run.success)


def calibration_job(shared, i: int) -> dict:
    specs, worlds, seed, off, engine, pads = shared
    t, w = divmod(i, worlds)
    name, text = specs[t]
    task = parse_task(text, source=name)
    world = hidden_world(task, seed, t, w, off, pads)
    truth = world.world_task(task)
    started = time.perf_counter()
    calibration = calibrate(task, lambda: SimulatedArm(engine, world, robot=task.environment.robot),
                            CalibrationSettings(return_to_start=False, estimate=(pads,)))
    wall = time.perf_counter() - started
    rows = []
    for field, interval in calibration.estimates.items():
        value = truth.value(field)
        rows.append({"field": field, "truth": value, "estimate": interval.value, "low": interval.low,
                     "high": interval.high, "covered": interval.low <= value <= interval.high,
                     "error": (interval.value - value) / value})
    calibrated = calibration.calibrated_task()
    return {"task": task.name, "world": w, "probes": len(calibration.probes), "wall_s": wall,
            "probe_s": sum(p.wall_time_s for p in calibration.probes), "rows": rows,
            "unidentified": calibration.unidentified, "stopped": calibration.stopped,
            "nominal_lands": _lands(task, world, engine), "calibrated_lands": _lands(calibrated, world, engine),
            "truth_lands": _lands(truth, world, engine)}


def runs_job(shared, i: int) -> dict:
    """Task t's nominal plan run `runs` times in hidden world w (each with its own tracker noise,
    0.02 mm / 0.02 deg), then calibration from those reports alone, after 1 and after all."""
    specs, worlds, seed, off, engine, runs = shared
    t, w = divmod(i, worlds)
    name, text = specs[t]
    task = parse_task(text, source=name)
    world = hidden_world(task, seed, t, w, off)
    truth = world.world_task(task)
    plan = plan_task(task, seed=1)
    reports = []
    for k in range(runs if plan.solved else 0):
        noisy = dataclasses.replace(world, tracker_noise_mm=0.02, tracker_noise_deg=0.02, seed=k)
        run = run_plan(task, plan, SimulatedArm(engine, noisy, robot=task.environment.robot), RunOptions())
        if run.fault is None:
            reports.append((f"run {k}", run.as_dict()))
    out = {"task": task.name, "world": w, "runs": len(reports), "contacts": sum(len(r["contacts"]) for _, r in reports)}
    out["unidentified"] = {}
    for label, used in (("one", reports[:1]), ("five", reports[:5]), ("all", reports)):
        if not used:
            continue
        calibration = calibrate_from_runs(task, used, CalibrationSettings())
        out[label] = {field: {"truth": truth.value(field), "low": iv.low, "high": iv.high,
                              "covered": iv.low <= truth.value(field) <= iv.high,
                              "share": iv.half_width / iv.value} for field, iv in calibration.estimates.items()}
        if label == "all":
            out["unidentified"] = calibration.unidentified
    return out


def _runs_summary(results: list) -> list:
    """Per task, world and field: the interval from the first run's report, the first 5 and all;
    then, over every row, coverage and the median half-width after 1, 5 and all runs."""
    def cell(row):
        return f"{row['low']:.3f}-{row['high']:.3f} (+-{row['share']:.0%})" if row else ""

    lines = ["| task | world | runs | contacts | field | truth | from 1 run | from 5 | from all | covered |",
             "|---|---:|---:|---:|---|---:|---|---|---|---|"]
    kinds: dict = {}
    for r in sorted(results, key=lambda r: (r["task"], r["world"])):
        for field, row in (r.get("all") or {}).items():
            one, five = (r.get("one") or {}).get(field), (r.get("five") or {}).get(field)
            lines.append(f"| {r['task']} | {r['world']} | {r['runs']} | {r['contacts']} | {field} | {row['truth']:.3f} "
                         f"| {cell(one)} | {cell(five)} | {cell(row)} | {'yes' if row['covered'] else 'NO'} |")
            kinds.setdefault("pads" if field == "gripper.mu" else "features", []).append((one, five, row))
        for field, why in (r.get("unidentified") or {}).items():
            lines.append(f"| {r['task']} | {r['world']} | {r['runs']} | {r['contacts']} | {field} | | | | "
                         f"not identified: {why} | |")
    lines.append("")
    for kind, rows in kinds.items():
        medians = [float(np.median([row[k]["share"] for row in rows if row[k]])) for k in range(3)]
        lines.append(f"- {kind}: interval from all runs holds the truth in {sum(r[2]['covered'] for r in rows)}/"
                     f"{len(rows)}; median half-width +-{medians[0]:.0%} from 1 run, +-{medians[1]:.0%} from 5, "
                     f"+-{medians[2]:.0%} from all")
    lines.append(f"- fields not identified from all runs: {sum(len(r.get('unidentified') or {}) for r in results)}")
    return lines


def _specs(args) -> list:
    specs = [(name, (TASKS / f"{name}.yaml").read_text()) for name in args.tasks]
    for index in range(args.generated):
        data = generate_task(args.seed, index)
        found = goal_for(data, args.seed, index)
        if found is not None:
            data["goal"] = found[0]
            specs.append((data["name"], yaml.safe_dump(data)))
    return specs


def _summary(results: list, targets=(0.07, 0.10)) -> list:
    lines = ["| task | world | probes | time s | field | truth | estimate | interval | covered | error |",
             "|---|---:|---:|---:|---|---:|---:|---|---|---:|"]
    kinds = {"pads": [], "features": []}
    for r in sorted(results, key=lambda r: (r["task"], r["world"])):
        for row in r["rows"]:
            kinds["features" if row["field"].startswith("pushers.") else "pads"].append(row)
            lines.append(f"| {r['task']} | {r['world']} | {r['probes']} | {r['wall_s']:.0f} | {row['field']} "
                         f"| {row['truth']:.3f} | {row['estimate']:.3f} | {row['low']:.3f}-{row['high']:.3f} "
                         f"| {'yes' if row['covered'] else 'NO'} | {row['error']:+.1%} |")
        for field, why in r["unidentified"].items():
            lines.append(f"| {r['task']} | {r['world']} | {r['probes']} | {r['wall_s']:.0f} | {field} | | | "
                         f"not identified: {why} | | |")
    lines.append("")
    for (kind, rows), target in zip(kinds.items(), targets):
        if rows:
            covered = sum(r["covered"] for r in rows)
            within = sum(abs(r["error"]) <= target for r in rows)
            lines.append(f"- {kind}: interval holds the truth in {covered}/{len(rows)} ({covered / len(rows):.0%}); "
                         f"estimate within {target:.0%} in {within}/{len(rows)}; median |error| "
                         f"{np.median([abs(r['error']) for r in rows]):.1%}")
    probes = [r["probes"] for r in results]
    lines.append(f"- probes: median {np.median(probes):g}, most {max(probes)}; wall time per calibration: median "
                 f"{np.median([r['wall_s'] for r in results]):.0f} s, most {max(r['wall_s'] for r in results):.0f} s")
    for key in ("nominal_lands", "calibrated_lands", "truth_lands"):
        runs = [r[key] for r in results if r[key] is not None]
        lines.append(f"- {key.replace('_', ' ')}: {sum(runs)}/{len(runs)} (no plan: "
                     f"{sum(r[key] is None for r in results)})")
    return lines


def agreement_job(shared, i: int) -> dict:
    """A random probe (of those the model would choose from a random start near a random task's) in
    a random hidden world: the model's verdict in that world and the simulator's slip."""
    specs, seed, off, engine = shared
    rng = np.random.default_rng([seed, 99, i])
    name, text = specs[int(rng.integers(len(specs)))]
    task = parse_task(text, source=name)
    world = hidden_world(task, seed, 1000 + i, 0, off)
    truth = world.world_task(task)
    at = tuple(float(v) for v in np.asarray(task.start) + rng.uniform(-3, 3, 3))
    grid = Unknowns.of(truth, 0.6, 9)
    belief = Belief(grid.pad_axis, grid.pusher_axes)
    probes = candidates(truth, WorldGrid(truth, grid, at), belief, at)
    if not probes:
        return {"task": name, "probe": None}
    probe = probes[int(rng.integers(len(probes)))]
    model = dataclasses.replace(truth, start=at, feature_orientations={}).model  # as the probe holds it
    margins = [model.check(pose_to_si(p), pose_to_si(probe.move), probe.index)
               for p in [probe.start] + probe.poses[:-1]]
    plan_world = probe_world(truth, grid, belief, probe)
    run = run_plan(plan_world, probe_plan(plan_world, probe), SimulatedArm(engine, world, robot=task.environment.robot),
                   RunOptions(guard=None))
    if run.fault is not None:
        return {"task": name, "probe": probe.pusher, "fault": run.fault.reason}
    contact = run.report_or_fault().contacts[0].__dict__
    return {"task": name, "probe": probe.pusher, "stable": all(r.feasible for r in margins),
            "margin": min(float(r.margin) for r in margins), "weight_n": truth.object.mass * 9.81e-3,
            "pads_n": 2 * truth.gripper.mu * truth.gripper.grip_force, "slip_mm": contact["slip_mm"],
            "slip_deg": contact["slip_deg"], "stuck": stuck(contact)}


def _agreement(results: list) -> list:
    done = [r for r in results if r.get("probe") and "fault" not in r]
    lines = ["| model says | sim stuck | sim slipped | slip mm p50 | slip mm p90 | slip mm max |", "|---|---:|---:|---:|---:|---:|"]
    for verdict in (True, False):
        rows = [r for r in done if r["stable"] == verdict]
        if rows:
            slips = np.array([r["slip_mm"] for r in rows])
            lines.append(f"| {'stable' if verdict else 'unstable'} | {sum(r['stuck'] for r in rows)} | "
                         f"{sum(not r['stuck'] for r in rows)} | {np.percentile(slips, 50):.3f} | "
                         f"{np.percentile(slips, 90):.3f} | {slips.max():.3f} |")
    for r in done:
        if r["stable"] != r["stuck"]:
            lines.append(f"| disagrees: {r['task']}, {r['probe']} | margin {r['margin']:+.3f} N | slip "
                         f"{r['slip_mm']:.3f} mm, {r['slip_deg']:.3f} deg | | | |")
    agree = sum(r["stable"] == r["stuck"] for r in done)
    lines += ["", f"- agreement: {agree}/{len(done)} ({agree / max(len(done), 1):.1%}); no safe probe: "
              f"{sum(not r.get('probe') for r in results)}; faults: {sum('fault' in r for r in results)}"]
    return lines


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--tasks", nargs="*", default=list(SHIPPED), help="shipped tasks (data/tasks/NAME.yaml)")
    parser.add_argument("--generated", type=int, default=2, help="generated tasks (generated_task_odds' set --seed)")
    parser.add_argument("--worlds", type=int, default=4, help="hidden worlds per task")
    parser.add_argument("--seed", type=int, default=1)
    parser.add_argument("--off", type=float, default=0.4, help="each mu is off by up to this share")
    parser.add_argument("--engine", default="mujoco")
    parser.add_argument("--agreement", type=int, default=0, metavar="N", help="instead: N random probes' agreement")
    parser.add_argument("--runs", type=int, default=0, metavar="N",
                        help="instead: calibrate from N runs' reports of each task's nominal plan (calibrate --from)")
    parser.add_argument("--estimate", default="gripper.mu", choices=PAD_PRODUCT,
                        help="the pads' quantity the hidden worlds change and calibration estimates (the others "
                             "as the task's)")
    parser.add_argument("--md", type=Path, default=None, help="also write the table here")
    parser.add_argument("--json", type=Path, default=None, help="also write every job's record here")
    add_runner_options(parser)
    args = parser.parse_args()
    runner = runner_of(args)
    specs = _specs(args)
    started = time.perf_counter()
    if args.agreement:
        job, shared, indices = agreement_job, (specs, args.seed, args.off, args.engine), range(args.agreement)
    elif args.runs:
        job, shared, indices = runs_job, (specs, args.worlds, args.seed, args.off, args.engine, args.runs), \
            range(len(specs) * args.worlds)
    else:
        job, shared, indices = calibration_job, (specs, args.worlds, args.seed, args.off, args.engine, args.estimate), \
            range(len(specs) * args.worlds)
    results = []
    lost = []
    for i, result in run_all(job, shared, indices, runner):
        if isinstance(result, (WorkerLost, Exception)):
            lost.append(f"job {i}: {result!r}")
            print(lost[-1], file=sys.stderr)
            continue
        results.append(result)
        print(f"{len(results)}/{len(indices)} done ({time.perf_counter() - started:.0f} s)", file=sys.stderr)
    summary = _agreement if args.agreement else _runs_summary if args.runs else _summary
    lines = summary(results) + [f"- lost: {line}" for line in lost]
    header = [f"`python3 benchmarks/calibrate.py {' '.join(sys.argv[1:])}` on {runner.describe()}, "
              f"{time.perf_counter() - started:.0f} s", ""]
    text = "\n".join(header + lines) + "\n"
    print(text)
    if args.md:
        args.md.write_text(text)
    if args.json:
        args.json.write_text(json.dumps(results, indent=1, default=str) + "\n")


if __name__ == "__main__":
    main()
