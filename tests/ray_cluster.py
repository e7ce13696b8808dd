"""A Ray cluster of several nodes on this machine, started with `ray start` as a lab starts one (a
head, then nodes that join it by its address), for the tests that run a batch on a real cluster.

Each node is `ray start --block` in a session of its own, on free ports and its own temporary
directory, so that it stops with its process group (never `ray stop`, which stops every Ray on the
machine, another user's included). The nodes run this checkout's stablepush (PYTHONPATH), as each
node of a lab's cluster must run the same stablepush as the driver. Token authentication is off
(RAY_AUTH_MODE=disabled): on a Ray that turns it on by default, a node or driver without the
cluster's token cannot join.
"""
from __future__ import annotations

import os
import shutil
import signal
import socket
import subprocess
import sys
import tempfile
import time
from pathlib import Path
from typing import Dict, List, Optional

RAY_CLI = Path(sys.executable).with_name("ray")


def free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def node_env() -> Dict[str, str]:
    """The environment a node runs in: this checkout's stablepush first on the path, then the tests
    (for the jobs below), no token, and workers at the tests' own priority (RAY_worker_niceness=0,
    as stablepush's local instance), so that the suite's other tests on the same cores do not
    starve them (Ray's nice 15 leaves a worker a few percent of a loaded CPU)."""
    import stablepush
    import stablepush_cli

    paths = [str(Path(m.__file__).resolve().parent.parent) for m in (stablepush, stablepush_cli)]
    paths.append(str(Path(__file__).resolve().parent))
    env = dict(os.environ, RAY_AUTH_MODE="disabled", RAY_USAGE_STATS_ENABLED="0", RAY_worker_niceness="0")
    env["PYTHONPATH"] = os.pathsep.join(dict.fromkeys(paths + [p for p in env.get("PYTHONPATH", "").split(os.pathsep)
                                                                if p]))
    return env


def _children(pid: int) -> List[int]:
    out = []
    for entry in Path("/proc").iterdir():
        if entry.name.isdigit():
            try:
                stat = (entry / "stat").read_text()
            except OSError:
                continue
            if int(stat.rsplit(")", 1)[1].split()[1]) == pid:
                out.append(int(entry.name))
    return out


def _cmdline(pid: int) -> str:
    try:
        return (Path("/proc") / str(pid) / "cmdline").read_bytes().replace(b"\0", b" ").decode()
    except OSError:
        return ""


class Node:
    """One `ray start --block` process and what it started."""

    def __init__(self, args: List[str], log: Path, env: Dict[str, str]):
        self.log = log
        with open(log, "w") as out:
            self.process = subprocess.Popen([str(RAY_CLI), "start", "--block", *args], stdout=out,
                                            stderr=subprocess.STDOUT, env=env, start_new_session=True)

    def raylet_pid(self) -> Optional[int]:
        """The node's raylet, the process that makes it a node (None once it is gone)."""
        for pid in _children(self.process.pid):
            if "/raylet/raylet " in _cmdline(pid):
                return pid
        return None

    def node_id(self) -> str:
        """Ray's id of the node (its raylet's --node_id), as stablepush.runners.this_node names it."""
        raylet = self.raylet_pid()
        assert raylet is not None, "the node has no raylet"
        return next(arg.split("=", 1)[1] for arg in _cmdline(raylet).split() if arg.startswith("--node_id="))

    def task_pids(self, prefix: str) -> List[int]:
        """The node's worker processes now running a task whose name starts with `prefix` (Ray
        titles a worker `ray::NAME` while it runs task NAME)."""
        raylet = self.raylet_pid()
        if raylet is None:
            return []
        return [pid for pid in _children(raylet) if _cmdline(pid).startswith(f"ray::{prefix}")]

    def task_names(self, prefix: str) -> List[str]:
        return [_cmdline(pid).split()[0][len("ray::"):] for pid in self.task_pids(prefix)]

    def stop(self) -> None:
        """Every process of the node's session, at once."""
        try:
            os.killpg(self.process.pid, signal.SIGKILL)
        except ProcessLookupError:
            pass
        self.process.wait(timeout=30)


class Cluster:
    """A head and `nodes - 1` nodes joined to it, `num_cpus` each; `address` is the head's."""

    def __init__(self, nodes: int = 2, num_cpus: int = 1, timeout_s: float = 60.0):
        self.dir = Path(tempfile.mkdtemp(prefix="sp-ray-"))  # short: Ray's socket paths must fit
        self.env = node_env()
        self.address = f"127.0.0.1:{free_port()}"
        self.nodes: List[Node] = []
        try:
            self._start(nodes, num_cpus, timeout_s)
        except BaseException:
            self.stop()
            raise

    def _node_ports(self) -> List[str]:
        ports = ("--node-manager-port", "--object-manager-port", "--metrics-export-port",
                 "--dashboard-agent-listen-port", "--dashboard-agent-grpc-port", "--runtime-env-agent-port")
        return [arg for name in ports for arg in (name, str(free_port()))]

    def _start(self, nodes: int, num_cpus: int, timeout_s: float) -> None:
        common = ["--num-cpus", str(num_cpus), "--disable-usage-stats"]
        self.nodes.append(Node(["--head", "--port", self.address.rsplit(":", 1)[1],
                                "--temp-dir", str(self.dir), "--include-dashboard", "false",
                                "--dashboard-port", str(free_port()),
                                *common, *self._node_ports()], self.dir / "head.log", self.env))
        self.wait_for(1, timeout_s)
        for k in range(1, nodes):
            self.nodes.append(Node(["--address", self.address,  *common,
                                    *self._node_ports()], self.dir / f"node{k}.log", self.env))
            self.wait_for(k + 1, timeout_s)

    def alive_nodes(self) -> int:
        """How many nodes the head counts alive (`ray status`' Active list), or -1 when it cannot say."""
        try:
            status = subprocess.run([str(RAY_CLI), "status", "--address", self.address], env=self.env,
                                    capture_output=True, text=True, timeout=30).stdout
        except subprocess.TimeoutExpired:
            return -1
        active = status.split("Active:", 1)[1].split("Pending:", 1)[0] if "Active:" in status else ""
        return sum(1 for line in active.splitlines() if line.strip().startswith("1 node_"))

    def wait_for(self, nodes: int, timeout_s: float) -> None:
        deadline = time.monotonic() + timeout_s
        while time.monotonic() < deadline:
            for node in self.nodes:
                if node.process.poll() is not None:
                    raise RuntimeError(f"`ray start` exited {node.process.returncode}: {node.log.read_text()[-2000:]}")
            if self.alive_nodes() == nodes:
                return
            time.sleep(0.5)
        raise RuntimeError(f"the cluster at {self.address} did not reach {nodes} nodes in {timeout_s:g} s")

    def stop(self) -> None:
        for node in reversed(self.nodes):
            node.stop()
        shutil.rmtree(self.dir, ignore_errors=True)


def attempts(folder: str, i: int) -> int:
    """How many times job i below started (each start is a line of folder/i)."""
    path = Path(folder) / str(i)
    return len(path.read_text().splitlines()) if path.exists() else 0


def _start(folder: str, i: int) -> int:
    with open(Path(folder) / str(i), "a") as out:
        out.write(f"{os.getpid()}\n")
    return attempts(folder, i)


def raises(folder: str, i: int):
    """A job that raises an error of its own, every time."""
    _start(folder, i)
    raise ValueError(f"job {i} raises")


def worker_dies_first_time(folder: str, i: int) -> int:
    """A job whose worker process dies the first time it runs (as with its node), and that returns
    i * i the next."""
    if _start(folder, i) == 1:
        os._exit(1)
    return i * i
