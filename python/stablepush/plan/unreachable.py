"""Goals no plan can reach, decided before the search (docs/planner.md, "Unreachable goals").

`why_unreachable(task)` returns a reason when one of these holds, else None:

1. every pusher is excluded by the uncertainty box (a point pusher makes no push robust to pad mu,
   grip force or mass: docs/model.md, "Point pushers and the box");
2. no pusher that may push has a stable push out of the start, in any direction, in every model
   the plan must hold in (the corners of an uncertainty box);
3. with `planner.min_hold_ratio` > 0, the pads cannot hold the object with that factor of its
   weight anywhere in the goal's tolerance box, whichever pusher pushes last;
4. no pusher has a stable push that ends within the goal's tolerance: wherever such a last push
   would start (the tolerance box grown by one unit step, since a push is checked at its start
   pose), the pads do not hold the object and no pusher's cone can carry what they leave;
5. a pad would have to leave the object between the start and the goal: its centre must stay
   where the pad's disc lies inside the outline (the outline eroded by the disc), and the part of
   that set it lies in at the start keeps clear of every place the goal's tolerance lets it end,
   the other parts joined to it only through necks narrower than the pad (decided geometrically,
   without an LP; below);
6. a pad is off the object at every pose within the goal's tolerance (load_task refuses a task
   whose goal pose itself puts one off, so only a task edited in code, or a `reach` cell, has one):
   no push can end where there is no grasp. A pad's disc lies inside the outline only where its
   centre is at least its radius r inside; a centre that is d inside (negative: outside) at the
   goal, with r - d more than it can move over the tolerance box (verdict 5's bound), is off at
   every pose of the box. The goal pose itself may be off while poses within its tolerance are not.

Each of 2-4 is a linear program over an outer approximation of the model, so that its
infeasibility (2, 4) or an upper bound under the requirement (3) holds for the model itself:
- every pad point's force lies in its friction disc (a sliding point's on its rim, a sticking
  point's in the polygon inscribed in it), so in the polygon circumscribed about it;
- the momentum term M xi / dt of a push of at most one unit step lies in a box;
- over the tolerance box, the weight in G moves by at most m |g| |dtheta| (gravity fixed in O)
  and its moment about G's origin, cross_y(o + R(theta) r_cm, W), within an interval bounded on
  a grid in theta with the derivative's bound for the gaps;
- a pusher's wrench lies in its closed cone (the model asks for the relative interior);
- over a box of poses (4), the pads' wrench and the weight's move by at most their sizes times
  the box's half-widths (|R(dtheta) - I| <= |dtheta|, a moment arm moves by at most |do|).
For a held start, 2 never fires: the ray from the gravity wrench into a pusher's cone leaves the
pads' limit surface somewhere, and there a motion is a stable push; it decides the starts the
pads alone do not hold. The same holds for 4 at the goal: only goals the pads do not hold are
tested.

For 5, shapely (GEOS) erodes the outline by a slightly smaller disc, r cos(pi / (4 QUAD_SEGS))
less ERODE_MARGIN: whatever polygon GEOS draws for the arcs about reflex corners then lies within
the true disc, so its eroded set contains the true one, and two of its parts can only be joined
through one of them.

HiGHS (scipy) solves each LP in doubles; the verdict rests on a bound computed from its dual
solution in exact rational arithmetic (weak duality with the variables' bounds, Neumaier and
Shcherbina 2004), so a rounding in the solver cannot call a reachable goal unreachable.
Wrenches are (f_x, f_z [N], torque [N m]); forces in G unless said; poses in SI (units.pose_to_si).
"""
from __future__ import annotations

import itertools
import math
import time
from fractions import Fraction
from typing import List, Optional, Sequence

import numpy as np

from stablepush.frames import direction_in_gripper
from stablepush.task.model import Task
from stablepush.task.parts import outline_corners
from stablepush.units import MM, pose_to_si

POLYGON_SIDES = 16  # of the polygon circumscribed about each pad point's friction disc
THETA_GRID = 65  # poses in theta at which the moment of the weight is bounded over the tolerance box
HOLD_CAP = 1e3  # hold factors are bounded by this in the LP (as in StablePushModel::hold_ratio)
QUAD_SEGS = 64  # segments per quarter circle of the eroding disc (verdict 5)
ERODE_MARGIN = 1e-6  # mm the eroding disc is made smaller by, over GEOS's rounding (verdict 5)


class _OutOfTime(Exception):
    """The verdicts' time ran out before they decided."""


def why_unreachable(task: Task, deadline: Optional[float] = None) -> Optional[str]:
    """The reason no plan of `task` can reach its goal, or None when none is found (module
    docstring), in the task's corner_models. `deadline`: a
    time.perf_counter() value after which the verdicts stop, undecided (None), between one pusher's
    or pad's test and the next: on a task of many pushers and pad points each costs seconds, and
    a verdict is never needed for soundness."""
    def on_time() -> None:
        if deadline is not None and time.perf_counter() > deadline:
            raise _OutOfTime

    try:
        return _decide(task, task.corner_models, on_time)
    except _OutOfTime:
        return None


def _decide(task: Task, models, on_time) -> Optional[str]:
    """why_unreachable's verdicts in their order, `on_time()` called before each pusher's or pad's test."""
    usable = [i for i, p in enumerate(task.pushers) if not _excluded_by_box(task, p)]
    if not usable:
        return ("every pusher is a point pusher, and a point pusher makes no push robust to the uncertainty "
                f"box's {', '.join(k for k in ('pad_mu', 'grip_force', 'mass') if task.uncertainty.get(k))}")
    start = pose_to_si(task.start)
    # Where the pads hold the object (in pusher i's gravity) the LP is feasible with no pusher force:
    # only the starts they do not hold need it.
    stuck = [i for i in usable
             if on_time() or any(m.hold_ratio(start, i) < 1.0 and not _may_push(task, m, start, i) for m in models)]
    if len(stuck) == len(usable):
        return ("no pusher has a stable push out of the start in any direction (" + ", ".join(
            task.pushers[i].name for i in stuck) + "): the pads do not hold the object there, and no pusher's "
            "friction cone can carry what they leave")
    goal = pose_to_si(task.goal)
    off = pads_off_near(task, task.goal, models[0].section)
    if off:
        return (f"gripper.pads[{off[0]}] is off the object at every pose within planner.tolerance of the goal: "
                f"there is no grasp there")
    apart = _pad_cut_off(task, models[0], on_time)
    if apart is not None:
        return apart
    # A last push ends within the tolerance, so it starts within it grown by a unit step (a push is
    # checked at its start). Where the pads hold at the goal, or the core finds a push from it,
    # some pusher may finish there and no LP is needed.
    tol, step = task.planner.tolerance, task.planner.step
    box = ((tol[0] + step[0]) * MM, math.radians(tol[1] + step[1]))

    witnessed = {(i, k): on_time() or m.hold_ratio(goal, i) >= 1.0 or _pushes_from(task, m, goal, i)
                 for i in usable for k, m in enumerate(models)}
    if not any(all(witnessed[i, k] for k in range(len(models))) for i in usable) and not any(
            all(witnessed[i, k] or on_time() or _may_push(task, m, goal, i, box) for k, m in enumerate(models))
            for i in usable):
        return ("no pusher has a stable push that ends within planner.tolerance of the goal (" + ", ".join(
            task.pushers[i].name for i in usable) + "): wherever such a last push would start, the pads do "
            "not hold the object, and no pusher's friction cone can carry what they leave")
    need = task.planner.min_hold_ratio
    # The bound is at least the hold at the goal itself: only goals held too little by every pusher need it.
    if need > 0.0 and all(on_time() or min(m.hold_ratio(goal, i) for m in models) < need for i in usable):
        bounds = {i: on_time() or min(_hold_bound(task, m, i) for m in models) for i in usable}
        if all(b < need for b in bounds.values()):
            best = max(bounds.values())
            return (f"the pads hold at most {float(best):.3g} times the object's weight anywhere within planner."
                    f"tolerance of the goal, whichever pusher pushes last, and planner.min_hold_ratio asks for "
                    f"{need:g}")
    return None


def _pad_cut_off(task: Task, model, on_time=lambda: None) -> Optional[str]:
    """Verdict 5 (module docstring): the reason, when the part of the outline eroded by a pad's disc
    that holds the pad's centre at the start is farther than the goal's tolerance lets the centre
    end from where it is at the goal; else None. Over the tolerance box (|do| <= sqrt(2) a,
    |dtheta| <= b) the centre in O, R(-theta) (p - o), moves by at most sqrt(2) a + 2 sin(b / 2)
    |p - o|. A convex outline erodes to one convex part, so only outlines with reflex corners are
    eroded (and shapely imported); `model` is one of the task's, for its cross-section."""
    if model.section.convex:
        return None
    from shapely.geometry import Point, Polygon  # here: only outlines with reflex corners need it

    outline = Polygon(outline_corners(task.object.vertices))
    for k, (centre, radius) in enumerate(task.gripper.pads):
        on_time()
        eroded = outline.buffer(-(radius * math.cos(math.pi / (4 * QUAD_SEGS)) - ERODE_MARGIN), quad_segs=QUAD_SEGS)
        parts = list(getattr(eroded, "geoms", [eroded]))
        if len(parts) < 2:
            continue
        start, goal = (Point(direction_in_gripper(-pose[2], (centre[0] - pose[0], centre[1] - pose[1])))
                       for pose in (task.start, task.goal))  # the pad's centre in O
        reach = _centre_travel(task, centre, task.goal)
        held = [part for part in parts if part.covers(start)]
        if held and all(part.distance(goal) > reach * (1.0 + 1e-9) + ERODE_MARGIN for part in held):
            return (f"gripper.pads[{k}] (radius {radius:g} mm) would have to leave the object between the start and "
                    f"the goal: between where the pad sits at the start and every place the goal's tolerance lets it "
                    f"end, the outline narrows to less than the pad's width")
    return None


def _centre_travel(task: Task, centre, pose) -> float:
    """How far [mm] a pad's centre seen from O, R(-theta) (p - o), can move from where it is at `pose`
    over the goal's tolerance box (|do| <= sqrt(2) a in x and z, |dtheta| <= b): at most
    sqrt(2) a + 2 sin(min(b, 180 deg) / 2) |p - o|, the turn's chord, which no turn makes longer
    than 2 |p - o|."""
    tol = task.planner.tolerance
    chord = 2.0 * math.sin(math.radians(min(tol[1], 180.0)) / 2.0)
    return math.sqrt(2.0) * tol[0] + chord * math.hypot(centre[0] - pose[0], centre[1] - pose[1])


def pads_off_near(task: Task, pose: Sequence[float], section=None) -> List[int]:
    """Verdict 6 (module docstring): the indices of the pads that are off the object at every pose
    within planner.tolerance of `pose` (mm, mm, deg). `section`: the task's cross-section, built
    here unless given."""
    section = section if section is not None else task.object.section()
    off = []
    for k, (centre, radius) in enumerate(task.gripper.pads):
        c = direction_in_gripper(-pose[2], (centre[0] - pose[0], centre[1] - pose[1]))  # the centre in O [mm]
        at = np.array(c) * MM
        depth = section.distance_to_boundary(at) / MM * (1.0 if section.contains_disc(at, 0.0) else -1.0)
        if radius - depth > _centre_travel(task, centre, pose) * (1.0 + 1e-9) + ERODE_MARGIN:
            off.append(k)
    return off


def _excluded_by_box(task: Task, pusher) -> bool:
    return pusher.is_point and any(task.uncertainty.get(k, 0.0) > 0.0 for k in ("pad_mu", "grip_force", "mass"))


def _polygon_rows(n_points: int, limits: Sequence[float], offset: int, n_vars: int):
    """n_k . f_i <= limit_i for the POLYGON_SIDES normals n_k: each pad force f_i (columns offset + 2i,
    offset + 2i + 1) in the polygon circumscribed about its disc."""
    rows, rhs = [], []
    for i in range(n_points):
        for k in range(POLYGON_SIDES):
            a = 2.0 * math.pi * k / POLYGON_SIDES
            row = np.zeros(n_vars)
            row[offset + 2 * i], row[offset + 2 * i + 1] = math.cos(a), math.sin(a)
            rows.append(row)
            rhs.append(limits[i])
    return rows, rhs


def _in_gripper(theta: float, v) -> np.ndarray:
    """R(theta) v [theta in rad]: a vector of O seen from G (the core's Rotation2)."""
    return np.array(direction_in_gripper(math.degrees(theta), v))


def _cross_y(a, f) -> float:
    return float(a[1] * f[0] - a[0] * f[1])


def _may_push(task: Task, model, q: Sequence[float], pusher: int, box=(0.0, 0.0)) -> bool:
    """False only when no motion from q is a stable push of `pusher` in `model` (module docstring, 2):
    the LP  sum_j l_j g_j - sum_i W(f_i) - e = w_g,  l >= 0, f_i in the circumscribed polygons,
    e in the momentum box, is infeasible (in O about O's origin; w_g the weight's wrench that
    the pusher and pads must carry). Decided as: the least t with |residual| <= t + s is positive.
    With `box` = (a [m], b [rad]), for every pose within a in x and z and b in theta of q (4):
    s bounds how far W(f_i) and w_g move over the box; s = 0 at q alone."""
    gens = [np.asarray(g, float) for g in model.pusher_cones[pusher].generators]
    positions = [np.asarray(p, float) for p in model.gripper.point_positions]
    limits = list(model.gripper.point_friction_limits)
    o = np.array(q[:2])
    body = model.body
    r_cm = _in_gripper(q[2], body.com)
    weight = body.mass * np.asarray(model.gravity_in_gripper(q, pusher), float)  # in G
    # The wrench the weight asks of pusher and pads (w_motion's gravity part, docs/model.md section 2).
    w_g = np.array([*_in_gripper(-q[2], -weight), _cross_y(r_cm, -weight)])
    # M xi / dt for a push of at most one unit step (|dx|, |dz| <= L, |dtheta| <= A): a box in O.
    L, A = task.planner.step[0] * MM, math.radians(task.planner.step[1])
    dt2 = task.dynamics.step_time ** 2
    arm = float(np.linalg.norm(r_cm))
    force = body.mass * (math.sqrt(2.0) * L + A * arm) / dt2
    momentum = np.array([force, force, arm * force + body.inertia * A / dt2])
    slack = _box_slack(model, limits, float(np.linalg.norm(weight)), arm, *box)
    n_g, n_p = len(gens), len(positions)
    # Columns: l (n_g), f (2 n_p), e (3), t.
    n = n_g + 2 * n_p + 3 + 1
    eq = np.zeros((3, n))
    for j, g in enumerate(gens):
        eq[:, j] = g
    for i, p in enumerate(positions):
        for k, unit in enumerate(np.eye(2)):
            eq[:2, n_g + 2 * i + k] = -_in_gripper(-q[2], unit)
            eq[2, n_g + 2 * i + k] = -_cross_y(p - o, unit)
    eq[:, n_g + 2 * n_p:n_g + 2 * n_p + 3] = -np.eye(3)
    # |eq x - w_g| <= t, row by row.
    ub_rows, ub_rhs = _polygon_rows(n_p, limits, n_g, n)
    for r in range(3):
        for sign in (1.0, -1.0):
            row = sign * eq[r].copy()
            row[-1] = -1.0
            ub_rows.append(row)
            ub_rhs.append(sign * w_g[r] + slack[r])
    scale = float(np.abs(w_g).sum() + sum(limits) + momentum.sum())
    lam_cap = 1e3 * scale
    bounds = ([(0.0, lam_cap)] * n_g + [(-2.0 * lim, 2.0 * lim) for lim in limits for _ in range(2)]
              + [(-m, m) for m in momentum] + [(0.0, 10.0 * scale)])
    c = np.zeros(n)
    c[-1] = -1.0  # maximize -t
    bound = _certified_max(c, np.array(ub_rows), np.array(ub_rhs), None, None, bounds)
    return not (bound < 0)


def _pushes_from(task: Task, model, q: Sequence[float], pusher: int) -> bool:
    """Whether the core finds a stable push of `pusher` from q toward one of the 26 neighbours of a
    unit-step grid: a witness that spares the LP (milliseconds) wherever one is that cheap (microseconds)."""
    L, A = task.planner.step[0] * MM, math.radians(task.planner.step[1])
    for d in itertools.product((-1.0, 0.0, 1.0), repeat=3):
        norm = math.sqrt(sum(v * v for v in d))
        if norm and model.check(q, (d[0] * L / norm, d[1] * L / norm, d[2] * A / norm), pusher).feasible:
            return True
    return False


def _box_slack(model, limits: Sequence[float], weight: float, com_arm: float, a: float, b: float) -> np.ndarray:
    """How far each row of _may_push's wrench balance (f_x, f_z [N], torque [N m], in O) can move
    between q and any pose within a [m] in x and z and b [rad] in theta of it. A pad force, at most
    F_i = limit_i / cos(pi / POLYGON_SIDES) in its polygon, turns into O by at most b F_i; its
    moment about O's origin, cross_y(p_i - o, f_i), moves by at most sqrt(2) a F_i. With gravity
    fixed in G, the weight turns in O by b |W| and its moment by b |r_cm| |W|; fixed in O, neither
    moves."""
    if a == 0.0 and b == 0.0:
        return np.zeros(3)
    pads = sum(limits) / math.cos(math.pi / POLYGON_SIDES)
    turns = str(model.gravity_frame).endswith("object")
    force = b * pads + (0.0 if turns else b * weight)
    torque = math.sqrt(2.0) * a * pads + (0.0 if turns else b * com_arm * weight)
    return np.array([force, force, torque]) * (1.0 + 1e-9)  # and the rounding of these sums


def _hold_bound(task: Task, model, pusher: int):
    """An upper bound on StablePushModel.hold_ratio(q, pusher) over every q in the goal's tolerance
    box (module docstring, 3): maximize lam subject to, in G about G's origin,
        sum f_i + lam W0 in lam [-d, d],   sum cross_y(p_i, f_i) + u = 0,   lam tau_lo <= u <= lam tau_hi,
    f_i in the circumscribed polygons, with W0 the weight at the goal, d its largest change over
    the box and [tau_lo, tau_hi] the range of the weight's moment about G's origin. A Fraction, or
    inf without gravity."""
    positions = [np.asarray(p, float) for p in model.gripper.point_positions]
    limits = list(model.gripper.point_friction_limits)
    goal = pose_to_si(task.goal)
    tol = task.planner.tolerance
    a, b = tol[0] * MM, math.radians(tol[1])
    body = model.body
    W0 = body.mass * np.asarray(model.gravity_in_gripper(goal, pusher), float)
    gmag = float(np.linalg.norm(W0))
    if gmag == 0.0:
        return math.inf  # no weight: held at any factor (hold_ratio's inf)
    turns = str(model.gravity_frame).endswith("object")  # gravity fixed in O turns in G with theta
    d = gmag * b if turns else 0.0
    tau_lo, tau_hi = _moment_range(model, goal, a, b, pusher, turns)
    n_p = len(positions)
    n = 2 * n_p + 2  # f, lam, u
    LAM, U = 2 * n_p, 2 * n_p + 1
    ub_rows, ub_rhs = _polygon_rows(n_p, limits, 0, n)
    for r in range(2):  # |sum f_r + lam W0_r| <= lam d
        for sign in (1.0, -1.0):
            row = np.zeros(n)
            row[r:2 * n_p:2] = sign
            row[LAM] = sign * W0[r] - d
            ub_rows.append(row)
            ub_rhs.append(0.0)
    row = np.zeros(n)  # lam tau_lo - u <= 0 and u - lam tau_hi <= 0
    row[LAM], row[U] = tau_lo, -1.0
    ub_rows.append(row)
    ub_rhs.append(0.0)
    row = np.zeros(n)
    row[LAM], row[U] = -tau_hi, 1.0
    ub_rows.append(row)
    ub_rhs.append(0.0)
    eq = np.zeros((1, n))
    for i, p in enumerate(positions):
        eq[0, 2 * i], eq[0, 2 * i + 1] = p[1], -p[0]  # cross_y(p, f) = p_z f_x - p_x f_z
    eq[0, U] = 1.0
    u_big = HOLD_CAP * max(abs(tau_lo), abs(tau_hi))
    bounds = ([(-2.0 * lim, 2.0 * lim) for lim in limits for _ in range(2)] + [(0.0, HOLD_CAP), (-u_big, u_big)])
    c = np.zeros(n)
    c[LAM] = 1.0
    return _certified_max(c, np.array(ub_rows), np.array(ub_rhs), eq, np.zeros(1), bounds)


def _moment_range(model, goal, a: float, b: float, pusher: int, turns: bool):
    """[lo, hi] containing cross_y(o + R(theta) r_cm, W(theta)) for |x - gx|, |z - gz| <= a and
    |theta - gtheta| <= b [N m]: linear in o, so at the corners of the square for each theta of a
    grid, widened by the derivative's bound times half the grid's spacing."""
    body = model.body
    com = np.asarray(body.com, float)
    values = []
    thetas = np.linspace(goal[2] - b, goal[2] + b, THETA_GRID)
    for theta in thetas:
        W = body.mass * np.asarray(model.gravity_in_gripper((goal[0], goal[1], theta), pusher), float)
        r_cm = _in_gripper(theta, com)
        for dx in (-a, a):
            for dz in (-a, a):
                values.append(_cross_y(np.array([goal[0] + dx, goal[1] + dz]) + r_cm, W))
    wmag = body.mass * float(np.linalg.norm(model.gravity_in_gripper(goal, pusher)))
    reach = math.hypot(abs(goal[0]) + a, abs(goal[1]) + a) + float(np.linalg.norm(com))
    # d/dtheta: |o| |W'| + |r_cm'| |W| + |r_cm| |W'| <= (|o| + 2 |r_cm|) |W| (|W'| = |W| when it turns).
    slope = ((reach + float(np.linalg.norm(com))) if turns else float(np.linalg.norm(com))) * wmag
    slack = slope * (thetas[1] - thetas[0]) / 2.0 if b > 0 else 0.0
    pad = 1e-9 * (reach * wmag + 1e-30)  # the rounding of the sums above, many times over
    return min(values) - slack - pad, max(values) + slack + pad


def _certified_max(c, A_ub, b_ub, A_eq, b_eq, bounds) -> Fraction:
    """A rigorous upper bound on max c.x subject to A_ub x <= b_ub, A_eq x = b_eq and the (finite)
    bounds: HiGHS's dual (y >= 0 for the rows, z for the equalities), then in exact arithmetic
    c.x = y.A_ub x + z.A_eq x + r.x <= y.b_ub + z.b_eq + sum_j max(r_j l_j, r_j u_j), r = c - A_ub^T y - A_eq^T z.
    A problem HiGHS cannot solve gets the bound of its box alone (y = z = 0)."""
    from scipy.optimize import linprog  # here: importing it costs every plan ~0.3 s, and few plans need an LP

    res = linprog(-c, A_ub=A_ub, b_ub=b_ub, A_eq=A_eq, b_eq=b_eq, bounds=bounds, method="highs")
    y = np.zeros(len(b_ub))
    z = np.zeros(0 if b_eq is None else len(b_eq))
    if res.status == 0:
        y = np.maximum(0.0, -np.asarray(res.ineqlin.marginals, float))
        if b_eq is not None:
            z = -np.asarray(res.eqlin.marginals, float)
    return _weak_duality_bound(c, A_ub, b_ub, A_eq, b_eq, bounds, y, z)


def _weak_duality_bound(c, A_ub, b_ub, A_eq, b_eq, bounds, y, z) -> Fraction:
    F = Fraction
    ys = [F(float(v)) for v in y]
    zs = [F(float(v)) for v in z]
    total = sum((yi * F(float(bi)) for yi, bi in zip(ys, b_ub) if yi), F(0))
    total += sum((zi * F(float(bi)) for zi, bi in zip(zs, b_eq if b_eq is not None else ()) if zi), F(0))
    rows: List = [(yi, A_ub[k]) for k, yi in enumerate(ys) if yi]
    rows += [(zi, A_eq[k]) for k, zi in enumerate(zs) if zi]
    for j, (lo, hi) in enumerate(bounds):
        r = F(float(c[j]))
        for weight, row in rows:
            if row[j]:
                r -= weight * F(float(row[j]))
        if r:
            total += max(r * F(float(lo)), r * F(float(hi)))
    return total
