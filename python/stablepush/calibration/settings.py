"""How a calibration runs (`stablepush calibrate`'s options as one value), and its defaults: a
module of its own so that a command line can offer them without loading the calibration."""
from __future__ import annotations

from dataclasses import dataclass
from typing import Tuple

from stablepush.errors import SettingError
from stablepush.units import is_integer, is_real

PROBE_PUSHES = 4  # unit pushes per probe: long enough that a slip shows in the tracker
MAX_PROBES = 12
NEIGHBOURHOOD = (10.0, 10.0)  # mm, deg: how far from the start a probe may take the object
DEFAULT_SPREAD = 0.5  # the grid spans the task's mu times 1 -+ this
DEFAULT_GRID = 25  # values per unknown
# The chance that an observed stick or slip is not the world's, and how far about the stable-push
# test's boundary an outcome is uncertain, as a share of the pads' sliding friction 2 mu N (the
# force a push works against). Fitted by likelihood to the 238 probes of probes.SLIP_MM: a boundary
# of 0.02 (0.015 to 0.03 within 2 log-units) and an error rate of 0.001, taken as 0.01 to spare the
# probes the search chooses, which lie near the boundary where the fit has few.
DEFAULT_ERROR_RATE = 0.01
DEFAULT_LEVEL = 0.95  # the intervals' credibility
DEFAULT_BOUNDARY = 0.02
# What a calibration aims for: the interval's half-width, as a share of the estimate, for the pads'
# mu and for a pusher's.
DEFAULT_TARGET = (0.07, 0.10)
# The pads' quantities, as the task file names them: they enter the stable-push test only as the
# product gripper.mu x gripper.grip_force / object.mass (every force of the balance scales with it,
# docs/model.md section 7), so probes measure that product. `estimate` names which of them it is
# read as; the others are taken as the task gives them (the gripper's setting, a scale).
PAD_PRODUCT = ("gripper.mu", "gripper.grip_force", "object.mass")
# Each setting's range, checked by CalibrationSettings whoever makes one (the command line too).
LIMITS = {"max_probes": (1, 200), "pushes": (1, 20), "grid": (5, 81), "spread": (0.05, 0.95),
          "error_rate": (1e-4, 0.45), "level": (0.5, 0.999),
          "boundary": (0.0, 1.0)}


@dataclass(frozen=True)
class CalibrationSettings:
    """How a calibration runs: at most `max_probes` probes of `pushes` unit pushes each; the
    unknowns' grid spans the task's mu times 1 -+ `spread` in `grid` values; an outcome is wrong
    with probability `error_rate`; the intervals hold the truth with `level` credibility; it stops
    once each interval's half-width is within `target` (pads, pushers: shares of the estimate);
    `rate_hz`, the runs' waypoints per second; `return_to_start`, push the object back to the
    task's start at the end; `estimate`, which of PAD_PRODUCT the probes' product is read as (one
    named: it is estimated; several: the product alone is reported, each unidentified)."""

    max_probes: int = MAX_PROBES
    pushes: int = PROBE_PUSHES
    spread: float = DEFAULT_SPREAD
    grid: int = DEFAULT_GRID
    error_rate: float = DEFAULT_ERROR_RATE
    boundary: float = DEFAULT_BOUNDARY
    level: float = DEFAULT_LEVEL
    target: Tuple[float, float] = DEFAULT_TARGET
    rate_hz: float = 100.0
    return_to_start: bool = True
    estimate: Tuple[str, ...] = PAD_PRODUCT[:1]

    def __post_init__(self) -> None:
        for name in ("max_probes", "pushes", "grid"):
            value, (low, high) = getattr(self, name), LIMITS[name]
            if isinstance(value, bool) or not is_integer(value) or not low <= value <= high:
                raise SettingError(name, f"must be a whole number from {low} to {high}, got {value!r:.40}")
        for name in ("spread", "error_rate", "level", "boundary"):
            value, bounds = getattr(self, name), LIMITS[name]
            if isinstance(value, bool) or not is_real(value) or not bounds[0] <= float(value) <= bounds[1]:
                raise SettingError(name, f"must be a number from {bounds[0]:g} to {bounds[1]:g}, got {value!r:.40}")
        if len(self.target) != 2 or not all(is_real(v) and 0.0 < float(v) < 1.0 for v in self.target):
            raise SettingError("target", f"must be two shares between 0 and 1 (pads, pushers), got {self.target!r:.60}")
        estimate = tuple(self.estimate)
        if not estimate or any(f not in PAD_PRODUCT for f in estimate) or len(set(estimate)) != len(estimate):
            raise SettingError("estimate", f"must name one or more of {', '.join(PAD_PRODUCT)}, each once, "
                                           f"got {self.estimate!r:.80}")
