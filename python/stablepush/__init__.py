"""stablepush: in-hand manipulation planning by stable prehensile pushing."""
from stablepush._core import ContactCase, PushResult  # noqa: F401
from stablepush.task import Task, TaskError, load_task  # noqa: F401

__version__ = "0.1.0"
