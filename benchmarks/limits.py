"""The resource caps at work: a task at every cap at once (1,000 vertices, 32 pushers of 20
points, 2 pads of 4 rings = 122 pad points, a 64-sided friction polygon), planned with a 2 s time
limit, and a 1,000-vertex object's simulated world built. Prints where the time goes and the peak
memory (docs/limits.md, "Limits and hostile inputs").

    python3 benchmarks/limits.py
"""
import math
import resource
import time

import yaml

from stablepush.execution.world import place_features, scene_description
from stablepush.plan import Waypoint, plan_task
from stablepush.sim.mujoco.arm import SimArm
from stablepush.task import parse_task
from stablepush.task.schema import MAX_PUSHER_POINTS, MAX_PUSHERS, MAX_VERTICES


def task_at_the_caps() -> str:
    n = MAX_VERTICES
    # A star-shaped (concave) 1,000-gon: radii alternate 60 and 72 mm.
    polygon = [[round(r * math.cos(2 * math.pi * i / n), 6), round(r * math.sin(2 * math.pi * i / n), 6)]
               for i, r in ((i, 60.0 * (1 + 0.2 * (i % 2))) for i in range(n))]
    pushers = [{"name": f"p{k}", "from": polygon[k * 31], "to": polygon[k * 31 + 1], "mu": 0.5,
                "points": MAX_PUSHER_POINTS} for k in range(MAX_PUSHERS)]
    return yaml.safe_dump({
        "name": "limits", "object": {"shape": "polygon", "polygon": polygon, "thickness": 25, "mass": 200},
        "gripper": {"grip_force": 10, "mu": 0.5, "pad_rings": 4,
                    "pads": [{"center": [-3, 0], "radius": 5}, {"center": [3, 0], "radius": 5}]},
        "dynamics": {"friction_polygon_sides": 64}, "pushers": pushers, "start": [0, 0, 0], "goal": [10, 0, 10],
        "planner": {"time_limit": 2.0},
    })


def main() -> None:
    text = task_at_the_caps()
    t0 = time.perf_counter()
    task = parse_task(text, "limits")
    t1 = time.perf_counter()
    task.model  # built here to time it apart from the plan, which takes the Task's own
    t2 = time.perf_counter()
    result = plan_task(task)
    t3 = time.perf_counter()
    steps = [Waypoint(*task.start), Waypoint(*task.start, pusher=task.pushers[0].name)]
    scene = scene_description(task, place_features(task, steps), task.start)
    t4 = time.perf_counter()
    arm = SimArm(scene)
    t5 = time.perf_counter()
    print(f"| load and validate | {t1 - t0:.2f} s |")
    print(f"| build the model | {t2 - t1:.2f} s |")
    print(f"| plan (time limit 2 s; search {result.stats['planning_time_s']:.2f} s, then the final hold check) "
          f"| {t3 - t2:.2f} s |")
    print(f"| place the features (the executor's scene) | {t4 - t3:.2f} s |")
    print(f"| build the simulated world ({arm.model.ngeom} geoms, {arm.model.npair} contact pairs) | {t5 - t4:.2f} s |")
    print(f"| peak memory | {resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024:.0f} MB |")


if __name__ == "__main__":
    main()
