"""`evaluate --ray ADDRESS` and `reach --ray ADDRESS` on a Ray cluster of two nodes, started with
`ray start` on this machine as a lab starts one (tests/ray_cluster.py): the same outcomes as on one
local worker, each record naming the node it ran on, and a node lost mid-study (its raylet killed
while a trial runs on it) costs no trial and counts none twice: Ray runs the lost trial again on
the node left (stablepush.runners.RAY_TASK_RETRIES)."""
import json
import os
import signal
import sys
import threading
import time

import pytest
from click.testing import CliRunner

pytest.importorskip("ray", reason="Ray is not installed (the [ray] extra)")
if not sys.platform.startswith("linux"):
    pytest.skip("the cluster's processes are found through /proc", allow_module_level=True)

from stablepush.evaluation import Batch, Spreads, evaluate  # noqa: E402
from stablepush.plan import check_plan, plan_task  # noqa: E402
from stablepush.runners import Runner, WorkerLost, run_all  # noqa: E402
from stablepush_cli.main import cli  # noqa: E402

from conftest import TASKS, shipped  # noqa: E402
from ray_cluster import RAY_CLI, Cluster, attempts, raises, worker_dies_first_time  # noqa: E402

pytestmark = [pytest.mark.slow,
              pytest.mark.skipif(not RAY_CLI.exists(), reason=f"no `ray` command beside {sys.executable}")]

TASK = str(TASKS / "horizontal-offset-low-mu.yaml")
VARY = ["--vary", "pad_mu=0.15", "--vary", "grip_force=0.1", "--feature-error", "0.3", "0.3"]
SPREADS = Spreads(vary={"pad_mu": 0.15, "grip_force": 0.1}, feature_error=(0.3, 0.3))
TRIALS = 6
NOT_OUTCOMES = ("wall_s", "node")  # where and how fast a trial ran; everything else is its outcome


@pytest.fixture(scope="module")
def cluster():
    """A head and one node joined to it, one CPU each, shared by the tests that lose no node."""
    started = Cluster(nodes=2, num_cpus=1)
    yield started
    started.stop()


@pytest.fixture(scope="module")
def one_worker(tmp_path_factory):
    """The study's trials on one local worker (`--workers 1`), as `evaluate --json` writes them."""
    out = tmp_path_factory.mktemp("local") / "local.json"
    result = CliRunner().invoke(cli, ["evaluate", TASK, "--trials", str(TRIALS), *VARY, "--workers", "1",
                                      "--json", str(out), "--quiet"])
    assert result.exit_code == 0, result.output
    return json.loads(out.read_text())["trials"]


def _outcome(record: dict) -> dict:
    return {k: v for k, v in record.items() if k not in NOT_OUTCOMES}


def test_evaluate_on_a_two_node_cluster_gives_the_outcomes_of_one_worker_and_names_each_trials_node(
        cluster, one_worker, tmp_path):
    out, table = tmp_path / "ray.json", tmp_path / "ray.csv"
    result = CliRunner().invoke(cli, ["evaluate", TASK, "--trials", str(TRIALS), *VARY, "--ray", cluster.address,
                                      "--json", str(out), "--csv", str(table), "--quiet"])
    assert result.exit_code == 0, result.output
    data = json.loads(out.read_text())
    assert [_outcome(t) for t in data["trials"]] == [_outcome(t) for t in one_worker]
    assert len({json.dumps(t["world"], sort_keys=True) for t in one_worker}) == TRIALS  # worlds of their own
    nodes = {t["node"] for t in data["trials"]}  # "ray:IP/NODE_ID": both nodes ran trials
    assert {n.rsplit("/", 1)[1] for n in nodes} == {node.node_id() for node in cluster.nodes}
    assert all(n.startswith("ray:") for n in nodes)
    assert data["summary"]["nodes"] == {n: sum(t["node"] == n for t in data["trials"]) for n in nodes}
    assert "over 2 nodes" in result.output
    assert {t["node"] for t in one_worker} == {f"local:{os.uname().nodename}"}
    header, *rows = table.read_text().splitlines()
    assert header.split(",")[-1] == "node" and {row.rsplit(",", 1)[1] for row in rows} == nodes


def test_a_job_lost_with_its_worker_is_run_again_and_one_that_raises_is_not(cluster, tmp_path):
    """Each index arrives once either way: a lost job's result when it ran again, a raising job's
    error (WorkerLost, which evaluate records as a crash) after one run."""
    runner = Runner(ray=True, ray_address=cluster.address)
    (tmp_path / "lost").mkdir(), (tmp_path / "raised").mkdir()
    lost = list(run_all(worker_dies_first_time, str(tmp_path / "lost"), range(3), runner))
    assert sorted(lost) == [(0, 0), (1, 1), (2, 4)]
    assert [attempts(str(tmp_path / "lost"), i) for i in range(3)] == [2, 2, 2]
    raised = list(run_all(raises, str(tmp_path / "raised"), range(3), runner))
    assert sorted(i for i, _ in raised) == [0, 1, 2]
    assert all(isinstance(r, WorkerLost) and r.why.startswith("RayTaskError(ValueError)") for _, r in raised)
    assert [attempts(str(tmp_path / "raised"), i) for i in range(3)] == [1, 1, 1]


def _reach_cells(result_path) -> list:
    """Each cell's verdict and plan; for a `not found` cell not its partial path, which is where
    the time limit stopped the search."""
    return [(c["goal"], c["verdict"], c["solved"], c["outcome"],
             *((c["switches"], c["pushes"]) if c["verdict"] != "not found" else ()))
            for c in json.loads(result_path.read_text())["cells"]]


def test_reach_on_a_two_node_cluster_gives_the_map_of_one_worker_and_names_each_cells_node(cluster, tmp_path):
    grid = ["--x", "-30:30:5", "--z", "-15:15:3", "--theta", "-20:20:2", "--seed", "3", "--time-limit", "0.3"]
    task = str(TASKS / "t-shaped.yaml")
    here, there = tmp_path / "here.json", tmp_path / "there.json"
    for runner, out in ((["--workers", "1"], here), (["--ray", cluster.address], there)):
        result = CliRunner().invoke(cli, ["reach", task, *grid, *runner, "--json", str(out), "--quiet"])
        assert result.exit_code == 0, result.output
    assert _reach_cells(here) == _reach_cells(there)
    ids = {node.node_id() for node in cluster.nodes}
    cells = json.loads(there.read_text())["cells"]
    assert {c["node"].rsplit("/", 1)[1] for c in cells} == ids and all(c["node"].startswith("ray:") for c in cells)
    assert {c["node"] for c in json.loads(here.read_text())["cells"]} == {f"local:{os.uname().nodename}"}


class _Watch:
    """Which trials each node runs, sampled every 50 ms from its workers' process titles; kills the
    second node's raylet once it has finished `finished` trials and run another for `after_s`."""

    def __init__(self, cluster: Cluster, finished: int = 1, after_s: float = 0.5):
        self.cluster, self.finished, self.after_s = cluster, finished, after_s
        self.seen = {k: {} for k in range(len(cluster.nodes))}  # node -> trial name -> first seen [s]
        self.killed_at, self.in_flight = None, []

    def sample(self, now: float) -> None:
        running = {}
        for k, node in enumerate(self.cluster.nodes):
            running[k] = node.task_names("run_trial[") if k == 0 or self.killed_at is None else []
            for name in running[k]:
                self.seen[k].setdefault(name, now)
        ready = len(self.seen[1]) - len(running[1]) >= self.finished
        if running[1] and ready and min(now - self.seen[1][n] for n in running[1]) >= self.after_s:
            os.kill(self.cluster.nodes[1].raylet_pid(), signal.SIGKILL)
            self.killed_at, self.in_flight = now, sorted(running[1])


def test_a_node_lost_mid_study_costs_no_trial_and_counts_none_twice(one_worker):
    cluster = Cluster(nodes=2, num_cpus=1)  # its own: this test kills a node
    try:
        head_id, lost_id = cluster.nodes[0].node_id(), cluster.nodes[1].node_id()
        task = shipped("horizontal-offset-low-mu")
        batch = Batch(task=task, plan=check_plan(task, plan_task(task)), spreads=SPREADS, seed=1)  # as the CLI's
        done = {}
        study = threading.Thread(target=lambda: done.update(
            result=evaluate(batch, TRIALS, Runner(ray=True, ray_address=cluster.address))), daemon=True)
        watch, started = _Watch(cluster), time.monotonic()
        study.start()
        while study.is_alive() and time.monotonic() - started < 120:
            watch.sample(time.monotonic() - started)
            time.sleep(0.05)
        assert not study.is_alive(), "the study did not end within 120 s of losing a node"
    finally:
        cluster.stop()
    assert watch.killed_at is not None, "the second node ran too few trials: nothing was lost"
    trials = done["result"].trials
    assert [t["trial"] for t in trials] == list(range(TRIALS))  # each trial once
    assert not [t for t in trials if t["cause"] == "crash"] and done["result"].summary()["crashed"] == 0
    assert [_outcome(t) for t in trials] == [_outcome(t) for t in one_worker]
    retried = [name for name in watch.in_flight if watch.seen[0].get(name, -1) > watch.killed_at]
    assert retried == watch.in_flight  # each trial in flight on the lost node ran again on the head
    number = {name: int(name[len("run_trial["):-1]) for name in watch.seen[1]}
    for name in watch.in_flight:
        assert trials[number[name]]["node"].endswith(head_id)
    finished = sorted(number[n] for n in watch.seen[1] if n not in watch.in_flight)  # before the node was lost
    assert finished and all(trials[i]["node"].endswith(lost_id) for i in finished)  # kept, not run again
    print(f"\nnode lost {watch.killed_at:.1f} s into the study, after trials {finished}, running {watch.in_flight}; "
          f"run again on the head at {[round(watch.seen[0][n], 1) for n in retried]} s; {len(trials)} trials, each "
          f"once, none crashed; "
          f"{done['result'].wall_s:.1f} s; per node: {done['result'].summary()['nodes']}")
