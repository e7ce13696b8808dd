"""An independent formulation of the stable-push test, written from docs/model.md section 2 alone.

It shares no code with the core: pad points, forces, the pusher cone (as generators, a
V-representation) and the sticking polygons (as vertices) are rebuilt here, and the decision is
an LP solved by scipy's HiGHS. A wrench w lies in the relative interior of cone(g_1..g_m) iff
w = sum lambda_k g_k with every lambda_k > 0, so the push is stable iff the optimum s* of

    maximize s  s.t.  sum_k lambda_k g_k + sum_j sum_v beta_jv W_jv = w_motion,
                      lambda_k >= s,  s <= 1,  beta_j in the simplex (per sticking point j)

is positive, where W_jv is the wrench of vertex v of point j's friction polygon.
"""
from __future__ import annotations

import math

import numpy as np
from scipy.optimize import linprog

MM, G = 1e-3, 1e-3


def rot(theta):
    c, s = math.cos(theta), math.sin(theta)
    return np.array([[c, s], [-s, c]])  # p_G = c + R p_O


def torque(r, f):
    return r[1] * f[0] - r[0] * f[1]


def polygon_props(vertices_m):
    v = np.asarray(vertices_m, float)
    x, z = v[:, 0], v[:, 1]
    xn, zn = np.roll(x, -1), np.roll(z, -1)
    cross = x * zn - xn * z
    area = cross.sum() / 2
    cx = ((x + xn) * cross).sum() / (6 * area)
    cz = ((z + zn) * cross).sum() / (6 * area)
    j0 = (cross * (x * x + x * xn + xn * xn + z * z + z * zn + zn * zn)).sum() / 12
    if area < 0:
        area, j0 = -area, -j0
    return area, np.array([cx, cz]), j0 - area * (cx * cx + cz * cz)


class IndependentModel:
    def __init__(self, task):
        self.vertices = np.array(task.object.vertices, float) * MM
        area, centroid, jc = polygon_props(self.vertices)
        self.mass = task.object.mass * G
        self.com = np.array(task.object.com, float) * MM if task.object.com is not None else centroid
        if task.object.inertia is not None:
            self.inertia = task.object.inertia
        else:
            d = centroid - self.com
            self.inertia = self.mass * (jc / area + d @ d)
        self.gravity = np.array(task.gravity, float)  # in G while G's axes are the world's
        # Against fixed features the object keeps its world orientation phi_p on pusher p's feature,
        # so gravity is fixed in O and turns in G: g_G = R(theta - phi_p) g (docs/model.md section 7).
        self.fixed_features = task.dynamics.pushes == "against_fixed_features"
        self.feature_angles = [math.radians(task.feature_angle(p.name)) for p in task.pushers]
        self.dt = task.dynamics.step_time
        self.sides = task.dynamics.friction_polygon_sides
        k = 1 + sum(6 * i for i in range(1, task.gripper.pad_rings + 1))
        self.pad_points = []  # (position in G, friction limit, pad radius)
        for center, radius in task.gripper.pads:
            c = np.array(center, float) * MM
            r = radius * MM
            self.pad_points.append((c, task.gripper.mu * task.gripper.grip_force / k, r))
            for ring in range(1, task.gripper.pad_rings + 1):
                for j in range(6 * ring):
                    a = 2 * math.pi * j / (6 * ring)
                    p = c + ring * r / task.gripper.pad_rings * np.array([math.cos(a), math.sin(a)])
                    self.pad_points.append((p, task.gripper.mu * task.gripper.grip_force / k, r))
        self.cones = [self._generators(p) for p in task.pushers]

    def _generators(self, spec):
        a, b = np.array(spec.a, float) * MM, np.array(spec.b, float) * MM
        if spec.is_point:
            points = [a]
        else:
            points = [a + (b - a) * i / (spec.points - 1) for i in range(spec.points)]
        # The inward normal: the left normal of the counterclockwise edge that holds the pusher.
        v = self.vertices
        n = None
        for i in range(len(v)):
            p, q = v[i], v[(i + 1) % len(v)]
            d = q - p

            def dist(x):
                t = np.clip((x - p) @ d / (d @ d), 0, 1)
                return np.linalg.norm(x - (p + t * d))

            if dist(a) < 1e-9 and dist(b) < 1e-9:
                n = np.array([-d[1], d[0]]) / np.linalg.norm(d)
                break
        signed = 0.5 * sum(v[i, 0] * v[(i + 1) % len(v), 1] - v[(i + 1) % len(v), 0] * v[i, 1] for i in range(len(v)))
        if signed < 0:
            n = -n
        t = np.array([-n[1], n[0]])
        gens = []
        for p in points:
            for e in (n + spec.mu * t, n - spec.mu * t):
                gens.append([e[0], e[1], torque(p, e)])
        return np.array(gens)

    def gravity_in_gripper(self, q, pusher):
        if not self.fixed_features or pusher is None:
            return self.gravity
        return rot(q[2] - self.feature_angles[pusher]) @ self.gravity

    def motion_terms(self, q, dq, pusher):
        """(w_motion in O, [(arm in G, friction limit) for each sticking point], R)."""
        R = rot(q[2])
        c = np.array(q[:2])
        v = np.array(dq[:2]) / self.dt
        w = dq[2] / self.dt
        F = np.zeros(2)
        tau = 0.0
        r_cm = R @ self.com
        v_cm = v + w * np.array([r_cm[1], -r_cm[0]])
        f = self.mass * (v_cm / self.dt - self.gravity_in_gripper(q, pusher))
        F += f
        tau += torque(r_cm, f) + self.inertia * w / self.dt
        sticking = []
        for p, limit, pad_r in self.pad_points:
            arm = p - c
            slip = v + w * np.array([arm[1], -arm[0]])
            speed = np.linalg.norm(slip)
            if speed < 1e-9 * (np.linalg.norm(v) + abs(w) * pad_r):
                sticking.append((arm, limit))
            else:
                f = limit * slip / speed
                F += f
                tau += torque(arm, f)
        FO = R.T @ F
        return np.array([FO[0], FO[1], tau]), sticking, R

    def stable(self, q, dq, pusher):
        """(feasible, s*) by HiGHS."""
        w, sticking, R = self.motion_terms(q, dq, pusher)
        gens = self.cones[pusher]
        m = len(gens)
        cols = [g for g in gens]
        for arm, limit in sticking:
            for vtx in range(self.sides):
                a = 2 * math.pi * vtx / self.sides
                f = limit * np.array([math.cos(a), math.sin(a)])  # in G
                fo = R.T @ f
                # A sticking force f moves to the other side of the balance: sum lambda g = w - W(f).
                cols.append(np.array([-fo[0], -fo[1], -torque(arm, f)]))
        n = len(cols) + 1  # ..., s
        A_eq = np.zeros((3 + len(sticking), n))
        A_eq[:3, : len(cols)] = np.array(cols).T
        b_eq = np.zeros(3 + len(sticking))
        b_eq[:3] = w
        for j in range(len(sticking)):
            A_eq[3 + j, m + j * self.sides : m + (j + 1) * self.sides] = 1.0
            b_eq[3 + j] = 1.0
        # lambda_k >= s  <=>  s - lambda_k <= 0
        A_ub = np.zeros((m, n))
        for k in range(m):
            A_ub[k, k] = -1.0
            A_ub[k, -1] = 1.0
        bounds = [(0, None)] * len(cols) + [(None, 1.0)]
        c = np.zeros(n)
        c[-1] = -1.0
        res = linprog(c, A_ub=A_ub, b_ub=np.zeros(m), A_eq=A_eq, b_eq=b_eq, bounds=bounds, method="highs")
        if res.status == 2:  # infeasible: w cannot be balanced at all
            return False, -math.inf
        assert res.status == 0, res.message
        return res.x[-1] > 0, res.x[-1]

    def hold_ratio(self, q, pusher=None):
        """The largest lambda with lambda * weight balanced by the pad points' friction polygons at
        rest (every point sticks; each point's force a convex combination of its polygon's
        vertices, scaled by beta_j in [0, 1]), gravity as during a push by `pusher`, by HiGHS; inf
        without gravity."""
        if not np.any(self.gravity):
            return math.inf
        R = rot(q[2])
        c = np.array(q[:2])
        r_cm = R @ self.com
        weight = self.mass * self.gravity_in_gripper(q, pusher)  # in G
        cols = []
        for p, limit, _ in self.pad_points:
            arm = p - c
            for vtx in range(self.sides):
                a = 2 * math.pi * vtx / self.sides
                f = limit * np.array([math.cos(a), math.sin(a)])
                cols.append([f[0], f[1], torque(arm, f)])
        n = len(cols) + 1  # vertex weights, then lambda
        A_eq = np.zeros((3, n))
        A_eq[:, :-1] = np.array(cols).T
        A_eq[:, -1] = [weight[0], weight[1], torque(r_cm, weight)]  # sum W(f) + lambda w_gravity = 0
        b_eq = np.zeros(3)
        A_ub = np.zeros((len(self.pad_points), n))
        for j in range(len(self.pad_points)):  # sum_v beta_jv <= 1 (the polygon with its interior)
            A_ub[j, j * self.sides:(j + 1) * self.sides] = 1.0
        c_obj = np.zeros(n)
        c_obj[-1] = -1.0
        res = linprog(c_obj, A_ub=A_ub, b_ub=np.ones(len(self.pad_points)), A_eq=A_eq, b_eq=b_eq,
                      bounds=[(0, None)] * n, method="highs")
        assert res.status == 0, res.message
        return res.x[-1]
