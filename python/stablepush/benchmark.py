"""Benchmarks of the stable-push test: median time per check, by contact case.

Queries run through `StablePushModel.check_batch` (one C++ loop, no Python per check) in batches;
each batch gives a time per check, and the median over batches is reported.
"""
from __future__ import annotations

import math
import time
from dataclasses import dataclass
from typing import Callable, Dict, Optional

import numpy as np

from stablepush.task import MM, Task


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
        pad = np.array(task.pads[0][0]) * MM
        arm = pad[None, :] - q[:, :2]
        dq = np.column_stack([-w * arm[:, 1], w * arm[:, 0], w])
    else:
        dq = np.column_stack([rng.uniform(-1, 1, n) * MM, rng.uniform(-1, 1, n) * MM, np.radians(rng.uniform(-1, 1, n))])
    return q, dq


def bench_checks(
    task: Task,
    checks: int = 200_000,
    batch: int = 2_000,
    seed: int = 0,
    progress: Optional[Callable[[int], None]] = None,
) -> Dict[str, CheckTiming]:
    """Median time per stable-push test for the all-sliding and the sticking case, cycling
    through the task's pushers."""
    model = task.build_model()
    rng = np.random.default_rng(seed)
    out = {}
    for case, sticking in (("all_sliding", False), ("sticking", True)):
        per_check, feasible, exact, done = [], 0, 0, 0
        while done < checks:
            q, dq = _queries(task, rng, batch, sticking)
            pusher = (done // batch) % len(task.pushers)
            start = time.perf_counter()
            f, _, e = model.check_batch(q, dq, pusher)
            per_check.append((time.perf_counter() - start) / batch)
            feasible += int(f.sum())
            exact += int(e.sum())
            done += batch
            if progress:
                progress(batch)
        out[case] = CheckTiming(
            case=case,
            median_us=float(np.median(per_check)) * 1e6,
            min_us=float(np.min(per_check)) * 1e6,
            checks=done,
            feasible_fraction=feasible / done,
            exact_fraction=exact / done,
        )
    return out
