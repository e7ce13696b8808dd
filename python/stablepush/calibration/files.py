"""A calibration's outputs: the calibrated task file (`calibrate -o`), with the task file's own
comments where they apply (task.task_text), and the JSON of what was measured (`--json`)."""
from __future__ import annotations

import math
from pathlib import Path
from typing import Any, Dict, Optional

import yaml

from stablepush.calibration.session import Calibration
from stablepush.calibration.settings import PAD_PRODUCT
from stablepush.task.model import VALUE_PATHS
from stablepush.task.task_text import commented_task, with_files_named_absolutely

DIGITS = 4  # significant digits of an estimate written to the task file


def calibrated_mapping(text: str, calibration: Calibration) -> Dict[str, Any]:
    """The task file's mapping (`text`, its YAML) with the calibrated values and `uncertainty`
    (Calibration.calibrated_task; the box rounded outward)."""
    mapping = yaml.safe_load(text)
    calibrated = calibration.calibrated_task()
    for field_name in PAD_PRODUCT:
        if field_name in calibration.estimates:
            group, key = VALUE_PATHS[field_name]
            mapping[group] = {**mapping[group], key: _rounded(calibrated.value(field_name))}
    pushers = []
    for entry, pusher in zip(mapping["pushers"], calibrated.pushers):
        estimated = f"pushers.{pusher.name}.mu" in calibration.estimates
        pushers.append({**entry, "mu": _rounded(pusher.mu)} if estimated else entry)
    mapping["pushers"] = pushers
    box = {key: _rounded_up(value) for key, value in calibrated.uncertainty.items()}
    if box:
        mapping["uncertainty"] = box
    return with_files_named_absolutely(mapping, calibration.task)


def calibrated_task_text(calibration: Calibration, text: Optional[str] = None) -> str:
    """The calibrated task file's text; `text`: the task file's own (None: read from the task's
    source)."""
    task = calibration.task
    if text is None:
        if task.source is None:
            raise ValueError("the task has no file to calibrate: give its text")
        text = Path(task.source).read_text(encoding="utf-8")
    lines = [f"# {task.name} calibrated by `stablepush calibrate`: {len(calibration.probes)} probe(s), "
             f"{calibration.settings.level:.0%} intervals"]
    for name, interval in calibration.estimates.items():
        lines.append(f"#   {name}: {interval.value:.4g} ({interval.low:.4g} to {interval.high:.4g}; "
                     f"the task said {task.value(name):.4g})")
    for name, why in calibration.unidentified.items():
        lines.append(f"#   {name}: not identified ({why}): the task's value is kept")
    if any(name.startswith("pushers.") for name in calibration.estimates):
        lines.append("# Each feature's mu is written at its interval's low end: a push stable there is stable at "
                     "any higher mu.")
    return commented_task(text, calibrated_mapping(text, calibration), "\n".join(lines) + "\n")


def _rounded(value: float) -> float:
    return float(f"{value:.{DIGITS}g}")


def _rounded_up(value: float) -> float:
    """A share rounded up to 3 decimals: the box written covers the interval."""
    return math.ceil(value * 1000.0 - 1e-9) / 1000.0
