"""Figures of plans and pusher cones: `stablepush show` and `stablepush cone`.

Figures are `matplotlib.figure.Figure` objects made without pyplot, so drawing one neither needs
nor changes the caller's plotting backend; `save_figure` renders PNG, PDF or SVG, as the file
name ends.

`plan_figure` draws, as the paper's fig. 1 does, snapshots of the object in the grasp along the
plan (outline, pads, the active pusher thick and coloured, switch-overs marked) above x, z and
theta against the step. `cone_figure` draws a pusher's generalized friction cone in wrench space
(f_x, f_z, tau_y / l), as the paper's figs. 4-5 do; l is the torque length of the margin metric.
"""
from __future__ import annotations

import io
import math
import os
import tempfile
import textwrap
from pathlib import Path
from typing import List, Optional, Sequence

import matplotlib
import numpy as np
from matplotlib import animation
from matplotlib.figure import Figure
from matplotlib.patches import Circle
from mpl_toolkits.mplot3d.art3d import Poly3DCollection

from stablepush.execution.world import contacts_of
from stablepush.frames import in_gripper
from stablepush.outputs import FIGURE_SUFFIXES, require_suffix, write_atomically
from stablepush.plan.plan import Plan, Waypoint
from stablepush.plan.verify import check_plan
from stablepush.task.model import Task

MAX_SNAPSHOTS = 6
PUSHER_COLOURS = matplotlib.rcParams["axes.prop_cycle"].by_key()["color"]


def _colour(task: Task, pusher: str) -> str:
    return PUSHER_COLOURS[task.pusher_index(pusher) % len(PUSHER_COLOURS)]


def _draw_grasp(ax, task: Task, pose, pusher: Optional[str], title: str, limits) -> None:
    outline = in_gripper(pose, list(task.object.vertices) + [task.object.vertices[0]])
    ax.fill(outline[:, 0], outline[:, 1], color="0.85", zorder=1)
    ax.plot(outline[:, 0], outline[:, 1], color="0.25", lw=1.2, zorder=2)
    for (cx, cz), r in task.gripper.pads:
        ax.add_patch(Circle((cx, cz), r, fill=False, ec="0.1", lw=1.0, ls="--", zorder=3))
    ax.plot([0], [0], "+", color="0.1", ms=6, zorder=3)
    for spec in task.pushers:
        seg = in_gripper(pose, [spec.a, spec.b])
        active = spec.name == pusher
        colour = _colour(task, spec.name) if active else "0.6"
        if spec.is_point:  # a segment of length 0 would draw nothing
            ax.plot(seg[:1, 0], seg[:1, 1], "o", color=colour, ms=8 if active else 5, zorder=4 if active else 2)
        else:
            ax.plot(seg[:, 0], seg[:, 1], color=colour, lw=5 if active else 1.5, solid_capstyle="butt",
                    zorder=4 if active else 2)
    # O's x axis from its origin: the object's orientation (a symmetric outline looks alike turned).
    size = 0.3 * max(max(abs(v) for v in p) for p in task.object.vertices)
    axis = in_gripper(pose, [(0.0, 0.0), (size, 0.0)])
    ax.annotate("", xy=axis[1], xytext=axis[0], zorder=5,
                arrowprops={"arrowstyle": "->", "color": "0.15", "lw": 1.2})
    ax.set_title(title, fontsize=9)
    ax.set_aspect("equal")
    ax.set_xlim(*limits[0])
    ax.set_ylim(*limits[1])
    ax.tick_params(labelsize=7)


def _limits(task: Task, steps: Sequence[Waypoint]):
    pts = np.vstack([in_gripper(s.pose, task.object.vertices) for s in steps])
    pad = 5.0
    return ((pts[:, 0].min() - pad, pts[:, 0].max() + pad), (pts[:, 1].min() - pad, pts[:, 1].max() + pad))


def _snapshots(steps: Sequence[Waypoint]) -> List[int]:
    """The start, the first pose of every contact (where switch-overs happen), the goal, and evenly
    spread poses in between, at most MAX_SNAPSHOTS."""
    keys = [0] + [c.first for c in contacts_of(steps)[1:]] + [len(steps) - 1]
    keys = sorted(set(keys))
    while len(keys) < min(MAX_SNAPSHOTS, len(steps)):
        gaps = [(b - a, a, b) for a, b in zip(keys, keys[1:])]
        size, a, b = max(gaps)
        if size < 2:
            break
        keys.append((a + b) // 2)
        keys.sort()
    return keys[:MAX_SNAPSHOTS] if len(keys) <= MAX_SNAPSHOTS else keys[:MAX_SNAPSHOTS - 1] + [keys[-1]]


def _end_from_goal(task: Task, pose) -> str:
    dx, dz, dth = (a - b for a, b in zip(pose, task.goal))
    return f"end: {math.hypot(dx, dz):.2f} mm and {dth:+.2f} deg in theta\nfrom the goal (red)"


def plan_title(task: Task, plan: Plan) -> str:
    """The task, the pushes, switch-overs and seed; NOT SOLVED first for a partial plan."""
    switches = max(len(plan.pusher_sequence) - 1, 0)
    title = (f"{task.name}: {len(plan.waypoints) - 1} pushes, {switches} switch-over(s), "
             f"seed {plan.stats.get('seed', '?')}")
    return title if plan.solved else f"NOT SOLVED ({plan.outcome or 'partial plan'}): {title}"


def plan_figure(task: Task, plan: Plan, title: Optional[str] = None) -> Figure:
    """The plan in the grasp: snapshots above, x, z, theta against step below; `title` defaults to
    plan_title. The last snapshot is labelled "goal", or "end" for a plan that does not reach it.
    `plan` is checked against the task first (stablepush.plan.verify.check_plan; unsolved plans
    too, PlanError if it is not this task's). A plan of the start alone (no push found, or the
    start already within the tolerance) is one panel: nothing moves."""
    steps = check_plan(task, plan, require_solved=False).waypoints
    title = plan_title(task, plan) if title is None else title
    # A plan that stops short also shows the goal it did not reach (in red, at its end).
    limits = _limits(task, list(steps) + ([] if plan.solved else [Waypoint(*task.goal)]))
    if len(steps) == 1:
        fig = Figure(figsize=(6.4, 4.6), layout="constrained")
        ax = fig.add_subplot()
        label = "start" if plan.solved else "start, no push found\n" + _end_from_goal(task, steps[0].pose)
        _draw_grasp(ax, task, steps[0].pose, None, label, limits)
        if not plan.solved:
            _draw_goal_outline(ax, task)
        ax.set_xlabel("x in G (mm)", fontsize=8)
        ax.set_ylabel("z in G (mm)", fontsize=8)
        fig.suptitle(textwrap.fill(title, 72), fontsize=11)
        return fig
    keys = _snapshots(steps)
    switches = {c.first for c in contacts_of(steps)[1:]}
    fig = Figure(figsize=(2.3 * len(keys) + 0.5, 6.2))
    grid = fig.add_gridspec(2, len(keys), height_ratios=[1.1, 1.0], hspace=0.35)
    for k, i in enumerate(keys):
        ax = fig.add_subplot(grid[0, k])
        pusher = steps[i + 1].pusher if i + 1 < len(steps) else steps[i].pusher
        last = i == len(steps) - 1
        label = "start" if i == 0 else (("goal" if plan.solved else "end") if last else f"step {i}")
        if last and not plan.solved:
            label = _end_from_goal(task, steps[i].pose)
        elif i in switches:
            label += f"\nswitch to {pusher}"
        elif pusher:
            label += f"\n{pusher}"
        _draw_grasp(ax, task, steps[i].pose, pusher, label, limits)
        if last and not plan.solved:
            _draw_goal_outline(ax, task)
        if k == 0:
            ax.set_ylabel("z in G (mm)", fontsize=8)
        ax.set_xlabel("x in G (mm)", fontsize=8)
    ax = fig.add_subplot(grid[1, :])
    n = np.arange(len(steps))
    poses = np.array([s.pose for s in steps])
    ax.plot(n, poses[:, 0], label="x (mm)")
    ax.plot(n, poses[:, 1], label="z (mm)")
    ax2 = ax.twinx()
    ax2.plot(n, poses[:, 2], color="C3", label="theta (deg)")
    ax2.set_ylabel("theta (deg)", color="C3")
    for c in contacts_of(steps):
        ax.axvspan(c.first, c.last, color=_colour(task, c.pusher), alpha=0.12, lw=0)
        ax.text((c.first + c.last) / 2, 1.01, c.pusher, transform=ax.get_xaxis_transform(), ha="center",
                va="bottom", fontsize=8, color=_colour(task, c.pusher))
    for i in switches:
        ax.axvline(i, color="0.3", ls="--", lw=1)
    ax.set_xlabel("step")
    ax.set_ylabel("mm")
    lines = ax.get_legend_handles_labels()
    lines2 = ax2.get_legend_handles_labels()
    ax.legend(lines[0] + lines2[0], lines[1] + lines2[1], loc="best", fontsize=8)
    ax.grid(alpha=0.3)
    fig.suptitle(title, fontsize=11)
    return fig


def _draw_goal_outline(ax, task: Task) -> None:
    """The object's outline at the goal pose, dashed red: where a plan that stops short should have ended."""
    goal = in_gripper(task.goal, list(task.object.vertices) + [task.object.vertices[0]])
    ax.plot(goal[:, 0], goal[:, 1], color="tab:red", lw=1.2, ls="--", zorder=6)


def save_plan_gif(task: Task, plan: Plan, path: str, max_frames: int = 80) -> None:
    """The plan animated, one frame per step (thinned to at most `max_frames`); `plan` as for
    plan_figure. OutputError unless `path` ends in .gif."""
    require_suffix("the animation", path, (".gif",))
    steps = check_plan(task, plan, require_solved=False).waypoints
    fig = Figure(figsize=(4, 4))
    ax = fig.subplots()
    limits = _limits(task, steps)
    frames = sorted(set(np.linspace(0, len(steps) - 1, min(max_frames, len(steps))).round().astype(int)))

    def draw(i):
        ax.clear()
        pusher = steps[i].pusher or (steps[1].pusher if len(steps) > 1 else None)
        _draw_grasp(ax, task, steps[i].pose, pusher, f"{task.name}: step {i}/{len(steps) - 1} ({pusher})", limits)

    anim = animation.FuncAnimation(fig, draw, frames=frames)
    with tempfile.TemporaryDirectory() as scratch:  # Pillow writes a path; the output is then written safely
        anim.save(os.path.join(scratch, "plan.gif"), writer=animation.PillowWriter(fps=10))
        write_atomically(path, Path(scratch, "plan.gif").read_bytes())


def save_figure(fig, path: str, dpi: int = 110) -> None:
    """Write a figure as PNG, PDF or SVG, as the file name ends (PNG when it has no suffix; OutputError
    for any other), the way every output is written (stablepush.outputs.write_files)."""
    suffix = Path(path).suffix.lower()
    if suffix:
        require_suffix("the figure", path, FIGURE_SUFFIXES)
    buffer = io.BytesIO()
    fig.savefig(buffer, format=suffix[1:] or "png", dpi=dpi, bbox_inches="tight")
    write_atomically(path, buffer.getvalue())


def cone_figure(task: Task, pusher: str):
    """The generalized friction cone of `pusher` in O: the edges n +- mu t of every contact point's
    cone as wrenches (f_x, f_z, tau_y / l), unit length, and the cone's surface."""
    model = task.model
    index = task.pusher_index(pusher)
    cone = model.pusher_cones[index]
    length = cone.torque_length
    gens = np.array([[g[0], g[1], g[2] / length] for g in cone.generators], float)
    gens /= np.linalg.norm(gens, axis=1, keepdims=True)
    fig = Figure(figsize=(6, 5.5))
    ax = fig.add_subplot(projection="3d")
    for g in gens:
        ax.plot([0, g[0]], [0, g[1]], [0, g[2]], color="0.3", lw=1)
    ax.scatter(gens[:, 0], gens[:, 1], gens[:, 2], color="C0", s=15, depthshade=False)
    ring = _cone_ring(gens)
    if len(ring) >= 3:
        faces = [[np.zeros(3), ring[i], ring[(i + 1) % len(ring)]] for i in range(len(ring))]
        ax.add_collection3d(Poly3DCollection(faces, facecolor=_colour(task, pusher), alpha=0.25, edgecolor="0.4",
                                             lw=0.5))
    elif len(ring) == 2:
        ax.add_collection3d(Poly3DCollection([[np.zeros(3), ring[0], ring[1]]], facecolor=_colour(task, pusher),
                                             alpha=0.3))
    ax.set_xlabel("f_x (N)")
    ax.set_ylabel("f_z (N)")
    ax.set_zlabel(f"tau_y / l (N), l = {length * 1e3:.1f} mm")
    for set_lim in (ax.set_xlim, ax.set_ylim, ax.set_zlim):
        set_lim(-1, 1)
    spec = task.pushers[index]
    kind = "point" if spec.is_point else f"segment of {spec.points} points"
    ax.set_title(f"{task.name}: pusher {pusher!r} ({kind}, mu {spec.mu:g})\n"
                 f"generalized friction cone in O, dimension {cone.dimension}", fontsize=10)
    return fig


def _cone_ring(gens: np.ndarray) -> List[np.ndarray]:
    """The extreme generators of a pointed cone in cyclic order (its cross-section's convex hull)."""
    axis = gens.mean(axis=0)
    axis /= np.linalg.norm(axis)
    u = np.cross(axis, [1.0, 0.0, 0.0] if abs(axis[0]) < 0.9 else [0.0, 1.0, 0.0])
    u /= np.linalg.norm(u)
    v = np.cross(axis, u)
    pts = [(float(np.dot(g, u) / np.dot(g, axis)), float(np.dot(g, v) / np.dot(g, axis)), i)
           for i, g in enumerate(gens)]
    pts.sort()
    def half(points):
        out: list = []
        for p in points:
            while len(out) >= 2 and ((out[-1][0] - out[-2][0]) * (p[1] - out[-2][1])
                                     - (out[-1][1] - out[-2][1]) * (p[0] - out[-2][0])) <= 1e-12:
                out.pop()
            out.append(p)
        return out
    lower, upper = half(pts), half(pts[::-1])
    hull = lower[:-1] + upper[:-1]
    return [gens[p[2]] for p in hull]


def evaluation_figure(summary: dict, trials: Sequence[dict]) -> Figure:
    """An evaluation (`stablepush.evaluation`) at a glance: left, the goal error's distribution
    (CDF of max(|x|, |z|) / tolerance mm and |theta| / tolerance deg, so 1 is the success line);
    right, success (green) and misses (red) over the two varied parameters that vary most."""
    fig = Figure(figsize=(11, 4.4))
    cdf, scatter = fig.subplots(1, 2)
    tol_mm, tol_deg = summary["tolerance"]
    ran = [t for t in trials if t["goal_error"] is not None]
    position = [max(abs(t["goal_error"]["x"]), abs(t["goal_error"]["z"])) / tol_mm for t in ran]
    angle = [abs(t["goal_error"]["theta"]) / tol_deg for t in ran]
    for label, values in ((f"position: max(|x|, |z|) / {tol_mm:g} mm", position),
                          (f"angle: |theta| / {tol_deg:g} deg", angle)):
        if values:
            x = np.sort(values)
            cdf.step(x, np.arange(1, len(x) + 1) / len(x), where="post", label=label)
    cdf.axvline(1.0, color="k", linestyle="--", linewidth=1)
    cdf.set_xlabel("goal error / tolerance")
    cdf.set_ylabel("fraction of trials")
    cdf.set_ylim(0, 1.02)
    judged, crashed = summary.get("judged", summary["trials"]), summary.get("crashed", 0)
    if judged:  # the rate is over the trials that did not crash; one world has no interval
        ci = summary["ci95"]
        interval = f", 95% CI {ci[0]:.1%}-{ci[1]:.1%}" if ci else ""
        cdf.set_title(f"{summary['task']}: {summary['successes']}/{judged} landed ({summary['success_rate']:.1%}"
                      f"{interval})" + (f"; {crashed} crashed" if crashed else ""), fontsize=10)
    else:  # stopped before any trial finished, or every one crashed: the axes, and no rate
        cdf.set_title(f"{summary['task']}: " + (f"all {crashed} trials crashed" if crashed else "no trial finished"),
                      fontsize=10)
    if ran:
        cdf.legend(fontsize=8, loc="lower right")
    spreads = sorted(summary["vary"], key=lambda k: -summary["vary"][k])[:2]
    if spreads:
        xs = [t["world"][spreads[0]] for t in trials]
        ys = [t["world"][spreads[1]] for t in trials] if len(spreads) > 1 else [0.0] * len(trials)
        colours = ["tab:green" if t["success"] else "tab:red" for t in trials]
        scatter.scatter(xs, ys, c=colours, s=14)
        scatter.set_xlabel(f"{spreads[0]} x task's")
        scatter.set_ylabel(f"{spreads[1]} x task's" if len(spreads) > 1 else "")
        scatter.set_title("landed (green) and missed (red) over the world", fontsize=10)
    else:
        scatter.text(0.5, 0.5, "no parameter varied (--vary)", ha="center", va="center")
        scatter.set_axis_off()
    return fig


MAX_REACH_SLICES = 6  # theta slices a reach map's figure draws
REACH_STYLE = {"reached": ("tab:green", "o"), "not found": ("tab:orange", "s"), "unreachable": ("0.55", "x")}


def reach_figure(task: Task, reach: dict) -> Figure:
    """A reach map (`stablepush.plan.reach`): first the grasp at the start with its pads and
    pushers (the fixtures); then one panel per slice of theta (at most MAX_REACH_SLICES, evenly
    chosen, the one nearest the start's theta among them; the title says how many of how many),
    each goal (x, z) marked by its verdict, the start's (x, z) a hollow star over it."""
    all_thetas = sorted({c["goal"][2] for c in reach["cells"]})
    thetas = all_thetas
    if len(all_thetas) > MAX_REACH_SLICES:
        picked = {int(round(k)) for k in np.linspace(0, len(all_thetas) - 1, MAX_REACH_SLICES)}
        nearest = int(np.argmin([abs(t - reach["start"][2]) for t in all_thetas]))
        if nearest not in picked:  # it takes the place of the picked slice nearest to it
            picked.remove(min(picked, key=lambda k: abs(k - nearest)))
            picked.add(nearest)
        thetas = [all_thetas[k] for k in sorted(picked)]
    fig = Figure(figsize=(3.3 * (len(thetas) + 1), 3.6))
    axes = np.atleast_1d(fig.subplots(1, len(thetas) + 1))
    start = list(reach["start"])
    _draw_grasp(axes[0], task, start, None, "the start in the grasp, pushers grey", _limits(task, [Waypoint(*start)]))
    xs = [c["goal"][0] for c in reach["cells"]]
    zs = [c["goal"][1] for c in reach["cells"]]
    margin = max(1.0, 0.05 * max(max(xs) - min(xs), max(zs) - min(zs)))
    for ax, theta in zip(axes[1:], thetas):
        for verdict, (colour, marker) in REACH_STYLE.items():
            cells = [c for c in reach["cells"] if c["goal"][2] == theta and c["verdict"] == verdict]
            ax.scatter([c["goal"][0] for c in cells], [c["goal"][1] for c in cells], c=colour, marker=marker, s=28,
                       label=f"{verdict} ({len(cells)})")
        # Hollow, so that the cell at the start's (x, z) shows through it.
        ax.plot([start[0]], [start[1]], "*", markerfacecolor="none", markeredgecolor="k", ms=14,
                label=f"start (theta {start[2]:g})")
        ax.set_xlim(min(xs) - margin, max(xs) + margin)
        ax.set_ylim(min(zs) - margin, max(zs) + margin)
        ax.set_aspect("equal")
        ax.set_title(f"goal theta {theta:g} deg", fontsize=9)
        ax.set_xlabel("x mm", fontsize=8)
        ax.tick_params(labelsize=7)
        ax.legend(fontsize=6, loc="upper center", bbox_to_anchor=(0.5, -0.2), ncol=2)
    axes[1].set_ylabel("z mm", fontsize=8)
    counts = reach["counts"]
    drawn = "" if len(thetas) == len(all_thetas) else f"; {len(thetas)} of {len(all_thetas)} theta slices drawn"
    fig.suptitle(f"{reach['task']}: {counts['reached']} reached, {counts['not found']} not found in "
                 f"{reach['time_limit_s']:g} s, {counts['unreachable']} unreachable (seed {reach['seed']}){drawn}",
                 fontsize=10)
    return fig


def layouts_figure(layouts: Sequence[dict], title: str = "") -> Figure:
    """Fixture layouts side by side (`stablepush design --plot`): for each, the part's section in
    O at the start (mm), the layout's fixtures drawn on it (a segment pusher as a thick line, a
    point pusher as a dot) and its figures as the panel's title. `layouts`: dicts with `task` (a
    Task with the layout's pushers), `rank`, `label` (e.g. the pushers and figures)."""
    fig = Figure(figsize=(4.2 * max(1, len(layouts)), 4.2))
    for k, layout in enumerate(layouts):
        ax = fig.add_subplot(1, max(1, len(layouts)), k + 1)
        task = layout["task"]
        outline = np.array(list(task.object.vertices) + [task.object.vertices[0]], float)
        ax.fill(outline[:, 0], outline[:, 1], color="0.85", edgecolor="0.3")
        for pusher in task.pushers:
            colour = _colour(task, pusher.name)
            if pusher.is_point:
                ax.plot([pusher.a[0]], [pusher.a[1]], "o", color=colour, markersize=8)
            else:
                ax.plot([pusher.a[0], pusher.b[0]], [pusher.a[1], pusher.b[1]], "-", color=colour, linewidth=5)
            ax.annotate(pusher.name, ((pusher.a[0] + pusher.b[0]) / 2, (pusher.a[1] + pusher.b[1]) / 2), fontsize=8,
                        color=colour, xytext=(4, 4), textcoords="offset points")
        ax.set_aspect("equal")
        ax.set_title(f"{layout['rank']}. " + "\n".join(textwrap.wrap(layout["label"], 40)), fontsize=9)
        ax.set_xlabel("x (mm, in O)")
    if title:
        fig.suptitle(title)
    fig.tight_layout()
    return fig
