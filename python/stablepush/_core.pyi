"""
stablepush C++ core: contact models, generalized friction cones, the stable-push test and the T-RRT* planner (SI units: m, rad, kg, N, s)
"""
from __future__ import annotations
import collections.abc
import numpy
import numpy.typing
import typing
__all__: list[str] = ['CERTIFICATION_BAND', 'CheckedPlan', 'ContactCase', 'CrossSection', 'GravityFrame', 'Gripper', 'MAX_TIME_LIMIT', 'Motion', 'MotionWrench', 'Pad', 'PathCost', 'PathNode', 'Plan', 'PlanOutcome', 'PlanStats', 'PlannerSettings', 'Pose', 'PushChecker', 'PushResult', 'Pusher', 'RigidBody', 'SHORTEST_PUSH', 'STICKING_SPEED_RATIO', 'StablePushModel', 'StepSize', 'StopFlag', 'TRRT_STAR_PARAMETERS', 'TRRT_STAR_PARAMETER_RANGES', 'Waypoint', 'WrenchCone', 'plan', 'plan_with_checker', 'steps_between', 'worst_case']
class Pose:
    """
    The object's pose O seen from the gripper frame G: x [m], z [m], theta [rad].
    """
    __hash__: typing.ClassVar[None] = None  # type: ignore[assignment]
    def __eq__(self, arg0: typing.Any) -> bool:
        ...
    def __getitem__(self, arg0: typing.SupportsInt | typing.SupportsIndex) -> float:
        ...
    @typing.overload
    def __init__(self) -> None:
        ...
    @typing.overload
    def __init__(self, x: typing.SupportsFloat | typing.SupportsIndex, z: typing.SupportsFloat | typing.SupportsIndex, theta: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
    @typing.overload
    def __init__(self, values: typing.Annotated[collections.abc.Sequence[typing.SupportsFloat | typing.SupportsIndex], "FixedSize(3)"]) -> None:
        ...
    def __iter__(self) -> collections.abc.Iterator[float]:
        ...
    def __len__(self) -> int:
        ...
    def __repr__(self) -> str:
        ...
    @property
    def theta(self) -> float:
        ...
    @theta.setter
    def theta(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
    @property
    def x(self) -> float:
        ...
    @x.setter
    def x(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
    @property
    def z(self) -> float:
        ...
    @z.setter
    def z(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
class Motion:
    """
    A displacement of the object in the grasp: dx [m], dz [m], dtheta [rad], in G.
    """
    __hash__: typing.ClassVar[None] = None  # type: ignore[assignment]
    def __eq__(self, arg0: typing.Any) -> bool:
        ...
    def __getitem__(self, arg0: typing.SupportsInt | typing.SupportsIndex) -> float:
        ...
    @typing.overload
    def __init__(self) -> None:
        ...
    @typing.overload
    def __init__(self, dx: typing.SupportsFloat | typing.SupportsIndex, dz: typing.SupportsFloat | typing.SupportsIndex, dtheta: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
    @typing.overload
    def __init__(self, values: typing.Annotated[collections.abc.Sequence[typing.SupportsFloat | typing.SupportsIndex], "FixedSize(3)"]) -> None:
        ...
    def __iter__(self) -> collections.abc.Iterator[float]:
        ...
    def __len__(self) -> int:
        ...
    def __repr__(self) -> str:
        ...
    @property
    def dtheta(self) -> float:
        ...
    @dtheta.setter
    def dtheta(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
    @property
    def dx(self) -> float:
        ...
    @dx.setter
    def dx(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
    @property
    def dz(self) -> float:
        ...
    @dz.setter
    def dz(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
class StepSize:
    """
    One unit step of the planner: length [m] and angle [rad].
    """
    @typing.overload
    def __init__(self, length: typing.SupportsFloat | typing.SupportsIndex, angle: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
    @typing.overload
    def __init__(self, values: typing.Annotated[collections.abc.Sequence[typing.SupportsFloat | typing.SupportsIndex], "FixedSize(2)"]) -> None:
        ...
    def __iter__(self) -> collections.abc.Iterator[float]:
        ...
    @property
    def angle(self) -> float:
        ...
    @angle.setter
    def angle(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
    @property
    def length(self) -> float:
        ...
    @length.setter
    def length(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
class CrossSection:
    """
    The object's cross-section in O: a simple polygon [m].
    """
    @staticmethod
    def box(length_x: typing.SupportsFloat | typing.SupportsIndex, height_z: typing.SupportsFloat | typing.SupportsIndex) -> CrossSection:
        ...
    @staticmethod
    def defect(vertices: collections.abc.Sequence[typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[2, 1]"]]) -> str:
        """
        Why the vertices are not a usable cross-section ('' when they are).
        """
    def __init__(self, vertices: collections.abc.Sequence[typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[2, 1]"]]) -> None:
        ...
    def contains_capsule(self, a: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[2, 1]"], b: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[2, 1]"], radius: typing.SupportsFloat | typing.SupportsIndex) -> bool:
        """
        Whether the disc of `radius` swept along the segment a-b lies inside the polygon.
        """
    def contains_disc(self, center: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[2, 1]"], radius: typing.SupportsFloat | typing.SupportsIndex) -> bool:
        ...
    def distance_to_boundary(self, point: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[2, 1]"]) -> float:
        ...
    def edges_holding(self, a: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[2, 1]"], b: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[2, 1]"], tolerance: typing.SupportsFloat | typing.SupportsIndex) -> list[int]:
        ...
    def inward_normal(self, edge: typing.SupportsInt | typing.SupportsIndex) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[2, 1]"]:
        ...
    def nearest_edge(self, a: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[2, 1]"], b: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[2, 1]"]) -> tuple[int, float]:
        """
        (edge index, distance m): the edge nearest to the segment a-b as a whole
        """
    @property
    def area(self) -> float:
        ...
    @property
    def centroid(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[2, 1]"]:
        ...
    @property
    def circumradius(self) -> float:
        ...
    @property
    def convex(self) -> bool:
        ...
    @property
    def polar_moment_about_centroid(self) -> float:
        ...
    @property
    def vertices(self) -> list[typing.Annotated[numpy.typing.NDArray[numpy.float64], "[2, 1]"]]:
        ...
class RigidBody:
    """
    Mass [kg], centre of mass in O [m], inertia about it [kg m^2].
    """
    @staticmethod
    def uniform(section: CrossSection, mass: typing.SupportsFloat | typing.SupportsIndex) -> RigidBody:
        ...
    def __init__(self, mass: typing.SupportsFloat | typing.SupportsIndex, com: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[2, 1]"], inertia: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
    @property
    def com(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[2, 1]"]:
        ...
    @property
    def inertia(self) -> float:
        ...
    @property
    def mass(self) -> float:
        ...
class Pad:
    """
    A finger pad: a disc in G (centre [m], radius [m]).
    """
    def __init__(self, center: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[2, 1]"], radius: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
    @property
    def center(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[2, 1]"]:
        ...
    @property
    def radius(self) -> float:
        ...
class Gripper:
    """
    The pads of a parallel-jaw grasp, their grip force [N] and friction.
    """
    def __init__(self, pads: collections.abc.Sequence[Pad], grip_force: typing.SupportsFloat | typing.SupportsIndex, mu: typing.SupportsFloat | typing.SupportsIndex, pad_rings: typing.SupportsInt | typing.SupportsIndex) -> None:
        ...
    def grasp_maintained_along(self, section: CrossSection, start: Pose | collections.abc.Sequence[typing.SupportsFloat] | numpy.typing.NDArray[numpy.float64], end: Pose | collections.abc.Sequence[typing.SupportsFloat] | numpy.typing.NDArray[numpy.float64]) -> bool:
        """
        Every pad disc inside the cross-section throughout the linear motion start -> end.
        """
    def pads_inside(self, section: CrossSection, pose: Pose | collections.abc.Sequence[typing.SupportsFloat] | numpy.typing.NDArray[numpy.float64]) -> list[bool]:
        ...
    @property
    def pads(self) -> list[Pad]:
        ...
    @property
    def point_friction_limits(self) -> list[float]:
        ...
    @property
    def point_positions(self) -> list[typing.Annotated[numpy.typing.NDArray[numpy.float64], "[2, 1]"]]:
        ...
class Pusher:
    """
    A pusher fixed on the object's boundary in O: its contact points and friction.
    """
    @staticmethod
    def on_boundary(section: CrossSection, name: str, a: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[2, 1]"], b: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[2, 1]"], mu: typing.SupportsFloat | typing.SupportsIndex, n_points: typing.SupportsInt | typing.SupportsIndex) -> Pusher:
        ...
    def cone_generators(self) -> list[typing.Annotated[numpy.typing.NDArray[numpy.float64], "[3, 1]"]]:
        ...
    @property
    def inward_normal(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[2, 1]"]:
        ...
    @property
    def mu(self) -> float:
        ...
    @property
    def name(self) -> str:
        ...
    @property
    def points(self) -> list[typing.Annotated[numpy.typing.NDArray[numpy.float64], "[2, 1]"]]:
        ...
class WrenchCone:
    """
    A pointed polyhedral wrench cone with its exact H-representation.
    """
    def __init__(self, generators: collections.abc.Sequence[typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[3, 1]"]], torque_length: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
    @property
    def dimension(self) -> int:
        ...
    @property
    def equality_rows(self) -> list[typing.Annotated[numpy.typing.NDArray[numpy.float64], "[3, 1]"]]:
        ...
    @property
    def facet_rows(self) -> list[typing.Annotated[numpy.typing.NDArray[numpy.float64], "[3, 1]"]]:
        ...
    @property
    def generators(self) -> list[typing.Annotated[numpy.typing.NDArray[numpy.float64], "[3, 1]"]]:
        ...
    @property
    def torque_length(self) -> float:
        ...
class ContactCase:
    """
    How the pads move against the object during a push
    
    Members:
    
      all_sliding
    
      sticking
    """
    __members__: typing.ClassVar[dict[str, ContactCase]]
    all_sliding: typing.ClassVar[ContactCase]
    sticking: typing.ClassVar[ContactCase]
    @typing.overload
    def __eq__(self, other: ContactCase) -> bool:
        ...
    @typing.overload
    def __eq__(self, other: typing.Any) -> bool:
        ...
    def __getstate__(self) -> int:
        ...
    def __hash__(self) -> int:
        ...
    def __index__(self) -> int:
        ...
    def __init__(self, value: typing.SupportsInt | typing.SupportsIndex) -> None:
        ...
    def __int__(self) -> int:
        ...
    @typing.overload
    def __ne__(self, other: ContactCase) -> bool:
        ...
    @typing.overload
    def __ne__(self, other: typing.Any) -> bool:
        ...
    def __repr__(self) -> str:
        ...
    def __setstate__(self, state: typing.SupportsInt | typing.SupportsIndex) -> None:
        ...
    def __str__(self) -> str:
        ...
    @property
    def name(self) -> str:
        ...
    @property
    def value(self) -> int:
        ...
class PushResult:
    """
    The stable-push test's verdict on one push by one pusher.
    """
    def __repr__(self) -> str:
        ...
    @property
    def contact_case(self) -> ContactCase:
        ...
    @property
    def exact(self) -> bool:
        """
        Decided in exact arithmetic
        """
    @property
    def feasible(self) -> bool:
        ...
    @property
    def margin(self) -> float:
        """
        How deep inside the cone [N]
        """
    @property
    def sticking_points(self) -> int:
        ...
    @property
    def witness(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[3, 1]"]:
        """
        Pusher wrench in O [N, N, N m]
        """
class MotionWrench:
    """
    What a push asks of the pusher, before the cone test.
    """
    @property
    def required(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[3, 1]"]:
        """
        M xi/dt - w_sliding - w_gravity in O [N, N, N m]
        """
    @property
    def scale(self) -> float:
        ...
    @property
    def sticking(self) -> list[tuple[typing.Annotated[numpy.typing.NDArray[numpy.float64], "[2, 1]"], float]]:
        """
        (arm in G from O's origin [m], friction disc radius [N]) per sticking location
        """
    @property
    def sticking_points(self) -> int:
        ...
class GravityFrame:
    """
    The frame in which gravity is fixed during a push
    
    Members:
    
      gripper
    
      object
    """
    __members__: typing.ClassVar[dict[str, GravityFrame]]
    gripper: typing.ClassVar[GravityFrame]
    object: typing.ClassVar[GravityFrame]
    @typing.overload
    def __eq__(self, other: GravityFrame) -> bool:
        ...
    @typing.overload
    def __eq__(self, other: typing.Any) -> bool:
        ...
    def __getstate__(self) -> int:
        ...
    def __hash__(self) -> int:
        ...
    def __index__(self) -> int:
        ...
    def __init__(self, value: typing.SupportsInt | typing.SupportsIndex) -> None:
        ...
    def __int__(self) -> int:
        ...
    @typing.overload
    def __ne__(self, other: GravityFrame) -> bool:
        ...
    @typing.overload
    def __ne__(self, other: typing.Any) -> bool:
        ...
    def __repr__(self) -> str:
        ...
    def __setstate__(self, state: typing.SupportsInt | typing.SupportsIndex) -> None:
        ...
    def __str__(self) -> str:
        ...
    @property
    def name(self) -> str:
        ...
    @property
    def value(self) -> int:
        ...
class StablePushModel:
    def __init__(self, *, section: CrossSection, body: RigidBody, gripper: Gripper, pushers: collections.abc.Sequence[Pusher], gravity: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[2, 1]"], step_time: typing.SupportsFloat | typing.SupportsIndex, friction_polygon_sides: typing.SupportsInt | typing.SupportsIndex = 16, gravity_frame: GravityFrame = GravityFrame.gripper, feature_angles: collections.abc.Sequence[typing.SupportsFloat | typing.SupportsIndex] = []) -> None:
        """
        gravity: in G's plane when G's axes are the world's [m/s^2]; gravity_frame, feature_angles (the
        object's world orientation on each pusher's feature [rad]): how gravity turns during a push.
        """
    def check(self, q: Pose | collections.abc.Sequence[typing.SupportsFloat] | numpy.typing.NDArray[numpy.float64], dq: Motion | collections.abc.Sequence[typing.SupportsFloat] | numpy.typing.NDArray[numpy.float64], pusher: typing.SupportsInt | typing.SupportsIndex) -> PushResult:
        ...
    def check_all(self, q: Pose | collections.abc.Sequence[typing.SupportsFloat] | numpy.typing.NDArray[numpy.float64], dq: Motion | collections.abc.Sequence[typing.SupportsFloat] | numpy.typing.NDArray[numpy.float64]) -> list[PushResult]:
        ...
    def check_batch(self, q: typing.Annotated[numpy.typing.ArrayLike, numpy.float64], dq: typing.Annotated[numpy.typing.ArrayLike, numpy.float64], pusher: typing.SupportsInt | typing.SupportsIndex) -> tuple[numpy.typing.NDArray[numpy.bool], numpy.typing.NDArray[numpy.float64], numpy.typing.NDArray[numpy.bool]]:
        """
        Check many (q, dq) rows for one pusher without Python overhead per row: (feasible, margin, exact).
        """
    def grasp_maintained(self, q: Pose | collections.abc.Sequence[typing.SupportsFloat] | numpy.typing.NDArray[numpy.float64]) -> bool:
        ...
    def gravity_in_gripper(self, q: Pose | collections.abc.Sequence[typing.SupportsFloat] | numpy.typing.NDArray[numpy.float64], pusher: typing.SupportsInt | typing.SupportsIndex) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[2, 1]"]:
        """
        gravity in G [m/s^2] at q during a push by `pusher` (-1: G's axes the world's)
        """
    def hold_ratio(self, q: Pose | collections.abc.Sequence[typing.SupportsFloat] | numpy.typing.NDArray[numpy.float64], pusher: typing.SupportsInt | typing.SupportsIndex = -1) -> float:
        """
        The largest multiple of the weight the pads alone hold at rest at q, gravity as during a push by
        `pusher` (-1: G's axes the world's); >= 1: held; inf: no gravity.
        """
    def in_world(self, pad_mu_scale: typing.SupportsFloat | typing.SupportsIndex, grip_force_scale: typing.SupportsFloat | typing.SupportsIndex, mass_scale: typing.SupportsFloat | typing.SupportsIndex) -> StablePushModel:
        """
        This model with the pads' mu, the grip force and the object's mass and inertia scaled (the pushers'
        cones shared): a world of the same part, grasp and pushers.
        """
    def motion_wrench(self, q: Pose | collections.abc.Sequence[typing.SupportsFloat] | numpy.typing.NDArray[numpy.float64], dq: Motion | collections.abc.Sequence[typing.SupportsFloat] | numpy.typing.NDArray[numpy.float64], pusher: typing.SupportsInt | typing.SupportsIndex = -1) -> MotionWrench:
        ...
    @property
    def body(self) -> RigidBody:
        ...
    @property
    def gravity_frame(self) -> GravityFrame:
        ...
    @property
    def gripper(self) -> Gripper:
        ...
    @property
    def pusher_cones(self) -> list[WrenchCone]:
        ...
    @property
    def pushers(self) -> list[Pusher]:
        ...
    @property
    def section(self) -> CrossSection:
        ...
    @property
    def torque_length(self) -> float:
        ...
class PlanOutcome:
    """
    How a solve ended
    
    Members:
    
      goal_reached
    
      goal_over_switch_limit
    
      time_limit
    
      invalid_start
    """
    __members__: typing.ClassVar[dict[str, PlanOutcome]]
    goal_over_switch_limit: typing.ClassVar[PlanOutcome]
    goal_reached: typing.ClassVar[PlanOutcome]
    invalid_start: typing.ClassVar[PlanOutcome]
    time_limit: typing.ClassVar[PlanOutcome]
    @typing.overload
    def __eq__(self, other: PlanOutcome) -> bool:
        ...
    @typing.overload
    def __eq__(self, other: typing.Any) -> bool:
        ...
    def __getstate__(self) -> int:
        ...
    def __hash__(self) -> int:
        ...
    def __index__(self) -> int:
        ...
    def __init__(self, value: typing.SupportsInt | typing.SupportsIndex) -> None:
        ...
    def __int__(self) -> int:
        ...
    @typing.overload
    def __ne__(self, other: PlanOutcome) -> bool:
        ...
    @typing.overload
    def __ne__(self, other: typing.Any) -> bool:
        ...
    def __repr__(self) -> str:
        ...
    def __setstate__(self, state: typing.SupportsInt | typing.SupportsIndex) -> None:
        ...
    def __str__(self) -> str:
        ...
    @property
    def name(self) -> str:
        ...
    @property
    def value(self) -> int:
        ...
class StopFlag:
    """
    Set from another thread to end a search early.
    """
    def __init__(self) -> None:
        ...
    def set(self) -> None:
        ...
    @property
    def is_set(self) -> bool:
        ...
class PlannerSettings:
    """
    What to plan: start and goal, the unit step, the limits.
    """
    def __init__(self, *, start: Pose | collections.abc.Sequence[typing.SupportsFloat] | numpy.typing.NDArray[numpy.float64], goal: Pose | collections.abc.Sequence[typing.SupportsFloat] | numpy.typing.NDArray[numpy.float64], step: StepSize | collections.abc.Sequence[typing.SupportsFloat], tolerance: StepSize | collections.abc.Sequence[typing.SupportsFloat], time_limit: typing.SupportsFloat | typing.SupportsIndex = 10.0, min_margin: typing.SupportsFloat | typing.SupportsIndex = 0.001, sampling_margin: typing.SupportsFloat | typing.SupportsIndex = 5.0, min_hold_ratio: typing.SupportsFloat | typing.SupportsIndex = 0.0, parameters: collections.abc.Mapping[str, str] = {}, min_transit_hold: typing.SupportsFloat | typing.SupportsIndex = 0.0, start_pusher: typing.SupportsInt | typing.SupportsIndex = -1) -> None:
        ...
    @property
    def goal(self) -> Pose:
        """
        [m, m, rad]
        """
    @goal.setter
    def goal(self, arg0: Pose | collections.abc.Sequence[typing.SupportsFloat] | numpy.typing.NDArray[numpy.float64]) -> None:
        ...
    @property
    def min_hold_ratio(self) -> float:
        """
        0: no hold requirement at the end
        """
    @min_hold_ratio.setter
    def min_hold_ratio(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
    @property
    def min_margin(self) -> float:
        """
        least depth inside the pusher's cone [N]
        """
    @min_margin.setter
    def min_margin(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
    @property
    def min_transit_hold(self) -> float:
        """
        switch pushers only where the pads hold this many times the weight (0: anywhere)
        """
    @min_transit_hold.setter
    def min_transit_hold(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
    @property
    def parameters(self) -> dict[str, str]:
        """
        TRRTstar's declared parameters by name, as text
        """
    @parameters.setter
    def parameters(self, arg0: collections.abc.Mapping[str, str]) -> None:
        ...
    @property
    def sampling_margin(self) -> float:
        """
        [unit steps] around the start-goal box
        """
    @sampling_margin.setter
    def sampling_margin(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
    @property
    def start(self) -> Pose:
        """
        [m, m, rad]
        """
    @start.setter
    def start(self, arg0: Pose | collections.abc.Sequence[typing.SupportsFloat] | numpy.typing.NDArray[numpy.float64]) -> None:
        ...
    @property
    def start_pusher(self) -> int:
        """
        the pusher in contact at the start, or -1
        """
    @start_pusher.setter
    def start_pusher(self, arg0: typing.SupportsInt | typing.SupportsIndex) -> None:
        ...
    @property
    def step(self) -> StepSize:
        """
        one unit step [m, rad]
        """
    @step.setter
    def step(self, arg0: StepSize | collections.abc.Sequence[typing.SupportsFloat]) -> None:
        ...
    @property
    def stop(self) -> StopFlag | None:
        """
        a StopFlag that ends the search early when set, or None
        """
    @stop.setter
    def stop(self, arg1: StopFlag | None) -> None:
        ...
    @property
    def time_limit(self) -> float:
        """
        [s]
        """
    @time_limit.setter
    def time_limit(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
    @property
    def tolerance(self) -> StepSize:
        """
        per coordinate, around the goal [m, rad]
        """
    @tolerance.setter
    def tolerance(self, arg0: StepSize | collections.abc.Sequence[typing.SupportsFloat]) -> None:
        ...
class Waypoint:
    """
    The pose after a unit push, its pusher (-1 at the start) and the verdict.
    """
    @property
    def contact_case(self) -> ContactCase:
        ...
    @property
    def margin(self) -> float:
        """
        [N]; NaN at the start
        """
    @property
    def pose(self) -> Pose:
        ...
    @property
    def pusher(self) -> int:
        ...
class PlanStats:
    @property
    def check_limit_reached(self) -> bool:
        """
        the search stopped at check_limit (a count), not at the time limit
        """
    @property
    def feasibility_checks(self) -> int:
        ...
    @property
    def first_length(self) -> float:
        """
        [unit steps]
        """
    @property
    def first_min_margin(self) -> float:
        """
        [N]
        """
    @property
    def first_switches(self) -> int:
        ...
    @property
    def first_time_s(self) -> float:
        """
        when the first plan was found [s]; NaN: none
        """
    @property
    def iterations(self) -> int:
        ...
    @property
    def length(self) -> float:
        """
        [unit steps]
        """
    @property
    def nodes(self) -> int:
        ...
    @property
    def path_min_margin(self) -> float:
        """
        [N], the search's path (no last push to the goal)
        """
    @property
    def planning_time_s(self) -> float:
        ...
    @property
    def restarts(self) -> int:
        ...
    @property
    def switches(self) -> int:
        ...
class Plan:
    """
    Waypoints after each unit push, start first (SI units).
    """
    @property
    def ends_at_goal(self) -> bool:
        """
        a solved plan's last push reaches the goal pose itself (else it ends within tolerance)
        """
    @property
    def goal_distance(self) -> float:
        """
        from the last waypoint [unit steps]
        """
    @property
    def outcome(self) -> PlanOutcome:
        ...
    @property
    def poses(self) -> numpy.typing.NDArray[numpy.float64]:
        """
        (n, 3): x [m], z [m], theta [rad]
        """
    @property
    def stats(self) -> PlanStats:
        ...
    @property
    def waypoints(self) -> list[Waypoint]:
        ...
class PathNode:
    """
    A node of the search's path: the pose and the pusher of the push into it.
    """
    @property
    def pose(self) -> Pose:
        ...
    @property
    def pusher(self) -> int:
        ...
class PathCost:
    """
    Switch-overs first, then length [unit steps].
    """
    @property
    def length(self) -> float:
        ...
    @property
    def switches(self) -> int:
        ...
class CheckedPlan:
    """
    A search's outcome with a PushChecker of one's own.
    """
    @property
    def cost(self) -> PathCost:
        ...
    @property
    def outcome(self) -> PlanOutcome:
        ...
    @property
    def path(self) -> list[PathNode]:
        """
        start first (pusher -1 at the start)
        """
    @property
    def restarts(self) -> int:
        ...
class PushChecker:
    """
    What the search asks of the mechanics: subclass it and define all_pushers() -> int (a bit mask),
    stable_pushers(a, b, candidates) -> int (the pushers among candidates that make the motion a -> b
    stable; a and b Poses) and push_margin(a, b, pusher) -> float (N), then plan with plan_with_checker:
    the search tested apart from the mechanics.
    """
    def __init__(self) -> None:
        ...
def plan(models: collections.abc.Sequence[StablePushModel], settings: PlannerSettings, interruptible: bool = False) -> Plan:
    """
    Plan stable pushes with TRRTstar. models: StablePushModels sharing the geometry (the corners of an
    uncertainty box, or the nominal model alone): a push counts when it is stable in all, its margin the
    least. Throws ValueError for a parameter TRRTstar does not declare or cannot take. interruptible (only from
    the main thread): SIGINT stops the search at once and raises KeyboardInterrupt.
    """
def plan_with_checker(checker: PushChecker, settings: PlannerSettings) -> CheckedPlan:
    """
    TRRTstar with `checker` deciding which pushers make a motion stable; every pose is valid, and
    settings.min_margin and min_hold_ratio are not used.
    """
def steps_between(a: Pose | collections.abc.Sequence[typing.SupportsFloat] | numpy.typing.NDArray[numpy.float64], b: Pose | collections.abc.Sequence[typing.SupportsFloat] | numpy.typing.NDArray[numpy.float64], step: StepSize | collections.abc.Sequence[typing.SupportsFloat]) -> float:
    """
    The distance from pose a to b in unit steps; a unit push moves at most 1.
    """
def worst_case(models: collections.abc.Sequence[StablePushModel], q: Pose | collections.abc.Sequence[typing.SupportsFloat] | numpy.typing.NDArray[numpy.float64], dq: Motion | collections.abc.Sequence[typing.SupportsFloat] | numpy.typing.NDArray[numpy.float64], pusher: typing.SupportsInt | typing.SupportsIndex) -> PushResult:
    """
    The push q -> q + dq by `pusher` as the least stable of `models` sees it (the corners of an
    uncertainty box): the result with the least margin, an infeasible one first.
    """
CERTIFICATION_BAND: float = 1e-09
MAX_TIME_LIMIT: float = 1000000.0
SHORTEST_PUSH: float = 1e-05
STICKING_SPEED_RATIO: float = 1e-09
TRRT_STAR_PARAMETERS: dict = {'check_limit': '0', 'finish_steps': '0', 'goal_bias': '0.2', 'improve_for': '0', 'init_temperature': '0.1', 'max_switches': '1', 'max_transition_failures': '10', 'pivot_steps': '0', 'restart_checks': '5000', 'rewire_radius': '2', 'seed': '1', 'steer_angle': '45', 'temp_change_factor': '2'}
TRRT_STAR_PARAMETER_RANGES: dict = {'check_limit': ('integer', 0.0, 1000000000000000.0), 'finish_steps': ('integer', 0.0, 1.0), 'goal_bias': ('number', 0.0, 1.0), 'improve_for': ('number', 0.0, 1000000.0), 'init_temperature': ('number', 1e-12, 1000000.0), 'max_switches': ('integer', 0.0, 100.0), 'max_transition_failures': ('integer', 1.0, 1000000.0), 'pivot_steps': ('integer', 0.0, 1.0), 'restart_checks': ('integer', 0.0, 1000000000000.0), 'rewire_radius': ('number', 0.0, 100.0), 'seed': ('integer', 0.0, 4294967295.0), 'steer_angle': ('number', 0.0, 90.0), 'temp_change_factor': ('number', 1.0, 1000.0)}
