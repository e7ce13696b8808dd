"""Calibration (`stablepush calibrate`): the arm measures the friction it will push with, by
probing pushes the model chooses (probes.py), the outcomes folded into a posterior on a grid
(belief.py), on the arm (session.py) or from runs already made (runs.py); the calibrated task file
(files.py); how it runs (settings.py). docs/calibrate.md. Names load their modules when first used
(stablepush.lazy): a command line can read the settings' defaults without loading the rest."""
from stablepush.lazy import lazy_exports

_EXPORTS = {
    "CalibrationSettings": "stablepush.calibration.settings",
    "LIMITS": "stablepush.calibration.settings",
    "NEIGHBOURHOOD": "stablepush.calibration.settings",
    "PAD_PRODUCT": "stablepush.calibration.settings",
    "Belief": "stablepush.calibration.belief",
    "Interval": "stablepush.calibration.belief",
    "Unknowns": "stablepush.calibration.probes",
    "Calibration": "stablepush.calibration.session",
    "ProbeRecord": "stablepush.calibration.session",
    "Session": "stablepush.calibration.session",
    "calibrate": "stablepush.calibration.session",
    "calibrate_from_runs": "stablepush.calibration.runs",
    "read_run_report": "stablepush.calibration.runs",
    "calibrated_task_text": "stablepush.calibration.files",
}
__all__ = list(_EXPORTS)
__getattr__ = lazy_exports(__name__, _EXPORTS)
