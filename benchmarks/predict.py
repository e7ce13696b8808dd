"""Odds from predictions (docs/evaluate.md, "Odds from predictions"): how often the model's verdict on
a world and the simulator's agree, row by row of the tables' worlds, and what the
prediction-powered interval gives against the trials' own.

    python3 benchmarks/predict.py rows [TASK.yaml ...] [--trials 100] [--predict 100000] [--plans nominal robust]
                                       [--loop open closed] [--workers 2] [--md OUT.md]
    python3 benchmarks/predict.py validity [--studies 2000] [--md OUT.md]
    python3 benchmarks/predict.py decision [--studies 2000] [--md OUT.md]

`rows`: each task's seed-1 plan (or its robust plan), in the tables' worlds (evaluate_tasks.SPREADS,
judged within 0.5 mm and 0.5 deg): N simulated trials with the model's verdict on each, the
confusion table, the trials' Clopper-Pearson interval, the prediction-powered one with the
model-only worlds, and the width 1,000 plain trials would give at the measured rate; the time the
predictions took.

`validity`: synthetic studies (100 trials, 100,000 model-only worlds; rates 0.99, 0.9, 0.6) with
predictors of every quality: how often the 95% interval holds the rate, for ours and, when the
`ppi-python` package is installed, for its CLT interval (`ppi_mean_ci`, PPI++).

`decision`: synthetic studies of `--target 0.99` (95% confidence, capped at the Wald test's default
cap, 1,276 trials; rates 0.999 to 0.95; 10,000 model-only worlds each, drawn with the same
predictor) decided by Wald's SPRT (the trials alone) and by the prediction-powered test (with the
model's verdicts): the share of studies decided each way, and the trials to decide (median, p90;
an undecided study counts the cap).
"""
import argparse
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
from evaluate_tasks import SPREADS, add_runner_options, progress_line, runner_of
from shipped import shipped_tasks

from stablepush.evaluation import Batch, evaluate, robust_task, with_predictions
from stablepush.evaluation.ppi import clopper_pearson, prediction_powered_rate
from stablepush.evaluation.sequential import PredictionPoweredTest, SequentialTest
from stablepush.plan import plan_task
from stablepush.task import load_task

TOLERANCE = (0.5, 0.5)
PREDICTORS = {
    "exact": lambda y, rng: y,
    "noisy (10% flipped)": lambda y, rng: y ^ (rng.random(y.size) < 0.1),
    "biased toward landing": lambda y, rng: y | (rng.random(y.size) < 0.5),
    # as the tables' model (results/predict_rows.md): never says lands of a miss, calls some landings misses
    "pessimistic (20% of landings called misses)": lambda y, rng: y & (rng.random(y.size) >= 0.2),
    "always wrong": lambda y, rng: ~y,
}


def rows(args) -> list:
    runner = runner_of(args)
    lines = ["| task | plan | loop | landed | model said lands: landed / missed | said misses: landed / missed "
             "| agree | trials' 95% CI | with predictions | 1,000 plain trials' width | predictions s |",
             "|---|---|---|---:|---|---|---:|---|---|---:|---:|"]
    print("\n".join(lines), flush=True)
    for path in args.tasks or shipped_tasks():
        nominal = load_task(path)
        for kind in args.plans:
            task = robust_task(nominal, SPREADS) if kind == "robust" else nominal
            plan = plan_task(task, seed=1)
            if not plan.solved:
                continue
            for loop in args.loop:
                batch = Batch(task=task, plan=plan, spreads=SPREADS, seed=args.seed, closed_loop=loop == "closed",
                              tolerance=TOLERANCE)
                evaluation = evaluate(batch, args.trials, runner, progress=progress_line(task.name, loop, args.trials))
                started = time.perf_counter()
                evaluation = with_predictions(evaluation, args.predict)
                took = time.perf_counter() - started
                p = evaluation.prediction
                a, s = p.agreement, evaluation.summary()
                low, high = clopper_pearson(s["successes"], s["judged"], 0.05)
                rate = s["successes"] / s["judged"]
                wide = clopper_pearson(round(rate * 1000), 1000, 0.05)
                line = (f"| {task.name} | {kind} | {loop} | {s['successes']}/{s['judged']} | {a['lands_landed']} / "
                        f"{a['lands_missed']} | {a['misses_landed']} / {a['misses_missed']} "
                        f"| {(a['lands_landed'] + a['misses_missed']) / p.trials:.1%} | {low:.1%}-{high:.1%} "
                        f"({high - low:.1%}) | {p.low:.1%}-{p.high:.1%} ({p.high - p.low:.1%}; model {p.predicted_rate:.2%}) "
                        f"| {wide[1] - wide[0]:.1%} | {took:.1f} |")
                lines.append(line)
                print(line, flush=True)
    return lines


def validity(args) -> list:
    try:
        from ppi_py import ppi_mean_ci
    except ImportError:
        ppi_mean_ci = None
        print("ppi-python is not installed: its CLT interval is not compared", file=sys.stderr)
    rng = np.random.default_rng(args.seed)
    lines = ["| predictor | rate | studies | ours holds | ours mean width | ppi_mean_ci holds | its mean width |",
             "|---|---:|---:|---:|---:|---:|---:|"]
    for name, predictor in PREDICTORS.items():
        for rate in (0.99, 0.9, 0.6):
            held, widths, clt_held, clt_widths = 0, [], 0, []
            for _ in range(args.studies):
                y = rng.random(100) < rate
                f = predictor(y, rng)
                f_unlabelled = predictor(rng.random(args.predict) < rate, rng)
                ours = prediction_powered_rate(y, f, f_unlabelled)
                held += ours.low <= rate <= ours.high
                widths.append(ours.high - ours.low)
                if ppi_mean_ci is not None:
                    lo, hi = ppi_mean_ci(y.astype(float), f.astype(float), f_unlabelled.astype(float), alpha=0.05)
                    lo, hi = float(np.ravel(lo)[0]), float(np.ravel(hi)[0])
                    clt_held += lo <= rate <= hi
                    clt_widths.append(hi - lo)
            clt = (f"{clt_held / args.studies:.1%} | {np.mean(clt_widths):.3f}" if ppi_mean_ci is not None else "- | -")
            line = f"| {name} | {rate:g} | {args.studies} | {held / args.studies:.1%} | {np.mean(widths):.3f} | {clt} |"
            lines.append(line)
            print(line, flush=True)
    return lines


DECISION_RATES = (0.999, 0.995, 0.99, 0.98, 0.95)


def decision(args) -> list:
    wald = SequentialTest(0.99)
    cap = wald.default_cap()
    lines = ["| predictor | rate | studies | Wald: above / below / undecided | trials median / p90 "
             "| with predictions: above / below / undecided | trials median / p90 |",
             "|---|---:|---:|---|---:|---|---:|"]
    for name, predictor in PREDICTORS.items():
        for rate in DECISION_RATES:
            rng = np.random.default_rng([args.seed, round(rate * 1000)])
            ours, theirs = [], []
            for _ in range(args.studies):
                y = rng.random(cap) < rate
                f = predictor(y, rng)
                test = PredictionPoweredTest.of(wald, predictor(rng.random(args.predict) < rate, rng))
                ours.append(test.first_decision(y, f))
                theirs.append(wald.first_decision(y))
            line = f"| {name} | {rate:g} | {args.studies} | {_decided(theirs)} | {_decided(ours)} |"
            lines.append(line)
            print(line, flush=True)
    return lines


def _decided(results) -> str:
    verdicts = [v for v, _ in results]
    shares = " / ".join(f"{verdicts.count(v) / len(results):.1%}" for v in ("above", "below", "undecided"))
    n = np.array([k for _, k in results])
    return f"{shares} | {np.median(n):.0f} / {np.percentile(n, 90):.0f}"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("what", choices=("rows", "validity", "decision"))
    parser.add_argument("tasks", nargs="*", type=Path)
    parser.add_argument("--trials", type=int, default=100)
    parser.add_argument("--predict", type=int, default=100_000)
    parser.add_argument("--studies", type=int, default=2000)
    parser.add_argument("--seed", type=int, default=1)
    parser.add_argument("--plans", nargs="+", choices=("nominal", "robust"), default=["nominal", "robust"])
    parser.add_argument("--loop", nargs="+", choices=("open", "closed"), default=["open", "closed"])
    parser.add_argument("--md", type=Path, default=None, help="also write the table to this markdown file")
    add_runner_options(parser, workers=2)
    args = parser.parse_args()
    if args.what in ("validity", "decision"):
        args.predict = min(args.predict, 10_000)  # the synthetic predictions cost nothing but memory
    lines = {"rows": rows, "validity": validity, "decision": decision}[args.what](args)
    if args.md:
        command = " ".join(["python3", "benchmarks/predict.py", *sys.argv[1:]])
        commit = subprocess.run(["git", "rev-parse", "--short", "HEAD"], capture_output=True, text=True).stdout.strip()
        args.md.write_text(f"Measured at commit {commit or '(unknown)'} with `{command}`\n\n" + "\n".join(lines) + "\n")


if __name__ == "__main__":
    main()
