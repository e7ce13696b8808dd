"""The optional parts of stablepush (the package's extras): planning, checking, drawing and
exporting CSV or JSON need none of them; a command or function that needs one imports it through
`require`, which names the extra to install when it is missing.

    pip install 'stablepush[sim]'     # MuJoCo: the simulated arm (execute --sim, evaluate, sim-arm, videos)
    pip install 'stablepush[drake]'   # Drake: the second engine (--engine drake)
    pip install 'stablepush[ray]'     # Ray: batches on a cluster (--ray)
    pip install 'stablepush[ros]'     # rosbags: ROS 2 bags (trajectory -o X.mcap, execute --record)
    pip install 'stablepush[video]'   # imageio-ffmpeg: videos of runs (with [sim])
    pip install 'stablepush[all]'     # every one (scripts/setup.sh installs it)
"""
from __future__ import annotations

import importlib
from types import ModuleType

from stablepush.errors import StablepushError

# The top-level module of each extra's package -> (extra, the package as PyPI names it).
EXTRAS = {
    "mujoco": ("sim", "mujoco"),
    "pydrake": ("drake", "drake"),
    "coacd": ("sim", "coacd"),  # a mesh part's convex pieces, on either engine: [drake] brings it too
    "ray": ("ray", "ray"),
    "h2": ("ray", "h2"),  # --ray HOST:PORT: the check that a Ray head answers there
    "rosbags": ("ros", "rosbags"),
    "imageio_ffmpeg": ("video", "imageio-ffmpeg"),
}


class MissingExtra(StablepushError, ImportError):
    """An optional part of stablepush that is not installed: `extra` is what to install."""

    def __init__(self, message: str, extra: str):
        super().__init__(message)
        self.extra = extra


def require(module: str, needed_for: str) -> ModuleType:
    """`module` (one of EXTRAS' packages, or a module in one), imported; MissingExtra naming the
    extra to install when its package is not there. `needed_for` says what asked, for the message
    ("execute --sim", "a ROS 2 bag")."""
    top = module.split(".")[0]
    extra, package = EXTRAS[top]
    try:
        return importlib.import_module(module)
    except ModuleNotFoundError as exc:
        if exc.name is None or exc.name.split(".")[0] != top:
            raise  # the package is there and lacks something of its own: not a missing extra
        raise MissingExtra(f"{needed_for} needs {package}, an optional part of stablepush that is not installed: "
                           f"pip install 'stablepush[{extra}]' (bash scripts/setup.sh installs every part)",
                           extra) from None
