"""The simulated arm's physics and the plan's geometry in the world.

The friction test is what the measured results rest on: a ledge pushing the held object along the
pads must need 2 mu N + m g (both pads slide; the weight is lifted), Coulomb's law, within 5%.
"""
import itertools
import math

import numpy as np
import pytest

from stablepush.execution.stream import arm_trajectory
from stablepush.execution.world import place_features, scene_description
from stablepush.frames import grasp_transform, pose_to_matrix
from stablepush.kinematics.cell_model import convex_pieces
from stablepush.plan import Waypoint
from stablepush.sim.engines import ENGINES, make_arm
from stablepush.sim.mujoco.arm import SimArm

from conftest import shipped, task_with

G0 = 9.81


def _ledge_force(task, speed=0.01, duration=1.0, engine="mujoco"):
    """Hold the object above the task's bottom pusher, made a ledge, and lower the gripper onto it at
    `speed` m/s: the mean ledge force on the object (N, world z) once the pads slide steadily."""
    start = task.start
    steps = [Waypoint(*start), Waypoint(*start, pusher="bottom")]
    features = place_features(task, steps)
    arm = make_arm(engine, scene_description(task, features, start, start_clear=False))
    pose = list(arm.state()["ee_pose"])
    z0 = pose[2]
    period = 0.01
    forces = []
    for k in range(int(duration / period)):
        pose[2] = z0 - speed * period * (k + 1)
        arm.move_to(pose, period)
        if k * period >= 0.3:  # past the start-up transient
            forces.append(arm.contact_force_on_object("bottom")[2])
    slid = arm.state()["object_in_grasp"]["z"] - start[1]
    return float(np.mean(forces)), slid


@pytest.mark.parametrize("engine", ENGINES)
@pytest.mark.parametrize("grip_force, mu", [
    (10.0, 0.425), (10.0, 0.6), (5.0, 0.3),
    (20.0, 0.8),  # chattered (16% high) before sliding pad points got Coulomb friction (sim/mujoco/friction.py)
])
def test_ledge_force_to_slide_the_held_object_is_coulombs(grip_force, mu, engine):
    def edit(data):
        data["gripper"]["grip_force"] = grip_force
        data["gripper"]["mu"] = mu

    task = task_with("horizontal-offset-low-mu", edit)
    force, slid = _ledge_force(task, engine=engine)
    expected = 2 * mu * grip_force + task.object.mass * 1e-3 * G0
    assert force == pytest.approx(expected, rel=0.05), (force, expected)
    assert slid > 5.0  # mm: the object really slid up between the pads while the force was measured


@pytest.mark.parametrize("engine", ENGINES)
def test_a_held_object_stays_put_under_gravity_alone(engine):
    """Static friction: 2 mu N = 8.5 N holds the 2 N prism; it must not creep over a second."""
    task = shipped("horizontal-offset-low-mu")
    arm = make_arm(engine, scene_description(task, {}, task.start))
    before = arm.state()["object_in_grasp"]
    arm.advance(1.0)
    after = arm.state()["object_in_grasp"]
    assert abs(after["z"] - before["z"]) < 0.02 and abs(after["x"] - before["x"]) < 0.02


@pytest.mark.parametrize("engine", ENGINES)
def test_ik_tracks_a_rotation_about_the_pads(engine):
    task = shipped("pivoting")
    arm = make_arm(engine, scene_description(task, {}, task.start))
    home = pose_to_matrix(arm.state()["ee_pose"])
    for deg in range(0, 91, 10):
        target = home.copy()
        target[:3, :3] = grasp_transform((0, 0, -deg))[:3, :3]
        q = arm.solve_ik(_pose(target), arm.target)
        assert arm.ik_error < 1e-6, deg
        arm.target = q


def _pose(T):
    from stablepush.frames import matrix_to_pose

    return matrix_to_pose(T)


def test_during_a_push_the_object_stays_on_its_feature():
    """T_WG(t) · T_GO(q(t)) is the feature's object pose at every push waypoint (the pusher sticks)."""
    task = shipped("t-shaped")
    from stablepush.plan import plan_task

    plan = plan_task(task, seed=2)
    steps = plan.waypoints
    features = place_features(task, steps)
    home = scene_description(task, features, task.start).gripper_pose
    waypoints = arm_trajectory(task, steps, features, 100.0, home)
    pushes = [w for w in waypoints if w.phase == "push"]
    assert sum(w.completes for w in pushes) == len(steps) - 1
    for w in pushes:
        if not w.completes:
            continue
        T_WO = pose_to_matrix(w.pose) @ grasp_transform(steps[w.step].pose)
        np.testing.assert_allclose(T_WO, features[steps[w.step].pusher].object_pose, atol=1e-9)
    # Waypoints are one period apart and the steps confirmed only go up.
    assert all(b.t - a.t == pytest.approx(0.01) for a, b in zip(waypoints, waypoints[1:]))
    confirmed = [w.step for w in waypoints if w.completes]
    assert confirmed == sorted(confirmed) == list(range(1, len(steps)))


def test_every_approach_ends_slowly_toward_where_the_plan_puts_its_feature():
    """Each contact's approach ends with GUARD_SPAN of guarded waypoints at GUARD_SPEED along the
    feature's inward normal, up to the plan's touch; the run starts GUARD_SPAN back from the
    feature it starts on (the world is built with the object clear of it)."""
    from stablepush.execution.stream import GUARD_SPEED
    from stablepush.execution.world import GUARD_SPAN
    from stablepush.plan import plan_task

    task = shipped("t-shaped")
    steps = plan_task(task, seed=2).waypoints
    features = place_features(task, steps)
    scene = scene_description(task, features, task.start)
    first = features[steps[1].pusher]
    touching = first.object_pose @ np.linalg.inv(grasp_transform(task.start))
    np.testing.assert_allclose(np.array(scene.gripper_pose[:3]) - touching[:3, 3], first.normal * GUARD_SPAN,
                               atol=1e-12)
    points = arm_trajectory(task, steps, features, 100.0, scene.gripper_pose)
    starts = [i for i, w in enumerate(points) if w.phase == "push" and points[i - 1].phase != "push"]
    assert len(starts) == sum(1 for a, b in zip(steps[1:], steps[2:]) if a.pusher != b.pusher) + 1
    for i in starts:
        n = len(list(itertools.takewhile(lambda w: w.guarded, reversed(points[:i]))))
        before = points[i - n - 1].pose if i > n else scene.gripper_pose  # where the slow end begins
        path = np.array([before[:3]] + [w.pose[:3] for w in points[i - n:i]])
        feature = features[steps[points[i].step].pusher]
        touch = feature.object_pose @ np.linalg.inv(grasp_transform(steps[points[i].step - 1].pose))
        np.testing.assert_allclose(path[-1], touch[:3, 3], atol=1e-12)
        np.testing.assert_allclose(path[0] - path[-1], feature.normal * GUARD_SPAN, atol=1e-12)
        travel = np.linalg.norm(np.diff(path, axis=0), axis=1)
        assert travel.max() <= GUARD_SPEED * 0.01 * (1 + 1e-9) and travel.min() > 0.9 * GUARD_SPEED * 0.01
        assert all(w.phase == "approach" for w in points[i - n:i])


def test_a_stream_resumed_on_a_feature_backs_off_that_feature():
    """A correction made as the object comes onto the next contact's feature (B), that begins with
    another pusher, first retracts G along B's inward normal, not along the normal of the feature
    that pushed the object into that step (A), which it left before the approach."""
    from stablepush.plan import plan_task

    task = shipped("t-shaped")
    steps = plan_task(task, seed=2).waypoints
    k = next(i for i in range(1, len(steps) - 1) if steps[i + 1].pusher != steps[i].pusher)
    a, b = steps[k].pusher, steps[k + 1].pusher
    c = next(name for name in task.pusher_names if name not in (a, b))
    features = place_features(task, steps, every_pusher=True)
    on_b = features[b].object_pose @ np.linalg.inv(grasp_transform(steps[k].pose))
    spliced = list(steps[:k + 1]) + [Waypoint(*steps[k + 1].pose, pusher=c)]
    retract = task.environment.retract * 1e-3
    for resting_on, normal in ((b, features[b].normal), (None, features[a].normal)):
        points = arm_trajectory(task, spliced, features, 100.0, _pose(on_b), resume_from=k, resting_on=resting_on)
        backing_off = list(itertools.takewhile(lambda w: w.phase == "retract", points))
        assert backing_off, [w.phase for w in points[:3]]
        np.testing.assert_allclose(np.array(backing_off[-1].pose[:3]) - on_b[:3, 3], normal * retract, atol=1e-9)


def test_features_from_the_task_environment():
    def edit(data):
        data["environment"] = {"features": {"left": [400, 50, 250, 10]}}

    task = task_with("horizontal-offset-high-mu", edit)
    steps = [Waypoint(*task.start), Waypoint(1.0, 0.0, 0.0, pusher="left")]
    feature = place_features(task, steps)["left"]
    np.testing.assert_allclose(feature.object_pose[:3, 3], [0.4, 0.05, 0.25])
    # The left face, 50 mm left of O, rotated 10 deg about y; its inward normal is O's +x.
    c, s = math.cos(math.radians(10)), math.sin(math.radians(10))
    np.testing.assert_allclose(feature.normal, [c, 0, -s], atol=1e-12)
    np.testing.assert_allclose((feature.start + feature.end) / 2, [0.4 - 0.05 * c, 0.05, 0.25 + 0.05 * s], atol=1e-12)


def test_convex_pieces_of_the_t_cover_its_area():
    t = shipped("t-shaped")
    pieces = convex_pieces(t.object.vertices)
    area = lambda p: 0.5 * sum(a[0] * b[1] - b[0] * a[1] for a, b in zip(p, p[1:] + p[:1]))  # noqa: E731
    assert len(pieces) <= 3
    assert sum(area(p) for p in pieces) == pytest.approx(area(list(t.object.vertices)))
    for p in pieces:
        n = len(p)
        assert all((p[i][0] - p[i - 1][0]) * (p[(i + 1) % n][1] - p[i - 1][1])
                   - (p[i][1] - p[i - 1][1]) * (p[(i + 1) % n][0] - p[i - 1][0]) > 0 for i in range(n))


@pytest.mark.parametrize("offset", [(0.0, 0.0, 0.0), (0.1, -0.4, 0.45), (-0.3, 0.2, -0.5)])
def test_a_feature_stops_short_of_a_reflex_corner_of_the_object_wherever_it_is_placed(offset):
    """The T's web feature runs down the web to its corner with the flange: its solid, at home and
    placed off by up to 0.5 mm / 0.5 deg, ends FEATURE_CORNER_GAP short of that corner and nowhere
    else, so the flange passes under it on the approach. The other features keep their segments."""
    from stablepush.kinematics.cell_model import FEATURE_CORNER_GAP, FEATURE_DEPTH, feature_solid
    from stablepush.sim.deviation import WorldDeviation

    task = shipped("t-shaped")
    scene = scene_description(task, place_features(task, [Waypoint(*task.start)], every_pusher=True), task.start)
    world = WorldDeviation(feature_offsets=tuple((name, *offset) for name in task.pusher_names)).apply(scene)
    for feature in world.features:
        solid = feature_solid(feature, world.object)
        a, b = np.asarray(feature.start), np.asarray(feature.end)
        length = np.linalg.norm(b - a)
        if feature.pusher != "web":
            assert 2 * solid["half_size"][0] == pytest.approx(length, abs=1e-12), feature.pusher
            continue
        assert 2 * solid["half_size"][0] == pytest.approx(length - FEATURE_CORNER_GAP, abs=1e-12)
        # The end that stops short is the one at the corner (10, -10) mm in O, the web's foot.
        T_WO = pose_to_matrix(feature.object_pose)
        corner = (T_WO @ np.array([0.010, 0.0, -0.010, 1.0]))[:3]
        near = a if np.linalg.norm(a - corner) < np.linalg.norm(b - corner) else b
        u = (b - a) / length
        centre = np.asarray(solid["center"]) + np.asarray(feature.normal) * FEATURE_DEPTH / 2  # on the contact face
        assert np.linalg.norm(centre + np.sign(u @ (near - centre)) * u * solid["half_size"][0] - near) == \
            pytest.approx(FEATURE_CORNER_GAP, abs=1e-9)


def test_a_deviated_world_scales_every_pad_and_feature_mu():
    from stablepush.sim.deviation import WorldDeviation

    task = shipped("horizontal-offset-low-mu")
    steps = [Waypoint(*task.start), Waypoint(*task.start, pusher="left")]
    scene = scene_description(task, place_features(task, steps), task.start)
    nominal, scaled = SimArm(scene), SimArm(scene, WorldDeviation(mu_scale=0.85))
    assert scene.gripper.mu == task.gripper.mu  # the scene itself is left as the executor sent it
    np.testing.assert_allclose(scaled.model.pair_friction, 0.85 * nominal.model.pair_friction)
    assert sorted(set(np.round(nominal.model.pair_friction[:, 0], 9))) == sorted({task.gripper.mu, 0.2})


def test_the_tracker_reports_the_pose_in_the_grasp_with_the_noise_asked_for():
    from stablepush.sim.deviation import WorldDeviation

    task = shipped("horizontal-offset-low-mu")
    arm = SimArm(scene_description(task, {}, task.start), WorldDeviation(tracker_noise_mm=0.2, tracker_noise_deg=0.1, seed=3))
    readings = np.array([[s["x"], s["z"], s["theta"]] for s in (arm.state()["object_in_grasp"] for _ in range(2000))])
    np.testing.assert_allclose(readings.std(axis=0), [0.2, 0.2, 0.1], rtol=0.1)
    np.testing.assert_allclose(readings.mean(axis=0), [0, 0, 0], atol=0.03)  # the object itself is still at the start


def test_default_stations_alternate_about_home_within_reach():
    """Six pushers' stations used to run 750 mm to one side, past the arm's reach: a closed-loop
    correction that switched to the fourth drove the simulated arm unstable (10 of 40 perturbed T
    runs). Now they alternate about home."""
    from stablepush.execution.world import station_offset

    assert [station_offset(k) for k in range(6)] == [0, 1, -1, 2, -2, 3]
    task = shipped("t-shaped")
    features = place_features(task, [Waypoint(*task.start)], every_pusher=True)
    home_y = task.environment.home[1] * 1e-3
    spacing = task.environment.station_spacing * 1e-3
    lanes = sorted(round((f.object_pose[1, 3] - home_y) / spacing) for f in features.values())
    assert lanes == [-2, -1, 0, 1, 2, 3]


@pytest.mark.parametrize("engine", ENGINES)
def test_a_waypoint_out_of_reach_is_refused_and_the_arm_held(engine):
    task = shipped("horizontal-offset-high-mu")
    arm = make_arm(engine, scene_description(task, {}, task.start))
    before = arm.state()["joints"]
    with pytest.raises(ValueError, match="cannot reach"):
        arm.move_to([0.4, 2.0, 0.3, 1.0, 0.0, 0.0, 0.0], 0.01)  # 2 m to the side
    assert arm.state()["joints"] == before
