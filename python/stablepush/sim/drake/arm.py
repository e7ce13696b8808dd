"""The simulated arm in Drake, the second engine: the same arm, grasp and world as the MuJoCo
one (`sim/mujoco/arm.py`), with Drake's own contact solver deciding stick and slip. Nothing here writes a
friction force.

The arm is the shipped arm.xml read by Drake's MJCF parser (`cell_model.arm_tree`); what that parser
leaves out is added with Drake's own API from the same tree: the position servos' damping `kv`
(as PD gains), the jaw coupling (a coupler constraint), gravity compensation (`gravcomp`: a
feed-forward torque) and the site G (a fixed frame). The pads' point spheres, the object's convex
pieces (a mesh part's own, or the prism of the section) and the features come from the same scene
parts as MuJoCo's (`cell_model.pad_layout`, `cell_model.object_solid`, `cell_model.feature_solid`).

Contact (chosen by the friction-fidelity contract, `sim/fidelity.py`; docs/engines.md says how):
- Drake's DRAKE_APPROXIMATION discrete model (a convex approximation solved by SAP; the PD servos,
  their effort limits and the coupler are implicit in it), at DRAKE_TIMESTEP: its friction is
  regularized, and a sticking contact slips at about 1e-3 w f h (w the contact's inverse mass, f
  its friction, h the step), so the step is the contract's to choose (0.2 ms fails it);
- the pads are point contacts (spheres); each feature is rigid hydroelastic against the object,
  compliant at HYDROELASTIC_MODULUS (a box on a box has one point contact, which chatters; a
  softer patch lets the object roll on the pusher where the rigid model says it sticks);
- only pads and features touch the object (collision filters); a pad touches a deep prism of
  the section under it (`_add_pad_faces`: Drake's sphere-vs-convex query misplaces a contact near
  a thin prism's side face), or a box piece itself;
- Drake combines two surfaces' friction as mu = 2 mu1 mu2 / (mu1 + mu2); the object carries
  OBJECT_MU and every pad and feature the partner value that makes the pair's mu the task's
  (`partner_mu`), since each pair in the task has its own mu.

Poses are (x, y, z, qw, qx, qy, qz) in the world [m]; the end effector is the gripper frame G.
"""
from __future__ import annotations

import math
import time
import xml.etree.ElementTree as ET
from typing import Callable, Dict, Optional, Sequence

import numpy as np

from stablepush.execution.scene import Scene, SceneObject
from stablepush.extras import require
from stablepush.frames import pose_to_matrix
from stablepush.kinematics import cell_model
from stablepush.kinematics.robot import FINGER_JOINTS, GRIPPER_SITE, arm_model
from stablepush.sim.deviation import WorldDeviation
from stablepush.sim.tracking import SETTLE_TIME, TrackingArm, in_grasp
from stablepush.task.model import Robot

DRAKE_TIMESTEP = 0.000125  # s (the friction-fidelity contract fails at 0.2 ms: module docstring)
DRAKE_APPROXIMATION = "lagged"  # DiscreteContactApproximation: sap, similar or lagged
STICTION_TOLERANCE = 1e-7  # m/s: under the regularization's own floor (1e-6 to 1e-9 give the same creep)
POINT_STIFFNESS = 1e5  # N/m per pad point
HUNT_CROSSLEY_DISSIPATION = 1.0  # s/m
HYDROELASTIC_MODULUS = 1e10  # Pa: the object's contact with a feature; softer lets the pusher roll (docstring)
HYDRO_RESOLUTION = 0.002  # m
PAD_FACE_DEPTH = 1.0  # m: how deep the prisms the pads touch reach into the object (_add_pad_faces)
OBJECT_MU = 1000.0  # the object's own friction; each partner's is set to give the pair's mu (partner_mu)
KINEMATIC_HAND_BODY = "hand"
KINEMATIC_HAND_MASS = 1e4  # kg


def partner_mu(mu: float, object_mu: float = OBJECT_MU) -> float:
    """The friction a pad or feature needs for the pair with the object to have `mu`, under
    Drake's rule mu = 2 mu_a mu_b / (mu_a + mu_b): mu_b = mu mu_a / (2 mu_a - mu), mu < 2 mu_a."""
    if not 0.0 <= mu < 2.0 * object_mu:
        raise ValueError(f"a contact's mu must be below {2 * object_mu:g} in the Drake world, got {mu:g}")
    return mu * object_mu / (2.0 * object_mu - mu)


def _drake():
    """pydrake's names, imported on first use: the MuJoCo engine never loads Drake."""
    return require("pydrake.all", "--engine drake")


def _vector(text: str) -> np.ndarray:
    return np.array([float(v) for v in text.split()])


class DrakeGrasp:
    """A scene's grasp in Drake, shared by the arm and the friction-fidelity rig: the diagram
    (plant and scene graph), the jaws closed on the object with the grip force, and the
    read-outs of the grasp. The counterpart of `arm.SimulatedGrasp`."""

    engine = "drake"

    def __init__(self, scene: Scene, kinematic_hand: bool = False, robot: Optional[Robot] = None):
        d = _drake()
        self._d = d
        self.timestep = time_step = DRAKE_TIMESTEP
        approximation = DRAKE_APPROXIMATION
        self.arm = arm_model(robot)
        tree = cell_model.arm_tree(scene, kinematic_hand, robot)
        if kinematic_hand:
            # Drake keeps a joint's armature only on an actuated joint: a heavy hand stands in for
            # the hand joints' (the pads' forces must not move it within a step).
            hand_geom = cell_model.found(tree, f".//body[@name='{KINEMATIC_HAND_BODY}']/geom")
            hand_geom.set("mass", repr(KINEMATIC_HAND_MASS))
        builder = d.DiagramBuilder()
        plant, scene_graph = d.AddMultibodyPlantSceneGraph(builder, time_step=time_step)
        plant.set_discrete_contact_approximation(getattr(d.DiscreteContactApproximation, "k" + approximation.title()))
        plant.set_contact_model(d.ContactModel.kHydroelasticWithFallback)
        plant.set_stiction_tolerance(STICTION_TOLERANCE)
        parser = d.Parser(plant)
        parser.SetAutoRenaming(False)
        (self._arm,) = _quietly(lambda: parser.AddModelsFromString(ET.tostring(tree, encoding="unicode"), "xml"))
        gx, gz = scene.gravity
        plant.mutable_gravity_field().set_gravity_vector([gx, 0.0, gz])
        if kinematic_hand:  # the hand's motion is prescribed, its fingers carried (gravcomp)
            plant.set_gravity_enabled(self._arm, False)
        self.plant = plant

        # What the MJCF parser leaves out, from the same tree.
        for position in cell_model.found(tree, "actuator"):
            actuator = plant.GetJointActuatorByName(position.get("name"), self._arm)
            actuator.set_controller_gains(d.PdControllerGains(p=float(position.attrib["kp"]),
                                                              d=float(position.get("kv", "0"))))
        pos_joint, neg_joint = (plant.GetJointByName(j, self._arm) for j in FINGER_JOINTS)
        plant.AddCouplerConstraint(joint0=neg_joint, joint1=pos_joint, gear_ratio=1.0)
        self._gravcomp_bodies = [plant.GetBodyByName(b.get("name"), self._arm).index()
                                 for b in tree.iter("body") if b.get("gravcomp") == "1"]
        site = cell_model.found(tree, f".//site[@name='{GRIPPER_SITE}']")
        parent = next(b for b in tree.iter("body") if site in list(b))
        X_BG = d.RigidTransform(d.Quaternion(_vector(site.get("quat", "1 0 0 0"))), _vector(site.get("pos", "0 0 0")))
        hand = plant.GetBodyByName(parent.get("name"), self._arm)
        self._G = plant.AddFrame(d.FixedOffsetFrame("G", hand.body_frame(), X_BG))

        arm_geometry = [g for b in plant.GetBodyIndices(self._arm)
                        for g in plant.GetCollisionGeometriesForBody(plant.get_body(b))]
        arm_geometry += plant.GetCollisionGeometriesForBody(plant.world_body())  # the floor
        self._pads = self._add_pads(scene)
        solid = cell_model.object_solid(scene.object)
        self._object_body, self._pieces = self._add_object(scene.object, solid)
        pad_faces = self._add_pad_faces(scene.object)
        self._features = self._add_features(scene)
        plant.Finalize()

        # Only pads and features touch the object; a pad touches a box piece, or the deep prism of a
        # section piece on its own side (_add_pad_faces).
        sides = [side for _, _, side, _ in cell_model.pad_layout(scene)]
        pads_on = {s: d.GeometrySet([g for g, side in zip(self._pads, sides) if side == s]) for s in (1.0, -1.0)}
        deep = [g for faces in pad_faces.values() for g in faces]
        boxes = [g for g, piece in zip(self._pieces, solid) if piece.box]
        everything = d.GeometrySet(arm_geometry + self._pads + self._pieces + deep + list(self._features.values()))
        declaration = (d.CollisionFilterDeclaration().ExcludeWithin(everything)
                       .AllowBetween(d.GeometrySet(list(self._features.values())), d.GeometrySet(self._pieces))
                       .AllowBetween(d.GeometrySet(self._pads), d.GeometrySet(boxes)))
        for side, faces in pad_faces.items():
            declaration.AllowBetween(pads_on[side], d.GeometrySet(faces))
        scene_graph.collision_filter_manager().Apply(declaration)

        self.diagram = builder.Build()
        self.simulator = d.Simulator(self.diagram)
        self.context = self.simulator.get_mutable_context()
        self.plant_context = plant.GetMyMutableContextFromRoot(self.context)
        self._actuated = [plant.get_joint_actuator(i) for i in plant.GetJointActuatorIndices(self._arm)]
        self._desired = np.zeros(2 * len(self._actuated))
        self._desired_port = plant.get_desired_state_input_port(self._arm)
        self._actuation_port = plant.get_actuation_input_port(self._arm)
        self._feed_forward = np.zeros(len(self._actuated))
        self.steps = 0
        self.step_wall_time = 0.0

        # The object where the scene puts it, the jaws at its faces; the subclass sets its drives.
        X_WO = d.RigidTransform(pose_to_matrix(scene.object_pose))
        plant.SetFreeBodyPose(self.plant_context, self._object_body, X_WO)
        for joint in (pos_joint, neg_joint):
            joint.set_translation(self.plant_context, scene.object.thickness / 2)
        self._finger_servos = [self._servo_index(j) for j in FINGER_JOINTS]
        if kinematic_hand:
            self._hand = [plant.GetJointByName(j, self._arm) for j in cell_model.HAND_JOINTS]
            self.simulator.Initialize()

    def step_hand(self, motion: Sequence[float], velocity: Sequence[float]) -> None:
        """With a kinematic hand: one time step with the hand at `motion` (x m, z m, theta rad about
        y, from its start) moving at `velocity` (m/s, m/s, rad/s)."""

        def drive_hand(_: int) -> None:
            q = self.plant.GetPositions(self.plant_context)
            v = self.plant.GetVelocities(self.plant_context)
            for joint, position, rate in zip(self._hand, motion, velocity):
                q[joint.position_start()] = position
                v[joint.velocity_start()] = rate
            self.plant.SetPositionsAndVelocities(self.plant_context, np.concatenate([q, v]))

        self._run(1, drive_hand)

    # -- building ---------------------------------------------------------------------------------

    def _properties(self, mu: float, hydroelastic: str = ""):
        d = self._d
        props = d.ProximityProperties()
        d.AddContactMaterial(dissipation=HUNT_CROSSLEY_DISSIPATION, point_stiffness=POINT_STIFFNESS,
                             friction=d.CoulombFriction(mu, mu), properties=props)
        if hydroelastic == "compliant":
            d.AddCompliantHydroelasticProperties(HYDRO_RESOLUTION, HYDROELASTIC_MODULUS, props)
        elif hydroelastic == "rigid":
            d.AddRigidHydroelasticProperties(HYDRO_RESOLUTION, props)
        return props

    def _add_pads(self, scene: Scene) -> list:
        d, plant = self._d, self.plant
        props = self._properties(partner_mu(scene.gripper.mu))
        pads = []
        for name, finger, side, (px, pz) in cell_model.pad_layout(scene):
            body = plant.GetBodyByName(finger, self._arm)
            X = d.RigidTransform([px, side * cell_model.PAD_POINT_RADIUS, pz])
            pads.append(plant.RegisterCollisionGeometry(body, X, d.Sphere(cell_model.PAD_POINT_RADIUS), name, props))
        return pads

    def _add_object(self, obj: SceneObject, solid: list):
        """The object's body (its solid's mass properties, scene.object_inertia) and the convex
        `solid` pieces (cell_model.object_solid) as its geometry: a box piece as a Box, any other as
        a Convex of its corners."""
        d, plant = self._d, self.plant
        instance = plant.AddModelInstance(cell_model.OBJECT_BODY)
        J = cell_model.object_inertia(obj)
        inertia = d.SpatialInertia.MakeFromCentralInertia(
            obj.mass, list(cell_model.object_com(obj)),
            d.RotationalInertia(J[0, 0], J[1, 1], J[2, 2], J[0, 1], J[0, 2], J[1, 2]))
        body = plant.AddRigidBody(cell_model.OBJECT_BODY, instance, inertia)
        props = self._properties(OBJECT_MU, "compliant")
        geometries = []
        for piece in solid:
            if piece.box:
                center, size = piece.box_center_size()
                X, shape = d.RigidTransform(center), d.Box(*size)
            else:
                X = d.RigidTransform()
                vertices = "".join(f"v {x!r} {y!r} {z!r}\n" for x, y, z in piece.vertices.tolist())
                shape = d.Convex(d.InMemoryMesh(mesh_file=d.MemoryFile(vertices, ".obj", piece.name)))
            geometries.append(plant.RegisterCollisionGeometry(body, X, shape, piece.name, props))
        return body, geometries

    def _add_pad_faces(self, obj: SceneObject) -> Dict[float, list]:
        """What the pads on each side (+1, -1: the object's +y and -y faces) touch: every piece of the
        section (cell_model.object_pieces) that is not built as a box, as a prism from that face
        PAD_FACE_DEPTH deep into the object, without mass. Drake's sphere-vs-convex query answers a
        pad point within about 5.5 times its penetration of a prism's side face through that side,
        along the direction from the prism's centre (the wedge's pad point 0.3 mm inside its heel
        face pushed the wedge out of the grasp with 7.5 N along x; docs/results/engines-cross-engine.md). A deep prism's
        side faces are far from its centre, so the query answers with the face the pad presses on.
        A mesh part gets them for every piece of its section, at +-thickness/2: the planner takes a
        plan only where the pads rest on the solid's flat faces there (within the part's tolerance),
        so the prism's faces under the pads are the solid's."""
        d, plant = self._d, self.plant
        props = self._properties(OBJECT_MU)  # point contact, as the pads': no hydroelastic mesh
        half = obj.thickness / 2
        faces: Dict[float, list] = {1.0: [], -1.0: []}
        for name, piece, rectangle in cell_model.object_pieces(obj):
            if rectangle and obj.mesh is None:
                continue  # the pads touch the box piece itself: the sphere-vs-box query is exact
            for side in faces:
                ys = (side * half, side * (half - PAD_FACE_DEPTH))
                vertices = "".join(f"v {x!r} {y!r} {z!r}\n" for y in ys for x, z in piece)
                shape = d.Convex(d.InMemoryMesh(mesh_file=d.MemoryFile(vertices, ".obj", f"{name}_pad_face{side:+g}")))
                faces[side].append(plant.RegisterCollisionGeometry(self._object_body, d.RigidTransform(), shape,
                                                                   f"{name}_pad_face{side:+g}", props))
        return faces

    def _add_features(self, scene: Scene) -> Dict[str, int]:
        d, plant = self._d, self.plant
        out = {}
        for feature in scene.features:
            solid = cell_model.feature_solid(feature, scene.object)
            if solid["kind"] == "box":
                R = d.RotationMatrix.MakeYRotation(solid["angle"])
                shape = d.Box(*(2 * np.asarray(solid["half_size"])))
            else:  # a rod along y
                R = d.RotationMatrix.MakeXRotation(math.pi / 2)
                shape = d.Capsule(solid["radius"], 2 * solid["half_length"])
            name = cell_model.feature_geom(feature.pusher)
            out[feature.pusher] = plant.RegisterCollisionGeometry(
                plant.world_body(), d.RigidTransform(R, solid["center"]), shape, name,
                self._properties(partner_mu(feature.mu), "rigid"))
        return out

    def _servo_index(self, joint_name: str) -> int:
        return next(i for i, a in enumerate(self._actuated) if a.joint().name() == joint_name)

    # -- stepping ---------------------------------------------------------------------------------

    def _gravity_compensation(self) -> None:
        """gravcomp's feed-forward: the servo torques that carry the arm's own weight (the
        generalized gravity forces of the gravcomp bodies, at the current configuration)."""
        plant, ctx = self.plant, self.plant_context
        tau = np.zeros(plant.num_velocities())
        g = plant.gravity_field().gravity_vector()
        for index in self._gravcomp_bodies:
            body = plant.get_body(index)
            p_com = body.CalcCenterOfMassInBodyFrame(ctx)
            J = plant.CalcJacobianTranslationalVelocity(ctx, self._d.JacobianWrtVariable.kV, body.body_frame(),
                                                        p_com, plant.world_frame(), plant.world_frame())
            tau -= J.T @ (body.get_mass(ctx) * g)
        for k, actuator in enumerate(self._actuated):
            self._feed_forward[k] = tau[actuator.joint().velocity_start()]

    def _run(self, n: int, before_step: Callable[[int], None]) -> None:
        """n time steps; `before_step(i)` (i = 1..n) sets the drives of step i."""
        t0 = time.perf_counter()
        for i in range(1, n + 1):
            before_step(i)
            self._desired_port.FixValue(self.plant_context, self._desired)
            self._actuation_port.FixValue(self.plant_context, self._feed_forward)
            self.simulator.AdvanceTo(self.context.get_time() + self.timestep)
        self.step_wall_time += time.perf_counter() - t0
        self.steps += n

    # -- read-outs --------------------------------------------------------------------------------

    @property
    def time(self) -> float:
        return self.context.get_time()

    def gripper_matrix(self) -> np.ndarray:
        """T_WG (4x4, m) now."""
        return self._G.CalcPoseInWorld(self.plant_context).GetAsMatrix4()

    def object_matrix(self) -> np.ndarray:
        """T_WO (4x4, m) now."""
        return self._object_body.EvalPoseInWorld(self.plant_context).GetAsMatrix4()

    def in_grasp(self) -> Dict[str, float]:
        """The object's true pose in the grasp now (see `tracking.in_grasp`)."""
        return in_grasp(self.gripper_matrix(), self.object_matrix())

    def _results(self):
        return self.plant.get_contact_results_output_port().Eval(self.plant_context)

    def _contacts(self):
        results = self._results()
        return [results.point_pair_contact_info(i) for i in range(results.num_point_pair_contacts())]

    def contact_force_on_object(self, pusher: str) -> np.ndarray:
        """Total force [N, world frame] that pusher `pusher`'s feature exerts on the object now
        (its hydroelastic contact surfaces and any point contacts)."""
        geometry = self._features[pusher]
        total = np.zeros(3)
        results = self._results()
        for i in range(results.num_hydroelastic_contacts()):
            info = results.hydroelastic_contact_info(i)
            surface = info.contact_surface()
            if geometry in (surface.id_M(), surface.id_N()):
                f = np.asarray(info.F_Ac_W().translational())  # on the body of geometry M
                total += -f if surface.id_M() == geometry else f
        for info in self._contacts():
            pair = info.point_pair()
            if geometry not in (pair.id_A, pair.id_B):
                continue
            f = np.asarray(info.contact_force())  # on body B, applied at the contact point
            total += f if info.bodyB_index() == self._object_body.index() else -f
        return total

    def pad_contacts(self) -> int:
        """How many pad points touch the object now."""
        pads = set(self._pads)
        return sum(1 for info in self._contacts() if info.point_pair().id_A in pads or info.point_pair().id_B in pads)

    @property
    def steps_per_second(self) -> float:
        return self.steps / self.step_wall_time if self.step_wall_time > 0 else 0.0

    def describe(self) -> str:
        return (f"Drake {self.plant.num_bodies()} bodies, {len(self._pads)} pad points, "
                f"{DRAKE_APPROXIMATION} contact, {self.timestep * 1e3:g} ms step")


class DrakeArm(TrackingArm, DrakeGrasp):
    """The arm, the grasp and the world of one scene (as `deviation` alters it), in
    Drake; the same interface as `arm.SimArm` (move_to, advance, stop, state, solve_ik)."""

    def __init__(self, scene: Scene, deviation: WorldDeviation = WorldDeviation(), robot: Optional[Robot] = None):
        super().__init__(scene, deviation, robot)
        plant = self.plant
        joints = [plant.GetJointByName(j, self._arm) for j in self.arm.joints]
        self._arm_q = np.array([j.position_start() for j in joints])
        self._arm_servos = [self._servo_index(j) for j in self.arm.joints]
        self._lower = np.array([j.position_lower_limits()[0] for j in joints])
        self._upper = np.array([j.position_upper_limits()[0] for j in joints])
        self._scratch = plant.CreateDefaultContext()

        home = self._find_home()
        q = plant.GetPositions(self.plant_context)
        q[self._arm_q] = home
        plant.SetPositions(self.plant_context, q)
        self._set_servos(home)
        self.simulator.Initialize()
        self.advance(SETTLE_TIME)

    # -- kinematics ---------------------------------------------------------------------------

    def _kinematics(self, q: np.ndarray):
        plant, ctx = self.plant, self._scratch
        full = plant.GetPositions(ctx)
        full[self._arm_q] = q
        plant.SetPositions(ctx, full)
        X = self._G.CalcPoseInWorld(ctx)
        J = plant.CalcJacobianSpatialVelocity(ctx, self._d.JacobianWrtVariable.kQDot, self._G, [0, 0, 0],
                                              plant.world_frame(), plant.world_frame())
        J = J[:, self._arm_q]  # rows: angular, then linear
        return X.rotation().matrix(), X.translation().copy(), np.vstack([J[3:], J[:3]])

    # -- simulation ---------------------------------------------------------------------------

    def _set_servos(self, q_arm: np.ndarray) -> None:
        n = len(self._actuated)
        self._desired[self._arm_servos] = q_arm
        self._desired[[n + k for k in self._arm_servos]] = 0.0
        self._desired[self._finger_servos] = 0.0  # the jaws close toward y = 0, capped at the grip force

    def advance(self, duration: float, target=None) -> None:
        self._gravity_compensation()  # gravcomp's torques, held over the waypoint period
        super().advance(duration, target)

    def stop(self) -> None:
        """Hold the joints where they are now."""
        q = self.plant.GetPositions(self.plant_context)
        self.target = q[self._arm_q].copy()
        self._set_servos(self.target)
        v = self.plant.GetVelocities(self.plant_context)
        v[self._arm_q] = 0.0  # the arm's joints are revolute: one velocity per position
        self.plant.SetVelocities(self.plant_context, v)

    # -- state --------------------------------------------------------------------------------

    def state(self, contact_force: bool = False) -> dict:
        """What the arm reports, as `arm.SimArm.state` does."""
        return self._report(float(self.time), self.plant.GetPositions(self.plant_context)[self._arm_q], contact_force)


def _quietly(build):
    """Run `build` with Drake's log quiet: its MJCF parser warns about every tag it skips
    (gravcomp, site, the jaw coupling), each of which this module adds itself."""
    import logging

    logger = logging.getLogger("drake")
    level = logger.level
    logger.setLevel(logging.ERROR)
    try:
        return build()
    finally:
        logger.setLevel(level)

