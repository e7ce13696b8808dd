"""Seeded mutation fuzzing of the CLI (run by tests/test_fuzz.py in a child process, so that a
crash by signal fails the test instead of killing pytest).

    python3 tests/fuzz_cli.py tasks N SEED SCRATCH    # N mutated task files: plan, and check every 4th
    python3 tests/fuzz_cli.py plans N SEED SCRATCH    # N mutated plan files of the shipped tasks: show
    python3 tests/fuzz_cli.py meshes N SEED SCRATCH   # N generated meshes (holes, two bodies, flat, huge,
                                                      # damaged; STL, OBJ, PLY, OFF): plan
    python3 tests/fuzz_cli.py semantics N SEED SCRATCH  # N valid plans that do not fit their task
                                                        # (short, reversed, other goal or model): trajectory
    python3 tests/fuzz_cli.py api N SEED SCRATCH      # N calls of the Python API with hostile arguments

Each case runs the CLI in this process (click's CliRunner) and must end with exit status 0, 1 or
2; a refusal (2) is one line on stderr starting "error:" (besides "warning:" lines); no
traceback, no internal error. The
case about to run is written to SCRATCH/current first (a crash leaves it there). The summary is
one JSON line on stdout: cases, exit statuses, the slowest case.
"""
from __future__ import annotations

import collections
import copy
import json
import math
import random
import sys
import time
from pathlib import Path

import yaml
from click.testing import CliRunner

from stablepush_cli.main import cli

ROOT = Path(__file__).resolve().parent.parent
TASKS = sorted((ROOT / "data" / "tasks").glob("*.yaml")) + sorted((ROOT / "data" / "tasks" / "more").glob("*.yaml"))

HOSTILE = [float("nan"), float("inf"), -float("inf"), 1.797e308, -1.797e308, 1e-300, 1e-160, 0, 0.0, -1, -0.5,
           2**31, 2**32, 2**62, 2**64, 10**400, 1e9, 1e30, "", "x", "1e-3", "../x", "/tmp/x", "a\x00b", None, True,
           False, [], {}, [1, 2], [[1, 2]], {"a": 1}, [0, 0, 0], [[0, 0], [0, 0], [0, 0]], "\u202e" * 5, "y" * 5000]


def _hostile(rng: random.Random):
    return copy.deepcopy(rng.choice(HOSTILE))  # a copy: the pool must not grow or loop as cases edit it


def _paths(node, prefix=()):
    """Every path into a YAML/JSON tree (containers and leaves)."""
    yield prefix
    if isinstance(node, dict):
        for key, value in node.items():
            yield from _paths(value, prefix + (key,))
    elif isinstance(node, list):
        for i, value in enumerate(node):
            yield from _paths(value, prefix + (i,))


def _mutate(data, rng: random.Random):
    """One to three random edits of a tree: a hostile value, a scaled number, a deleted or an
    unknown key, a nested value, a duplicated list entry."""
    data = copy.deepcopy(data)
    for _ in range(rng.randint(1, 3)):
        paths = [p for p in _paths(data) if p]
        if not paths:
            return _hostile(rng)
        path = rng.choice(paths)
        parent = data
        for key in path[:-1]:
            parent = parent[key]
        key, value = path[-1], parent[path[-1]]
        kind = rng.random()
        if kind < 0.45:
            parent[key] = _hostile(rng)
        elif kind < 0.65 and isinstance(value, (int, float)) and not isinstance(value, bool) and abs(value) < 1e300:
            parent[key] = value * 10.0 ** rng.randint(-12, 12) * rng.choice((1, -1))
        elif kind < 0.75 and isinstance(parent, dict):
            del parent[key]
        elif kind < 0.8 and isinstance(parent, dict):
            parent[rng.choice(["extra", "Name", 1, "name "])] = _hostile(rng)
        elif kind < 0.88:
            nested = value
            for _ in range(rng.choice((3, 50))):
                nested = [nested]
            parent[key] = nested
        elif isinstance(value, list) and value:
            value.append(copy.deepcopy(rng.choice(value)) if rng.random() < 0.5 else _hostile(rng))
        else:
            parent[key] = _hostile(rng)
    return data


def _text_mutation(text: str, rng: random.Random) -> str:
    """A whole-file mutation: truncated, a byte changed, an alias bomb, deep nesting, not UTF-8."""
    kind = rng.randrange(5)
    if kind == 0:
        return text[: rng.randrange(len(text))]
    if kind == 1:
        i = rng.randrange(len(text))
        return text[:i] + rng.choice("[]{}:&*!|>-'\"\t\n#%@`") + text[i + 1:]
    if kind == 2:
        bomb = "a: &a [x, x, x, x, x, x, x, x, x]\n" + "".join(
            f"{chr(98 + i)}: &{chr(98 + i)} [{', '.join(['*' + chr(97 + i)] * 9)}]\n" for i in range(8))
        return bomb + text
    if kind == 3:
        return text.replace("name:", "name: " + "[" * 3000 + "]" * 3000 + "\nx:", 1)
    return text.encode().replace(b"a", b"\xff", 3).decode("latin-1")


def run_tasks(count: int, seed: int, scratch: Path):
    rng = random.Random(seed)
    sources = [(path, path.read_text(), yaml.safe_load(path.read_text())) for path in TASKS]
    for case in range(count):
        path, text, data = rng.choice(sources)
        if rng.random() < 0.15:
            mutated = _text_mutation(text, rng)
        else:
            tree = _mutate(data, rng)
            try:
                mutated = yaml.safe_dump(tree, allow_unicode=True)
            except (yaml.YAMLError, ValueError, RecursionError):
                mutated = json.dumps(tree, default=str)
        task = scratch / "case.yaml"
        task.write_text(mutated, encoding="utf-8", errors="surrogateescape")
        args = ["plan", str(task), "--time-limit", "0.02", "-o", str(scratch / "out.plan.json"), "--quiet"]
        yield f"task {case} from {path.name}", args, mutated
        if case % 4 == 0:
            move = [rng.choice([1.0, 0.0, -1.0, 1e-160, float("nan"), 1e308, 0.5]) for _ in range(3)]
            yield (f"task {case} check", ["check", str(task), "--move", *map(repr, move)], mutated)
        if case % 8 == 0:
            at = [rng.choice([0.0, -1.0, 1e-160, float("nan"), 1e308, 5.0, -40.0]) for _ in range(3)]
            step = rng.choice(["10", "90", "0.7"])  # click refuses the rest itself, with its usage text
            yield (f"task {case} check --directions",
                   ["check", str(task), "--directions", "--at", *map(repr, at), "--heading-step", step], mutated)


def run_plans(count: int, seed: int, scratch: Path):
    from stablepush.plan import plan_task
    from stablepush.plan.files import plan_to_dict
    from stablepush.task import load_task

    rng = random.Random(seed)
    plans = []
    for path in TASKS[:5]:
        plans.append((path, plan_to_dict(plan_task(load_task(path), seed=1))))
    for case in range(count):
        path, plan = rng.choice(plans)
        if rng.random() < 0.1:
            text = _text_mutation(json.dumps(plan), rng)
        else:
            text = json.dumps(_mutate(plan, rng), default=str)  # NaN and inf written as JSON allows them
        plan_file = scratch / "case.plan.json"
        plan_file.write_text(text, encoding="utf-8", errors="surrogateescape")
        yield f"plan {case} of {path.name}", ["show", str(plan_file), "--task", str(path), "-o", str(scratch / "out.png")], text


def _mesh(rng: random.Random):
    """A generated solid, good or hostile: a box, a cylinder or a washer (a hole), two bodies, a
    flat or a huge one, or a solid with faces missing; with the x of its left side at z = 0 (mm)."""
    import numpy as np
    import trimesh

    kind = rng.choice(["box", "cylinder", "washer", "two", "flat", "huge", "open", "shaft", "dimpled"])
    turn = trimesh.transformations.rotation_matrix(math.pi / 2, [1, 0, 0])
    if kind in ("shaft", "dimpled"):  # pads on a round shaft along x; a puck with a dimple under the path
        radius, half = rng.uniform(5, 30), rng.uniform(3, 20)
        profile = ([(0, -half), (radius, -half), (radius, half), (0, half)] if kind == "shaft" else
                   [(0, -half + 0.5), (2, -half + 0.5), (2, -half), (radius, -half), (radius, half), (2, half),
                    (2, half - 0.5), (0, half - 0.5)])
        solid = trimesh.creation.revolve(np.array(profile, float), sections=16)
        axis = [0, 1, 0] if kind == "shaft" else [1, 0, 0]
        solid.apply_transform(trimesh.transformations.rotation_matrix(math.pi / 2 * (1 if kind == "shaft" else -1),
                                                                      axis))
        return kind, solid, float(solid.bounds[0, 0])
    if kind == "cylinder":
        radius = rng.uniform(5, 40)
        solid = trimesh.creation.cylinder(radius=radius, height=rng.uniform(5, 40), sections=32)
        solid.apply_transform(turn)
        return kind, solid, -radius
    if kind == "washer":
        radius = rng.uniform(12, 40)
        solid = trimesh.creation.annulus(r_min=rng.uniform(2, 10), r_max=radius, height=10.0, sections=32)
        solid.apply_transform(turn)
        return kind, solid, -radius
    if kind == "two":
        a, b = trimesh.creation.box([40, 25, 40]), trimesh.creation.box([40, 25, 40])
        b.apply_translation([rng.choice([45, 500]), 0, 0])
        return kind, trimesh.util.concatenate([a, b]), -20.0
    else:
        size = {"box": [rng.uniform(10, 80), rng.uniform(5, 40), rng.uniform(10, 80)], "flat": [40, 1e-4, 40],
                "huge": [4e6, 25, 40], "open": [60, 25, 40]}[kind]
        solid = trimesh.creation.box(size)
        if kind == "open":
            solid.update_faces(np.arange(len(solid.faces)) != 0)
    return kind, solid, -size[0] / 2


def run_meshes(count: int, seed: int, scratch: Path):
    """Generated meshes in every format the task files take (and garbage bytes), planned."""
    rng = random.Random(seed)
    for case in range(count):
        kind, solid, left = _mesh(rng)
        fmt = rng.choice(["stl", "obj", "ply", "off"])
        mesh_file = scratch / f"case.{fmt}"
        data = solid.export(file_type=fmt)
        data = data.encode() if isinstance(data, str) else data
        if rng.random() < 0.15:  # truncated or garbage
            data = data[: rng.randrange(len(data) + 1)] if rng.random() < 0.5 else bytes(rng.randrange(256)
                                                                                           for _ in range(200))
            kind += " damaged"
        mesh_file.write_bytes(data)
        obj = {"shape": "mesh", "file": mesh_file.name, rng.choice(["mass", "density"]): rng.choice([100, 2.7, 1e-3])}
        if rng.random() < 0.3:
            obj["scale"] = rng.choice([1e-3, 1.0, 1000.0, 1e-6])
        if rng.random() < 0.3:
            obj["plane_y"] = rng.choice([0.0, 5.0, -100.0, 1e9])
        task = {"name": "fuzz-mesh", "object": obj, "gripper": {"grip_force": 10, "mu": 0.5},
                "pushers": [{"name": "left", "from": [left, -1.0], "to": [left, 1.0], "mu": 0.5}],
                "start": [0, 0, 0], "goal": [3, 0, 0]}
        text = yaml.safe_dump(task)
        path = scratch / "case.yaml"
        path.write_text(text)
        yield f"mesh {case} ({kind}, {fmt})", ["plan", str(path), "--time-limit", "0.02", "-o",
                                                str(scratch / "out.plan.json"), "--quiet"], text


def run_semantics(count: int, seed: int, scratch: Path):
    """Valid plan files that do not fit their task: cut short, reversed, made for another goal or
    another model, with alternating pushers; given to trajectory (the arm's stream)."""
    import dataclasses

    from stablepush.plan import plan_task
    from stablepush.plan.files import plan_to_dict
    from stablepush.task import load_task

    rng = random.Random(seed)
    made = [(path, load_task(path)) for path in TASKS[:5]]
    made = [(path, task, plan_task(task, seed=1)) for path, task in made]
    for case in range(count):
        path, task, plan = rng.choice(made)
        how = rng.choice(["short", "reversed", "other-goal", "other-model", "alternating"])
        steps = list(plan.waypoints)
        if how == "short":
            steps = steps[: rng.randrange(1, len(steps))]
        elif how == "reversed":
            steps = steps[::-1]
        elif how == "alternating" and len(task.pushers) > 1:
            names = task.pusher_names
            steps = steps[:1] + [dataclasses.replace(w, pusher=names[i % 2]) for i, w in enumerate(steps[1:])]
        edited = plan
        if how == "other-goal":
            edited = plan_task(dataclasses.replace(task, goal=(task.goal[0] - 3, task.goal[1], task.goal[2])), seed=1)
            steps = list(edited.waypoints)
        if how == "other-model":
            edited = plan_task(dataclasses.replace(task, mu=task.mu * 2), seed=1)
            steps = list(edited.waypoints)
        text = json.dumps(plan_to_dict(dataclasses.replace(edited, waypoints=steps)))
        plan_file = scratch / "case.plan.json"
        plan_file.write_text(text)
        yield (f"plan {case} of {path.name} ({how})",
               ["trajectory", str(plan_file), "--task", str(path), "-o", str(scratch / "out.csv")], text[:2000])


API_ERRORS = ("StablepushError", "TypeError", "ValueError", "KeyboardInterrupt")


def run_api(count: int, seed: int, scratch: Path) -> None:
    """The Python API misused: sp.plan_task, sp.check, sp.check_plan, sp.trajectory and sp.save_plan with
    hostile arguments. Each call returns or raises a StablepushError, TypeError or ValueError;
    anything else (or a crash by signal, which kills this process) is a failure. Prints the summary."""
    import dataclasses

    import stablepush as sp

    rng = random.Random(seed)
    tasks = [sp.load_task(path) for path in TASKS[:5]]
    plans = [sp.plan_task(task, seed=1) for task in tasks]
    outcomes, failures, slowest = collections.Counter(), [], (0.0, "")

    def hostile():
        return rng.choice(HOSTILE + [(1, 2), (float("nan"),) * 3, (0, 0, 0), (1e308, 0, 0), "left", -5, 3.5])

    for case in range(count):
        k = rng.randrange(len(tasks))
        task, plan = tasks[k], plans[k]
        what = rng.choice(["plan", "check", "check_plan", "trajectory", "save_plan", "plan-models", "plan-edited"])
        if what == "plan":
            key = rng.choice(["seed", "time_limit", "max_switches", "improve_for", "min_transit_hold", "start_pusher"])
            call = lambda: sp.plan_task(task, **{key: hostile()}, **({} if key == "time_limit" else {"time_limit": 0.02}))  # noqa: E731
        elif what == "plan-models":
            call = lambda: sp.plan_task(task, models=rng.choice([[None], [], "x", [task], tasks[k - 1].corner_models()]),  # noqa: E731
                                   time_limit=0.02)
        elif what == "plan-edited":  # a Task edited past its loader's checks
            field = rng.choice(["mu", "grip_force", "mass", "start", "goal", "pads", "pushers", "gravity"])
            call = lambda: sp.plan_task(dataclasses.replace(task, **{field: hostile()}), time_limit=0.02)  # noqa: E731
        elif what == "check":
            call = lambda: sp.check(task, at=hostile(), move=hostile(), pusher=rng.choice([None, "left", hostile()]))  # noqa: E731
        elif what == "check_plan":
            steps = list(plan.waypoints)
            steps[rng.randrange(len(steps))] = rng.choice([None, "x", hostile()])
            call = lambda: sp.check_plan(task, dataclasses.replace(plan, waypoints=steps))  # noqa: E731
        elif what == "trajectory":
            call = lambda: sp.trajectory(task, plan, rate_hz=hostile())  # noqa: E731
        else:
            call = lambda: sp.save_plan(dataclasses.replace(plan, stats=hostile()), str(scratch / "api.plan.json"))  # noqa: E731
        label = f"api {case} {what} on {task.name}"
        (scratch / "current").write_text(label)
        started = time.perf_counter()
        try:
            call()
            outcomes["returned"] += 1
        except BaseException as exc:  # noqa: BLE001 - sorting what escaped is the point
            kinds = [c.__name__ for c in type(exc).__mro__]
            if any(kind in API_ERRORS for kind in kinds):
                outcomes["refused"] += 1
            else:
                failures.append({"case": label, "problem": f"{type(exc).__name__}: {str(exc)[:200]}"})
        slowest = max(slowest, (time.perf_counter() - started, label))
    print(json.dumps({"cases": count, "exit_statuses": dict(outcomes), "failures": failures[:20],
                      "failure_count": len(failures), "slowest_s": round(slowest[0], 3), "slowest": slowest[1]}))


def main() -> None:
    kind, count, seed, scratch = sys.argv[1], int(sys.argv[2]), int(sys.argv[3]), Path(sys.argv[4])
    if kind == "api":
        run_api(count, seed, scratch)
        return
    cases = {"tasks": run_tasks, "plans": run_plans, "meshes": run_meshes, "semantics": run_semantics}[kind](
        count, seed, scratch)
    runner = CliRunner()
    statuses, failures, slowest = collections.Counter(), [], (0.0, "")
    for label, args, content in cases:
        (scratch / "current").write_text(f"{label}\n{args}\n{content[:20000]}", errors="replace")
        started = time.perf_counter()
        result = runner.invoke(cli, args, catch_exceptions=True)
        elapsed = time.perf_counter() - started
        slowest = max(slowest, (elapsed, label))
        statuses[result.exit_code] += 1
        stderr = [line for line in result.stderr.splitlines() if line.strip() and not line.startswith("warning: ")]
        problem = None
        if result.exit_code not in (0, 1, 2):
            problem = f"exit {result.exit_code}: {result.stderr.strip()[-300:] or result.exception!r}"
        elif "Traceback" in result.output + result.stderr:
            problem = "a traceback"
        elif result.exit_code == 2 and (len(stderr) != 1 or not stderr[0].startswith("error: ")):
            problem = f"a refusal not in one 'error:' line: {stderr[:3]}"
        if problem:
            failures.append({"case": label, "args": args[:2], "problem": problem, "input": content[:300]})
    print(json.dumps({"cases": sum(statuses.values()), "exit_statuses": dict(statuses), "failures": failures[:20],
                      "failure_count": len(failures), "slowest_s": round(slowest[0], 3), "slowest": slowest[1]}))


if __name__ == "__main__":
    main()
