"""Why a point pusher's plan ends off its goal (docs/results/engines-cross-engine.md, the pegs): where the pushers'
stable pushes can carry the pads, in the object's frame, against where the goal needs them.

With the pads sliding, a push by a point pusher is stable only on a surface of motions (docs/model.md
section 2): at each pose its stable unit pushes form one arc. This prints three measurements of it:

1. The pad centre's course in O under the pusher's push that does not turn the object, at the
   start's pad centre for several turns theta: the course does not depend on theta, so during one
   contact every such push carries the pads along one line in O, whatever the object's turn.
2. How far the goal's pad centre lies from that line through the start's (mm): what turning pushes
   must make up.
3. At every waypoint of the seed's plan, the rest of the way to the goal (unit steps) and its
   distance from the cone of every allowed pusher's stable unit pushes there (non-negative least
   squares over the arcs, unit steps): 0 when some positive mix of the stable pushes there points
   at the goal. It is a local test (the cone turns along the way), not a proof.

    python3 benchmarks/point_pusher_cone.py [TASK.yaml] [--pusher NAME] [--seed 1] [--heading-step 5]
"""
import argparse
import math
from pathlib import Path

import numpy as np
from scipy.optimize import nnls

from stablepush.frames import direction_in_gripper, point_in_gripper
from stablepush.plan import plan_task
from stablepush.task import load_task
from stablepush.task.mechanics import stable_directions

TASK = Path(__file__).resolve().parent.parent / "data" / "tasks" / "more" / "cube-pegs.yaml"
TURNS_DEG = (0.0, 5.0, 10.0, 15.0, 20.0)  # added to the start's theta in measurement 1
LINE_STEP_MM = 0.25  # the line's integration step in measurement 2


def pad_centre_in_object(pose, pad_centre_g):
    """The pads' centre (mm in G) seen from O at pose q: p_O = R(theta)^T (p_G - (x, z))."""
    return np.array(direction_in_gripper(-pose[2], (pad_centre_g[0] - pose[0], pad_centre_g[1] - pose[1])))


def pose_with_pad_centre(p_o, theta_deg, pad_centre_g):
    """The pose (x, z, theta) whose pads' centre lies at p_O in O: (x, z) = p_G - R(theta) p_O."""
    seen = point_in_gripper((0.0, 0.0, theta_deg), p_o)
    return (pad_centre_g[0] - seen[0], pad_centre_g[1] - seen[1], theta_deg)


def untwisted_course(task, pose, pusher, pad_centre_g, heading_step):
    """The unit direction (in O) the pads' centre moves under `pusher`'s stable push at `pose` that
    does not turn the object: where the arc's elevation crosses 0 between neighbouring headings,
    interpolated (of such crossings, the one nearest 0 on both sides: a heading can hold two roots)."""
    arc = stable_directions(task, pose, pusher, heading_step)["pushers"][pusher]
    crossings = [(abs(a["elevation"]) + abs(b["elevation"]), a, b) for a in arc for b in arc
                 if 0.0 < (b["heading"] - a["heading"]) % 360.0 <= heading_step + 1e-9
                 and a["elevation"] * b["elevation"] <= 0.0]
    if not crossings:
        return None
    _, a, b = min(crossings, key=lambda c: c[0])
    gap = (b["heading"] - a["heading"]) % 360.0
    h = math.radians(a["heading"] + gap * a["elevation"] / (a["elevation"] - b["elevation"]))
    course = -np.array(direction_in_gripper(-pose[2], (math.cos(h), math.sin(h))))  # p_O moves by -R^T dq
    return course / np.linalg.norm(course)


def cone_residual(task, pose, pushers, goal, heading_step):
    """The rest of the way (unit steps) and its distance from the cone of the stable unit pushes."""
    step_mm, step_deg = task.planner.step
    scale = np.array([step_mm, step_mm, step_deg])
    rest = (np.asarray(goal) - np.asarray(pose)) / scale
    found = stable_directions(task, pose, None, heading_step)["pushers"]
    moves = [np.array(u["move"]) / scale for name in pushers for u in found[name]]
    if not moves:
        return rest, float(np.linalg.norm(rest))
    return rest, float(nnls(np.array(moves).T, rest)[1])


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("task", nargs="?", type=Path, default=TASK)
    parser.add_argument("--pusher", default=None, help="the point pusher of measurements 1 and 2 (default: the plan's last)")
    parser.add_argument("--seed", type=int, default=1)
    parser.add_argument("--heading-step", type=float, default=5.0, help="deg between the headings of each arc")
    args = parser.parse_args()
    task = load_task(args.task)
    plan = plan_task(task, seed=args.seed)
    pusher = args.pusher or (plan.waypoints[-1].pusher if len(plan.waypoints) > 1 else task.pusher_names[0])
    pad_g = np.mean([centre for centre, _ in task.gripper.pads], axis=0)
    print(f"{task.name}: {plan.message}")

    if not task.model.pusher_cones[task.pusher_index(pusher)].equality_rows:
        parser.error(f"{pusher} is not a point pusher (its cone is 3-D): name one with --pusher")
    p_start = pad_centre_in_object(task.start, pad_g)
    print(f"1. {pusher}: the pads' centre moves in O, under its push that does not turn the object, toward")
    for turn in TURNS_DEG:
        theta = task.start[2] + turn
        course = untwisted_course(task, pose_with_pad_centre(p_start, theta, pad_g), pusher, pad_g, 1.0)
        shown = "no such push" if course is None else f"{math.degrees(math.atan2(course[1], course[0])):7.2f} deg"
        print(f"   at theta {theta:6.1f} deg: {shown}")

    p_goal = pad_centre_in_object(task.goal, pad_g)
    line, p = [p_start], p_start.copy()
    while np.linalg.norm(p - p_start) < 1.5 * np.linalg.norm(p_goal - p_start):
        course = untwisted_course(task, pose_with_pad_centre(p, task.start[2], pad_g), pusher, pad_g, 1.0)
        if course is None:
            break
        p = p + LINE_STEP_MM * course
        line.append(p.copy())
    nearest = min(np.linalg.norm(p_goal - (a + np.clip((p_goal - a) @ (b - a) / ((b - a) @ (b - a)), 0.0, 1.0) * (b - a)))
                  for a, b in zip(line, line[1:])) if len(line) > 1 else float("nan")
    print(f"2. the goal's pads' centre in O {np.round(p_goal, 3).tolist()} mm lies {nearest:.3f} mm from that line "
          f"through the start's {np.round(p_start, 3).tolist()} ({len(line) - 1} steps of {LINE_STEP_MM} mm)")

    allowed = task.pusher_names
    print(f"3. the rest of the way from each waypoint (unit steps) and its distance from the cone of the stable "
          f"pushes of {', '.join(allowed)} there:")
    for k, w in enumerate(plan.waypoints):
        rest, residual = cone_residual(task, w.pose, allowed, task.goal, args.heading_step)
        print(f"   waypoint {k:3d} rest {np.round(rest, 3).tolist()} ({np.linalg.norm(rest):.3f}): {residual:.3f}")


if __name__ == "__main__":
    main()
