"""Videos of runs (`stablepush execute --video run.mp4`, `evaluate --video-failed DIR`): a run
recorded by the executor (`stablepush.execution.bags.RunRecording`, one sample per acknowledged
waypoint) drawn after the run by MuJoCo's renderer, headless (OSMesa), and encoded as H.264 MP4 by
the ffmpeg that the imageio-ffmpeg wheel ships.

The drawing is a render-only MuJoCo model built from the run's scene (the one the executor sends
in its hello, `stablepush.execution.world.scene_description`): the features, the
object, the pads and the plan's ghost are mocap bodies or fixed geoms whose poses are set from
the recorded states frame by frame, and nothing is simulated. So a run on Drake, or on an arm that
reports the object, is drawn the same way as one on MuJoCo.

What a frame shows (poses [x, y, z, qw, qx, qy, qz] in W, m, as recorded):
- the camera: fixed in the gripper frame G, on the gripping axis (G's -y side) looking along +y,
  orthographic, with G's x to the right and z up: the view of the plan figures
  (`stablepush show`), so the pads stay put and the object slides between them. Only a slab
  a few centimetres deep about G's xz-plane is drawn, so that the features of other stations
  (150 mm away along y) never hide the object;
- the object (orange) where the arm reports it (`object_pose`, a simulator's truth; else G's
  pose times the tracker's `object_in_grasp`);
- the pads (dark, translucent discs) and the fingers (faint) at G's reported pose;
- every feature (blue-grey), the one the pusher in contact belongs to in bright blue;
- the ghost (translucent green with a green outline): the plan's pose in the grasp at the sample's
  step (`RunSample.planned`: the step a push heads for, or the last one reached), in the plan being
  followed, a re-planned one after a closed-loop correction;
- a caption: the task, the stream's time, the step, the phase and the pusher in contact.

Frames are taken from the samples every 1/fps s of the stream's time (100 Hz at `execute`'s default
rate) and played at fps, so the video runs at the robot's speed.

That is the `schematic` view (the default). The `3d` view draws the run's whole MuJoCo model instead
(cell_model.build_mjcf: the arm of the task's robot with its jaws, the object and the features, the
floor), posed from the recorded states (the arm's reported joints, the object's pose, the jaws at
the object's faces; nothing simulated), seen by a fixed camera from the front and above that frames
the arm and the features over the whole run; `both` puts the 3-D view left of the schematic, each
at the size asked, the video twice as wide. The 3-D view needs the arm's joints in the samples and
its model: a run whose arm has one (RunRecording.robot: the simulated arm, or an arm checked
against --robot or environment.robot).

MuJoCo picks its GL back-end when it is first imported (`mujoco.gl_context`, from MUJOCO_GL): this
module sets MUJOCO_GL=osmesa when it is unset and mujoco is not imported yet. A process that
imported mujoco first without MUJOCO_GL (the simulated arm does) got GLFW, which needs a display;
without one, the renderer here is switched to OSMesa, as MUJOCO_GL=osmesa would have chosen.
"""
from __future__ import annotations

import math
import os
import sys
import tempfile
import time
import xml.etree.ElementTree as ET
from dataclasses import dataclass
from pathlib import Path
from typing import Callable, List, Optional, Sequence, Tuple, Union

import numpy as np

from stablepush.errors import OutputError, SettingError
from stablepush.execution.bags import RunSample
from stablepush.execution.run import RunOutput, RunResult
from stablepush.execution.scene import Scene
from stablepush.execution.world import place_features, scene_description
from stablepush.extras import require
from stablepush.frames import grasp_transform, matrix_to_pose, pose_to_matrix, quat_about_y
from stablepush.kinematics.cell_model import (
    OBJECT_BODY,
    add_object_geoms,
    build_mjcf,
    feature_geom,
    feature_solid,
    mjcf_numbers,
    simulated_outline,
)
from stablepush.kinematics.robot import FINGER_JOINTS, arm_model
from stablepush.plan.plan import Plan
from stablepush.sim import VIDEO_VIEWS
from stablepush.task.model import Robot, Task

SUFFIX = ".mp4"  # H.264 in MP4: plays in browsers, on GitHub and in every player
DEFAULT_FPS = 25.0  # frames per second of the stream's time: 2.5 frames per 0.1 s push
MAX_FPS = 100.0  # the executor's default rate: one frame per sample
DEFAULT_SIZE = (640, 480)  # width, height in pixels
SIZE_RANGE = (64, 3840)  # each side, pixels; even, as H.264's 4:2:0 colour needs
CRF = 20  # x264's constant rate factor: flat shaded scenes stay sharp at about 1 MB a minute
DEFAULT_VIEW = "schematic"

_CAMERA_DISTANCE = 0.5  # m from G along -y; orthographic, so only the clipping slab depends on it
_SLAB = 0.03  # m drawn beyond each face of the object along y (the pads, fingers and backdrop)
_MARGIN = (0.015, 0.2)  # around the plan's outlines and the pads: m, and a fraction of their size
_OBJECT_RGBA = (0.85, 0.55, 0.25, 1.0)
_GHOST_RGBA = (0.1, 0.75, 0.3, 0.35)
_GHOST_EDGE_RGBA = (0.0, 0.5, 0.15, 0.9)
_FEATURE_RGBA = (0.62, 0.66, 0.74, 1.0)
_ACTIVE_FEATURE_RGBA = (0.12, 0.42, 0.9, 1.0)
_PAD_RGBA = (0.15, 0.15, 0.15, 0.55)
_FINGER_RGBA = (0.5, 0.52, 0.56, 0.12)
_BACKDROP_RGBA = (0.97, 0.97, 0.97, 1.0)
_ARM_RGBA = (0.72, 0.74, 0.78, 1.0)  # arm.xml's links
# The 3-D view's camera: in front of the arm (+x, where it reaches) and to its -y side, above,
# looking down at the work with the arm behind it.
_AZIMUTH, _ELEVATION = 150.0, -30.0  # deg (mjvCamera)
_FRAMING_SAMPLES = 12  # poses of the run the 3-D camera's framing takes in
_WORK_RADIUS = 0.25  # m: the least the 3-D view shows about the work (the jaws, 90 mm, and the wrist)
_SKY_RGB = "0.97 0.97 0.97"  # the 3-D view's background, light as the schematic's, for the caption


@dataclass(frozen=True)
class VideoInfo:
    """A written video: its frames, their size (pixels), fps, and the time spent drawing and
    encoding them (s)."""

    path: str
    frames: int
    width: int
    height: int
    fps: float
    render_s: float

    @property
    def ms_per_frame(self) -> float:
        return 1e3 * self.render_s / self.frames if self.frames else 0.0


# -- options, checked before a run ----------------------------------------------------------------


def check_video_path(path: Union[str, Path]) -> None:
    """Refuse a video that cannot be written, before anything runs (OutputError naming the path):
    a file name not ending in .mp4, the encoder (imageio-ffmpeg) or the renderer (MuJoCo with
    OSMesa) missing. Loads mujoco with MUJOCO_GL=osmesa when it is not loaded yet: call it before
    the simulated arm starts."""
    if not str(path).lower().endswith(SUFFIX):
        raise OutputError(f"{path}: a video's file name must end in {SUFFIX} (H.264 in MP4)")
    _encoder()
    _mujoco()


def check_fps(fps: float) -> None:
    """SettingError unless 0 < fps <= MAX_FPS."""
    if not (isinstance(fps, (int, float)) and 0 < fps <= MAX_FPS):
        raise SettingError("video_fps", f"frames per second must be above 0 and at most {MAX_FPS:g} (one frame per "
                                        f"waypoint at 100 Hz), got {fps!r:.40}")


def check_size(size: Sequence[int]) -> None:
    """SettingError unless `size` is (width, height), both even and within SIZE_RANGE pixels."""
    low, high = SIZE_RANGE
    if (not isinstance(size, (tuple, list)) or len(size) != 2
            or not all(isinstance(n, int) and low <= n <= high and n % 2 == 0 for n in size)):
        raise SettingError("video_size", f"width and height must be even numbers of pixels from {low} to {high} "
                                         f"(H.264's colour is sampled in 2 x 2 blocks), got {size!r:.40}")


def check_view(view: str) -> None:
    """SettingError unless `view` is one of VIDEO_VIEWS."""
    if view not in VIDEO_VIEWS:
        raise SettingError("video_view", f"must be one of {', '.join(VIDEO_VIEWS)}, got {view!r:.40}")


def video_directory(path: Union[str, Path]) -> str:
    """`path` as a directory for videos, made (with its parents) when missing, as an absolute path
    (workers, Ray's among them, need not share the caller's working directory); OutputError when
    it is a file or cannot be made."""
    try:
        os.makedirs(path, exist_ok=True)
    except OSError as exc:
        raise OutputError(f"{path}: cannot make the directory for videos ({exc.strerror or exc})") from None
    return os.path.abspath(path)


def run_scene(task: Task, plan: Plan, closed_loop: bool = False, resume_from: int = 0) -> Scene:
    """The scene `execute_plan` sends for this run (the features it places: every
    pusher's with a closed loop), in the task's own world; a simulated world that departs from it
    is `WorldDeviation.apply` of this."""
    steps = list(plan.waypoints)
    return scene_description(task, place_features(task, steps, every_pusher=closed_loop), steps[resume_from].pose)


class RunVideo(RunOutput):
    """A run drawn into `path` (.mp4) at `fps` and `size` in `view` (render_run), in the world its
    arm was given (run_scene), after a fault too when any waypoint was acknowledged. `progress(frames
    done, frames)` after each frame. Checked when made (SettingError for fps, size and view;
    OutputError, MissingExtra for the path), so a video that could not be written is refused before
    the run."""

    records = True

    def __init__(self, path: str, fps: float = DEFAULT_FPS, size: Tuple[int, int] = DEFAULT_SIZE,
                 progress: Optional[Callable[[int, int], None]] = None, view: str = DEFAULT_VIEW):
        check_fps(fps)
        check_size(tuple(size))
        check_view(view)
        check_video_path(path)
        width, height = size
        self.path, self.fps, self.size, self.progress, self.view = path, fps, (width, height), progress, view
        self.info: Optional[VideoInfo] = None

    def write(self, run: RunResult) -> Optional[str]:
        recording = run.recording
        if recording is None:  # `records`: run_plan keeps a recording for this output
            raise ValueError("a video needs the run's recording")
        if run.fault is not None and not recording.samples:
            return None
        closed_loop = run.options.closed_loop is not None
        scene = run_scene(run.task, run.plan, closed_loop, run.options.resume_from)
        robot = run.task.environment.robot if recording.robot is not None else None  # the arm's joints are its
        info = self.info = render_run(self.path, run.task, scene, recording.samples,
                                      look=VideoLook(self.fps, self.size, self.view), progress=self.progress,
                                      robot=robot)
        return (f"video written to {self.path}: {info.frames} frames, {info.width}x{info.height} at {info.fps:g} "
                f"fps, drawn in {info.render_s:.1f} s ({info.ms_per_frame:.0f} ms a frame)")


def _mujoco():
    """mujoco, imported with MUJOCO_GL=osmesa unless the caller chose a back-end or mujoco is
    loaded already (mujoco reads MUJOCO_GL once, at its import); OutputError when OSMesa is missing."""
    if "mujoco" not in sys.modules:
        os.environ.setdefault("MUJOCO_GL", "osmesa")
    try:
        import mujoco
    except (ImportError, AttributeError, OSError) as exc:  # PyOpenGL cannot load libOSMesa
        if isinstance(exc, ModuleNotFoundError) and (exc.name or "").split(".")[0] == "mujoco":
            require("mujoco", "a video")  # not installed at all: the extra to install, not OSMesa
        raise OutputError(f"cannot load MuJoCo's headless renderer with MUJOCO_GL={os.environ.get('MUJOCO_GL')} "
                          f"({type(exc).__name__}: {exc}); videos need the Debian package libosmesa6 "
                          f"(apt-get install libosmesa6, or bash scripts/setup.sh)") from None
    return mujoco


def _encoder():
    return require("imageio_ffmpeg", "a video")


def _headless_gl(mujoco) -> None:
    """With mujoco imported before this module without MUJOCO_GL (the simulated arm imports it),
    mujoco.Renderer would open a GLFW context, which needs a display. Without one, give it the
    OSMesa context that MUJOCO_GL=osmesa would have chosen at mujoco's import."""
    from mujoco import gl_context

    chosen = getattr(gl_context, "GLContext", None)
    display = os.environ.get("DISPLAY") or os.environ.get("WAYLAND_DISPLAY")
    if chosen is not None and chosen.__module__.startswith("mujoco.glfw") and not display:
        try:
            from mujoco.osmesa import GLContext
        except (ImportError, AttributeError, OSError) as exc:
            raise OutputError(f"cannot load MuJoCo's headless renderer ({type(exc).__name__}: {exc}); videos need "
                              f"the Debian package libosmesa6 (apt-get install libosmesa6)") from None
        gl_context.GLContext = GLContext


# -- which samples become frames ------------------------------------------------------------------


def frame_samples(times: Sequence[float], fps: float) -> List[int]:
    """The samples drawn: for frame k, the last sample at or before times[0] + k / fps, for every k
    up to the last sample's time (so floor((times[-1] - times[0]) fps) + 1 frames, about)."""
    if not times:
        return []
    out, i = [], 0
    count = int(math.floor((times[-1] - times[0]) * fps + 1e-9)) + 1
    for k in range(count):
        due = times[0] + k / fps + 1e-9
        while i + 1 < len(times) and times[i + 1] <= due:
            i += 1
        out.append(i)
    return out


def object_in_world(sample: RunSample) -> Optional[np.ndarray]:
    """T_WO (4x4, m) of a sample: the reported object pose, else G's reported pose times the
    tracked pose in the grasp, else None (the arm reports neither)."""
    if sample.object_pose is not None:
        return pose_to_matrix(sample.object_pose)
    if sample.object_in_grasp is not None:
        q = sample.object_in_grasp
        return pose_to_matrix(sample.reported) @ grasp_transform((q["x"], q["z"], q["theta"]))
    return None


# -- the render-only model ------------------------------------------------------------------------


def _frame_box(scene: Scene, samples: Sequence[RunSample], chosen: Sequence[int]) -> Tuple[float, float, float, float]:
    """The region of G's xz-plane the camera shows (x0, z0, x1, z1, m): the plan's outline at
    every drawn step, the object at the start and the pads, with a margin for the features. An
    object dropped from the grasp leaves the picture rather than shrinking it."""
    outline = np.asarray(simulated_outline(scene.object.polygon)[0])
    points = []
    poses = {q for q in (samples[i].planned for i in chosen) if q is not None}
    for q in poses:
        T = grasp_transform(q)
        points.append(outline @ T[[0, 2]][:, [0, 2]].T + T[[0, 2], 3])
    first = object_in_world(samples[chosen[0]])
    if first is not None:
        T = np.linalg.inv(pose_to_matrix(samples[chosen[0]].reported)) @ first
        points.append(outline @ T[[0, 2]][:, [0, 2]].T + T[[0, 2], 3])
    for pad in scene.gripper.pads:
        (cx, cz), r = pad.center, pad.radius
        points.append(np.array([[cx - r, cz - r], [cx + r, cz + r]]))
    allp = np.vstack(points)
    low, high = allp.min(axis=0), allp.max(axis=0)
    margin = max(_MARGIN[0], _MARGIN[1] * float(max(high - low)))
    return low[0] - margin, low[1] - margin, high[0] + margin, high[1] + margin


def render_model_xml(scene: Scene, box: Tuple[float, float, float, float], size: Tuple[int, int]) -> str:
    """The render-only MJCF of a scene (SI units): the features as fixed geoms named as
    the simulated arm names them (`scene.feature_geom`), the object, the plan's ghost and the
    gripper (pads, fingers, backdrop and the camera `view`) as mocap bodies; no joints, no contacts.
    The camera frames `box` (G's xz-plane, m) at the aspect of `size` (width, height)."""
    obj = scene.object
    half = obj.thickness / 2
    width, height = size
    x0, z0, x1, z1 = box
    # 6% of the height above and below for the caption and the legend
    extent_z = max(z1 - z0, (x1 - x0) * height / width) / (1 - 2 * 0.06)
    root = ET.Element("mujoco", model="stablepush-video")
    ET.SubElement(root, "compiler", angle="radian")
    visual = ET.SubElement(root, "visual")
    ET.SubElement(visual, "global", offwidth=str(width), offheight=str(height))
    ET.SubElement(visual, "headlight", ambient="0.45 0.45 0.45", diffuse="0.55 0.55 0.55", specular="0 0 0")
    ET.SubElement(visual, "quality", shadowsize="0")
    # The camera sees only a slab about G's xz-plane (mjVisual.map.znear/zfar are fractions of the
    # extent, set to 1 m): features of other stations, along y, stay out of the picture.
    ET.SubElement(visual, "map", znear=repr(_CAMERA_DISTANCE - half - _SLAB),
                  zfar=repr(_CAMERA_DISTANCE + half + _SLAB))
    ET.SubElement(root, "statistic", extent="1", center="0 0 0")
    ET.SubElement(root, "default").append(ET.Element("geom", contype="0", conaffinity="0"))
    assets = ET.SubElement(root, "asset")
    world = ET.SubElement(root, "worldbody")

    for feature in scene.features:
        solid = feature_solid(feature, obj)
        name = feature_geom(feature.pusher)
        if solid["kind"] == "box":
            ET.SubElement(world, "geom", name=name, type="box", pos=mjcf_numbers(solid["center"]),
                          quat=mjcf_numbers(quat_about_y(solid["angle"])), size=mjcf_numbers(solid["half_size"]),
                          rgba=mjcf_numbers(_FEATURE_RGBA))
        else:
            c, h = np.asarray(solid["center"]), solid["half_length"]
            ET.SubElement(world, "geom", name=name, type="capsule", size=repr(solid["radius"]),
                          fromto=mjcf_numbers((*(c - [0, h, 0]), *(c + [0, h, 0]))), rgba=mjcf_numbers(_FEATURE_RGBA))

    body = ET.SubElement(world, "body", name="object", mocap="true")
    add_object_geoms(body, assets, obj, half, mjcf_numbers(_OBJECT_RGBA), prefix="object_")

    # The ghost's fill is a little thinner than the object, so the object hides it where the two
    # agree and it shows where the object is not where the plan has it; its outline lies in front
    # of the object's face and of the pads, so it is always seen, 3 pixels wide.
    ghost = ET.SubElement(world, "body", name="ghost", mocap="true")
    add_object_geoms(ghost, assets, obj, max(half - 0.001, half / 2), mjcf_numbers(_GHOST_RGBA), prefix="ghost_")
    outline = simulated_outline(obj.polygon)[0]
    front = -(half + 0.0015)
    for k, (a, b) in enumerate(zip(outline, outline[1:] + outline[:1])):
        ET.SubElement(ghost, "geom", name=f"ghost_edge{k}", type="capsule",
                      size=mjcf_numbers([1.5 * extent_z / height]),
                      fromto=mjcf_numbers((a[0], front, a[1], b[0], front, b[1])), rgba=mjcf_numbers(_GHOST_EDGE_RGBA))

    hand = ET.SubElement(world, "body", name="gripper", mocap="true")
    for k, pad in enumerate(scene.gripper.pads):  # pad k on the finger at +y when k is even (cell_model.pad_layout)
        side = 1.0 if k % 2 == 0 else -1.0
        (cx, cz), r = pad.center, pad.radius
        ET.SubElement(hand, "geom", name=f"pad{k}", type="cylinder", size=mjcf_numbers((r, 0.0005)),
                      pos=mjcf_numbers((cx, side * (half + 0.0006), cz)),
                      quat=mjcf_numbers((math.sqrt(0.5), math.sqrt(0.5), 0, 0)),
                      rgba=mjcf_numbers(_PAD_RGBA))
    # The fingers as the shipped arm's (arm.xml: 16 mm wide, 90 mm from G toward the palm, +z),
    # just outside the pads.
    for side in (1.0, -1.0):
        ET.SubElement(hand, "geom", type="box", size="0.008 0.003 0.045",
                      pos=mjcf_numbers((0.0, side * (half + 0.0045), 0.045)), rgba=mjcf_numbers(_FINGER_RGBA))
    ET.SubElement(hand, "geom", name="backdrop", type="box", size="2 0.0005 2",
                  pos=mjcf_numbers((0.0, half + _SLAB - 0.002, 0.0)), rgba=mjcf_numbers(_BACKDROP_RGBA))
    # xyaxes: the image's x along G's x, its y along G's z, so the camera looks along G's +y.
    ET.SubElement(hand, "camera", name="view", orthographic="true", fovy=mjcf_numbers([extent_z]),
                  pos=mjcf_numbers(((x0 + x1) / 2, -_CAMERA_DISTANCE, (z0 + z1) / 2)), xyaxes="1 0 0 0 0 1")
    return ET.tostring(root, encoding="unicode")


# -- drawing and encoding ------------------------------------------------------------------------


@dataclass(frozen=True)
class VideoLook:
    """How a video is drawn: `fps` frames per second of robot time, `size` (width, height) in
    pixels, `view` (VIDEO_VIEWS). Checked where it is drawn (render_run)."""

    fps: float = DEFAULT_FPS
    size: Tuple[int, int] = DEFAULT_SIZE
    view: str = DEFAULT_VIEW


def render_run(path: Union[str, Path], task: Task, scene: Scene, samples: Sequence[RunSample], *,
               look: VideoLook = VideoLook(), progress: Optional[Callable[[int, int], None]] = None,
               robot: Optional[Robot] = None) -> VideoInfo:
    """Draw the recorded run `samples` (RunRecording.samples) of `task` in the world `scene` (the
    scene the run's arm built; the features are drawn where it has them) as `look` says (the 3-D
    view draws the arm of `robot` from the samples' joints) and write it to `path` (.mp4)
    atomically. `progress(frames done, frames)` after each frame. OutputError (naming
    the path) for a bad file name or setting, a run without samples or without the object's pose (a
    real arm without a tracker), a 3-D view without the arm's model or joints, or a missing renderer
    or encoder."""
    from stablepush.outputs import write_files

    fps, size, view = look.fps, look.size, look.view
    try:
        check_fps(fps)
        check_size(tuple(size))
        check_view(view)
    except SettingError as exc:
        raise OutputError(f"{path}: {exc.reason}") from None
    if not str(path).lower().endswith(SUFFIX):
        raise OutputError(f"{path}: a video's file name must end in {SUFFIX} (H.264 in MP4)")
    if not samples:
        raise OutputError(f"{path}: the run has no acknowledged waypoint to draw")
    if all(object_in_world(s) is None for s in samples):
        raise OutputError(f"{path}: the arm reported no pose of the object (neither object_pose nor a tracker's "
                          f"object_in_grasp), so there is nothing to draw; a simulated arm (--sim) reports it")
    joints: Sequence[Optional[np.ndarray]] = (_arm_joints(path, samples, robot) if view != "schematic"
                                              else [None] * len(samples))
    width, height = (int(n) for n in size)
    imageio_ffmpeg = _encoder()
    mujoco = _mujoco()
    _headless_gl(mujoco)
    started = time.perf_counter()
    chosen = frame_samples([s.t for s in samples], fps)
    panels: list = []
    try:
        if view != "schematic":
            panels.append(_ArmView(mujoco, path, scene, robot, [samples[i] for i in chosen],
                                   [joints[i] for i in chosen], (width, height)))
        if view != "3d":
            panels.append(_Schematic(mujoco, path, scene, samples, chosen, (width, height)))
        caption = _Caption(width, height)
        with tempfile.TemporaryDirectory(prefix="stablepush-video-") as scratch:
            encoded = Path(scratch) / f"video{SUFFIX}"
            writer = imageio_ffmpeg.write_frames(str(encoded), (width * len(panels), height), fps=fps,
                                                 codec="libx264", quality=None, macro_block_size=2,
                                                 ffmpeg_log_level="error", output_params=["-crf", str(CRF)])
            writer.send(None)  # starts ffmpeg
            try:
                last = next(T for T in map(object_in_world, samples) if T is not None)  # until the arm reports one
                for n, i in enumerate(chosen):
                    sample = samples[i]
                    T_WO = object_in_world(sample)
                    last = T_WO if T_WO is not None else last  # a tracker may miss a sample: keep the last pose
                    frame = np.hstack([caption.draw(panel.draw(sample, last, joints[i]), task.name, sample,
                                                    panel.legend) for panel in panels])
                    writer.send(np.ascontiguousarray(frame))
                    if progress is not None:
                        progress(n + 1, len(chosen))
            finally:
                writer.close()
            write_files({path: encoded.read_bytes()})
    finally:
        for panel in panels:
            panel.close()
    return VideoInfo(path=str(path), frames=len(chosen), width=width * len(panels), height=height, fps=float(fps),
                     render_s=time.perf_counter() - started)


def _arm_joints(path, samples: Sequence[RunSample], robot: Optional[Robot]) -> List[np.ndarray]:
    """The arm's joints [rad] at each sample for the 3-D view: as reported, the last reported
    where a sample has none (or not the model's number); OutputError without a model or joints."""
    if robot is None:
        raise OutputError(f"{path}: the 3-D view draws the arm from its joints, and this arm has no model naming "
                          f"them (run it with --sim, or give --robot or the task's environment.robot)")
    count = len(arm_model(robot).joints)
    reported = [None if s.joints is None or len(s.joints) != count else np.asarray(s.joints, float) for s in samples]
    present = [q for q in reported if q is not None]
    if not present:
        raise OutputError(f"{path}: the arm reported none of its {count} joints, so the 3-D view cannot draw it")
    out, last = [], present[0]
    for q in reported:
        last = q if q is not None else last
        out.append(last)
    return out


def _renderer(mujoco, model, size: Tuple[int, int], path):
    width, height = size
    try:
        return mujoco.Renderer(model, height=height, width=width)
    except Exception as exc:  # noqa: BLE001 - whatever the GL back-end raises, said in one line
        raise OutputError(f"{path}: cannot open MuJoCo's renderer with MUJOCO_GL={os.environ.get('MUJOCO_GL')} "
                          f"({type(exc).__name__}: {' '.join(str(exc).split())[:200]}); headless rendering needs "
                          f"MUJOCO_GL=osmesa and the Debian package libosmesa6") from None


class _Schematic:
    """The view along the gripping axis (render_model_xml), a frame per sample."""

    legend = ((_OBJECT_RGBA, "object"), (_GHOST_EDGE_RGBA, "plan at this step"),
              (_ACTIVE_FEATURE_RGBA, "pusher in contact"), (_PAD_RGBA, "pads"))

    def __init__(self, mujoco, path, scene: Scene, samples: Sequence[RunSample], chosen: Sequence[int],
                 size: Tuple[int, int]):
        self.mujoco = mujoco
        self.model = mujoco.MjModel.from_xml_string(render_model_xml(scene, _frame_box(scene, samples, chosen), size))
        self.data = mujoco.MjData(self.model)
        self.mocap = {name: self.model.body(name).mocapid[0] for name in ("object", "ghost", "gripper")}
        self.features = {f.pusher: self.model.geom(feature_geom(f.pusher)).id for f in scene.features}
        self.renderer = _renderer(mujoco, self.model, size, path)

    def draw(self, sample: RunSample, T_WO: np.ndarray, _joints) -> np.ndarray:
        model, data = self.model, self.data
        T_WG = pose_to_matrix(sample.reported)
        _place(data, self.mocap["gripper"], T_WG)
        _place(data, self.mocap["object"], T_WO)
        if sample.planned is not None:
            _place(data, self.mocap["ghost"], T_WG @ grasp_transform(sample.planned))
        for pusher, geom in self.features.items():
            model.geom_rgba[geom] = _ACTIVE_FEATURE_RGBA if pusher == sample.pusher else _FEATURE_RGBA
        self.mujoco.mj_kinematics(model, data)
        self.mujoco.mj_camlight(model, data)  # the camera rides on the gripper's mocap body
        self.renderer.update_scene(data, camera="view")
        return self.renderer.render()

    def close(self) -> None:
        self.renderer.close()


class _ArmView:
    """The run's MuJoCo model (cell_model.build_mjcf with the task's robot) posed from the recorded
    joints and object pose, the jaws at the object's faces as the simulated arm starts them, seen
    by a fixed camera that frames the arm and the features at `samples` (the drawn ones)."""

    legend = ((_OBJECT_RGBA, "object"), (_ACTIVE_FEATURE_RGBA, "pusher in contact"), (_ARM_RGBA, "arm"))

    def __init__(self, mujoco, path, scene: Scene, robot: Optional[Robot], samples: Sequence[RunSample],
                 joints: Sequence[Optional[np.ndarray]], size: Tuple[int, int]):
        self.mujoco = mujoco
        root = ET.fromstring(build_mjcf(scene, robot=robot))
        assets = root.find("asset")
        if assets is None:
            assets = ET.SubElement(root, "asset")
        ET.SubElement(assets, "texture", type="skybox", builtin="flat", rgb1=_SKY_RGB, rgb2=_SKY_RGB, width="8",
                      height="8")
        model = self.model = mujoco.MjModel.from_xml_string(ET.tostring(root, encoding="unicode"))
        model.vis.global_.offwidth, model.vis.global_.offheight = size
        model.vis.headlight.ambient[:], model.vis.headlight.diffuse[:] = (0.4,) * 3, (0.5,) * 3
        self.data = mujoco.MjData(model)
        self.arm = [int(model.jnt_qposadr[model.joint(j).id]) for j in arm_model(robot).joints]
        self.object = int(model.jnt_qposadr[model.joint(OBJECT_BODY).id])
        for finger in FINGER_JOINTS:
            self.data.qpos[model.jnt_qposadr[model.joint(finger).id]] = scene.object.thickness / 2
        self.features = {f.pusher: model.geom(feature_geom(f.pusher)).id for f in scene.features}
        self.camera = self._framing(samples, joints)
        self.renderer = _renderer(mujoco, model, size, path)

    def _pose(self, T_WO: np.ndarray, joints: np.ndarray) -> None:
        self.data.qpos[self.arm] = joints
        self.data.qpos[self.object:self.object + 7] = matrix_to_pose(T_WO)
        self.mujoco.mj_kinematics(self.model, self.data)

    def _framing(self, samples: Sequence[RunSample], joints: Sequence[Optional[np.ndarray]]):
        """A free camera at _AZIMUTH, _ELEVATION on the work: the features, and the object and G at a
        few poses spread over the run, with room around them for the jaws and the arm's wrist (the
        rest of the arm runs out of the picture, where the part would be too small to see)."""
        model, data = self.model, self.data
        self.mujoco.mj_kinematics(model, data)
        points = [data.geom_xpos[g].copy() for g in self.features.values()]
        for k in np.unique(np.linspace(0, len(samples) - 1, _FRAMING_SAMPLES).astype(int)):
            T_WO = object_in_world(samples[k])
            if T_WO is not None:
                points.append(T_WO[:3, 3])
            points.append(np.asarray(samples[k].reported[:3], float))
        corners = np.array(points)
        low, high = corners.min(axis=0), corners.max(axis=0)
        camera = self.mujoco.MjvCamera()
        camera.type = self.mujoco.mjtCamera.mjCAMERA_FREE
        camera.lookat[:] = (low + high) / 2
        radius = max(float(np.linalg.norm(high - low)) / 2, _WORK_RADIUS)
        camera.distance = radius / math.sin(math.radians(model.vis.global_.fovy) / 2)
        camera.azimuth, camera.elevation = _AZIMUTH, _ELEVATION
        return camera

    def draw(self, sample: RunSample, T_WO: np.ndarray, joints: np.ndarray) -> np.ndarray:
        for pusher, geom in self.features.items():
            self.model.geom_rgba[geom] = _ACTIVE_FEATURE_RGBA if pusher == sample.pusher else _FEATURE_RGBA
        self._pose(T_WO, joints)
        self.renderer.update_scene(self.data, camera=self.camera)
        return self.renderer.render()

    def close(self) -> None:
        self.renderer.close()


def _place(data, mocap_id: int, T: np.ndarray) -> None:
    pose = matrix_to_pose(T)
    data.mocap_pos[mocap_id] = pose[:3]
    data.mocap_quat[mocap_id] = pose[3:]


class _Caption:
    """The caption and legend drawn on each frame (Pillow)."""

    def __init__(self, width: int, height: int):
        from PIL import ImageFont

        self.scale = max(0.5, height / 480)
        try:
            self.font = ImageFont.load_default(size=round(15 * self.scale))
            self.small = ImageFont.load_default(size=round(12 * self.scale))
        except TypeError:  # Pillow before 10.1: one bitmap size
            self.font = self.small = ImageFont.load_default()

    def draw(self, pixels: np.ndarray, task: str, sample: RunSample, legend) -> np.ndarray:
        from PIL import Image, ImageDraw

        image = Image.fromarray(pixels)
        pen = ImageDraw.Draw(image)
        s = self.scale
        contact = f" on {sample.pusher}" if sample.pusher else ""
        pen.text((8 * s, 6 * s), f"{task}   t {sample.t:6.2f} s   step {sample.step}   {sample.phase}{contact}",
                 fill=(20, 20, 20), font=self.font)
        x, y = 8 * s, image.height - 20 * s
        for rgba, label in legend:
            colour = tuple(round(255 * c) for c in rgba[:3])
            pen.rectangle((x, y + 2 * s, x + 11 * s, y + 13 * s), fill=colour)
            pen.text((x + 15 * s, y), label, fill=(40, 40, 40), font=self.small)
            x += 15 * s + pen.textlength(label, font=self.small) + 14 * s
        return np.asarray(image)
