"""Videos of runs (`execute --video`, `evaluate --video-failed`; stablepush.sim.mujoco.video): drawn
headless from the recorded states, decoded back with imageio-ffmpeg's reader. The fast tests check
the options and what each waypoint carries; the slow ones (marked) run the simulated arm."""
import json

import numpy as np
import pytest
from click.testing import CliRunner

from stablepush.errors import OutputError
from stablepush.execution.bags import RunRecording, RunSample
from stablepush.execution.stream import arm_trajectory
from stablepush.execution.world import place_features
from stablepush.plan import check_plan, plan_task
from stablepush.sim.mujoco import video
from stablepush_cli.main import cli

from conftest import TASKS, shipped

SHORT = "more/tilted-gravity"  # 15 pushes along one feature: 192 waypoints, 1.92 s of stream


def _plan_file(tmp_path, name=SHORT):
    task, plan = str(TASKS / f"{name}.yaml"), tmp_path / "p.plan.json"
    assert CliRunner().invoke(cli, ["plan", task, "-o", str(plan), "--quiet"]).exit_code == 0
    return task, plan


def _decode(path):
    """The frames of a video (n x height x width x 3, uint8) and its fps, by imageio-ffmpeg's reader."""
    import imageio_ffmpeg

    frames = imageio_ffmpeg.read_frames(str(path))
    meta = next(frames)
    width, height = meta["size"]
    return np.stack([np.frombuffer(f, np.uint8).reshape(height, width, 3) for f in frames]), meta["fps"]


def _orange(frame):
    """The pixels of the object's colour (0.85, 0.55, 0.25), lit by the headlight: a mask."""
    r, g, b = (frame[..., k].astype(int) for k in range(3))
    return (r > 180) & (g > 100) & (g < 170) & (b < 100)


def test_a_bad_video_suffix_or_size_is_refused_before_anything_runs(tmp_path):
    task, plan = _plan_file(tmp_path)
    for extra, option in ((["--video", str(tmp_path / "run.avi")], "--video"),
                          (["--video", str(tmp_path / "run.mp4"), "--video-size", "641x480"], "--video-size"),
                          (["--video", str(tmp_path / "run.mp4"), "--video-size", "big"], "--video-size"),
                          (["--video", str(tmp_path / "run.mp4"), "--video-fps", "0"], "--video-fps"),
                          (["--video", str(tmp_path / "run.mp4"), "--video-fps", "101"], "--video-fps")):
        result = CliRunner().invoke(cli, ["execute", str(plan), "--task", task, "--sim", "--quiet"] + extra)
        assert result.exit_code == 2 and option in result.output, (extra, result.output)
        assert "waypoints" not in result.output  # refused before the run
    assert ".mp4" in CliRunner().invoke(cli, ["execute", str(plan), "--task", task, "--sim", "--video",
                                              str(tmp_path / "run.avi")]).output
    result = CliRunner().invoke(cli, ["evaluate", task, "--plan", str(plan), "--trials", "1",
                                      "--video-failed", str(plan)])  # a file, not a directory
    assert result.exit_code == 2 and "--video-failed" in result.output
    result = CliRunner().invoke(cli, ["execute", str(plan), "--task", task, "--sim", "--video-fps", "10"])
    assert result.exit_code == 2 and "--video-fps: only with --video" in result.output
    result = CliRunner().invoke(cli, ["evaluate", task, "--plan", str(plan), "--video-size", "320x240"])
    assert result.exit_code == 2 and "--video-size: only with --video-failed" in result.output


def test_a_missing_encoder_is_refused_before_the_run_naming_the_option(tmp_path, monkeypatch):
    import sys

    task, plan = _plan_file(tmp_path)
    monkeypatch.setitem(sys.modules, "imageio_ffmpeg", None)  # as if it were not installed
    result = CliRunner().invoke(cli, ["execute", str(plan), "--task", task, "--sim", "--video",
                                      str(tmp_path / "run.mp4")])
    assert result.exit_code == 2 and "--video" in result.output and "imageio-ffmpeg" in result.output
    assert "waypoints" not in result.output


def test_frames_are_taken_every_1_over_fps_of_the_stream():
    times = [(k + 1) / 100 for k in range(192)]  # 100 Hz, as `execute` streams
    chosen = video.frame_samples(times, 25)
    assert len(chosen) == 48 and chosen[:3] == [0, 4, 8] and chosen[-1] == 188
    assert video.frame_samples(times, 100) == list(range(192))
    assert video.frame_samples(times[:1], 25) == [0] and video.frame_samples([], 25) == []


def test_each_waypoint_carries_the_plan_pose_of_its_step():
    task = shipped("t-shaped")
    steps = list(check_plan(task, plan_task(task, seed=1)).waypoints)
    points = arm_trajectory(task, steps, place_features(task, steps), 100.0, [0.45, 0, 0.3, 1, 0, 0, 0])
    assert all(w.planned == tuple(steps[w.step].pose) for w in points)


def test_a_run_without_the_object_pose_is_refused_naming_the_file(tmp_path):
    """A real arm without a tracker reports neither object_pose nor object_in_grasp: nothing to draw."""
    task = shipped("t-shaped")
    scene = video.run_scene(task, check_plan(task, plan_task(task, seed=1)))
    sample = RunSample(0.01, [0.45, 0, 0.3, 1, 0, 0, 0], [0.45, 0, 0.3, 1, 0, 0, 0], None, None, "", "approach", 0,
                       (0.0, 0.0, 0.0))
    with pytest.raises(OutputError, match="run.mp4: the arm reported no pose of the object"):
        video.render_run(tmp_path / "run.mp4", task, scene, [sample])
    with pytest.raises(OutputError, match="must end in .mp4"):
        video.render_run(tmp_path / "run.avi", task, scene, [sample])
    assert not list(tmp_path.iterdir())


@pytest.mark.slow
@pytest.mark.parametrize("engine", ["mujoco", "drake"])
def test_execute_video_draws_the_run_and_the_object_moves_in_it(tmp_path, engine):
    """`execute --sim --video`: 70 frames of 640 x 480 at 25 fps for the 2.81 s run (the last
    waypoint at or before each 1/25 s); the object slides 15 mm along G's x in the grasp, so in
    the camera fixed in G its pixels move right by about that, and the frames change. Drake's run
    is drawn from its recorded states just as MuJoCo's."""
    task, plan = _plan_file(tmp_path)
    out, report = tmp_path / "run.mp4", tmp_path / "run.json"
    result = CliRunner().invoke(cli, ["execute", str(plan), "--task", task, "--sim", "--engine", engine,
                                      "--video", str(out), "--json", str(report)])
    assert result.exit_code == 0, result.output
    assert f"video written to {out}: 70 frames, 640x480 at 25 fps" in result.output
    frames, fps = _decode(out)
    waypoints = json.loads(report.read_text())["waypoints"]
    assert fps == 25 and frames.shape == (len(video.frame_samples([(k + 1) / 100 for k in range(waypoints)], 25)),
                                          480, 640, 3)
    first, last = frames[0].astype(float), frames[-1].astype(float)
    assert np.abs(first - last).mean() > 1.0  # the frames change over the run
    columns = [np.nonzero(_orange(f).any(axis=0))[0] for f in (frames[0], frames[-1])]
    assert min(len(c) for c in columns) > 100  # the object fills a good part of the picture
    shift = columns[1].mean() - columns[0].mean()  # px; 15 mm at the frame's scale
    scale = (columns[0].max() - columns[0].min()) / 100.0  # px per mm: the object is 100 mm long
    assert shift == pytest.approx(15 * scale, rel=0.25), (shift, scale)
    green = (frames[-1][..., 1] > frames[-1][..., 0] + 40) & (frames[-1][..., 1] > frames[-1][..., 2] + 40)
    assert green.sum() > 200  # the plan's ghost outline


def _arm_grey(frame):
    """The pixels of the arm's links (arm.xml's 0.72, 0.74, 0.78, lit): a bluish grey, where the
    floor is a neutral one."""
    r, g, b = (frame[..., k].astype(int) for k in range(3))
    return (b - r >= 6) & (r > 90) & (np.abs(2 * g - r - b) < 16)


def _shaded_orange(frame):
    """The object's orange as the 3-D view's lights shade it (darker on the faces turned away)."""
    r, g, b = (frame[..., k].astype(int) for k in range(3))
    return (r > 100) & (r > g + 30) & (g > b + 30)


def test_execute_video_draws_the_arm_and_the_part_in_3d(tmp_path):
    """Issue 68, item 5: `--video-view 3d` draws the run's cell in perspective from the arm's
    reported joints: frames that are not blank (many colours, the part's orange and the arm's
    grey each over a good area, the caption's dark text), that change as the arm moves; `both`
    puts it beside the schematic, the video twice as wide; --video-view without --video is refused,
    and so is a 3-D view of an arm with no model of its joints."""
    task, plan = _plan_file(tmp_path)
    out, both = tmp_path / "run3d.mp4", tmp_path / "both.mp4"
    result = CliRunner().invoke(cli, ["execute", str(plan), "--task", task, "--sim", "--video", str(out),
                                      "--video-view", "3d", "--video-size", "320x240"])
    assert result.exit_code == 0, result.output
    assert f"video written to {out}: 70 frames, 320x240 at 25 fps" in result.output
    frames, fps = _decode(out)
    assert frames.shape == (70, 240, 320, 3) and fps == 25
    for frame in (frames[0], frames[35], frames[-1]):
        assert frame.std() > 20 and len(np.unique(frame.reshape(-1, 3) // 16, axis=0)) > 30  # not blank
        assert _shaded_orange(frame).sum() > 200 and _arm_grey(frame).sum() > 3000  # the part, and the arm
        assert (frame[:20].max(axis=2) < 100).sum() > 30  # the caption on the background
    moved = np.abs(frames[0].astype(int) - frames[-1].astype(int)).max(axis=2) > 40
    assert moved.sum() > 100  # the hand and the part moved (15 mm, a few pixels at this size)

    result = CliRunner().invoke(cli, ["execute", str(plan), "--task", task, "--sim", "--video", str(both),
                                      "--video-view", "both", "--video-size", "320x240", "--quiet"])
    assert result.exit_code == 0, result.output
    three_d = frames
    frames, _ = _decode(both)
    assert frames.shape == (70, 240, 640, 3)
    left, right = frames[35][:, :320].astype(float), frames[35][:, 320:].astype(float)
    assert np.abs(left - three_d[35]).mean() < 3 < 20 < np.abs(right - three_d[35]).mean()
    refused = CliRunner().invoke(cli, ["execute", str(plan), "--task", task, "--sim", "--video-view", "3d"])
    assert refused.exit_code == 2 and "--video-view: only with --video" in refused.output
    sample = RunSample(0.01, [0.45, 0, 0.3, 1, 0, 0, 0], [0.45, 0, 0.3, 1, 0, 0, 0], [0.45, 0, 0.3, 1, 0, 0, 0],
                       None, "", "approach", 0, (0.0, 0.0, 0.0))
    shipped_task = shipped("t-shaped")
    scene = video.run_scene(shipped_task, check_plan(shipped_task, plan_task(shipped_task, seed=1)))
    with pytest.raises(OutputError, match="no3d.mp4: the 3-D view draws the arm from its joints"):
        video.render_run(tmp_path / "no3d.mp4", shipped_task, scene, [sample], look=video.VideoLook(view="3d"))


@pytest.mark.slow
def test_the_ghost_follows_the_re_planned_steps(tmp_path):
    """With the closed loop, the waypoints after a correction carry the new plan's poses. The new
    plan starts at the measured pose, so the step after the correction shows a pose one unit push
    from the measured one, not the old plan's; a transit at the step where the correction starts
    (a new plan that starts with another pusher) shows the measured pose itself, until the guarded
    approach measures it again on the next feature."""
    from stablepush import _core
    from stablepush.execution import ClosedLoop, RunOptions, execute_plan
    from stablepush.sim.deviation import WorldDeviation
    from stablepush.sim.local_arm import SimulatedArm
    from stablepush.units import pose_to_si

    task = shipped("horizontal-offset-low-mu")
    plan = check_plan(task, plan_task(task, seed=1))
    recording = RunRecording()
    report = execute_plan(task, plan, SimulatedArm(deviation=WorldDeviation(mu_scale=0.85)),
                          RunOptions(rate_hz=100.0, closed_loop=ClosedLoop.for_task(task)), record=recording)
    taken = [r for r in report.replans if r.solved and r.pushes]
    assert taken
    unit = (task.planner.step[0] * 1e-3, np.radians(task.planner.step[1]))
    for r in taken:
        # its push: a transit to the next pusher that follows it in the same step shows the pose
        # the next touch measures
        heading = [s.planned for s in recording.samples if s.step == r.after_step + 1 and s.phase == "push"]
        assert heading and all(_core.steps_between(pose_to_si(r.measured), pose_to_si(p), unit) <= 1.0 + 1e-6
                               for p in heading), (r.measured, heading[:1])
        transit = [s for s in recording.samples if s.step == r.after_step and s.phase not in ("push", "settle")]
        # Up to the next feature's touch; from there the pose the guarded approach measured on it.
        if not transit:  # the new plan goes on with the pusher it has
            continue
        shown = [s.planned == pytest.approx(r.measured, abs=1e-9) for s in transit]
        touched = shown.index(False) if False in shown else len(shown)
        assert touched > 0 and not any(shown[touched:])
        assert all(s.phase == "approach" and np.hypot(*np.subtract(s.planned[:2], r.measured[:2])) < 0.2
                   for s in transit[touched:])
    k = taken[0].after_step + 1  # the old plan's pose there is not shown any more
    assert all(s.planned != pytest.approx(plan.waypoints[k].pose, abs=1e-6) for s in recording.samples if s.step == k)
    assert recording.samples[-1].planned == pytest.approx(report.planned_final)


@pytest.mark.slow
def test_evaluate_writes_a_video_of_each_failed_trial(tmp_path):
    """A tolerance of 1 um makes every trial fail, deterministically: each gets
    DIR/trial-<i>.mp4, named in its record and its CSV row, decodable; the outcomes are those of
    the same batch without videos."""
    task, plan = _plan_file(tmp_path)
    runs = {}
    for name, extra in (("with", ["--video-failed", str(tmp_path / "videos")]), ("without", [])):
        out = tmp_path / f"{name}.json"
        result = CliRunner().invoke(cli, ["evaluate", task, "--plan", str(plan), "--trials", "2", "--workers", "1",
                                          "--success-tolerance", "0.001", "0.001", "--json", str(out), "--csv",
                                          str(tmp_path / f"{name}.csv"), "--quiet"] + extra)
        assert result.exit_code == 0, result.output
        assert ("videos of 2 of the 2 failed trial(s)" in result.output) == (name == "with")
        runs[name] = json.loads(out.read_text())["trials"]
    for trial in runs["with"]:
        assert not trial["success"]
        path = tmp_path / "videos" / f"trial-{trial['trial']}.mp4"
        assert trial["video"] == str(path)
        frames, _ = _decode(path)
        waypoints = round(trial["sim_time_s"] * 100)  # the trial's own world: its guard met its features
        assert frames.shape == (len(video.frame_samples([(k + 1) / 100 for k in range(waypoints)], 25)), 480, 640, 3)
    keep = ("world", "goal_error", "success", "cause")
    assert [{k: t[k] for k in keep} for t in runs["with"]] == [{k: t[k] for k in keep} for t in runs["without"]]
    header, *rows = (tmp_path / "with.csv").read_text().splitlines()
    assert header.endswith(",video,video_error") and rows[0].endswith("trial-0.mp4,")  # drawn: no video_error
    assert "video" not in (tmp_path / "without.csv").read_text().splitlines()[0]
