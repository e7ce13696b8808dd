"""Every plan of the shipped tasks over seeds, written exactly (poses as repr, pushers, margins,
outcome, stable-push tests), so that two builds can be compared byte for byte after a change that
must not change any plan:

    python3 benchmarks/plan_fingerprint.py after.json [--seeds 30]
    cmp before.json after.json

To fingerprint another build, run it with PYTHONPATH pointing at a `pip install --target DIR .` of
that commit.
"""
import argparse
import json
from pathlib import Path

from shipped import shipped_tasks

from stablepush.plan import plan_task
from stablepush.task import load_task


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("out", type=Path, help="JSON file to write")
    parser.add_argument("--seeds", type=int, default=30, help="seeds 1..N (default 30)")
    args = parser.parse_args()
    tasks = shipped_tasks()
    out = {}
    for path in tasks:
        task = load_task(path)
        for seed in range(1, args.seeds + 1):
            plan = plan_task(task, seed=seed)
            out[f"{task.name}:{seed}"] = {
                "outcome": plan.outcome, "checks": plan.stats["feasibility_checks"],
                "waypoints": [[repr(w.x), repr(w.z), repr(w.theta), w.pusher, repr(w.margin)] for w in plan.waypoints],
            }
    args.out.write_text(json.dumps(out, sort_keys=True))
    print(f"{len(out)} plans written to {args.out}")


if __name__ == "__main__":
    main()
