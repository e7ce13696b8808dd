"""Where a batch of independent jobs runs: in this process, on local worker processes (the standard
library's pool), or on Ray (a local instance, or a cluster by address). `stablepush evaluate` runs
its trials here, `stablepush reach` its cells and `stablepush bench --workers/--ray` its planning
runs.

A job is `job(shared, i)` for i in the batch's indices: a module-level function (so that workers
can import it), `shared` picklable and sent once per worker (Ray: once per cluster, `ray.put`).
Results arrive as they finish, as (i, result); a job whose worker died arrives as (i, WorkerLost).
"""
from __future__ import annotations

import os
from concurrent.futures import FIRST_COMPLETED, ProcessPoolExecutor, wait
from dataclasses import dataclass
from typing import Any, Callable, Iterable, Iterator, Optional, Tuple

Job = Callable[[Any, int], Any]


@dataclass(frozen=True)
class Runner:
    """Where the jobs run: `workers` local processes (1: in this process), or Ray when `ray` is set
    (`ray_address` None: a local instance started for the batch and stopped after it)."""

    workers: int = 1
    ray: bool = False
    ray_address: Optional[str] = None

    def describe(self) -> str:
        if self.ray:
            return f"Ray ({self.ray_address or 'local instance'})"
        return "this process" if self.workers <= 1 else f"{self.workers} local processes"


def default_workers() -> int:
    """The machine's CPU count."""
    return max(1, os.cpu_count() or 1)


@dataclass(frozen=True)
class WorkerLost:
    """A job whose worker died (or that Ray lost) before it returned."""

    why: str


def run_all(job: Job, shared: Any, indices: Iterable[int], runner: Runner) -> Iterator[Tuple[int, Any]]:
    """Run job(shared, i) for every index on `runner`, yielding (i, result) as each finishes.
    Closing the iterator (or Ctrl-C in the caller) cancels the jobs not yet started."""
    indices = list(indices)
    if runner.ray:
        return _ray(job, shared, indices, runner.ray_address)
    if runner.workers > 1 and len(indices) > 1:
        return _processes(job, shared, indices, runner.workers)
    return ((i, job(shared, i)) for i in indices)


def _processes(job: Job, shared: Any, indices: list, workers: int) -> Iterator[Tuple[int, Any]]:
    """A worker that dies takes its job with it (WorkerLost); the rest go on in a new pool."""
    from concurrent.futures.process import BrokenProcessPool

    pending = list(indices)
    while pending:
        with ProcessPoolExecutor(max_workers=workers) as pool:
            futures = {pool.submit(job, shared, i): i for i in pending}
            try:
                while futures:
                    done, _ = wait(futures, return_when=FIRST_COMPLETED)
                    for future in done:
                        i = futures.pop(future)
                        pending.remove(i)
                        try:
                            result = future.result()
                        except BrokenProcessPool:
                            yield i, WorkerLost("the worker process died")
                            raise
                        yield i, result
            except BrokenProcessPool:
                continue  # the jobs still pending start again in a new pool
            except BaseException:
                for future in futures:
                    future.cancel()
                raise


def _ray(job: Job, shared: Any, indices: list, address: Optional[str]) -> Iterator[Tuple[int, Any]]:
    import ray

    started_here = not ray.is_initialized()
    if started_here:
        ray.init(address=address, include_dashboard=False, logging_level="ERROR", log_to_driver=False)
    try:
        remote = ray.remote(max_retries=0)(job)
        shared_ref = ray.put(shared)
        refs = {remote.remote(shared_ref, i): i for i in indices}
        try:
            while refs:
                done, _ = ray.wait(list(refs), num_returns=1)
                for ref in done:
                    i = refs.pop(ref)
                    try:
                        result = ray.get(ref)
                    except ray.exceptions.RayError as exc:  # the worker died, or Ray lost the task
                        result = WorkerLost(f"{type(exc).__name__}: {str(exc)[:200]}")
                    yield i, result
        except BaseException:
            for ref in refs:
                ray.cancel(ref, force=True)
            raise
    finally:
        if started_here:
            ray.shutdown()
