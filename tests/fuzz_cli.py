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
import contextlib
import copy
import json
import math
import os
import random
import re
import signal
import sys
import time
from pathlib import Path
from typing import List, Optional

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
            edited = plan_task(task.with_values({"gripper.mu": task.gripper.mu * 2}), seed=1)
            steps = list(edited.waypoints)
        text = json.dumps(plan_to_dict(dataclasses.replace(edited, waypoints=steps)))
        plan_file = scratch / "case.plan.json"
        plan_file.write_text(text)
        yield (f"plan {case} of {path.name} ({how})",
               ["trajectory", str(plan_file), "--task", str(path), "-o", str(scratch / "out.csv")], text[:2000])


# -- api, every public function and value type: generated wrong types and values --------------------

NAN, INF = float("nan"), float("inf")
BAD, MAYBE = "bad", "maybe"  # a value the task file would refuse; one that may be taken (a default, a quirk)


def _pool(kind: str, ctx: dict):
    """(good values, bad values) of an argument kind: the good ones are what the task file or the
    command line takes, the bad ones what either would refuse."""
    from stablepush.plan import SearchRules

    pools = {
        "count": ([1, 2], [0, -1, 1.5, NAN, "2", 10 ** 30, [1]]),
        "whole0": ([0, 1], [-1, 1.5, "1", NAN, 2 ** 70]),
        "seed": ([0, 1, 2 ** 32 - 1], [-1, 2 ** 32, 1.5, "1", NAN, 2 ** 64]),
        "time": ([0.01, 0.02], [0, -1.0, NAN, INF, "0.1", 1e300]),
        "rate": ([100.0, 50], [0, -1, NAN, INF, "100", 1e9, None]),
        "vary": ([{"pad_mu": 0.1}, {"mass": 0.05}], [{"pad_mu": -0.1}, {"pad_mu": 5}, {"heat": 0.1}, {"pad_mu": NAN},
                                                      "pad_mu", [("pad_mu", 0.1)], {"pad_mu": "0.1"}]),
        "pair": ([(0.0, 0.0), (0.1, 0.1)], [(-1, 0), (NAN, 0), (0,), "0 0", (1e308, 0), (0, INF), None]),
        "prob": ([0.5, 0.9], [0, 1, -0.1, NAN, "0.9", 1.5, None]),
        "confidence": ([0.9, 0.95], [0.5, 1, NAN, "0.95", 2]),
        "engine": (["mujoco"], ["bullet", "", 3, None, "MUJOCO"]),
        "bool": ([True, False], ["yes", "false", NAN]),
        "flag": ([True, False, 1, 0], []),  # an argument of the API alone, truthy as Python's
        "path_in": ([ctx["task_path"]], [ctx["folder"], ctx["fifo"], "/dev/null", ctx["missing"], 3, b"\xff", "",
                                         ctx["binary"]]),
        "plan_path": ([ctx["plan_path"]], [ctx["folder"], ctx["fifo"], "/dev/null", ctx["missing"], 3, "",
                                           ctx["binary"], ctx["task_path"]]),
        "path_out": ([ctx["out"] + ".json"], [ctx["folder"], "", ctx["task_path"], "/proc/self", 3, ctx["out"] + "/"]),
        # the plan file is not among them: this call reads no plan file (a plan read earlier is refused: protect_input)
        "csv_out": ([None, ctx["out"] + ".csv"], [ctx["folder"], ctx["task_path"], 3]),
        "pusher": (["left", None], ["", 3, "nobody", ["left"]]),
        "pose": ([(0, 0, 0), (1.0, 0.0, 0.0)], [(NAN, 0, 0), (0, 0), "000", (1e308, 0, 0), None, (0, 0, INF)]),
        "model": ([None, ctx["model"]], [ctx["folder"], ctx["fifo"], ctx["missing"], ctx["task_path"], 3, "",
                                         "/dev/null"]),
        "flange": (["hand"], ["", " ", 3, None]),
        "tcp": ([(0, 0, 110, 0, 180, 0)], [(NAN, 0, 110, 0, 180, 0), (0, 0, 110), (1e300, 0, 0, 0, 0, 0), "0 0 110",
                                           None]),
        "base": ([(0, 0, 0, 0)], [(0, 0, 0), (0, -1e5, 0, 0), (NAN, 0, 0, 0), "0"]),
        "speed": ([2.5, 1.0], [0, -1, 1e9, NAN, "2.5"]),
        "length": ([20.0, 150.0], [-50, 0, NAN, INF, 1e9, "20"]),
        "noise": ([0.0, 0.1], [-0.1, NAN, INF, 1e9, "0.1"]),  # a standard deviation: 0 is no noise
        "point": ([(0.0, 0.0), (-20.0, 5.0)], [(NAN, 0), (0,), "0 0", (1e308, 0), (0, INF), None]),  # mm in O
        "seconds0": ([None, 0, 0.01], [-1.0, NAN, INF, "0.1", 1e300]),  # a duration where 0 is none
        "name": (["left", "a pusher"], ["", " ", 3, "x" * 500, None]),  # a new pusher's name: any but empty
        "tolerance": ([None, (0.5, 0.5)], [(-1, 0), (NAN, 0), (0,), "0 0", (0, INF), (0.0, 0.5)]),
        "home": ([(450.0, 0.0, 300.0)], [(1e9, 0, 0), (NAN, 0, 0), (0, 0), "450 0 300"]),
        "features": ([{}, {"left": (0, 0, 0, 0)}], [{"left": (0, 0, 1e9, 0)}, {"left": (NAN, 0, 0, 0)}, {"left": (0,)},
                                                   ["left"], {3: (0, 0, 0, 0)}]),
        "rank": ([("fixtures", "margin"), ("margin",)], [("bogus",), ("fixtures", "fixtures"), (["arm"],), "fixtures",
                                                        (), 3]),
        "axis": ([(-1.0, 1.0, 2), (0.0, 0.0, 1)], [(NAN, 1, 2), (0, 1, 0), (0, 1, 10 ** 6), "0:1:2", (0, 1),
                                                   (0, INF, 2), (0, 1, 1.5)]),
        "grid": ([ctx["grid"]], [None, 3, ((-1.0, 1.0, 2), (0.0, 0.0, 1), (0.0, 0.0, 1)), ctx["task"]]),
        "layout_search": ([ctx["layout_search"]], [None, 3, {"time_limit": 0.05}, ctx["odds"]]),
        "odds": ([ctx["odds"]], [None, 3, ctx["spreads"], ctx["layout_search"]]),
        "rules": ([None, SearchRules(), SearchRules(start_pusher="left", min_transit_hold=1.0)],
                  [3, "left", SearchRules(start_pusher="nobody"), SearchRules(start_pusher=3),
                   SearchRules(min_transit_hold=NAN), SearchRules(min_transit_hold=-1.0),
                   SearchRules(min_transit_hold="1")]),
        "task": ([ctx["task"]], [None, ctx["task_path"], {"name": "x"}, ctx["plan"], 3]),
        "plan": ([ctx["plan"]], [None, ctx["plan_path"], ctx["task"], {"waypoints": []}, 3]),
        "runner": ([None], ["ray", 3, "local", ctx["task"]]),
        "spreads": ([ctx["spreads"]], [{"pad_mu": 0.1}, 3, "pad_mu=0.1"]),
        "study": ([ctx["study"]], [None, 3, ctx["task"], "study"]),
        "batch": ([ctx["batch"]], [None, 3, ctx["task"], "batch"]),
        "test": ([None, ctx["test"]], [3, "sprt", 0.9]),
        "workers": ([1, 2], [0, -2, 1.5, "2", 10 ** 6]),
        "ray_address": ([None], [3, ":::", "host:0", "127.0.0.1:٦٣٧٩"]),
        "robot": ([None, ctx["robot"]], ["arm.urdf", {"model": ctx["model"]}, 3]),
        "title": ([None, "a title", 3], []),  # matplotlib's to print
        "design_task": ([ctx["design_task"]], [None, "task.yaml", 3, ctx["task"]]),
        "candidates": ([ctx["candidates"]], [None, [], "left", [{"name": "left"}], 3]),
        "text": ([ctx["task_text"]], [None, 3, "", "name: [", {"name": 1}, b"\xff"]),
        "source": ([None, "mine.yaml"], [3, ["x"]]),
        "label": ([None, "mine.yaml", 3], []),  # a name in messages: any value will do
        "mu": ([0.5], [-1, NAN, INF, "0.5", 1e300]),
        "size": ([(640, 480)], [(0, 0), (-1, 5), (99999, 99999), "640x480", (640.5, 480)]),
        "deviation": ([ctx["deviation"]], [3, "none", {"mu_scale": 2}]),
    }
    return pools[kind]


def _api_table(sp, ctx):
    """function -> (callable, {parameter: kind}): every name of stablepush.__all__ that is a function
    or a value type, and the documented functions of the subpackages (design, evaluation, runners,
    reach, the simulated arm, the run's options)."""
    from stablepush.design import DesignOdds, LayoutSearch, design, evaluate_designs
    from stablepush.evaluation import Batch, SequentialTest, Spreads, evaluate
    from stablepush.execution.executor import RunOptions
    from stablepush.plan.reach import ReachGrid, reach_map
    from stablepush.runners import Runner
    from stablepush.sim.deviation import WorldDeviation
    from stablepush.sim.local_arm import SimulatedArm

    return {
        "load_task": (sp.load_task, {"path": "path_in"}),
        "parse_task": (sp.parse_task, {"text": "text", "source": "source"}),
        "load_plan": (sp.load_plan, {"path": "plan_path"}),
        "save_plan": (sp.save_plan, {"plan": "plan", "json_path": "path_out", "csv_path": "csv_out"}),
        "plan_task": (sp.plan_task, {"task": "task", "seed": "seed", "time_limit": "time", "max_switches": "whole0",
                                     "improve_for": "seconds0", "check_limit": "whole0", "rules": "rules"}),
        "check": (sp.check, {"task": "task", "at": "pose", "move": "pose", "pusher": "pusher"}),
        "check_plan": (sp.check_plan, {"task": "task", "plan": "plan", "source": "label",
                                       "require_solved": "flag"}),
        "trajectory": (sp.trajectory, {"task": "task", "plan": "plan", "rate_hz": "rate"}),
        "joint_path": (sp.joint_path, {"task": "task", "plan": "plan", "rate_hz": "rate", "robot": "robot"}),
        "plan_figure": (sp.plan_figure, {"task": "task", "plan": "plan", "title": "title"}),
        "Robot": (sp.Robot, {"model": "model", "flange": "flange", "tcp": "tcp", "base": "base",
                             "max_joint_speed": "speed"}),
        "Cell": (sp.Cell, {"home": "home", "retract": "length", "station_spacing": "length", "lane_offset": "length",
                           "features": "features", "end_on_feature": "bool", "robot": "robot"}),
        "PlannerSettings": (sp.PlannerSettings, {"time_limit": "time", "seed": "seed", "max_switches": "whole0"}),
        "PusherSpec": (sp.PusherSpec, {"name": "name", "a": "point", "b": "point", "mu": "mu", "points": "count"}),
        "Spreads": (Spreads, {"vary": "vary", "feature_error": "pair", "tracker_noise": "pair"}),
        "SequentialTest": (SequentialTest, {"target": "prob", "confidence": "confidence"}),
        "Runner": (Runner, {"workers": "workers", "ray": "bool", "ray_address": "ray_address"}),
        "Batch": (Batch, {"task": "task", "plan": "plan", "spreads": "spreads", "seed": "seed", "closed_loop": "bool",
                          "guarded": "bool", "engine": "engine", "tolerance": "pair", "video_fps": "rate",
                          "video_size": "size"}),
        "evaluate": (evaluate, {"batch": "batch", "trials": "count", "runner": "runner", "test": "test"}),
        "LayoutSearch": (LayoutSearch, {"max_fixtures": "count", "rank": "rank", "reach_top": "whole0",
                                        "time_limit": "time", "check_limit": "whole0"}),
        "design": (design, {"task": "design_task", "candidates": "candidates", "source": "source",
                            "search": "layout_search", "runner": "runner"}),
        "DesignOdds": (DesignOdds, {"trials": "count", "spreads": "spreads", "top": "count", "seed": "seed",
                                    "closed_loop": "bool", "engine": "engine"}),
        "evaluate_designs": (evaluate_designs, {"study": "study", "odds": "odds", "runner": "runner"}),
        "ReachGrid": (ReachGrid, {"x": "axis", "z": "axis", "theta": "axis"}),
        "reach_map": (reach_map, {"task": "task", "grid": "grid", "seed": "seed", "time_limit": "time",
                                  "check_limit": "whole0"}),
        "SimulatedArm": (SimulatedArm, {"engine": "engine", "deviation": "deviation", "robot": "robot"}),
        "WorldDeviation": (WorldDeviation, {"mu_scale": "mu", "tracker_noise_mm": "noise", "seed": "seed"}),
        "RunOptions": (RunOptions, {"rate_hz": "rate", "resume_from": "whole0", "pace": "bool",
                                    "success_tolerance": "tolerance"}),
    }


# Arguments the table must keep cheap when good: the fixed ones each call gets unless drawn.
API_FIXED = {"plan_task": {"time_limit": 0.02}, "reach_map": {"time_limit": 0.01}, "evaluate": {"trials": 1},
             "WorldDeviation": {}, "Runner": {"workers": 1}}
# Good values that the kind's pool would not give for this function.
API_GOOD = {("Cell", "retract"): [20.0], ("Cell", "lane_offset"): [75.0], ("WorldDeviation", "tracker_noise_mm"): [0.0],
            ("SimulatedArm", "robot"): [None], ("Runner", "workers"): [1], ("evaluate", "trials"): [1],
            ("plan_task", "improve_for"): [None], ("plan_task", "check_limit"): [None, 100000],
            ("reach_map", "check_limit"): [100000], ("PusherSpec", "points"): [2], ("Batch", "tolerance"): [None, (0.5, 0.5)]}


def _api_context(sp, scratch: Path) -> dict:
    from stablepush.design import DesignOdds, LayoutSearch, design
    from stablepush.evaluation import Batch, SequentialTest, Spreads
    from stablepush.plan.reach import ReachGrid
    from stablepush.sim.deviation import WorldDeviation
    from stablepush.task.design_file import load_design

    from generated_arms import urdf_arm

    folder = scratch / "in"
    folder.mkdir(exist_ok=True)
    task_path = folder / "task.yaml"
    task_path.write_text(LOW_MU.read_text())
    task = sp.load_task(task_path)
    plan = sp.plan_task(task, seed=1)
    plan_path = folder / "task.plan.json"
    sp.save_plan(plan, str(plan_path))
    data = yaml.safe_load(LOW_MU.read_text())
    data["candidates"] = [p for p in data.pop("pushers") if p["name"] in ("left", "bottom")]
    design_path = folder / "two.design.yaml"
    design_path.write_text(yaml.safe_dump(data))
    design_task, candidates = load_design(design_path)
    arm = urdf_arm(folder / "arm.urdf", 3, ("z", "y", "y", "z", "y", "z"))
    fifo = scratch / "fifo"
    if not fifo.exists():
        os.mkfifo(fifo)
    (scratch / "a-folder").mkdir(exist_ok=True)
    (folder / "binary.bin").write_bytes(bytes(range(256)))
    spreads = Spreads(vary={"pad_mu": 0.1})
    # cheap when good: layouts of one fixture, each searched within 100,000 tests, no reach map
    layout_search = LayoutSearch(max_fixtures=1, time_limit=0.05, reach_top=0, check_limit=100000)
    study = design(design_task, candidates, source=str(design_path), search=LayoutSearch(time_limit=0.05, reach_top=0))
    return {"task": task, "plan": plan, "task_path": str(task_path), "plan_path": str(plan_path),
            "task_text": LOW_MU.read_text(), "folder": str(scratch / "a-folder"), "fifo": str(fifo),
            "missing": str(scratch / "missing.yaml"), "binary": str(folder / "binary.bin"),
            "out": str(scratch / "out" / "api"),
            "model": arm["model"], "robot": sp.Robot(model=arm["model"], flange="tool0", tcp=arm["tcp"]),
            "spreads": spreads, "study": study, "batch": Batch(task=task, plan=plan, spreads=spreads),
            "test": SequentialTest(target=0.5), "design_task": design_task, "candidates": candidates,
            "deviation": WorldDeviation(), "grid": ReachGrid((-1.0, 1.0, 2), (0.0, 0.0, 1), (0.0, 0.0, 1)),
            "layout_search": layout_search, "odds": DesignOdds(1, spreads, top=1)}


class _Work:
    """Probes on the work a call may start (the planner's search, a batch's trials, a design's or
    a reach map's jobs): which one started, if any; a batch's trials land without a simulation."""

    def __init__(self):
        from stablepush import _core, runners
        from stablepush.design import layouts
        from stablepush.evaluation import batch

        self.started = None
        for module, name in ((_core, "plan"), (runners, "run_all"), (layouts, "run_all"), (batch, "run_all")):
            setattr(module, name, self._probe(f"{module.__name__}.{name}", getattr(module, name)))
        batch.run_trial = _landed

    def _probe(self, label, original):
        def probe(*args, **kwargs):
            self.started = self.started or label
            return original(*args, **kwargs)

        return probe


def run_api_surface(rng: random.Random, count: int, scratch: Path, tally: "Tally") -> None:
    """`count` calls of the public functions and value types (_api_table), each with one or two
    arguments drawn: a bad one (what the task file or the CLI refuses) three times in four, the
    rest good. A call may only return or raise a StablepushError, or a TypeError for a wrong type;
    a bad argument must be refused, and before any work (_Work) starts."""
    import stablepush as sp
    from stablepush.errors import StablepushError

    (scratch / "out").mkdir(exist_ok=True)
    ctx = _api_context(sp, scratch)
    work = _Work()
    table = _api_table(sp, ctx)
    for case in range(count):
        name = rng.choice(sorted(table))
        function, params = table[name]
        kwargs = dict(API_FIXED.get(name, {}))
        for param, kind in params.items():
            if param not in kwargs:
                good = API_GOOD.get((name, param)) or _pool(kind, ctx)[0]
                kwargs[param] = rng.choice(good)
        drawn = {}
        for param in rng.sample(sorted(params), min(len(params), rng.choice([1, 1, 2]))):
            good, bad = _pool(params[param], ctx)
            good = API_GOOD.get((name, param)) or good
            is_bad = bool(bad) and rng.random() < 0.75
            value = copy.copy(rng.choice(bad if is_bad else good))
            kwargs[param], drawn[param] = value, is_bad
        label = f"api {case} {name}({', '.join(f'{k}={kwargs[k]!r:.60}' for k in drawn)})"
        work.started = None
        with tally.case(label):
            try:
                function(**kwargs)
                tally.count("returned")
                if any(drawn.values()):
                    tally.fail(label, f"a bad value was taken: {[k for k, b in drawn.items() if b]}")
            except (StablepushError, TypeError) as exc:
                tally.count("refused")
                if any(drawn.values()) and work.started:
                    tally.fail(label, f"{work.started} started before the refusal: {type(exc).__name__}: "
                                      f"{str(exc)[:150]}")
            except Exception as exc:  # noqa: BLE001 - what escapes is the finding
                tally.count("escaped")
                tally.fail(label, f"{type(exc).__name__}: {str(exc)[:200]}")


def run_api(count: int, seed: int, scratch: Path) -> None:
    """The Python API misused, 2 x `count` calls: `count` of sp.plan_task, sp.check, sp.check_plan,
    sp.trajectory and sp.save_plan with hostile arguments, then `count` of every public function
    and value type with generated wrong types and values (run_api_surface). Each call returns or
    raises a StablepushError, or a TypeError for a wrong type; anything else (or a crash by
    signal, which kills this process) is a failure. Prints the summary."""
    import dataclasses

    import stablepush as sp
    from stablepush.errors import StablepushError
    from stablepush.plan import SearchRules

    rng = random.Random(seed)
    tasks = [sp.load_task(path) for path in TASKS[:5]]
    plans = [sp.plan_task(task, seed=1) for task in tasks]
    tally = Tally(scratch)

    def hostile():
        return rng.choice(HOSTILE + [(1, 2), (float("nan"),) * 3, (0, 0, 0), (1e308, 0, 0), "left", -5, 3.5])

    for case in range(count):
        k = rng.randrange(len(tasks))
        task, plan = tasks[k], plans[k]
        what = rng.choice(["plan", "check", "check_plan", "trajectory", "save_plan", "plan-edited"])
        if what == "plan":
            key = rng.choice(["seed", "time_limit", "max_switches", "improve_for", "min_transit_hold", "start_pusher"])
            given = {"rules": SearchRules(**{key: hostile()})} if key in ("min_transit_hold", "start_pusher") else {
                key: hostile()}
            call = lambda: sp.plan_task(task, **given, **({} if key == "time_limit" else {"time_limit": 0.02}))  # noqa: E731
        elif what == "plan-edited":  # a Task edited past its loader's checks: a quantity by its path, or a field
            field = rng.choice(["gripper.mu", "gripper.grip_force", "object.mass", "pushers.left.mu", "start", "goal",
                                "gripper.pads", "object", "pushers", "gravity"])
            call = lambda: sp.plan_task(_edited(task, field, hostile()), time_limit=0.02)  # noqa: E731
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
        with tally.case(label):
            try:
                call()
                tally.count("returned")
            except (StablepushError, TypeError):
                tally.count("refused")
            except Exception as exc:  # noqa: BLE001 - what escapes is the finding
                tally.count("escaped")
                tally.fail(label, f"{type(exc).__name__}: {str(exc)[:200]}")
    run_api_surface(rng, count, scratch, tally)
    print(json.dumps(tally.summary()))


def _edited(task, field: str, value):
    """`task` with `field` set to `value`: gripper.pads in its group, another dotted path through
    Task.with_values, else a field of the Task."""
    import dataclasses

    if field == "gripper.pads":
        return dataclasses.replace(task, gripper=dataclasses.replace(task.gripper, pads=value))
    if "." in field:
        return task.with_values({field: value})
    return dataclasses.replace(task, **{field: value})


# -- shared by the generated kinds: a bound on each case, a tally, the judge of a CLI result -------

CASE_LIMIT_S = 60.0  # a case past this is a hang (SIGALRM); one stuck in C past HARD_LIMIT_S ends the worker


class CaseTimeout(BaseException):
    """A case that ran past CASE_LIMIT_S (raised in the main thread by SIGALRM: no `except
    Exception` of the library or the CLI catches it)."""


def _on_alarm(_signum, _frame):
    raise CaseTimeout()


class Tally:
    """Counts per exit status, failures, the slowest case; a watchdog thread that, should a case
    be stuck where SIGALRM cannot reach it (a blocking call in C), prints the summary with that
    case as a hang and ends the worker (exit 3)."""

    HARD_LIMIT_S = CASE_LIMIT_S + 60.0

    def __init__(self, scratch: Path):
        import threading

        self.scratch, self.statuses, self.failures, self.slowest = scratch, collections.Counter(), [], (0.0, "")
        self.label, self.started = None, None
        signal.signal(signal.SIGALRM, _on_alarm)
        threading.Thread(target=self._watch, daemon=True).start()

    def _watch(self):
        while True:
            time.sleep(1.0)
            started, label = self.started, self.label
            if started is not None and time.perf_counter() - started > self.HARD_LIMIT_S:
                self.failures.append({"case": label, "problem": f"hang: still running after {self.HARD_LIMIT_S:.0f} s "
                                                                 f"(not interruptible; the worker stopped here)"})
                print(json.dumps(self.summary()), flush=True)
                os._exit(3)

    @contextlib.contextmanager
    def case(self, label: str, detail: str = ""):
        (self.scratch / "current").write_text(f"{label}\n{detail[:20000]}", errors="replace")
        self.label, self.started = label, time.perf_counter()
        signal.setitimer(signal.ITIMER_REAL, CASE_LIMIT_S)
        try:
            yield
        except CaseTimeout:
            self.count("hang")
            self.fail(label, f"hang: still running after {CASE_LIMIT_S:.0f} s", detail)
        finally:
            signal.setitimer(signal.ITIMER_REAL, 0)
            self.slowest = max(self.slowest, (time.perf_counter() - self.started, label))
            self.started = None

    def count(self, status) -> None:
        self.statuses[str(status)] += 1

    def fail(self, label: str, problem: str, detail: str = "") -> None:
        """A failure, kept (the summary shows 20) and appended to SCRATCH/failures.jsonl (all)."""
        self.failures.append({"case": label, "problem": problem, "input": detail[:600]})
        with open(self.scratch / "failures.jsonl", "a") as out:
            out.write(json.dumps(self.failures[-1]) + "\n")

    def summary(self) -> dict:
        kinds = collections.Counter(re.sub(r"[0-9]+|'[^']*'|\([^)]*\)", "#", f"{f['case'].split(' ')[2]}: {f['problem']}")[:120]
                                    for f in self.failures)
        return {"cases": sum(self.statuses.values()), "exit_statuses": dict(self.statuses),
                "failures": self.failures[:20], "failure_count": len(self.failures),
                "failure_kinds": dict(kinds.most_common(30)),
                "slowest_s": round(self.slowest[0], 3), "slowest": self.slowest[1]}


def judge(result, allowed=(0, 1, 2)) -> Optional[str]:
    """What is wrong with a CLI result, if anything: an exit status outside `allowed`, a
    traceback, an internal error, or a refusal (2) that is neither one `error:` line nor click's
    own usage error ("Usage: ..." and one "Error: ..." line)."""
    text = result.output + result.stderr
    stderr = [line for line in result.stderr.splitlines() if line.strip() and not line.startswith("warning: ")]
    if result.exit_code not in allowed:
        return f"exit {result.exit_code}: {result.stderr.strip()[-300:] or result.exception!r}"
    if "Traceback" in text or "internal error" in text:
        return "a traceback or an internal error"
    if result.exception is not None and not isinstance(result.exception, SystemExit):
        return f"an exception escaped: {type(result.exception).__name__}: {str(result.exception)[:200]}"
    if result.exit_code == 2:
        usage = any(line.startswith("Usage: ") for line in stderr) and sum(
            line.startswith("Error: ") for line in stderr) == 1
        if not usage and (len(stderr) != 1 or not stderr[0].startswith("error: ")):
            return f"a refusal not in one 'error:' line: {stderr[:3]}"
    return None


def _digest(paths) -> dict:
    import hashlib

    return {str(p): hashlib.sha256(Path(p).read_bytes()).hexdigest() for p in paths if Path(p).is_file()}


# -- options: every command's options generated from its click parameters --------------------------

LOW_MU = ROOT / "data" / "tasks" / "horizontal-offset-low-mu.yaml"
OUTPUT_PARAMS = {"json_path", "csv_path", "png_path", "gif_path", "out_path", "out_dir", "record_path", "video_path",
                 "video_dir"}
LEGAL = 0.8  # the chance that an option's value is drawn from the legal ones (so that most cases get past parsing)
REAL = 0.25  # the chance that evaluate, design --evaluate and execute --sim simulate (else stand-ins, below)

# Legal values kept cheap: (command or "*", parameter) -> values. Hostile ones come from the type.
CHEAP = {
    ("plan", "time_limit"): ["0.05", "1e-6", "0.01"], ("bench", "time_limit"): ["0.02", "1e-6"],
    ("bench", "trials"): ["1", "2"], ("bench", "count"): ["1", "50", "2000"], ("bench", "improve_for"): ["0", "0.02"],
    ("design", "time_limit"): ["0.05", "1e-6"], ("design", "check_limit"): ["0", "1", "100000"],
    ("design", "reach_top"): ["0", "1"], ("design", "trials"): ["1", "2"], ("design", "evaluate_top"): ["1", "2"],
    ("reach", "time_limit"): ["0.01", "1e-6"], ("reach", "check_limit"): ["0", "1", "10000"],
    ("evaluate", "trials"): ["1", "2"], ("*", "workers"): ["1", "2"], ("execute", "resume_from"): ["0", "1", "21", "22"],
    ("execute", "ack_timeout"): ["0.01", "5", "3600"], ("sim-arm", "idle_timeout"): ["0.1", "2"],
    ("sim-arm", "port"): ["0"], ("sim-arm", "exit_after"): ["1", "5"], ("*", "video_fps"): ["1", "5", "25"],
    ("*", "seed"): ["0", "1", "4294967295"], ("plan", "max_switches"): ["0", "1", "100"],
}


class Scene:
    """The files a case may name: good inputs (a task, its plan, a design file, two arms), hostile
    paths (a folder, a FIFO nobody writes, /dev/null, a missing file, an empty and a binary file),
    outputs (fresh names, a FIFO drained by a thread, an input's own name), and a TCP port that
    accepts but is no Ray head nor arm."""

    def __init__(self, scratch: Path):
        import socket
        import threading

        import stablepush as sp

        from generated_arms import mjcf_arm, urdf_arm

        self.scratch = scratch
        folder = scratch / "in"
        folder.mkdir(exist_ok=True)
        self.task = folder / "task.yaml"
        self.task.write_text(LOW_MU.read_text())
        self.plan = folder / "task.plan.json"
        sp.save_plan(sp.plan_task(sp.load_task(self.task)), str(self.plan))
        design = yaml.safe_load(LOW_MU.read_text())
        design["candidates"] = design.pop("pushers")
        self.design = folder / "two.design.yaml"
        self.design.write_text(yaml.safe_dump(design))
        self.urdf = urdf_arm(folder / "arm.urdf", 3, ("z", "y", "y", "z", "y", "z"))
        self.mjcf = mjcf_arm(folder / "arm.xml", 5, ("z", "x", "z", "-x", "z", "x", "z"))
        self.empty = folder / "empty.yaml"
        self.empty.write_text("")
        self.binary = folder / "binary.json"
        self.binary.write_bytes(bytes(range(256)) * 4)
        self.folder = scratch / "a-folder"
        self.folder.mkdir(exist_ok=True)
        self.fifo_in, self.fifo_out = scratch / "fifo-in", scratch / "fifo-out"
        for fifo in (self.fifo_in, self.fifo_out):
            if not fifo.exists():
                os.mkfifo(fifo)
        threading.Thread(target=self._drain, daemon=True).start()
        self.listener = socket.socket()
        self.listener.bind(("127.0.0.1", 0))
        self.listener.listen(16)
        self.silent_port = self.listener.getsockname()[1]  # accepts, answers nothing
        threading.Thread(target=self._accept, daemon=True).start()
        self.inputs = [self.task, self.plan, self.design, Path(self.urdf["model"]), Path(self.mjcf["model"]), self.empty,
                       self.binary]
        self.pristine = {str(p): p.read_bytes() for p in self.inputs}
        self.digests = _digest(self.inputs)

    def _drain(self):
        while True:
            with open(self.fifo_out, "rb") as fifo:
                while fifo.read(65536):
                    pass

    def _accept(self):
        held = []
        while True:
            connection, _ = self.listener.accept()
            held = (held + [connection])[-16:]

    def input_path(self, rng, good: Path) -> str:
        if rng.random() < 0.85:
            return str(good)
        return str(rng.choice([self.folder, self.fifo_in, "/dev/null", self.scratch / "missing.yaml", self.empty,
                               self.binary, self.task, self.plan, self.design, self.urdf["model"], "", "/proc/self/mem"]))

    def output_path(self, rng, suffixes) -> str:
        if rng.random() < 0.7:
            return str(self.scratch / "out" / f"o{rng.randrange(100)}{rng.choice(suffixes)}")
        return str(rng.choice([self.folder, self.fifo_out, "/dev/null", "/dev/full", self.scratch / "no" / "dir" / "x",
                               "", str(self.scratch / "out") + "/", ".", "..", self.task, self.plan, self.design,
                               self.urdf["model"], self.mjcf["model"], "/proc/self", self.scratch / "out" / "x.unknown"]))

    def changed_inputs(self) -> List[str]:
        """Inputs a case wrote over (each put back)."""
        now = _digest(self.inputs)
        changed = [p for p in self.digests if now.get(p) != self.digests[p]]
        for path in changed:
            Path(path).write_bytes(self.pristine[path])
        return changed


def _finite_text(t, rng, legal: bool) -> str:
    lo, hi = t.min, t.max
    if legal:
        edges = ([lo] if lo is not None and not t.min_open else []) + ([hi] if hi is not None and not t.max_open else [])
        a = lo if lo is not None else -1e3
        b = hi if hi is not None else a + 1e3
        inside = a + (b - a) * rng.choice([0.5, 0.25, 1e-9, 0.999])
        return repr(float(rng.choice(edges + [inside, inside])))
    out = ["nan", "inf", "-inf", "1e400", "-1e400", "abc", "", " ", "٣", "３", "0x10", "1,5", "-0"]
    if lo is not None:
        out += [repr(lo - 1), repr(lo - 1e-12) if lo else "-1e-300", repr(lo) if t.min_open else "-1"]
    if hi is not None:
        out += [repr(hi * 2 + 1), repr(hi) if t.max_open else "1e308"]
    return rng.choice(out)


def _whole_text(t, rng, legal: bool) -> str:
    lo = t.min if t.min is not None else -(2 ** 31)
    hi = t.max if t.max is not None else 2 ** 31
    if legal:
        return str(rng.choice([lo, min(hi, lo + 1), min(hi, lo + 2), hi if hi < 10 ** 6 else lo + 3]))
    return rng.choice([str(lo - 1), str(hi + 1), "1.5", "1e3", "٢", "", "x", str(2 ** 64), "-0", " 1", "0b1"])


def _real_text(rng, legal: bool) -> str:
    if legal:
        return rng.choice(["0", "1", "-1", "110", "180", "0.5", "5", "-40", "-0", "1e-3"])
    return rng.choice(["nan", "inf", "-inf", "1e308", "-1e308", "1e-300", "x", "٣", "", "1e400", "1e9"])


STRINGS = {
    "ray_address": lambda r, s: r.choice(["127.0.0.1:1", "notanaddress", ":::", f"127.0.0.1:{s.silent_port}",
                                          "host:0", "[::1]:x", "127.0.0.1:٦٣٧٩", ""]),
    "rank_text": lambda r, s: r.choice(["margin", "arm,fixtures", "margin,margin", "speed", "", ",", "success",
                                        "time,reach,pushes", "fixtures,points,end,switches,margin,pushes,reach,tests"]),
    "vary": lambda r, s: f"{r.choice(['pad_mu', 'pusher_mu', 'grip_force', 'mass', '', 'heat', 'pad_mu=1'])}="
                         f"{r.choice(['0.1', '0', '-0', '0.9', '1', 'nan', '-1', '1e308', ''])}",
    "pusher": lambda r, s: r.choice(["left", "right", "bottom", "", "nobody", "left,right", "'", "Left"]),
    "flange": lambda r, s: r.choice(["tool0", "flange", "hand", "", "fl'ange", "link1", "object", "nope", " ", "G"]),
    "stamp_ns": lambda r, s: r.choice(["0", "-1", "1764600000.5", "2026-12-01T15:00:00Z", "2026-12-01T15:00:00",
                                       "1e30", "nan", "٣", "", "99999999999999999999999"]),
    "video_size": lambda r, s: r.choice(["640x480", "64x48", "0x0", "1x1", "99999x99999", "x", "-1x5", "", "640"]),
    "x_axis": lambda r, s: r.choice(["-1:1:2", "0:0:1", "0:1:0", "nan:1:2", "0:inf:2", "0:1", "a:b:c", "0:1:٢", "",
                                     "-1e5:1:2", "0:1:100000", "::", "0:1:2:3", "-0:-0:1"]),
    "host": lambda r, s: r.choice(["127.0.0.1", "", "999.1.1.1", "localhost", "::1", "not a host", "127.0.0.1 "]),
    "arm": lambda r, s: r.choice(["127.0.0.1:1", "x:٣", "", "host", f"127.0.0.1:{s.silent_port}", "127.0.0.1:99999"]),
}
STRINGS["z_axis"] = STRINGS["theta_axis"] = STRINGS["x_axis"]
SUFFIXES = {"json_path": [".json"], "csv_path": [".csv"], "png_path": [".png", ".svg", ".jpg", ".pdf", ".txt"],
            "gif_path": [".gif", ".png"], "out_path": [".csv", ".json", ".mcap", ".txt"], "out_dir": ["", "/"],
            "record_path": [".mcap", ".json"], "video_path": [".mp4", ".gif", ".avi"], "video_dir": ["", "/"]}


def _option_value(command: str, param, rng, scene: Scene) -> List[str]:
    """One option's words on the command line: drawn from its type (legal three times in ten...
    LEGAL), cheap legal values for the costly ones (CHEAP)."""
    import click

    name, t = param.name, param.type
    if param.is_flag if isinstance(param, click.Option) else False:
        return [rng.choice([param.opts[0]] + list(param.secondary_opts))]
    words = []
    hostile = -1 if rng.random() < LEGAL else rng.randrange(param.nargs)  # the one word drawn hostile, if any
    for k in range(param.nargs):
        legal = k != hostile
        cheap = CHEAP.get((command, name)) or CHEAP.get(("*", name))
        if name in OUTPUT_PARAMS:
            words.append(scene.output_path(rng, SUFFIXES[name]))
        elif name == "robot_model":
            words.append(scene.input_path(rng, Path(rng.choice([scene.urdf, scene.mjcf])["model"])))
        elif name == "task_file":
            words.append(scene.input_path(rng, scene.task))
        elif name == "plan_file":
            words.append(scene.input_path(rng, scene.plan))
        elif cheap and legal:
            words.append(rng.choice(cheap))
        elif isinstance(t, click.Choice):
            words.append(rng.choice(list(t.choices)) if legal else rng.choice(["", "bogus", t.choices[0].upper()]))
        elif isinstance(t, click.IntRange):
            words.append(_whole_text(t, rng, legal))
        elif isinstance(t, click.FloatRange):
            words.append(_finite_text(t, rng, legal))
        elif isinstance(t, click.types.FloatParamType):
            words.append(_real_text(rng, legal))
        elif name in STRINGS:
            words.append(STRINGS[name](rng, scene))
        else:
            words.append(rng.choice(["", "x", "-1", "nan", "\u202e", "y" * 500]))
    return [param.opts[0], *words] if isinstance(param, click.Option) else words


# What a command is given whatever else is drawn, unless drawn itself: the cheap bounds.
DEFAULTS = {
    "plan": {"time_limit": ["--time-limit", "0.05"], "quiet": ["--quiet"]},
    "bench": {"trials": ["--trials", "1"], "time_limit": ["--time-limit", "0.02"], "count": ["-n", "50"]},
    "design": {"time_limit": ["--time-limit", "0.05"], "workers": ["--workers", "1"], "reach_top": ["--reach-top", "0"],
               "quiet": ["--quiet"]},
    "reach": {"time_limit": ["--time-limit", "0.01"], "workers": ["--workers", "1"], "x_axis": ["--x", "-1:1:2"],
              "z_axis": ["--z", "0:0:1"], "theta_axis": ["--theta", "0:0:1"], "quiet": ["--quiet"]},
    "evaluate": {"trials": ["--trials", "1"], "workers": ["--workers", "1"], "quiet": ["--quiet"]},
    "execute": {"pace": ["--no-pace"], "quiet": ["--quiet"]},
    "sim-arm": {"port": ["--port", "0"], "idle_timeout": ["--idle-timeout", "2"]},
}


def options_case(command: str, rng, scene: Scene) -> List[str]:
    """A command line for `command`: its arguments, its required options, 0-5 of its other
    options (the robot's four together now and then), each drawn from its click parameter."""
    import click

    from stablepush_cli.main import cli

    params = cli.commands[command].params
    args = [command]
    for param in params:
        if isinstance(param, click.Argument):
            if param.nargs == -1:  # bench: one or two task files
                args += [scene.input_path(rng, scene.task) for _ in range(rng.choice([1, 1, 2]))]
            elif param.name == "design_file":
                args.append(scene.input_path(rng, scene.design))
            else:
                args += _option_value(command, param, rng, scene)
    required = [p for p in params if isinstance(p, click.Option) and p.required]
    optional = [p for p in params if isinstance(p, click.Option) and not p.required]
    drawn = required + rng.sample(optional, rng.randint(0, min(5, len(optional))))
    names = {p.name for p in drawn}
    if {"robot_model", "flange", "tcp"} <= {p.name for p in params} and rng.random() < 0.3:
        arm = rng.choice([scene.urdf, scene.mjcf])
        args += ["--robot", arm["model"], "--flange", arm["flange"], "--tcp", *map(str, arm["tcp"])]
        names |= {"robot_model", "flange", "tcp"}
        drawn = [p for p in drawn if p.name not in ("robot_model", "flange", "tcp")]
    if command == "check" and not names & {"move", "directions"}:
        args += ["--move", *rng.choice([["1", "0", "0"], ["0", "1", "0"], ["0", "0", "1"], ["-1", "0", "0.5"]])]
    if command == "execute" and not names & {"arm", "sim"}:
        args.append(rng.choice(["--sim", "--sim", "--sim", "--arm"]))
        if args[-1] == "--arm":
            args.append(STRINGS["arm"](rng, scene))
    for param in drawn:
        args += _option_value(command, param, rng, scene)
    for name, words in DEFAULTS.get(command, {}).items():
        if name not in names:
            args += words
    return args


class _NoWorld:
    """execute's simulated arm, refusing to build its world: the run faults at its hello (exit 3)
    once every option has been taken, without a simulation."""

    name = "fuzz arm"

    def __init__(self, engine="mujoco", deviation=None, log=None, robot=None):
        self.engine, self.deviation, self.connected, self.robot = engine, deviation, False, robot

    def check_cell(self, task, plan, rate_hz):
        return None

    def robot_description(self):
        from stablepush.kinematics.robot import robot_description

        return robot_description(self.robot)

    def hello(self, scene, rate_hz, resume):
        from stablepush.execution.arm import ArmError

        raise ArmError("fuzz: no world is built here")

    move = hello

    def stop(self):
        return None

    close = stop


def _landed(batch, trial):
    """A trial that draws its world as run_trial does, and lands, without a simulation."""
    return {"trial": trial, "world": batch.world(trial).as_dict(), "goal_error": None, "final_error": None,
            "replans": 0, "sim_time_s": 1.0, "wall_s": 0.0, "verdict": None, "error": None, "success": True,
            "cause": None}


def _sim_arm(args: List[str]):
    """sim-arm in a child process (it serves until interrupted): refused at once (exit 2, one
    line), or listening: sent a line that is no message, then Ctrl-C, after which it must exit 0.
    Returns its exit status ("hang" if it would not end) and what is wrong, if anything."""
    import socket
    import subprocess

    child = subprocess.Popen([sys.executable, "-c", "from stablepush_cli.main import cli; cli(prog_name='stablepush')",
                              *args], stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                             # a test worker may ignore SIGINT, and an ignored SIGINT survives exec: the child
                             # would never see the Ctrl-C this harness sends
                             preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL))
    try:
        line, lines = "", []
        deadline = time.monotonic() + 30
        while time.monotonic() < deadline:
            line = child.stderr.readline()
            lines.append(line)
            if "listening on" in line or not line:
                break
        if "listening on" in line:
            port = int(line.split("listening on ")[1].split(" ")[0].rsplit(":", 1)[1])
            host = "::1" if "listening on ::1" in line else "127.0.0.1"
            with socket.create_connection((host, port), timeout=10) as connection:
                connection.sendall(b"not a message\n")
                connection.recv(4096)
            child.send_signal(signal.SIGINT)
        _, err = child.communicate(timeout=30)
    except subprocess.TimeoutExpired:
        child.kill()
        child.communicate()
        return "hang", "hang: sim-arm did not exit"
    err, code = "".join(lines) + err, child.returncode
    lines = [x for x in err.splitlines() if x.strip() and not x.startswith(("warning: ", "sim-arm: "))]
    if code not in (0, 2) or "Traceback" in err or "internal error" in err:
        return code, f"exit {code}: {err.strip()[-300:]}"
    if code == 2 and not (any(x.startswith("Error: ") for x in lines) or
                          (len(lines) == 1 and lines[0].startswith("error: "))):
        return code, f"a refusal not in one 'error:' line: {lines[:3]}"
    return code, None


def run_options(count: int, seed: int, scratch: Path) -> None:
    """`count` command lines per command that `stablepush --help` lists, generated from each
    command's click parameters; prints the summary (statuses keyed "command:status")."""
    import shlex

    import stablepush.sim.local_arm as local_arm
    from stablepush.evaluation import batch as batch_mod
    from stablepush_cli.main import cli

    rng = random.Random(seed)
    scene = Scene(scratch)
    (scratch / "out").mkdir(exist_ok=True)
    os.chdir(scratch / "out")  # where the default outputs (named after the task) go
    tally = Tally(scratch)
    real_trial, real_arm = batch_mod.run_trial, local_arm.SimulatedArm
    runner = CliRunner()
    for case in range(count):
        for command in sorted(cli.commands):
            args = options_case(command, rng, scene)
            label = f"options {case} {command}"
            detail = shlex.join(args)
            if command == "sim-arm":
                with tally.case(label, detail):
                    code, problem = _sim_arm(args)
                    tally.count(code)
                    tally.count(f"{command}:{code}")
                    if problem:
                        tally.fail(label, problem, detail)
                continue
            real = rng.random() < REAL
            batch_mod.run_trial = real_trial if real else _landed
            local_arm.SimulatedArm = real_arm if real else _NoWorld
            with tally.case(label + (" (simulated)" if real else ""), detail):
                result = runner.invoke(cli, args, catch_exceptions=True)
                tally.count(result.exit_code)
                tally.count(f"{command}:{result.exit_code}")
                problem = judge(result, (0, 1, 2, 3, 5) if command == "execute" else (0, 1, 2, 3))
                changed = scene.changed_inputs()
                if changed:
                    problem = f"an input was written over: {changed}"
                if problem:
                    tally.fail(label, problem, detail)
    batch_mod.run_trial, local_arm.SimulatedArm = real_trial, real_arm
    summary = tally.summary()
    summary["cases"] = sum(v for k, v in tally.statuses.items() if ":" not in k)
    print(json.dumps(summary))


# -- robots: generated URDF and MJCF arms, mutated, given to check-cell and to arm_model ------------

PROJECT_NAMES = ["finger_pos", "finger_neg", "arm_base", "object", "feature_left", "floor", "G", "hand", "pad_left"]
ODD_NAMES = ["fl'ange", "a&quot;b", "關節", "link one", "", "x" * 300, "robot/x", "~", "..", "a<b".replace("<", "&lt;")]


def _rename(text: str, old: str, new: str) -> str:
    """Every attribute value `old` (a name and the references to it) made `new` (XML-escaped already)."""
    return text.replace(f'"{old}"', f'"{new}"')


def _mutate_encoding(urdf, text, folder, rng, flange, links, joints):
    how = rng.choice(["ISO-8859-1", "UTF-16", "BOM", "invalid bytes", "latin-1 undeclared", "UTF-16 undeclared"])
    renamed = _rename(text, links[0], "lïnk_é")
    if how == "ISO-8859-1":
        body = renamed.replace('<?xml version="1.0"?>', "")
        return f'<?xml version="1.0" encoding="ISO-8859-1"?>{body}'.encode("latin-1"), flange, how
    if how == "UTF-16":
        body = renamed.replace('<?xml version="1.0"?>', "")
        return f'<?xml version="1.0" encoding="UTF-16"?>{body}'.encode("utf-16"), flange, how
    if how == "UTF-16 undeclared":
        return renamed.replace('<?xml version="1.0"?>', "").encode("utf-16"), flange, how
    if how == "BOM":
        return b"\xef\xbb\xbf" + renamed.encode(), flange, how
    if how == "latin-1 undeclared":
        return renamed.encode("latin-1"), flange, how
    data = text.encode()
    at = data.index(f'"{links[1]}"'.encode()) + 2
    return data[:at] + rng.choice([b"\xff\xfe", b"\xc3", b"\x00", b"\xed\xa0\x80"]) + data[at:], flange, how


def _mutate_names(urdf, text, folder, rng, flange, links, joints):
    new = rng.choice(PROJECT_NAMES + ODD_NAMES + links + joints)
    old = rng.choice(links + joints + [flange] * 3)
    note = f"{old} renamed {new!r}"
    if rng.random() < 0.2 and not urdf:
        return text.replace('<geom type="cylinder"', '<geom name="floor" type="cylinder"', 1), flange, \
            "a geom named floor"
    text = _rename(text, old, new)
    if old == flange:
        flange = new.replace("&quot;", '"').replace("&lt;", "<")
    return text, flange, note


def _mutate_couplings(urdf, text, folder, rng, flange, links, joints):
    a, b = rng.sample(joints[:4], 2)
    if urdf:
        at = text.index(f'<joint name="{b}"')
        end = text.index("</joint>", at)
        on = rng.choice([a, "no_such_joint", b])
        return text[:end] + f'<mimic joint="{on}" multiplier="{rng.choice([1, -1, 0, "nan"])}"/>' + text[end:], \
            flange, f"{b} mimics {on}"
    how = rng.choice(["equality", "tendon limited", "tendon unlimited", "equality on nothing"])
    block = {"equality": f'<equality><joint joint1="{a}" joint2="{b}"/></equality>',
             "equality on nothing": '<equality><weld body1="pedestal"/></equality>',
             "tendon limited": f'<tendon><fixed name="t" limited="true" range="-1 1"><joint joint="{a}" coef="1"/>'
                               f'<joint joint="{b}" coef="1"/></fixed></tendon>',
             "tendon unlimited": f'<tendon><fixed name="t"><joint joint="{a}" coef="1"/></fixed></tendon>'}[how]
    return text.replace("</mujoco>", block + "</mujoco>"), flange, how


def _mutate_includes(urdf, text, folder, rng, flange, links, joints):
    how = rng.choice(["missing", "a folder", "a FIFO", "a loop", "nested", "/dev/null", "absolute", "not XML"])
    (folder / "sub").mkdir(exist_ok=True)
    (folder / "b.xml").write_text('<mujoco><option timestep="0.002"/></mujoco>')
    target = {"missing": "missing.xml", "a folder": "sub", "a FIFO": "fifo.xml", "a loop": "a.xml",
              "nested": "a.xml", "/dev/null": "/dev/null", "absolute": str(folder / "b.xml"),
              "not XML": "junk.xml"}[how]
    if how == "a FIFO":
        os.mkfifo(folder / "fifo.xml")
    (folder / "junk.xml").write_bytes(b"\x00\xffnot xml")
    (folder / "a.xml").write_text('<mujoco><include file="a.xml"/></mujoco>' if how == "a loop" else
                                  '<mujoco><include file="b.xml"/></mujoco>')
    include = f'<include file="{target}"/>'
    if urdf:  # MuJoCo's extension of a URDF
        return text.replace("</robot>", f"<mujoco>{include}</mujoco></robot>"), flange, f"include {how}"
    return text.replace("<worldbody>", include + "<worldbody>", 1), flange, f"include {how}"


def _mutate_meshes(urdf, text, folder, rng, flange, links, joints):
    import trimesh

    how = rng.choice(["relative meshdir", "missing", "a FIFO", "a folder", "garbage", "absolute", "no meshdir"])
    import shutil

    (folder / "meshes").mkdir(exist_ok=True)
    mesh = folder / "meshes" / "part.stl"
    if mesh.is_dir():  # a second mutation of the same model
        shutil.rmtree(mesh)
    elif mesh.exists() or mesh.is_symlink():
        mesh.unlink()
    if how == "a FIFO":
        os.mkfifo(mesh)
    elif how == "a folder":
        mesh.mkdir()
    elif how == "garbage":
        mesh.write_bytes(b"solid x\n" + bytes(rng.randrange(256) for _ in range(300)))
    elif how != "missing":
        mesh.write_bytes(trimesh.creation.box([0.05, 0.05, 0.05]).export(file_type="stl"))
    name = str(mesh) if how == "absolute" else "meshes/part.stl" if how == "no meshdir" else "part.stl"
    meshdir = "" if how in ("absolute", "no meshdir") else ' meshdir="meshes"'
    if urdf:
        geometry = f'<collision><geometry><mesh filename="{name}"/></geometry></collision>'
        text = text.replace('<link name="link1">', '<link name="link1">' + geometry, 1)
        return text.replace("</robot>", f"<mujoco><compiler{meshdir}/></mujoco></robot>"), flange, f"mesh {how}"
    text = text.replace('<compiler angle="radian"', f'<compiler{meshdir} angle="radian"', 1)
    text = text.replace("<worldbody>", f'<asset><mesh name="part" file="{name}"/></asset><worldbody>', 1)
    return text.replace('<body name="pedestal">', '<body name="pedestal"><geom type="mesh" mesh="part"/>', 1), \
        flange, f"mesh {how}"


def _mutate_limits(urdf, text, folder, rng, flange, links, joints):
    bad = rng.choice(["abc", "inf", "-1", "nan", "", "0", "1e308", "-inf", "2 3"])
    if urdf:
        how = rng.choice(["velocity", "lower>upper", "no limit", "effort", "lower"])
        if how == "velocity":
            return re.sub(r'velocity="[^"]*"', f'velocity="{bad}"', text, count=rng.randint(1, 6)), flange, \
                f"velocity {bad!r}"
        if how == "lower>upper":
            return text.replace('lower="-2.6" upper="2.6"', 'lower="2.6" upper="-2.6"'), flange, how
        if how == "no limit":
            return re.sub(r"<limit [^>]*/>", "", text, count=1), flange, how
        return re.sub(f'{how}="[^"]*"', f'{how}="{bad}"', text, count=1), flange, f"{how} {bad!r}"
    return re.sub(r'range="[^"]*"', rng.choice(['range="2.6 -2.6"', f'range="{bad} 1"', 'range=""', 'range="1"']),
                  text, count=rng.randint(1, 3)), flange, "a joint range"


def _mutate_truncated(urdf, text, folder, rng, flange, links, joints):
    data = text.encode()
    return data[:rng.randrange(len(data))], flange, "truncated"


def _mutate_joint_types(urdf, text, folder, rng, flange, links, joints):
    if urdf:
        new = rng.choice(["continuous", "floating", "planar", "prismatic", "bogus", ""])
        return text.replace('type="revolute"', f'type="{new}"', rng.randint(1, 2)), flange, f"joint type {new!r}"
    new = rng.choice(['<freejoint/>', '<joint type="ball"/>', '<joint type="slide" name="s"/>', '<joint/>'])
    return text.replace('<body name="l2" pos="0 0 0.', f'<body name="l2">{new}<body name="l2b" pos="0 0 0.', 1
                        ).replace("</worldbody>", "</body></worldbody>", 1), flange, f"a joint {new}"


def _mutate_numbers(urdf, text, folder, rng, flange, links, joints):
    numbers = re.findall(r"-?\d+\.\d+", text)
    old = rng.choice(numbers)
    new = rng.choice(["nan", "inf", "-inf", "1e308", "-0", "x", "1e9", "0"])
    return text.replace(old, new, 1), flange, f"number {old} made {new}"


ROBOT_MUTATIONS = {"encoding": _mutate_encoding, "names": _mutate_names, "couplings": _mutate_couplings, "includes": _mutate_includes, "meshes": _mutate_meshes, "limits": _mutate_limits, "truncated": _mutate_truncated, "joint types": _mutate_joint_types, "numbers": _mutate_numbers}


def _robot_mutation(kind: str, text: str, folder: Path, rng: random.Random, flange: str):
    """One edit of a generated arm's file: returns (text or bytes, flange, what was done). Files it
    names (included models, meshes, FIFOs, folders) are made in `folder`."""
    urdf = kind == "urdf"
    links = [f"link{i}" for i in range(1, 7)] + ["tool0"] if urdf else [f"l{i}" for i in range(1, 8)] + ["flange"]
    joints = [f"joint_{i}" for i in range(1, 7)] if urdf else [f"q{i}" for i in range(1, 8)]
    what = rng.choice(["encoding", "names", "names", "couplings", "includes", "meshes", "limits", "truncated",
                       "joint types", "numbers"])
    return ROBOT_MUTATIONS[what](urdf, text, folder, rng, flange, links, joints)


def run_robots(count: int, seed: int, scratch: Path) -> None:
    """`count` generated arms (tests/generated_arms.py: URDF or MJCF, 6 or 7 joints), each with
    one to two mutations (_robot_mutation), given to `check-cell` (now and then with `--json`
    naming the model itself) or to stablepush.kinematics.robot.arm_model. check-cell must end 0, 1 or
    2 in one `error:` line; arm_model must return or raise a StablepushError; no case may hang or
    write over the model."""
    import shlex
    import shutil

    import stablepush as sp
    from stablepush.errors import StablepushError
    from stablepush.kinematics.robot import arm_model
    from stablepush_cli.main import cli

    from generated_arms import TCP, mjcf_arm, urdf_arm

    rng = random.Random(seed)
    task = scratch / "task.yaml"
    task.write_text(LOW_MU.read_text())
    plan = scratch / "task.plan.json"
    sp.save_plan(sp.plan_task(sp.load_task(task)), str(plan))
    (scratch / "elsewhere").mkdir(exist_ok=True)
    os.chdir(scratch / "elsewhere")  # not the model's folder: a relative meshdir must not depend on it
    tally, runner = Tally(scratch), CliRunner()
    for case in range(count):
        folder = scratch / f"arm{case % 2}"
        shutil.rmtree(folder, ignore_errors=True)
        folder.mkdir()
        kind = rng.choice(["urdf", "mjcf"])
        axes = rng.choice([("z", "y", "y", "z", "y", "z")] if kind == "urdf" else
                          [("z", "x", "z", "-x", "z", "x", "z")])
        path = folder / ("arm.urdf" if kind == "urdf" else rng.choice(["arm.xml", "arm.mjcf"]))
        arm = (urdf_arm if kind == "urdf" else mjcf_arm)(path, rng.randrange(100), axes)
        content, flange, notes = path.read_text(), arm["flange"], []
        for _ in range(rng.choice([1, 1, 2])):
            text = content if isinstance(content, str) else content.decode("utf-8", "replace")
            content, flange, note = _robot_mutation(kind, text, folder, rng, flange)
            notes.append(note)
        if isinstance(content, str):
            path.write_text(content, encoding="utf-8")
        else:
            path.write_bytes(content)
        if rng.random() < 0.05:
            path.unlink()
            os.mkfifo(path)
            notes.append("the model a FIFO")
        before = _digest([path])
        label = f"robot {case} {kind}: {'; '.join(notes)}"
        if rng.random() < 0.25:
            with tally.case(label, str(path)):
                try:
                    arm_model(sp.Robot(model=str(path), flange=flange, tcp=TCP))
                    tally.count("returned")
                except StablepushError:
                    tally.count("refused")
                except Exception as exc:  # noqa: BLE001 - what escapes is the finding
                    tally.count("escaped")
                    tally.fail(label, f"{type(exc).__name__}: {str(exc)[:200]}", str(path))
            continue
        args = ["check-cell", str(plan), "--task", str(task), "--robot", str(path), "--flange", flange, "--tcp",
                *map(str, TCP)]
        if rng.random() < 0.15:
            args += ["--json", str(path)]
        with tally.case(label, shlex.join(args)):
            result = runner.invoke(cli, args, catch_exceptions=True)
            tally.count(result.exit_code)
            problem = judge(result, (0, 1, 2))
            if "--json" in args and result.exit_code != 2:
                problem = problem or "--json naming the model was not refused"
            if _digest([path]) != before:
                problem = "the model was written over"
            if problem:
                tally.fail(label, problem, shlex.join(args))
    print(json.dumps(tally.summary()))


def main() -> None:
    kind, count, seed, scratch = sys.argv[1], int(sys.argv[2]), int(sys.argv[3]), Path(sys.argv[4])
    if kind in ("api", "options", "robots"):
        {"api": run_api, "options": run_options, "robots": run_robots}[kind](count, seed, scratch)
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
