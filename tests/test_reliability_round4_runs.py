"""Reliability, round four (issue 69), the classes of runs and outputs: G (a --ray address where
something accepts TCP but is not a Ray head) and the rule that no output names an input. Each
test fails on the code before its fix."""
import json
import socket
import socketserver
import threading
import time

import pytest
from click.testing import CliRunner

from stablepush.errors import RunnerError
from stablepush.runners import probe_ray_head
from stablepush_cli.main import cli

from conftest import TASKS


class _Silent(socketserver.BaseRequestHandler):
    def handle(self):
        time.sleep(8)  # accepts, reads nothing, says nothing


class _Http1(socketserver.BaseRequestHandler):
    def handle(self):
        self.request.recv(1024)
        self.request.sendall(b"HTTP/1.1 400 Bad Request\r\ncontent-length: 0\r\n\r\n")


class _Http2NotGrpc(socketserver.BaseRequestHandler):
    """An HTTP/2 endpoint that is not a gRPC server: its SETTINGS, then a 404 to any request (h2)."""

    def handle(self):
        from h2.config import H2Configuration
        from h2.connection import H2Connection
        from h2.events import RequestReceived

        conn = H2Connection(H2Configuration(client_side=False))
        conn.initiate_connection()
        self.request.sendall(conn.data_to_send())
        while True:
            data = self.request.recv(65536)
            if not data:
                return
            for event in conn.receive_data(data):
                if isinstance(event, RequestReceived):
                    conn.send_headers(event.stream_id, [(":status", "404")], end_stream=True)
            self.request.sendall(conn.data_to_send())


@pytest.fixture(params=[_Silent, _Http1, _Http2NotGrpc], ids=["silent", "http1", "http2-not-grpc"])
def not_a_head(request):
    server = socketserver.ThreadingTCPServer(("127.0.0.1", 0), request.param)
    server.daemon_threads = True
    threading.Thread(target=server.serve_forever, daemon=True).start()
    yield f"127.0.0.1:{server.server_address[1]}"
    server.shutdown()
    server.server_close()


def test_g_a_server_that_is_not_a_ray_head_is_refused_within_seconds(not_a_head):
    """Something that accepts TCP but is not a Ray head: ray.init waited (killed after 150 s)."""
    started = time.perf_counter()
    with pytest.raises(RunnerError, match=f"{not_a_head} (answers, but as|accepts a connection but)"):
        probe_ray_head(not_a_head)
    assert time.perf_counter() - started < 15
    with pytest.raises(RunnerError):
        probe_ray_head(f"ray://{not_a_head}")


def test_g_evaluate_names_the_address_and_exits_2_before_any_work(not_a_head, tmp_path):
    task = str(TASKS / "t-shaped.yaml")
    result = CliRunner().invoke(cli, ["evaluate", task, "--trials", "2", "--ray", not_a_head,
                                      "--json", str(tmp_path / "out.json")])
    assert result.exit_code == 2, result.output
    assert not_a_head in result.output and "not a Ray head" in result.output
    assert not (tmp_path / "out.json").exists()


def test_g_nothing_listening_is_still_named_at_once():
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        port = s.getsockname()[1]
    with pytest.raises(RunnerError, match=f"no Ray head answers at 127.0.0.1:{port}"):
        probe_ray_head(f"127.0.0.1:{port}")


# A local Ray started in the test process would leave it unable to join the test cluster later
# (tests/test_ray_cluster.py: OwnerDiedError once a local session has run in the same process):
# the local instances below run in a child process of their own.
def _in_a_child(code: str) -> str:
    import subprocess
    import sys

    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=300)
    assert done.returncode == 0, done.stderr[-2000:]
    return done.stdout


def test_r_a_batch_on_ray_that_finishes_nothing_for_a_while_says_what_ray_waits_for():
    """A starved machine: no trial finished in 15 minutes on a local Ray and nothing was printed."""
    pytest.importorskip("ray")
    out = _in_a_child(
        "import json, time\n"
        "from stablepush import runners\n"
        "from stablepush.runners import Runner, run_all\n"
        "runners.RAY_QUIET_S = 0.5\n"
        "said = []\n"
        "slow = lambda _shared, i: time.sleep(1.5) or i\n"
        "print(json.dumps([dict(run_all(slow, None, [0, 1], Runner(ray=True, on_wait=said.append))), said]))\n")
    results, said = json.loads(out.strip().splitlines()[-1])
    assert results == {"0": 0, "1": 1}
    assert said, "nothing said while Ray finished nothing"
    assert said[0].startswith("Ray: 0 of 2 jobs finished after ") and "CPUs" in said[0], said[0]


def test_r_a_local_rays_jobs_run_at_this_processs_priority():
    """Ray ran its workers at nice 15: on 2 cores with 10 busy loops each got 0.7% of a CPU and 4
    trials finished none in 400 s, where at nice 0 they took 114 s."""
    pytest.importorskip("ray")
    out = _in_a_child(
        "import json, os\n"
        "from stablepush.runners import RAY_LOCAL_CONFIG, Runner, run_all\n"
        "niceness = lambda _shared, i: os.nice(0)\n"
        "jobs = dict(run_all(niceness, None, [0, 1], Runner(ray=True)))\n"
        "print(json.dumps([jobs, os.nice(0), RAY_LOCAL_CONFIG]))\n")
    jobs, driver, config = json.loads(out.strip().splitlines()[-1])
    assert jobs == {"0": driver, "1": driver}
    assert config == {"worker_niceness": 0}, "one session's settings kept for the next"


@pytest.mark.parametrize("address", [None, "local", "auto", "10.0.0.5:6379"])
def test_r_rays_config_is_set_for_a_local_instance_only(monkeypatch, address):
    ray = pytest.importorskip("ray")
    from stablepush import runners

    calls = []
    monkeypatch.setattr(runners, "probe_ray_head", lambda _address: None)
    monkeypatch.setattr(ray, "init", lambda **kw: calls.append(kw))
    runners._join_ray(ray, address)
    configs = [call.get("_system_config") for call in calls]
    assert configs == ([{"worker_niceness": 0}] if address in (None, "local") else [None])


def test_r_no_address_that_joins_a_running_cluster_leaves_its_config(monkeypatch):
    """No address joins the cluster RAY_ADDRESS or `ray start` names, and Ray refuses a config for it."""
    ray = pytest.importorskip("ray")
    from stablepush import runners

    calls = []

    def init(**kw):
        calls.append(kw)
        if "_system_config" in kw:
            raise ValueError("When connecting to an existing cluster, _system_config must not be provided.")

    monkeypatch.setattr(ray, "init", init)
    runners._join_ray(ray, None)
    assert len(calls) == 2 and "_system_config" not in calls[1]


def test_a_plan_file_read_is_not_written_over_by_the_api(tmp_path):
    """Inputs are never outputs, in the library: sp.save_plan wrote over the plan file it had read."""
    import stablepush as sp
    from stablepush.errors import OutputError

    from conftest import shipped

    task = shipped("t-shaped")
    path = tmp_path / "t.json"
    sp.save_plan(sp.plan_task(task, seed=1), str(path))
    plan = sp.load_plan(str(path))
    before = path.read_bytes()
    with pytest.raises(OutputError, match="a plan file this process read; refusing to write over it"):
        sp.save_plan(plan, str(path))
    assert path.read_bytes() == before


def test_a_file_the_robot_model_includes_is_refused_as_an_output_before_any_work(tmp_path):
    """check-cell --json naming a file the MJCF arm includes: the model's include was written over."""
    from generated_arms import mjcf_arm

    arm = mjcf_arm(tmp_path / "arm.xml", 5, ("z", "x", "z", "-x", "z", "x", "z"))
    model = tmp_path / "arm.xml"
    extra = tmp_path / "extra.xml"
    extra.write_text('<mujoco><default><geom rgba="1 0 0 1"/></default></mujoco>')
    model.write_text(model.read_text().replace("<worldbody>", '<include file="extra.xml"/><worldbody>'))
    runner = CliRunner()
    task = str(TASKS / "horizontal-offset-low-mu.yaml")
    plan = str(tmp_path / "p.json")
    assert runner.invoke(cli, ["plan", task, "-o", plan]).exit_code == 0
    result = runner.invoke(cli, ["check-cell", plan, "--task", task, "--robot", str(model), "--flange",
                                 arm["flange"], "--tcp", *map(str, arm["tcp"]), "--json", str(extra)])
    assert result.exit_code == 2, result.output
    assert f"--json {extra}: is a file the robot model includes this process read" in result.output, result.output
    assert extra.read_text().startswith("<mujoco><default>")


def test_the_design_commands_bounds_are_the_librarys():
    """--evaluate-top and --reach-top are bounded by the numbers design() and evaluate_designs()
    refuse past (one bound, two places: the command line keeps from loading the design package)."""
    from stablepush.design.layouts import MAX_REACH_TOP
    from stablepush.design.odds import MAX_TOP

    params = {p.name: p for p in cli.commands["design"].params}
    assert params["evaluate_top"].type.max == MAX_TOP and params["reach_top"].type.max == MAX_REACH_TOP
