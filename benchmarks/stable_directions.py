"""Which ways the task's pushers can move the object from a pose: the directions of the stable
unit pushes, per pusher, and for each of +-x, +-z, +-theta the largest component any of them has.

    python3 benchmarks/stable_directions.py TASK.yaml [--at X Z THETA] [--heading-step 10]

A push of one unit step (planner.step) is written in unit steps as
(cos b cos h, cos b sin h, sin b): heading h in the (x, z) plane, elevation b toward +theta. For
each heading, a pusher with a 3-D cone is tested on a grid of elevations (1 deg); a point pusher's
stable pushes lie on its surface e . w(motion) = 0 (docs/model.md, sections 2 and 3), so its
elevations are the roots of that equation on the grid, refined by bisection, then tested. Every
direction printed passed the model's own test (`StablePushModel.check`) with the grasp kept.

A coordinate that no pusher moves in one sense (its largest component about 0 or below) cannot be
pushed back there: an overshoot along it is beyond any correction from that pose. The default pose
is the end of the task's plan (seed 1).
"""
from __future__ import annotations

import argparse
import math

import numpy as np

from stablepush.plan import plan_task
from stablepush.task import load_task
from stablepush.units import pose_to_si

ELEVATIONS = np.radians(np.arange(-89.0, 89.5, 1.0))
BISECTIONS = 50


def _unit_push(h: float, b: float, scale: np.ndarray) -> np.ndarray:
    """The SI motion of a unit push at heading h and elevation b (rad)."""
    return np.array([math.cos(b) * math.cos(h), math.cos(b) * math.sin(h), math.sin(b)]) * scale


def stable_directions(model, q: np.ndarray, pusher: int, scale: np.ndarray, headings: np.ndarray) -> list:
    """[(heading deg, elevation deg, margin N)] of the stable unit pushes from q by `pusher`."""
    cone = model.pusher_cones[pusher]
    found = []
    for h in headings:
        if len(cone.equality_rows) == 0:  # a 3-D cone: every elevation on the grid
            dq = np.array([_unit_push(h, b, scale) for b in ELEVATIONS])
            feasible, margin, _ = model.check_batch(np.tile(q, (len(dq), 1)), dq, pusher)
            found += [(h, b, m) for b, f, m in zip(ELEVATIONS, feasible, margin) if f]
            continue
        e = np.asarray(cone.equality_rows[0])

        def off(b: float) -> float:  # e . w_required / scale: 0 on the surface
            w = model.motion_wrench(list(q), list(_unit_push(h, b, scale)), pusher)
            return float(e @ np.asarray(w.required)) / w.scale

        values = [off(b) for b in ELEVATIONS]
        for lo, hi, f_lo, f_hi in zip(ELEVATIONS, ELEVATIONS[1:], values, values[1:]):
            if f_lo * f_hi >= 0:
                continue
            for _ in range(BISECTIONS):
                mid = 0.5 * (lo + hi)
                if off(mid) * f_lo < 0:
                    hi = mid
                else:
                    lo = mid
            for b in (lo, hi):  # the side of the root the test accepts, if either
                result = model.check(list(q), list(_unit_push(h, b, scale)), pusher)
                if result.feasible:
                    found.append((h, b, result.margin))
                    break
    return [(math.degrees(h), math.degrees(b), m) for h, b, m in found
            if model.grasp_maintained(list(q + _unit_push(h, b, scale)))]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("task")
    parser.add_argument("--at", type=float, nargs=3, metavar=("X", "Z", "THETA"),
                        help="the pose (mm, mm, deg); default: the end of the task's plan")
    parser.add_argument("--heading-step", type=float, default=10.0, help="deg between headings")
    args = parser.parse_args()
    task = load_task(args.task)
    model = task.build_model()
    at = args.at if args.at else plan_task(task, seed=1).waypoints[-1].pose
    q = np.array(pose_to_si(at))
    step_mm, step_deg = task.planner["step"]
    scale = np.array([step_mm * 1e-3, step_mm * 1e-3, math.radians(step_deg)])
    goal = (np.array(pose_to_si(task.goal)) - q) / scale
    print(f"{task.name} at {[round(v, 4) for v in at]}: the goal is {np.round(goal, 3).tolist()} unit steps away "
          f"(unit step {step_mm:g} mm, {step_deg:g} deg)")
    headings = np.radians(np.arange(0.0, 360.0, args.heading_step))
    every = []
    for k, name in enumerate(task.pusher_names):
        found = stable_directions(model, q, k, scale, headings)
        every += found
        kind = "point" if len(model.pusher_cones[k].equality_rows) else "3-D cone"
        print(f"\n{name} ({kind}): {len(found)} stable unit pushes")
        if kind == "point":
            for h, b, m in found:
                print(f"  heading {h:5.1f}  elevation {b:+6.1f}  margin {m:.4f} N")
        else:
            for h in sorted({h for h, _, _ in found}):
                bs = [b for hh, b, _ in found if hh == h]
                print(f"  heading {h:5.1f}  elevations {min(bs):+6.1f} .. {max(bs):+6.1f}")
    print("\nlargest component of a stable unit push along each sense (unit steps; <= 0: none moves it that way):")
    units = np.array([[math.cos(math.radians(b)) * math.cos(math.radians(h)),
                       math.cos(math.radians(b)) * math.sin(math.radians(h)), math.sin(math.radians(b))]
                      for h, b, _ in every]).reshape(-1, 3)
    for axis, label in enumerate(("x", "z", "theta")):
        for sign, s in ((1, "+"), (-1, "-")):
            best = float((sign * units[:, axis]).max()) if len(units) else float("nan")
            print(f"  {s}{label:6s} {best:+.3f}")


if __name__ == "__main__":
    main()
