"""Failures the generated fuzzers of issue 69 found (tests/fuzz_cli.py kinds options, robots and
api), one test per class; each fails on the code before its fix."""
import socket

import pytest
from click.testing import CliRunner

from stablepush.errors import SettingError
from stablepush_cli.main import cli

pytest.importorskip("mujoco")


@pytest.mark.parametrize("host", ["999.1.1.1", "not a host"])
def test_sim_arm_on_a_host_it_cannot_listen_on_is_refused_in_one_line(host):
    """`sim-arm --host 999.1.1.1` exited 4 (OSError: Name or service not known, from bind)."""
    result = CliRunner().invoke(cli, ["sim-arm", "--host", host, "--port", "0"])
    assert result.exit_code == 2, result.output
    assert result.stderr.startswith("error: host: cannot listen on") and len(result.stderr.splitlines()) == 1


def test_sim_arm_on_a_port_in_use_is_refused_by_the_library():
    from stablepush.sim.server import SimArmServer

    with socket.socket() as taken:
        taken.bind(("127.0.0.1", 0))
        taken.listen(1)
        with pytest.raises(SettingError) as refused:
            SimArmServer("127.0.0.1", taken.getsockname()[1])
    assert refused.value.field == "host" and "cannot listen" in str(refused.value)


def _mjcf(tmp_path, ranges):
    from generated_arms import mjcf_arm

    path = tmp_path / "arm.xml"
    arm = mjcf_arm(path, 5, ("z", "x", "z", "-x", "z", "x", "z"))
    text = path.read_text()
    for old, new in ranges:
        text = text.replace(old, new, 1)
    path.write_text(text)
    return arm


def test_a_joint_range_with_its_lower_end_above_its_upper_is_refused_by_name(tmp_path):
    """A joint of range="1e308 2.9" (MuJoCo compiles it): check-cell exited 4, "ValueError: high -
    low < 0", from the IK's draws of a starting posture."""
    import stablepush as sp
    from stablepush.errors import TaskError
    from stablepush.kinematics.robot import arm_model

    arm = _mjcf(tmp_path, [('range="-2.9 2.9"', 'range="1e308 2.9"')])
    with pytest.raises(TaskError) as refused:
        arm_model(sp.Robot(model=arm["model"], flange=arm["flange"], tcp=arm["tcp"]))
    assert refused.value.field == "environment.robot.model" and "joint 'q1'" in str(refused.value)
    assert "is empty" in str(refused.value)


def test_a_joint_whose_range_lies_past_a_half_turn_is_drawn_within_it(tmp_path):
    """range="4 5" (all of it past pi): the draws were uniform(4, pi), a ValueError."""
    import numpy as np

    import stablepush as sp
    from stablepush.kinematics.robot import arm_model

    arm = _mjcf(tmp_path, [('range="-2.6 2.6"', 'range="4 5"'), ('range="-2.9 2.9"', 'range="-5 -4"')])
    model = arm_model(sp.Robot(model=arm["model"], flange=arm["flange"], tcp=arm["tcp"]))
    for guess in model.home_guesses:
        assert 4 <= guess[1] <= 5 and -5 <= guess[0] <= -4, guess
    assert len({tuple(np.round(g, 6)) for g in model.home_guesses}) > 2


def test_show_of_a_plan_path_that_names_no_file_is_refused_in_one_line(tmp_path):
    """`show '' --task T --gif x.png` exited 4 (ValueError: PosixPath('.') has an empty name) making
    the default PNG's name beside the plan file."""
    from conftest import TASKS

    result = CliRunner().invoke(cli, ["show", "", "--task", str(TASKS / "t-shaped.yaml"), "--gif",
                                      str(tmp_path / "x.gif")])
    assert result.exit_code == 2, result.output
    assert result.stderr.startswith("error: ") and len(result.stderr.splitlines()) == 1, result.stderr
