"""Hand-derived mechanics cases (docs/model.md section 2, paper section IV)."""
import math

import numpy as np
import pytest

from stablepush.units import pose_to_si

from conftest import shipped, task_with

MM = 1e-3


def horizontal(task_name="horizontal-offset-low-mu", **edits):
    def edit(d):
        d["gravity"] = [0, 0]
        for key, value in edits.items():
            d["gripper"][key] = value

    return task_with(task_name, edit)


def test_pure_translation_pad_friction_is_mu_N_per_pad_opposite_the_motion():
    task = horizontal()
    model = task.model
    for direction_deg in (0, 30, 90, 145, 270):
        u = np.array([math.cos(math.radians(direction_deg)), math.sin(math.radians(direction_deg))])
        dq = (u[0] * MM, u[1] * MM, 0.0)
        load = model.motion_wrench((0, 0, 0), dq)
        assert load.sticking_points == 0
        # Two pads, each pressed with N: sliding friction 2 mu N opposite the motion, so the
        # pusher must supply +2 mu N along u, plus the momentum m v / dt (v = 1 mm / 0.1 s).
        inertial = task.object.mass * 1e-3 * (1e-3 / task.dynamics.step_time) / task.dynamics.step_time
        expected = (2 * task.gripper.mu * task.gripper.grip_force + inertial) * u
        np.testing.assert_allclose(load.required[:2], expected, rtol=1e-12)
        assert abs(load.required[2]) < 1e-12  # symmetric pads: no torque about the centre


def test_pure_rotation_about_pad_centre_friction_torque_and_sticking_centre():
    task = horizontal()
    model = task.model
    dtheta = math.radians(1.0)
    load = model.motion_wrench((0, 0, 0), (0, 0, dtheta))
    # The centre point of each pad sticks; the 6 ring points of each pad slide tangentially.
    assert load.sticking_points == 2
    [(arm, disc_radius)] = load.sticking
    np.testing.assert_array_equal(arm, [0.0, 0.0])
    k = 7  # points per pad with one ring
    assert disc_radius == pytest.approx(2 * task.gripper.mu * task.gripper.grip_force / k, rel=1e-15)
    r = 5 * MM
    friction_torque = 2 * 6 * (task.gripper.mu * task.gripper.grip_force / k) * r  # 12 points at radius r
    inertia = model.body.inertia
    omega = dtheta / task.dynamics.step_time
    expected_tau = friction_torque + inertia * omega / task.dynamics.step_time
    assert load.required[2] == pytest.approx(expected_tau, rel=1e-12)
    np.testing.assert_allclose(load.required[:2], [0, 0], atol=1e-12)


def test_uniform_box_inertia():
    task = horizontal()
    body = task.model.body
    m, L, H = 0.202, 0.1, 0.025
    assert body.inertia == pytest.approx(m * (L * L + H * H) / 12, rel=1e-12)


def test_gravity_load_the_pusher_must_carry():
    task = shipped("horizontal-offset-low-mu")
    model = task.model
    m = task.object.mass * 1e-3
    load = model.motion_wrench((0, 0, 0), (0, 1 * MM, 0))
    inertial = m * (1e-3 / task.dynamics.step_time) / task.dynamics.step_time
    assert load.required[1] == pytest.approx(2 * task.gripper.mu * task.gripper.grip_force + inertial + m * 9.81, rel=1e-12)
    # With the centre of mass 10 mm off along x, the force m (a - g) acting there adds the torque
    # r_z f_x - r_x f_z = -r_x m (a_z - g_z) about O's origin, which the pusher must supply.
    off = task_with("horizontal-offset-low-mu", lambda d: d["object"].update(com=[10, 0]))
    load_off = off.model.motion_wrench((0, 0, 0), (0, 1 * MM, 0))
    a_z = 1e-3 / task.dynamics.step_time / task.dynamics.step_time
    assert load_off.required[2] - load.required[2] == pytest.approx(-0.010 * m * (a_z + 9.81), rel=1e-9)


def test_paper_low_mu_horizontal_push_unstable_and_stable_at_mu_0_6():
    low = shipped("horizontal-offset-low-mu")
    high = shipped("horizontal-offset-high-mu")
    dq = pose_to_si((1, 0, 0))
    left_low = low.model.check((0, 0, 0), dq, low.pusher_index("left"))
    left_high = high.model.check((0, 0, 0), dq, high.pusher_index("left"))
    assert not left_low.feasible and left_low.margin < 0
    assert left_high.feasible and left_high.margin > 0
    # Hand check of the boundary: the side pusher carries the weight by friction, so the push is
    # stable iff m g / (2 mu N + m a) < mu_p (and < 0.25 for the torque, face half-height / 50 mm).
    ratio = 0.202 * 9.81 / (2 * 0.45 * 10 + 0.0202)
    assert 0.2 < ratio < 0.25 < 0.6


def test_pivot_is_feasible_only_through_the_sticking_pad_centre():
    task = shipped("pivoting")
    model = task.model
    left = task.pusher_index("left")
    q, dq = (0, 0, 0), (0, 0, math.radians(1))
    result = model.check(q, dq, left)
    assert result.feasible and result.contact_case.name == "sticking" and result.sticking_points == 2
    # Without the sticking centre's friction the same motion wrench lies outside the cone (fig. 7, left).
    required = model.motion_wrench(q, dq).required
    cone = model.pusher_cones[left]
    assert max(row @ required for row in cone.facet_rows) > 0
    # Rotating about a point 0.5 mm away: every pad point slides, and the push is not stable.
    off_centre = model.check((0.5 * MM, 0, 0), dq, left)
    assert off_centre.contact_case.name == "all_sliding" and not off_centre.feasible
    # The witness balances the motion wrench with a sticking force inside its friction disc.
    [(arm, disc)] = model.motion_wrench(q, dq).sticking
    stick = required - np.asarray(result.witness)
    assert abs(stick[2]) < 1e-12 and np.hypot(stick[0], stick[1]) <= disc * (1 + 1e-9)


def point_pusher_task(at, mu=0.5):
    def edit(d):
        d["gravity"] = [0, 0]
        d["pushers"] = [{"name": "tip", "at": at, "mu": mu}]

    return task_with("horizontal-offset-low-mu", edit)


def test_point_pusher_cone_is_a_wedge_and_in_plane_pushes_are_stable():
    task = point_pusher_task([-50, 0])
    model = task.model
    assert model.pusher_cones[0].dimension == 2
    # Pushing along x through the centre: the motion wrench (F, 0, 0) lies in the wedge's plane
    # (the pad points' torques cancel by symmetry, to rounding), inside its two friction edges.
    r = model.check((0, 0, 0), (1 * MM, 0, 0), 0)
    assert r.feasible and r.margin > 0
    # The plane is met within the certification band of the loads (docs/model.md section 2); a
    # turn of 1e-3 deg per mm off it leaves a torque the point cannot give.
    tilted = model.check((0, 0, 0), (1 * MM, 0, math.radians(1e-3)), 0)
    assert not tilted.feasible and tilted.margin < 0
    # The same pusher 5 mm off the axis would need torque 5 mm x F: not stable, and certain.
    off = point_pusher_task([-50, 5]).model.check((0, 0, 0), (1 * MM, 0, 0), 0)
    assert not off.feasible and off.margin < 0
    # mu = 0: the cone is a ray.
    assert point_pusher_task([-50, 0], mu=0.0).model.pusher_cones[0].dimension == 1


def test_point_pusher_pivot_uses_the_exact_lp():
    # Paper figs. 6-7: a point pusher and the sticking pad centre. A point pusher's wedge has no
    # interior in wrench space, so the sticking case needs the equality-constrained exact LP.
    task = point_pusher_task([-50, 0], mu=0.6)
    model = task.model
    r = model.check((0, 0, 0), (0, 0, math.radians(-1)), 0)
    assert r.exact and r.contact_case.name == "sticking"


def mirror_task(name):
    """The task mirrored through the gripper's z axis (x -> -x)."""

    def edit(d):
        obj = d["object"]
        if obj["shape"] == "polygon":
            obj["polygon"] = [[-x, z] for x, z in reversed(obj["polygon"])]
        for p in d["pushers"]:
            for key in ("from", "to", "at"):
                if key in p:
                    p[key] = [-p[key][0], p[key][1]]
        d["gravity"] = [-d.get("gravity", [0, -9.81])[0], d.get("gravity", [0, -9.81])[1]]
        d["start"] = [-d["start"][0], d["start"][1], -d["start"][2]]
        d["goal"] = [-d["goal"][0], d["goal"][1], -d["goal"][2]]

    return task_with(name, edit)


@pytest.mark.parametrize("name", ["horizontal-offset-low-mu", "pivoting", "large-manipulation", "t-shaped"])
def test_mirror_the_task_mirror_the_answer(name):
    task, mirrored = shipped(name), mirror_task(name)
    model, mirror_model = task.model, mirrored.model
    rng = np.random.default_rng(7)
    for _ in range(300):
        q = (rng.uniform(-3, 3) * MM, rng.uniform(-3, 3) * MM, math.radians(rng.uniform(-20, 20)))
        if rng.random() < 0.3:  # rotation about the pad centre: the sticking case
            w = math.radians(rng.choice([-1, 1]))
            dq = (-w * (-q[1]), w * (-q[0]), w)  # v = -omega x (p - c) with p = 0
        else:
            dq = (rng.uniform(-1, 1) * MM, rng.uniform(-1, 1) * MM, math.radians(rng.uniform(-1, 1)))
        qm, dqm = (-q[0], q[1], -q[2]), (-dq[0], dq[1], -dq[2])
        for p in range(len(task.pushers)):
            a, b = model.check(q, dq, p), mirror_model.check(qm, dqm, p)
            assert a.contact_case == b.contact_case
            assert a.margin == pytest.approx(b.margin, abs=1e-9 * (1 + abs(a.margin)))
            if abs(a.margin) > 1e-9:
                assert a.feasible == b.feasible
            # The mirrored witness: f_x and tau change sign.
            np.testing.assert_allclose(np.asarray(b.witness) * [-1, 1, -1], a.witness, atol=1e-7)


def test_zero_motion_is_refused():
    model = shipped("pivoting").model
    with pytest.raises(ValueError, match="zero"):
        model.check((0, 0, 0), (0, 0, 0), 0)


def test_default_inertia_about_a_given_com_uses_parallel_axes():
    base = shipped("horizontal-offset-low-mu").model.body
    off = task_with("horizontal-offset-low-mu", lambda d: d["object"].update(com=[10, 0])).model.body
    assert off.inertia == pytest.approx(base.inertia + 0.202 * 0.010**2, rel=1e-12)
    np.testing.assert_allclose(off.com, [0.010, 0.0])


def test_a_centred_grasp_holds_its_weight_by_the_pads_friction_2_mu_n_over_m_g():
    """Hand-derived: centred, gravity straight down, the pads' polygons have a vertex on +z, so the
    largest weight they hold is 2 mu N; the ratio is 2 mu N / (m g) = 8.5 / 1.98162."""
    task = shipped("horizontal-offset-low-mu")  # 202 g, mu 0.425, 10 N, pads at the centroid
    ratio = task.model.hold_ratio(pose_to_si(task.start))
    assert ratio == pytest.approx(2 * 0.425 * 10 / (0.202 * 9.81), rel=1e-9)


def test_hold_ratio_agrees_with_an_independent_lp_and_is_infinite_without_gravity():
    import random

    from independent_lp import IndependentModel

    rng = random.Random(7)
    for name in ("horizontal-offset-low-mu", "large-manipulation", "t-shaped"):
        task = shipped(name)
        model, reference = task.model, IndependentModel(task)
        for _ in range(40):
            q = (rng.uniform(-20, 20), rng.uniform(-10, 10), rng.uniform(-90, 90))
            if not model.grasp_maintained(pose_to_si(q)):
                continue
            assert model.hold_ratio(pose_to_si(q)) == pytest.approx(reference.hold_ratio(pose_to_si(q)), rel=1e-6), (name, q)
    assert math.isinf(shipped("pivoting").model.hold_ratio((0.0, 0.0, 0.0)))


def test_hold_ratio_answers_where_the_fast_lp_stalls_at_a_degenerate_vertex():
    """The hexagon, held with its centre of mass on the pads' axis, at two poses (found by a random
    search) where the fast active-set LP stalls: the exact LP answers, as the independent LP does."""
    from independent_lp import IndependentModel

    task = shipped("more/hexagon-offset")
    model, reference = task.model, IndependentModel(task)
    for q, pusher in (((6.595234876716923, 2.8980005094153807, 22.666233343058526), 0),
                      ((7.837396483733109, 6.12360638911497, 22.783082226508174), 1)):
        q = pose_to_si(q)
        assert model.hold_ratio(q, pusher) == pytest.approx(reference.hold_ratio(q, pusher), rel=1e-6)


def test_released_at_the_offsets_goal_the_prism_is_not_held_and_the_planner_can_require_a_held_goal():
    from stablepush.plan import plan_task

    task = shipped("horizontal-offset-high-mu")
    free = plan_task(task)
    assert free.solved and free.final_hold_ratio < 1.0  # the sim turns it 15 deg on release (docs/planner.md)
    held = plan_task(task_with("horizontal-offset-high-mu", lambda d: d["planner"].update(min_hold_ratio=1.0)),
                     time_limit=0.5)
    assert not held.solved and "min_hold_ratio" in held.message  # no pose within 0.5 mm of x = 20 holds it
    large = plan_task(task_with("large-manipulation", lambda d: d["planner"].update(min_hold_ratio=1.0)))
    assert large.solved and large.final_hold_ratio >= 1.0


def test_against_fixed_features_gravity_turns_in_g_and_stays_fixed_in_o():
    """Hand-derived (docs/planner.md, "Gravity during a push"): on a feature the object keeps its world
    orientation phi_p, so G turns by phi_p - theta and gravity in G is R(theta - phi_p) g; pushed
    by a moving pusher, gravity stays g in G."""
    g = np.array([0.0, -9.81])
    fixed = shipped("large-manipulation")  # dynamics.pushes defaults to against_fixed_features
    moving = task_with("large-manipulation", lambda d: d["dynamics"].update(pushes="by_moving_pusher"))
    tilted = task_with("large-manipulation", lambda d: d.setdefault("environment", {}).update(
        features={"left": [400, 0, 300, 30]}))  # the object sits on the left feature turned 30 deg
    for theta_deg in (0.0, 20.0, 45.0):
        q = (0.0, 0.0, math.radians(theta_deg))
        t = math.radians(theta_deg)
        R = np.array([[math.cos(t), math.sin(t)], [-math.sin(t), math.cos(t)]])  # R(theta)
        left = fixed.pusher_index("left")
        np.testing.assert_allclose(fixed.model.gravity_in_gripper(q, left), R @ g, atol=1e-12)
        np.testing.assert_allclose(moving.model.gravity_in_gripper(q, left), g, atol=1e-12)
        a = math.radians(theta_deg - 30.0)
        R30 = np.array([[math.cos(a), math.sin(a)], [-math.sin(a), math.cos(a)]])
        np.testing.assert_allclose(tilted.model.gravity_in_gripper(q, left), R30 @ g, atol=1e-12)
        # The motion wrench carries it: the force in O differs from the moving pusher's by
        # -m (g - R^T g) (the weight is g in O against fixed features, R^T g with a moving pusher).
        dq = (1e-3, 0.0, 0.0)
        w_fixed = np.array(fixed.model.motion_wrench(q, dq, left).required)
        w_moving = np.array(moving.model.motion_wrench(q, dq, left).required)
        m = fixed.object.mass * 1e-3
        np.testing.assert_allclose(w_fixed[:2] - w_moving[:2], -m * (g - R.T @ g), atol=1e-12)
    with pytest.raises(Exception, match="dynamics.pushes"):
        task_with("large-manipulation", lambda d: d["dynamics"].update(pushes="sideways"))


def test_stable_directions_of_line_pushers_are_stable_by_the_independent_lp():
    """stable_directions over 3-D cones (the high-mu offset's three line pushers, at its start): a
    sample of the pushes it lists is stable by the independent LP, a sample of those it leaves out
    at the same headings is not, and the largest components are those of the pushes listed."""
    from stablepush.task import stable_directions

    from independent_lp import IndependentModel

    task = shipped("horizontal-offset-high-mu")
    found = stable_directions(task, task.start, heading_step=30.0)
    reference, q = IndependentModel(task), np.array(pose_to_si(task.start))
    rng = np.random.default_rng(3)
    for pusher, (name, pushes) in enumerate(found["pushers"].items()):
        assert pushes, name
        listed = {(p["heading"], round(p["elevation"])) for p in pushes}
        for p in rng.choice(pushes, size=min(15, len(pushes)), replace=False):
            assert reference.stable(q, np.array(pose_to_si(p["move"])), pusher)[0], (name, p)
        for heading in sorted({h for h, _ in listed})[:4]:
            for elevation in range(-89, 90, 7):
                if (heading, elevation) in listed:
                    continue
                h, b = math.radians(heading), math.radians(elevation)
                move = (math.cos(b) * math.cos(h), math.cos(b) * math.sin(h), math.sin(b))
                stable, _ = reference.stable(q, np.array(pose_to_si(move)), pusher)
                assert not stable or not task.model.grasp_maintained(list(q + pose_to_si(move))), \
                    (name, heading, elevation)
    moves = [p["move"] for pushes in found["pushers"].values() for p in pushes]
    assert found["largest"]["+x"] == pytest.approx(max(m[0] for m in moves))
    assert found["largest"]["-theta"] == pytest.approx(max(-m[2] for m in moves))
