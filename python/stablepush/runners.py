"""Where a batch of independent jobs runs: in this process, on local worker processes (the standard
library's pool), or on Ray (a local instance, or a cluster by address). `stablepush evaluate` runs
its trials here, `stablepush reach` its cells and `stablepush bench --workers/--ray` its planning
runs.

A job is `job(shared, i)` for i in the batch's indices: a module-level function (so that workers
can import it), `shared` picklable and sent once per worker (Ray: once per cluster, `ray.put`).
Results arrive as they finish, as (i, result); a job whose worker died arrives as (i, WorkerLost).
On Ray a job lost with its worker or node (not one that raised) is run again, up to RAY_TASK_RETRIES
times, on the nodes left, and arrives once. `this_node()` says, inside a job, which node runs it.
"""
from __future__ import annotations

import contextlib
import os
import socket
import time
from concurrent.futures import FIRST_COMPLETED, ProcessPoolExecutor, wait
from dataclasses import dataclass, field
from typing import Any, Callable, Iterable, Iterator, Optional, Tuple

from stablepush.errors import RunnerError, SettingError
from stablepush.extras import require

Job = Callable[[Any, int], Any]
# The most local workers a Runner may name (the CLI's --workers bound): a batch still starts no more
# than max_workers() processes.
MAX_RUNNER_WORKERS = 1024
# How long joining a Ray cluster may wait for its head to answer: Ray itself retries for minutes.
RAY_CONNECT_TIMEOUT_S = 5.0
# After this long with no job finished, and again after each as long, Runner.on_wait is told why.
RAY_QUIET_S = 30.0
# Local worker processes per CPU at most: each job keeps a CPU busy (a simulation, a search), so
# more only share the CPUs (and each costs a process's memory); `--workers 1000` started 1,000.
WORKERS_PER_CPU = 2
# How many times Ray runs a job again whose worker process or node was lost (a job that raises is
# not run again: its error is its result). Each index still arrives once.
RAY_TASK_RETRIES = 3
# Ray's own settings for a local instance it starts for a batch (never for a cluster joined: its
# config is its owner's). Ray lowers its workers' priority to nice 15 (`worker_niceness`), which
# on a machine other processes load leaves them about 1/28 of a CPU's share each (Linux's weights
# for nice 15 and 0): on 2 cores with 10 busy loops a trial's worker ran at 0.7% of a CPU and 4
# trials finished none in 400 s. 0 keeps them at this process's priority, as --workers's are.
RAY_LOCAL_CONFIG = {"worker_niceness": 0}
# The node the Ray job running in this process is on ("ray:IP/NODE_ID"); None outside a Ray job.
_ray_node: Optional[str] = None


def check_ray_address(address: Optional[str]) -> Optional[str]:
    """`address` if Ray can take it as where a cluster is: None (a local instance), "auto" or "local"
    (as `ray.init` reads them), or HOST:PORT of a running head, optionally as ray://HOST:PORT (Ray
    Client); a ValueError that says which otherwise."""
    if address is None or address in ("auto", "local"):
        return address
    host, port = _host_port(address)
    if not host or not (port.isascii() and port.isdigit()) or not 0 < int(port) < 65536:  # "٦٣٧٩" is no port
        raise SettingError("ray_address", f"expected HOST:PORT of a running Ray head (e.g. 10.0.0.5:6379, or "
                                          f"ray://HOST:10001), 'auto' or 'local'; got {address!r}")
    return address


def _host_port(address: str) -> Tuple[str, str]:
    bare = address[len("ray://"):] if address.startswith("ray://") else address
    host, _, port = bare.rpartition(":")
    return host.strip("[]"), port


@dataclass(frozen=True)
class Runner:
    """Where the jobs run: `workers` local processes (1: in this process), or Ray when `ray` is set
    (`ray_address` None: a local instance started for the batch and stopped after it)."""

    workers: int = 1
    ray: bool = False
    ray_address: Optional[str] = None
    # Told what Ray is waiting for when no job has finished for RAY_QUIET_S (a line of text): a
    # study on a starved machine otherwise says nothing for minutes. Not part of the value.
    on_wait: Optional[Callable[[str], None]] = field(default=None, compare=False, repr=False)

    def __post_init__(self):
        if isinstance(self.workers, bool) or not isinstance(self.workers, int) or self.workers < 1:
            raise SettingError("workers", f"must be a whole number from 1, got {self.workers!r:.40}")
        if self.workers > MAX_RUNNER_WORKERS:
            raise SettingError("workers", f"must be at most {MAX_RUNNER_WORKERS}, got {self.workers}")
        if not isinstance(self.ray, bool):
            raise TypeError(f"ray must be True or False, got {self.ray!r:.40}")
        if self.ray_address is not None and not isinstance(self.ray_address, str):
            raise TypeError(f"ray_address must be a string or None, got {type(self.ray_address).__name__}")
        check_ray_address(self.ray_address)
        if self.on_wait is not None and not callable(self.on_wait):
            raise TypeError(f"on_wait must be callable, got {type(self.on_wait).__name__}")

    def processes(self, jobs: int) -> int:
        """How many local processes a batch of `jobs` runs on: `workers`, but no more than the jobs
        nor than max_workers()."""
        return max(1, min(self.workers, jobs, max_workers()))

    def describe(self, jobs: Optional[int] = None) -> str:
        """Where the jobs run, in words; with `jobs`, the processes a batch of them runs on."""
        if self.ray:
            return f"Ray ({self.ray_address or 'local instance'})"
        workers = self.processes(self.workers if jobs is None else jobs)
        return "this process" if workers <= 1 else f"{workers} local processes"


def default_workers() -> int:
    """The machine's CPU count."""
    return max(1, os.cpu_count() or 1)


def max_workers() -> int:
    """The most local worker processes a batch starts: WORKERS_PER_CPU per CPU."""
    return WORKERS_PER_CPU * default_workers()


@dataclass(frozen=True)
class WorkerLost:
    """A job whose worker died (or that Ray lost) before it returned."""

    why: str


def this_node() -> str:
    """Where the job calling it runs: "ray:IP/NODE_ID" on a Ray node (its IP and Ray's node id, as
    `ray status` and `ray list nodes` name it), else "local:HOSTNAME" (this process or a local
    worker process)."""
    return _ray_node or f"local:{socket.gethostname()}"


def _on_ray_node(job: Job, shared: Any, i: int) -> Any:
    """job(shared, i) as a Ray task, with this_node() naming the node it runs on."""
    ray = require("ray", "a Ray task")
    global _ray_node
    _ray_node = f"ray:{ray.util.get_node_ip_address()}/{ray.get_runtime_context().get_node_id()}"
    return job(shared, i)


def run_all(job: Job, shared: Any, indices: Iterable[int], runner: Runner) -> Iterator[Tuple[int, Any]]:
    """Run job(shared, i) for every index on `runner`, yielding (i, result) as each finishes.
    Closing the iterator (or Ctrl-C in the caller) cancels the jobs not yet started."""
    indices = list(indices)
    if runner.ray:
        return _ray(job, shared, indices, runner.ray_address, runner.on_wait)
    workers = runner.processes(len(indices))
    if workers > 1:
        return _processes(job, shared, indices, workers)
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


def _ray(job: Job, shared: Any, indices: list, address: Optional[str],
         on_wait: Optional[Callable[[str], None]] = None) -> Iterator[Tuple[int, Any]]:
    ray = require("ray", "--ray")

    started_here = not ray.is_initialized()
    if started_here:
        _join_ray(ray, address)
    try:
        # Retried where its worker or node was lost (the job ran again on a node left), not where it raised.
        remote = ray.remote(max_retries=RAY_TASK_RETRIES, retry_exceptions=False)(_on_ray_node)
        shared_ref = ray.put(shared)
        name = getattr(job, "__name__", "job")
        refs = {remote.options(name=f"{name}[{i}]").remote(job, shared_ref, i): i for i in indices}
        began = quiet_since = time.monotonic()
        try:
            while refs:
                done, _ = ray.wait(list(refs), num_returns=1, timeout=RAY_QUIET_S if on_wait else None)
                if not done:
                    if on_wait is not None and time.monotonic() - quiet_since >= RAY_QUIET_S:
                        on_wait(ray_waiting(ray, len(indices) - len(refs), len(indices), time.monotonic() - began))
                        quiet_since = time.monotonic()
                    continue
                quiet_since = time.monotonic()
                for ref in done:
                    i = refs.pop(ref)
                    try:
                        result = ray.get(ref)
                    except ray.exceptions.RayError as exc:  # lost RAY_TASK_RETRIES + 1 times, or it raised
                        result = WorkerLost(f"{type(exc).__name__}: {str(exc)[:200]}")
                    yield i, result
        except BaseException:
            for ref in refs:
                ray.cancel(ref, force=True)
            raise
    finally:
        if started_here:
            ray.shutdown()


# The call that tells a Ray head from anything else that accepts a connection: the method every
# Ray client asks a head's GCS first (its cluster id), made over gRPC (HTTP/2, by h2).
RAY_HEAD_METHOD = "/ray.rpc.NodeInfoGcsService/GetClusterId"
# A Ray Client server (ray://) is asked a method no server has: a gRPC server answers it with
# status 12, UNIMPLEMENTED, which is enough to tell it from a proxy or another kind of server.
GRPC_PROBE_METHOD = "/stablepush.Probe/NoSuchMethod"
GRPC_OK, GRPC_UNIMPLEMENTED = 0, 12


def ray_waiting(ray, finished: int, total: int, elapsed_s: float) -> str:
    """What a batch on Ray is waiting for, in a line: how many jobs finished, and whether Ray's
    CPUs are all taken (the jobs are running, slowly) or some are free (Ray is still starting the
    worker processes that would take them: slow on a loaded machine)."""
    try:
        cpus, free = ray.cluster_resources().get("CPU", 0.0), ray.available_resources().get("CPU", 0.0)
    except Exception:  # noqa: BLE001 - a report must not end the batch; Ray raises many kinds
        return f"Ray: {finished} of {total} jobs finished after {elapsed_s:.0f} s (its resources cannot be read)"
    if free > 0:
        why = (f"{free:g} of its {cpus:g} CPUs are free, so it is still starting the worker processes that take "
               f"the jobs (a loaded machine starts them slowly; --workers runs without Ray)")
    else:
        why = f"all {cpus:g} of its CPUs are running jobs"
    return (f"Ray: {finished} of {total} jobs finished after {elapsed_s:.0f} s, none in the last {RAY_QUIET_S:g} s: "
            f"{why}")


def probe_ray_head(address: Optional[str]) -> None:
    """RunnerError unless a Ray head answers at a HOST:PORT address within RAY_CONNECT_TIMEOUT_S:
    its GCS returns the cluster id over gRPC (for ray://HOST:PORT, a gRPC server answers at all).
    ray.init waits minutes on anything else that accepts the connection (a proxy, another server).
    None, "auto" and "local" are left to ray.init."""
    if address is None or address in ("auto", "local"):
        return
    host, port = _host_port(check_ray_address(address) or address)
    advice = "start one there (`ray start --head`), or run on a local instance"
    client = address.startswith("ray://")
    try:
        status = grpc_status(host, int(port), GRPC_PROBE_METHOD if client else RAY_HEAD_METHOD,
                             RAY_CONNECT_TIMEOUT_S)
    except socket.timeout:
        raise RunnerError(f"{address} accepts a connection but answers nothing within {RAY_CONNECT_TIMEOUT_S:g} s: "
                          f"not a Ray head (its GCS answers gRPC at once): {advice}") from None
    except OSError as exc:
        raise RunnerError(f"no Ray head answers at {address} ({exc.strerror or type(exc).__name__}): "
                          f"{advice}") from None
    expected = (GRPC_OK, GRPC_UNIMPLEMENTED) if client else (GRPC_OK,)
    if status not in expected:
        what = "no gRPC server" if status is None else f"a gRPC server without Ray's GCS (status {status})"
        raise RunnerError(f"{address} answers, but as {what}, not a Ray head: {advice}")


def grpc_status(host: str, port: int, method: str, timeout: float) -> Optional[int]:
    """The grpc-status a server at host:port returns for an empty unary call of `method`, or None
    when it does not answer as a gRPC server (HTTP status not 200, not application/grpc, no
    status). socket.timeout when it answers nothing within `timeout` s; OSError when it cannot
    be reached."""
    require("h2", "--ray HOST:PORT (checking that a Ray head answers there)")
    from h2 import events as h2_events
    from h2.connection import H2Connection
    from h2.exceptions import ProtocolError

    with socket.create_connection((host, port), timeout=timeout) as sock:
        sock.settimeout(timeout)
        conn = H2Connection()
        conn.initiate_connection()
        stream = conn.get_next_available_stream_id()
        conn.send_headers(stream, [(":method", "POST"), (":scheme", "http"), (":path", method),
                                   (":authority", f"{host}:{port}"), ("content-type", "application/grpc"),
                                   ("te", "trailers")])
        conn.send_data(stream, bytes(5), end_stream=True)  # one message: uncompressed, 0 bytes (an empty request)
        sock.sendall(conn.data_to_send())
        headers: dict = {}
        while True:
            data = sock.recv(65536)
            if not data:
                return _grpc_code(headers)
            try:
                events = conn.receive_data(data)
            except ProtocolError:
                return None
            for event in events:
                if isinstance(event, (h2_events.ResponseReceived, h2_events.TrailersReceived)):
                    headers.update((bytes(k).decode(errors="replace"), bytes(v).decode(errors="replace"))
                                   for k, v in event.headers)
                if isinstance(event, (h2_events.StreamEnded, h2_events.StreamReset, h2_events.ConnectionTerminated)):
                    return _grpc_code(headers)
            sock.sendall(conn.data_to_send())


def _grpc_code(headers: dict) -> Optional[int]:
    if headers.get(":status") != "200" or not headers.get("content-type", "").startswith("application/grpc"):
        return None
    code = headers.get("grpc-status")
    return int(code) if code is not None and code.isdigit() else None


def _join_ray(ray, address: Optional[str]) -> None:
    """ray.init, with a head that does not answer (or an address Ray refuses) a RunnerError at once,
    and any other failure to start or join it a RunnerError too, naming the address: a local
    instance on a loaded machine times out with a bare Exception ("The current node timed out
    during startup", after Ray's own 30 s), which was an internal error."""
    probe_ray_head(address)
    options = dict(address=address, include_dashboard=False, logging_level="ERROR", log_to_driver=False)
    try:
        if address in (None, "local"):
            try:
                ray.init(**options, _system_config=dict(RAY_LOCAL_CONFIG))  # Ray adds this session's to it
            except ValueError as exc:
                # No address joins a cluster if RAY_ADDRESS or `ray start` names one, and Ray
                # refuses a config for it: that cluster keeps its own.
                if "_system_config" not in str(exc):
                    raise
                ray.init(**options)
        else:
            ray.init(**options)
    except Exception as exc:  # noqa: BLE001 - Ray raises bare Exceptions; whatever it is, Ray did not start
        with contextlib.suppress(Exception):  # noqa: BLE001 - what it did start, it stops
            ray.shutdown()
        text = " ".join(str(exc).split())[:300] or type(exc).__name__
        where, option = (f"Ray at {address}", f"--ray {address}") if address else ("a local Ray instance", "--ray")
        raise RunnerError(f"cannot start or join {where} ({option}): {text}") from None
