"""Reading the files a user names (task, plan and mesh files): regular files only, and never more
than a byte cap, so that /dev/zero, a FIFO or a sparse file of gigabytes is refused at once instead
of filling memory or waiting forever."""
from __future__ import annotations

import os
import stat
from pathlib import Path
from typing import Union


def read_capped(path: Union[str, Path], limit: int) -> bytes:
    """The bytes of the regular file at `path`, at most `limit`. ValueError (its message for a
    person) when it is not a regular file or is larger; OSError when it cannot be read."""
    # Opened without blocking, so a FIFO with no writer cannot hang the open, then checked.
    fd = os.open(path, os.O_RDONLY | getattr(os, "O_NONBLOCK", 0))
    with os.fdopen(fd, "rb") as handle:
        mode = os.fstat(handle.fileno()).st_mode
        if not stat.S_ISREG(mode):
            raise ValueError("not a regular file (a device, a FIFO or a directory)")
        data = handle.read(limit + 1)
    if len(data) > limit:
        raise ValueError(f"larger than {limit} bytes")
    return data
