"""Reliability, round three (issue 61): each class of fault found, at its root, with the input that
showed it. Fast: nothing here runs the simulated arm."""
import dataclasses
import json
import math
import re
import socket

import pytest
from click.testing import CliRunner
from hypothesis import given, settings
from hypothesis import strategies as st

import stablepush as sp
from stablepush import runners
from stablepush.errors import OutputError, RunnerError, SettingError, StablepushError, TaskError
from stablepush.evaluation import Spreads, draw_world
from stablepush.evaluation import batch as batch_mod
from stablepush.execution.guard import GuardedApproach
from stablepush.execution.protocol import PROTOCOL, ProtocolError, decode, encode
from stablepush.plan.files import MAX_WAYPOINTS
from stablepush.plan.search import SearchRules
from stablepush.runners import Runner, run_all
from stablepush_cli.main import cli

from conftest import TASKS, shipped

HIGH_MU = TASKS / "horizontal-offset-high-mu.yaml"


@pytest.fixture(scope="module")
def high_mu_plan(tmp_path_factory):
    path = tmp_path_factory.mktemp("plans") / "high-mu.plan.json"
    sp.save_plan(sp.plan_task(shipped("horizontal-offset-high-mu")), str(path))
    return path


def _with_step(task, step):
    return dataclasses.replace(task, planner=task.planner.replace(step=step))


# -- 1. tracker noise and the guard; crashed trials ------------------------------------------------

@pytest.mark.parametrize("noise", [("1", "0"), ("0", "1"), ("0.126", "0")])
def test_a_tracker_noise_the_guard_cannot_tell_a_touch_from_is_refused_naming_the_option(high_mu_plan, noise):
    """It exited 4 ("guard touch_mm must lie in [0.001, 0.5], got 4.0"): the guard reads a touch past
    four standard deviations of the noise, at most 0.5 mm and 0.5 deg."""
    result = CliRunner().invoke(cli, ["execute", str(high_mu_plan), "--task", str(HIGH_MU), "--sim",
                                      "--tracker-noise", *noise])
    assert result.exit_code == 2, result.output
    assert "error: --tracker-noise:" in result.output and "--no-guard" in result.output
    assert "internal error" not in result.output


def test_evaluate_refuses_such_a_noise_before_any_trial(high_mu_plan, monkeypatch):
    """Every trial crashed, and the run said "landed 0 of 2" with exit 0."""
    monkeypatch.setattr(batch_mod, "run_plan", lambda *a, **k: pytest.fail("a trial ran"))
    result = CliRunner().invoke(cli, ["evaluate", str(HIGH_MU), "--plan", str(high_mu_plan), "--trials", "2",
                                      "--workers", "1", "--tracker-noise", "0.5", "0", "--quiet"])
    assert result.exit_code == 2, result.output
    assert "error: --tracker-noise:" in result.output
    monkeypatch.setattr(sp.plan, "plan_task", lambda *a, **k: pytest.fail("a plan was searched for"))
    result = CliRunner().invoke(cli, ["evaluate", str(HIGH_MU), "--trials", "2", "--tracker-noise", "0", "0.2",
                                      "--quiet"])
    assert result.exit_code == 2 and "error: --tracker-noise:" in result.output, result.output


def test_the_guard_takes_every_noise_up_to_its_limit_and_the_api_refuses_past_it_by_field():
    guard = GuardedApproach.for_tracker_noise(0.125, 0.125)
    assert (guard.touch_mm, guard.touch_deg, guard.seat_deg) == (0.5, 0.5, 0.5)
    for noise in [(0.1251, 0.0), (0.0, 0.1251), (float("nan"), 0.0), (float("inf"), 0.0)]:
        with pytest.raises(SettingError) as caught:
            GuardedApproach.for_tracker_noise(*noise)
        assert caught.value.field == "tracker_noise"


def test_crashed_trials_are_errors_not_misses_and_the_run_fails(high_mu_plan, monkeypatch, tmp_path):
    """A crashing trial counted as a miss: every trial crashed and evaluate printed "landed 0 of 2"
    with exit 0, a false 0% success rate."""
    def crash(*args, **kw):
        raise RuntimeError("the simulator blew up")

    monkeypatch.setattr(batch_mod, "run_plan", crash)
    out = tmp_path / "eval.json"
    result = CliRunner().invoke(cli, ["evaluate", str(HIGH_MU), "--plan", str(high_mu_plan), "--trials", "2",
                                      "--workers", "1", "--vary", "pad_mu=0.1", "--json", str(out), "--quiet"])
    assert result.exit_code == 4, result.output
    assert "landed 0 of" not in result.output and "0.0%" not in result.output
    assert "error: 2 of 2 trials crashed" in result.output
    summary = json.loads(out.read_text())["summary"]
    assert summary["crashed"] == 2 and summary["crashed_trials"] == [0, 1]
    assert summary["success_rate"] is None and summary["ci95"] is None and summary["causes"] == {}


def test_a_crashed_trial_is_left_out_of_the_rate_and_the_decision(monkeypatch):
    def landed_but_one(batch, trial):
        record = {"trial": trial, "world": batch.world(trial).as_dict(), "goal_error": None, "final_error": None,
                  "replans": 0, "sim_time_s": 1.0, "wall_s": 0.1, "verdict": None, "error": None,
                  "success": trial != 1, "cause": None}
        if trial == 1:
            record.update(cause="crash", error="RuntimeError: the simulator blew up")
        return record

    monkeypatch.setattr(batch_mod, "run_trial", landed_but_one)
    task = shipped("horizontal-offset-high-mu")
    batch = batch_mod.Batch(task=task, plan=sp.plan_task(task), spreads=batch_mod.Spreads(vary={"pad_mu": 0.01}))
    result = batch_mod.evaluate(batch, 3, batch_mod.Runner(workers=1), test=batch_mod.SequentialTest(0.5, 0.9))
    s = result.summary()
    assert (s["trials"], s["judged"], s["crashed"], s["successes"]) == (3, 2, 1, 2)
    assert s["success_rate"] == 1.0 and s["causes"] == {}
    assert (s["decision"]["trials"], s["decision"]["successes"]) == (2, 2)
    assert any(line.startswith("crashed: 1 of 3 trials") for line in result.describe())


# -- 6. steps too small for a plan file, and the time limit ----------------------------------------

def test_a_step_no_plan_within_the_push_cap_can_take_is_refused_before_the_search():
    """It searched, made 18,001 pushes, spent 11 s past a 2 s limit and was refused by the writer."""
    task = _with_step(shipped("pivoting"), (0.002, 0.005))
    with pytest.raises(TaskError) as caught:
        sp.plan_task(task, time_limit=2)
    # the bound from the distance to the goal's tolerance box, known before any search
    assert caught.value.field == "planner.step" and "17,800 pushes" in str(caught.value)


def test_a_plan_found_longer_than_the_push_cap_is_refused_naming_the_step():
    """The pivot's 90 deg in steps of 0.009 deg: the bound lets it search (9,889 pushes at least),
    the straight plan it finds takes 10,000, one more than a plan file holds."""
    with pytest.raises(TaskError) as caught:
        sp.plan_task(_with_step(shipped("pivoting"), (0.009, 0.009)), time_limit=1)
    assert caught.value.field == "planner.step" and f"{MAX_WAYPOINTS:,} pushes" in str(caught.value)


def test_a_long_plan_is_made_and_written(tmp_path):
    """A plan of nearly the push cap is made and round-trips through its file. (Making its waypoints
    copied the core's whole path once per waypoint, quadratic; how long it takes is a benchmark's
    to say, not a test's.)"""
    plan = sp.plan_task(_with_step(shipped("pivoting"), (0.0091, 0.0091)), time_limit=0.5)
    assert plan.solved and len(plan.waypoints) > 9_800
    sp.save_plan(plan, str(tmp_path / "long.plan.json"))
    assert len(sp.load_plan(str(tmp_path / "long.plan.json")).waypoints) == len(plan.waypoints)


# -- 2. a spread of -0 -----------------------------------------------------------------------------

def test_a_spread_of_minus_zero_is_zero():
    """`--vary mass=-0` passed the range check, then numpy refused uniform(0, -0): exit 4."""
    spreads = Spreads(vary={"mass": -0.0, "pad_mu": 0.1}, feature_error=(-0.0, -0.0), tracker_noise=(-0.0, 0.0))
    assert math.copysign(1.0, spreads.vary["mass"]) == 1.0 and spreads.feature_error == (0.0, 0.0)
    world = draw_world(1, 0, spreads, ["left"])
    assert world.multipliers["mass"] == 1.0 and world.feature_offsets["left"] == (0.0, 0.0, 0.0)


def test_evaluate_takes_vary_minus_zero(high_mu_plan, monkeypatch):
    def drawn_and_landed(batch, trial):  # the worlds are drawn as a trial draws them; nothing is simulated
        return {"trial": trial, "world": batch.world(trial).as_dict(), "goal_error": None, "final_error": None,
                "replans": 0, "sim_time_s": 1.0, "wall_s": 0.1, "verdict": None, "error": None, "success": True,
                "cause": None}

    monkeypatch.setattr(batch_mod, "run_trial", drawn_and_landed)
    result = CliRunner().invoke(cli, ["evaluate", str(HIGH_MU), "--plan", str(high_mu_plan), "--trials", "2",
                                      "--workers", "1", "--vary", "mass=-0", "--vary", "pad_mu=0.1",
                                      "--feature-error", "-0", "0", "--quiet"])
    assert result.exit_code == 0, result.output
    assert "landed 2 of 2" in result.output


# -- 3. a Ray that cannot start ------------------------------------------------------------------

@pytest.mark.parametrize("address", [None, "local", "auto"])
def test_a_ray_that_cannot_start_is_a_runner_error_naming_its_address(monkeypatch, address):
    """`reach ... --ray local` on a loaded machine exited 4 after 32 s: ray.init raises a bare
    Exception when its node times out during startup."""
    ray = pytest.importorskip("ray")
    stopped = []

    def times_out(*args, **kw):
        raise Exception("The current node timed out during startup. This could happen because some of the raylet "
                        "failed to startup or the GCS has become overloaded.")

    monkeypatch.setattr(ray, "init", times_out)
    monkeypatch.setattr(ray, "shutdown", lambda: stopped.append(1))
    monkeypatch.setattr(ray, "is_initialized", lambda: False)
    with pytest.raises(RunnerError) as caught:
        list(run_all(_square, None, [1, 2], Runner(ray=True, ray_address=address)))
    assert "timed out during startup" in str(caught.value) and stopped
    assert (f"Ray at {address} (--ray {address})" if address else "a local Ray instance (--ray)") in str(caught.value)
    grid = ["--x", "-1:1:2", "--z", "0:0:1", "--time-limit", "0.05"]
    result = CliRunner().invoke(cli, ["reach", str(HIGH_MU), *grid, "--ray", *([address] if address else []),
                                      "--json", "/dev/null"])
    assert result.exit_code == 2, result.output
    assert result.output.startswith("error: cannot start or join") and "internal error" not in result.output


def _square(_shared, i):
    return i * i


# -- 5. output names that name no file -------------------------------------------------------------

@pytest.mark.parametrize("name", ["out.json/", ""])
def test_the_api_refuses_an_output_name_that_names_no_file(tmp_path, monkeypatch, name):
    """`out.json/` was written as the file out.json (and the CLI said "written to out.json/")."""
    monkeypatch.chdir(tmp_path)
    (tmp_path / "out").mkdir()
    plan = sp.plan_task(shipped("horizontal-offset-high-mu"))
    with pytest.raises(OutputError, match="names a directory|an empty file name|ends in '/'"):
        sp.save_plan(plan, name)
    with pytest.raises(OutputError):
        sp.save_plan(plan, "fine.json", name)  # an empty CSV name wrote no CSV without a word
    assert sorted(p.name for p in tmp_path.iterdir()) == ["out"]


def _output_cases(plan_file, tmp_path):
    """(option, the command up to it, a file name the option takes)."""
    task = str(HIGH_MU)
    grid = ["--x", "-1:1:2", "--z", "0:0:1", "--time-limit", "0.05"]
    return [
        ("-o", ["plan", task, "-o"], "out.json"),
        ("--csv", ["plan", task, "-o", str(tmp_path / "p.json"), "--csv"], "out.csv"),
        ("--json", ["reach", task, *grid, "--json"], "out.json"),
        ("-o", ["trajectory", str(plan_file), "--task", task, "-o"], "out.csv"),
        ("--record", ["execute", str(plan_file), "--task", task, "--sim", "--record"], "out.mcap"),
        ("--json", ["execute", str(plan_file), "--task", task, "--sim", "--json"], "out.json"),
        ("--json", ["evaluate", task, "--plan", str(plan_file), "--trials", "1", "--json"], "out.json"),
    ]


@pytest.mark.parametrize("ending", ["/", "/.", None])
def test_every_command_refuses_an_output_name_that_names_no_file_naming_the_option(high_mu_plan, tmp_path,
                                                                                   monkeypatch, ending):
    """`plan t.yaml -o out.json/` said "written to out.json/" and made the file out.json (so did reach
    --json, trajectory -o, execute --record); `--json ""` wrote nothing without a word."""
    monkeypatch.chdir(tmp_path)
    for option, args, good in _output_cases(high_mu_plan, tmp_path):
        name = "" if ending is None else good + ending
        result = CliRunner().invoke(cli, args + [name])
        assert result.exit_code == 2, (args, name, result.output)
        assert result.output.startswith(f"error: {option} "), (args, name, result.output)
    assert sorted(p.name for p in tmp_path.iterdir()) == []


# -- 4. an edited Task ---------------------------------------------------------------------------

@pytest.mark.parametrize("field", ["uncertainty", "feature_orientations"])
@pytest.mark.parametrize("value", [None, (), [], "pad_mu"])
def test_a_task_edited_with_a_field_of_the_wrong_type_is_refused_naming_it(field, value):
    """`sp.check(dataclasses.replace(task, uncertainty=None), ...)` escaped as an AttributeError."""
    with pytest.raises(TypeError, match=f"Task.{field}"):
        dataclasses.replace(shipped("horizontal-offset-low-mu"), **{field: value})


WRONG_TYPED = st.one_of(
    st.none(), st.booleans(), st.integers(min_value=-2**70, max_value=2**70), st.floats(),
    st.text(max_size=5), st.binary(max_size=3), st.builds(object),
    st.tuples(st.text(max_size=2)), st.lists(st.one_of(st.none(), st.text(max_size=2)), max_size=3),
    st.lists(st.floats(allow_nan=True), min_size=2, max_size=4).map(tuple),
    st.dictionaries(st.text(max_size=8), st.one_of(st.none(), st.floats(), st.text(max_size=2)), max_size=2),
    st.dictionaries(st.sampled_from(["pad_mu", "mass", "left"]), st.floats(), min_size=1, max_size=2),
)
TASK_FIELDS = [f.name for f in dataclasses.fields(sp.Task)]


@settings(max_examples=300, deadline=None, derandomize=True)
@given(field=st.sampled_from(TASK_FIELDS), value=WRONG_TYPED)
def test_every_task_field_edited_to_any_type_is_refused_by_name_or_taken(field, value):
    """Every field of a Task, replaced by a value of any type: the Task refuses it naming the field
    (TypeError or ValueError), or takes it, and then sp.check and sp.plan_task answer or raise a
    StablepushError, TypeError or ValueError, never anything else."""
    base = _LOW_MU
    try:
        task = dataclasses.replace(base, **{field: value})
    except (TypeError, ValueError) as exc:
        assert field in str(exc), (field, value, exc)
        return
    for call in (lambda: sp.check(task, at=task.start, move=(0.1, 0.0, 0.0)),
                 lambda: sp.plan_task(task, time_limit=0.01, rules=SearchRules(explain=False))):
        try:
            call()
        except (StablepushError, TypeError, ValueError):
            pass


_LOW_MU = shipped("horizontal-offset-low-mu")


# -- 8. the arm server's hello -------------------------------------------------------------------

def _scene(name="horizontal-offset-high-mu"):
    from stablepush.execution.world import place_features, scene_description

    task = shipped(name) if "/" not in name else sp.load_task(TASKS / name)
    plan = sp.plan_task(task, time_limit=0.5)
    return scene_description(task, place_features(task, plan.waypoints), task.start).as_dict()  # as on the wire


def _hello_line(scene):
    return encode({"type": "hello", "protocol": PROTOCOL, "rate_hz": 100, "scene": scene})


def _impossible(edit):
    scene = json.loads(json.dumps(_HIGH_MU_SCENE))
    edit(scene)
    return scene


IMPOSSIBLE_HELLOS = [  # (what, the edit, what the error names)
    ("a negative pad mu", lambda s: s["gripper"].update(mu=-1), "scene.gripper.mu"),
    ("a pad mu of 1e300", lambda s: s["gripper"].update(mu=1e300), "scene.gripper.mu"),
    ("a normal [0, 0, 0]", lambda s: s["features"][0].update(normal=[0, 0, 0]), "scene.features[0].normal"),
    ("a feature mu of 1e300", lambda s: s["features"][0].update(mu=1e300), "scene.features[0].mu"),
    ("a feature mu of 1e-300", lambda s: s["features"][0].update(mu=1e-300), "scene.features[0].mu"),
    ("no pads", lambda s: s["gripper"].update(pads=[]), "scene.gripper.pads"),
    ("a grip force of 1e300", lambda s: s["gripper"].update(grip_force=1e300), "scene.gripper.grip_force"),
    ("a grip force of 0", lambda s: s["gripper"].update(grip_force=0), "scene.gripper.grip_force"),
    ("a negative mass", lambda s: s["object"].update(mass=-0.2), "scene.object.mass"),
    ("a zero inertia", lambda s: s["object"].update(inertia=0), "scene.object.inertia"),
    ("a thickness of 1 km", lambda s: s["object"].update(thickness=1000.0), "scene.object.thickness"),
    ("a vertex at 1e9 m", lambda s: s["object"]["polygon"][0].__setitem__(0, 1e9), "scene.object.polygon[0][0]"),
    ("two vertices", lambda s: s["object"].update(polygon=s["object"]["polygon"][:2]), "scene.object.polygon"),
    ("a pad of radius 0", lambda s: s["gripper"]["pads"][0].update(radius=0), "scene.gripper.pads[0].radius"),
    ("254 pad points", lambda s: s["gripper"].update(pad_rings=6), "254 pad points"),
    ("gravity of 1e6", lambda s: s.update(gravity=[0, 1e6]), "scene.gravity[1]"),
    ("a feature's pose no pose", lambda s: s["features"][0].update(object_pose=[0, 0, 0, 0, 0, 0, 0]),
     "scene.features[0].object_pose"),
    ("a feature without a pusher", lambda s: s["features"][0].pop("pusher"), "scene.features[0]"),
    ("no gravity", lambda s: s.pop("gravity"), "scene has no 'gravity'"),
    ("a string for the mass", lambda s: s["object"].update(mass="0.2"), "scene.object.mass"),
]


@pytest.mark.parametrize("what, edit, says", IMPOSSIBLE_HELLOS, ids=[case[0] for case in IMPOSSIBLE_HELLOS])
def test_a_hello_whose_scene_no_world_can_be_built_from_is_refused_naming_the_field(what, edit, says):
    """The sim-arm built worlds from these and answered `ready`."""
    with pytest.raises(ProtocolError, match=re.escape(says)):
        decode(_hello_line(_impossible(edit)), "client")


@pytest.mark.parametrize("name", ["horizontal-offset-high-mu", "pivoting", "t-shaped", "more/tilted-gravity.yaml",
                                  "more/hexagon-offset.yaml"])
def test_the_executors_own_hellos_are_taken(name):
    assert decode(_hello_line(_scene(name)), "client")["type"] == "hello"


def test_the_sim_arm_answers_each_impossible_hello_with_an_error_and_then_serves(tmp_path):
    from stablepush.sim.server import SimArmServer

    server = SimArmServer(log=lambda text: None, idle_timeout=3.0)
    server.start_in_thread()

    def exchange(scene):
        with socket.create_connection((server.host, server.port), timeout=30) as conn:
            conn.sendall(_hello_line(scene) + encode({"type": "bye"}))
            return decode(conn.makefile("rb").readline(), "server")

    try:
        for what, edit, says in IMPOSSIBLE_HELLOS:
            reply = exchange(_impossible(edit))
            assert reply["type"] == "error" and says in reply["message"], (what, reply)
        assert exchange(_HIGH_MU_SCENE)["type"] == "ready"
    finally:
        server.close()


_HIGH_MU_SCENE = _scene()


# -- 9. workers, Unicode digits, a CSV over a task file -------------------------------------------

class _InlinePool:
    """A ProcessPoolExecutor that records how many workers it was asked for and runs each job here."""

    asked = []

    def __init__(self, max_workers):
        _InlinePool.asked.append(max_workers)

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        return False

    def submit(self, job, *args):
        from concurrent.futures import Future

        future = Future()
        future.set_result(job(*args))
        return future


def test_workers_are_capped_at_the_jobs_and_at_a_few_per_cpu(monkeypatch):
    """`reach --workers 1000` for 2 cells started 1,000 processes."""
    monkeypatch.setattr(runners, "ProcessPoolExecutor", _InlinePool)
    _InlinePool.asked.clear()
    assert sorted(r for _, r in run_all(_square, None, [1, 2], Runner(workers=1000))) == [1, 4]
    assert _InlinePool.asked == [2]
    assert sorted(r for _, r in run_all(_square, None, range(5000), Runner(workers=1000)))[-1] == 4999 ** 2
    assert _InlinePool.asked == [2, runners.max_workers()]
    assert runners.max_workers() == runners.WORKERS_PER_CPU * runners.default_workers()
    result = CliRunner().invoke(cli, ["reach", str(HIGH_MU), "--x", "-1:1:2", "--z", "0:0:1", "--time-limit", "0.05",
                                      "--workers", "1000"])
    assert result.exit_code == 0, result.output
    assert _InlinePool.asked[-1] == 2 and "on 2 local processes" in result.output
    with pytest.raises(ValueError, match="workers"):
        Runner(workers=0)


# Each evaluate here would fail fast once parsed (--robust with --plan), and never start its trials.
_FAST_FAIL = ["--robust", "--plan", "none.plan.json"]


@pytest.mark.parametrize("args, option", [
    (["reach", str(HIGH_MU), "--x", "-1:1:٣", "--z", "0:0:1"], "--x"),
    (["reach", str(HIGH_MU), "--x", "-١:1:3", "--z", "0:0:1"], "--x"),
    (["reach", str(HIGH_MU), "--x", "-1:1:３", "--z", "0:0:1"], "--x"),
    (["evaluate", str(HIGH_MU), "--vary", "mass=٠.١", *_FAST_FAIL], "--vary"),
    (["evaluate", str(HIGH_MU), "--trials", "٣", *_FAST_FAIL], "--trials"),
    (["evaluate", str(HIGH_MU), "--tracker-noise", "٠", "0", *_FAST_FAIL], "--tracker-noise"),
    (["evaluate", str(HIGH_MU), "--ray", "127.0.0.1:٦٣٧٩", *_FAST_FAIL], "--ray"),
    (["check", str(HIGH_MU), "--move", "١", "0", "0"], "--move"),
])
def test_numbers_in_other_scripts_digits_are_refused_naming_the_option(args, option):
    """Python reads "٣" as 3: `--x -1:1:٣` made an axis of three values, `--vary mass=٠.١` a spread of 0.1."""
    result = CliRunner().invoke(cli, args)
    assert result.exit_code == 2, result.output
    assert f"Invalid value for '{option}" in result.output


def test_the_library_writes_no_output_over_a_task_or_mesh_file_it_read(tmp_path):
    """`sp.save_plan(plan, "x.json", "t.yaml")` wrote a CSV over the task file: the CLI refused
    that, the library did not."""
    (tmp_path / "tasks").mkdir()
    (tmp_path / "meshes").mkdir()
    task_file = tmp_path / "tasks" / "t.yaml"
    mesh_file = tmp_path / "meshes" / "l-bracket.stl"
    task_file.write_text((TASKS / "more" / "l-bracket-mesh.yaml").read_text().replace("../../meshes", "../meshes"))
    mesh_file.write_bytes((TASKS.parent / "meshes" / "l-bracket.stl").read_bytes())
    before = task_file.read_bytes(), mesh_file.read_bytes()
    task = sp.load_task(str(task_file))
    plan = sp.plan_task(task, time_limit=0.5)
    for json_path, csv_path in ((tmp_path / "x.json", task_file), (task_file, None), (tmp_path / "x.json", mesh_file)):
        with pytest.raises(OutputError, match="this process read; refusing to write over it"):
            sp.save_plan(plan, str(json_path), None if csv_path is None else str(csv_path))
    assert (task_file.read_bytes(), mesh_file.read_bytes()) == before and not (tmp_path / "x.json").exists()
    sp.save_plan(plan, str(tmp_path / "x.json"), str(tmp_path / "x.csv"))  # other files are written as ever


# -- found by tests/test_fuzz_options.py -----------------------------------------------------------

def test_an_ack_timeout_no_socket_can_wait_is_refused_naming_the_option(high_mu_plan):
    """`execute --arm HOST:PORT --ack-timeout 1e308` was an internal error: a socket's timeout past
    about 1e10 s overflows the platform's time_t."""
    from stablepush.execution import TcpArm

    result = CliRunner().invoke(cli, ["execute", str(high_mu_plan), "--task", str(HIGH_MU), "--arm", "127.0.0.1:1",
                                      "--ack-timeout", "1e308"])
    assert result.exit_code == 2 and "Invalid value for '--ack-timeout'" in result.output, result.output
    for timeout in (1e308, 0.0, float("nan"), "5"):
        with pytest.raises(SettingError, match="ack_timeout"):
            TcpArm("127.0.0.1", 1, timeout)


@pytest.mark.parametrize("option, values", [("--feature-error", ["0.9", "1e308"]), ("--feature-error", ["1e5", "0"]),
                                            ("--tracker-noise", ["0", "4000"])])
def test_spreads_past_the_task_files_bounds_are_refused_naming_the_option(high_mu_plan, monkeypatch, option, values):
    """`evaluate --feature-error 0.9 1e308` overflowed numpy's uniform draw in every trial: exit 4."""
    monkeypatch.setattr(batch_mod, "run_plan", lambda *a, **k: pytest.fail("a trial ran"))
    result = CliRunner().invoke(cli, ["evaluate", str(HIGH_MU), "--plan", str(high_mu_plan), "--trials", "2",
                                      "--workers", "1", "--no-guard", option, *values, "--quiet"])
    assert result.exit_code == 2, result.output
    assert result.output.startswith(f"error: {option}: must be 2 numbers, not negative, at most 10000 mm and 3600 deg")
    with pytest.raises(SettingError):
        Spreads(feature_error=(0.0,))


def test_the_evaluation_figure_draws_a_study_of_crashes_and_of_one_world():
    """A study whose every trial crashed has no rate (None) and no interval, and a study of one world
    no interval: the figure's title unpacked both."""
    from stablepush.viz.figures import evaluation_figure

    task = shipped("horizontal-offset-high-mu")
    batch = batch_mod.Batch(task=task, plan=sp.plan_task(task), spreads=Spreads(vary={"pad_mu": 0.1}))
    crashed = [{"trial": i, "world": batch.world(i).as_dict(), **batch_mod._not_run("crash", "RuntimeError: x"),
                "wall_s": 0.0} for i in range(2)]
    evaluation = batch_mod.Evaluation(batch=batch, trials=crashed, wall_s=1.0, runner="this process", requested=2)
    figure = evaluation_figure(evaluation.summary(), crashed)
    assert figure.axes[0].get_title().endswith("all 2 trials crashed")
    one = dataclasses.replace(batch, spreads=Spreads())
    landed = [{**crashed[0], "cause": None, "success": True, "error": None}]
    summary = batch_mod.Evaluation(batch=one, trials=landed, wall_s=1.0, runner="this process", requested=1).summary()
    assert "1/1 landed (100.0%)" in evaluation_figure(summary, landed).axes[0].get_title()


def test_an_input_read_after_the_outputs_were_checked_is_refused_when_it_is_one_of_them(tmp_path):
    """A file a task names is read only as the task loads, after a command checked its outputs:
    protect_input refuses it then (before any work), and forget_outputs ends the command's claim."""
    from stablepush.errors import OutputError
    from stablepush.outputs import check_outputs, forget_outputs, protect_input

    model = tmp_path / "arm.urdf"
    model.write_text("<robot/>")
    check_outputs({"--json": str(model)}, {})
    try:
        with pytest.raises(OutputError, match="--json .*arm.urdf: is a robot model this process read; refusing"):
            protect_input(model, "a robot model")
    finally:
        forget_outputs()
    other = tmp_path / "other.urdf"
    other.write_text("<robot/>")
    protect_input(other, "a robot model")  # no command claims it
    with pytest.raises(OutputError, match="refusing to write over it"):
        check_outputs({"--json": str(other)}, {})
    forget_outputs()
