"""Nominal against robust plans on the simulated arm: every shipped task (and data/tasks/more),
planned once with the task's nominal friction and once with `uncertainty: {pad_mu: 0.15,
pusher_mu: 0.15}` (seed 1, the task's own switch budget, 20 s), each run open loop in worlds whose
pad and feature mu are 0.85, 1 and 1.15 times the task's. Prints the table of docs/results/planner-robust-on-arm.md.

    python3 benchmarks/robust_execution.py      # about 4 minutes
"""
import time

import yaml
from shipped import shipped_tasks

from stablepush.execution.run import RunOptions, run_plan
from stablepush.plan import check_plan, plan_task
from stablepush.sim.deviation import WorldDeviation
from stablepush.sim.local_arm import SimulatedArm
from stablepush.task import parse_task

UNCERTAINTY = {"pad_mu": 0.15, "pusher_mu": 0.15}
WORLDS = (0.85, 1.0, 1.15)


def main() -> None:
    paths = shipped_tasks()
    print("| task | plan | pushes | contacts | planning | least margin N | " +
          " | ".join(f"world μ x{s:g}: error mm / deg" for s in WORLDS) + " |")
    print("|---|---|---|---|---|---|" + "---|" * len(WORLDS))
    for path in paths:
        data = yaml.safe_load(path.read_text())
        if data.get("uncertainty"):
            continue  # already a robust variant of another task
        for label, uncertainty in (("nominal", {}), ("robust ±15% μ", UNCERTAINTY)):
            data["uncertainty"] = uncertainty
            data["planner"] = dict(data.get("planner", {}), time_limit=20)
            task = parse_task(yaml.safe_dump(data), str(path))
            started = time.perf_counter()
            plan = plan_task(task, seed=1)
            took = time.perf_counter() - started
            if not plan.solved:
                print(f"| {task.name} | {label} | not solved ({plan.outcome}) in {took:.0f} s |", flush=True)
                continue
            check_plan(task, plan)
            errors = []
            for scale in WORLDS:
                report = run_plan(task, plan, SimulatedArm(deviation=WorldDeviation(mu_scale=scale)), RunOptions()).report_or_fault()
                errors.append(f"{report.final_error['distance']:.2f} / {report.final_error['theta']:+.2f}")
            print(
                f"| {task.name} | {label} | {plan.stats['pushes']} | {' → '.join(plan.pusher_sequence)} "
                f"| {took * 1e3:.0f} ms | {min(w.margin for w in plan.waypoints[1:]):.3f} | "
                + " | ".join(errors)
                + " |",
                flush=True,
            )


if __name__ == "__main__":
    main()
