"""Median time per stable-push test on the paper's square prism (three pushers).

    python benchmarks/bench_checks.py [TASK.yaml] [-n CHECKS]

Same measurement as `stablepush bench --checks`; kept here so the figure in docs/results/planning.md can be
reproduced without the CLI.
"""
import argparse
from pathlib import Path

from stablepush.plan.benchmark import bench_checks
from stablepush.task import load_task

ROOT = Path(__file__).resolve().parent.parent

parser = argparse.ArgumentParser()
parser.add_argument("task", nargs="?", default=ROOT / "data/tasks/horizontal-offset-low-mu.yaml")
parser.add_argument("-n", type=int, default=200_000)
args = parser.parse_args()
for t in bench_checks(load_task(args.task), checks=args.n).values():
    print(f"{t.case:<12} median {t.median_us:.3f} us  min {t.min_us:.3f} us  over {t.checks} checks, "
          f"{t.exact_fraction:.3%} decided exactly")
