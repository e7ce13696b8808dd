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
