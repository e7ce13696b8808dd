"""The errors stablepush raises on purpose: one base class, one subclass per kind of fault.

The CLI maps each kind to its exit status in one table (stablepush_cli.main.EXIT_STATUS); a
caller of the Python API catches `StablepushError` for all of them. Each message is one line
that names the offending field, file or message.
"""
from __future__ import annotations

from typing import Optional


class StablepushError(Exception):
    """Base of every error stablepush raises on purpose."""


class _FieldError(StablepushError, ValueError):
    """An input refused at a named field: `field` is its dotted path ('' for the whole input),
    `source` the file it came from, if any."""

    def __init__(self, field: str, reason: str, source: Optional[str] = None):
        self.field = field
        self.reason = reason
        self.source = source
        where = f"{source}: " if source else ""
        super().__init__(f"{where}{field}: {reason}" if field else f"{where}{reason}")


class TaskError(_FieldError):
    """A task that cannot be used (task file or API input)."""


class PadFaceError(TaskError):
    """A mesh part's pads that a plan's path would take off the two parallel faces the model takes
    them to press on (stablepush.task.mesh.first_pad_off_faces): the field is the pad, the message
    says at which pose and what lies under it."""


class PlanError(_FieldError):
    """A plan file that is not a valid plan, or a plan that does not belong to the task."""


class SettingError(_FieldError):
    """A setting of a run or a study that cannot be used: a command's option or an argument of the
    API (the tracker's noise beyond what the guarded approach can tell a touch from, say), named by
    its field."""


class OutputError(StablepushError, OSError):
    """An output file that cannot, or must not, be written (the path is in the message). `output`:
    the path as the caller gave it, when writing it failed (a full disk, /dev/full), so that a
    command can name the option it came from."""

    def __init__(self, message: str, output=None):
        super().__init__(message)
        self.output = output


class RunnerError(StablepushError, RuntimeError):
    """A batch's runner that cannot start (no Ray cluster where its address says), or that lost a
    worker a batch cannot do without."""


class ArmFault(StablepushError, RuntimeError):
    """Execution stopped on the arm's side or on its link: the arm was told to stop when it could
    be (`arm_stopped`: True, or None when the arm could not be reached), and
    `last_confirmed_step` is the last plan step the arm confirmed (resume after it). `connected`:
    False when the arm server was never reached, so nothing was sent. `replanned`: the closed loop
    had changed the run's steps before `last_confirmed_step`, which so counts the re-planned steps,
    not the plan file's: no resume of that file continues the run."""

    def __init__(self, reason: str, last_confirmed_step: int, arm_stopped: Optional[bool], connected: bool = True,
                 replanned: bool = False):
        super().__init__(reason)
        self.reason = reason
        self.last_confirmed_step = last_confirmed_step
        self.arm_stopped = arm_stopped
        self.connected = connected
        self.replanned = replanned
