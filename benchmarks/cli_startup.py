"""CLI start-up time: `stablepush --help` and a `check` (which loads a task and builds its model),
each run 10 times in a fresh process; prints the median and the fastest (docs/results/cli-startup.md).

    python3 benchmarks/cli_startup.py
"""
import statistics
import subprocess
import time
from pathlib import Path

TASK = Path(__file__).resolve().parent.parent / "data" / "tasks" / "pivoting.yaml"
COMMANDS = {
    "stablepush --help": ["stablepush", "--help"],
    "stablepush check (pivoting, one move)": ["stablepush", "check", str(TASK), "--move", "0", "0", "1"],
}


def main() -> None:
    print("| command | median s | fastest s |")
    print("|---|---:|---:|")
    for label, argv in COMMANDS.items():
        times = []
        for _ in range(10):
            started = time.perf_counter()
            subprocess.run(argv, check=True, capture_output=True)
            times.append(time.perf_counter() - started)
        print(f"| `{label}` | {statistics.median(times):.3f} | {min(times):.3f} |")


if __name__ == "__main__":
    main()
