"""Output files written so that a reader never sees a part of one: plan files, figures, reports.
"""
from __future__ import annotations

import contextlib
import os
import re
import signal
import stat
import threading
from pathlib import Path
from typing import Mapping, Union

from stablepush.errors import OutputError


def default_output(input_file: Union[str, Path], suffix: str) -> str:
    """The default output for an input file: its stem plus `suffix`, in the current directory.
    Derived from the file's own name (never from names inside it), so it cannot point elsewhere."""
    stem = Path(input_file).stem or "stablepush"
    return re.sub(r"[^\w.+-]", "_", stem + suffix)


def write_files(files: Mapping[Union[str, Path], Union[str, bytes]]) -> None:
    """Write each file so that a reader sees its old content or the whole new one, never a part,
    and a set of files is replaced together: every new file is written and synced beside its
    target first, then all are renamed into place with SIGINT, SIGTERM and SIGHUP held off, so
    that only a SIGKILL or a power cut between two renames can leave old and new side by side
    (or a temporary file behind).

    A symlink is written through (its target is replaced; the link stays). A character device or
    FIFO (/dev/null, /dev/stdout) is written to, never replaced. A directory or any other kind of
    file is refused, as is a missing directory: OutputError naming the path. New files take the
    umask's permissions; a replaced file keeps its own."""
    plan = []
    for path, content in files.items():
        target = Path(os.path.realpath(path))
        try:
            mode = os.stat(target).st_mode
        except FileNotFoundError:
            mode = None
        except OSError as exc:
            raise OutputError(f"{path}: cannot write ({exc.strerror})") from None
        if mode is not None and (stat.S_ISCHR(mode) or stat.S_ISFIFO(mode)):
            plan.append((path, target, content, "stream", None))
        elif mode is not None and not stat.S_ISREG(mode):
            raise OutputError(f"{path}: not a regular file; refusing to replace it")
        elif not target.parent.is_dir():
            raise OutputError(f"{path}: the directory {target.parent} does not exist")
        else:
            plan.append((path, target, content, "replace", stat.S_IMODE(mode) if mode is not None else None))
    with _signals_deferred():
        _write_and_rename(plan)


def _write_and_rename(plan) -> None:
    import tempfile  # here, not at the top: it costs every command's start-up about 20 ms

    temporaries = []  # written, not yet renamed: removed on any failure
    try:
        for path, target, content, how, mode in plan:
            data = content.encode() if isinstance(content, str) else content
            if how == "stream":
                with open(target, "wb") as handle:
                    handle.write(data)
                continue
            fd, tmp = tempfile.mkstemp(prefix=f".{target.name}.", suffix=".tmp", dir=target.parent)
            temporaries.append((tmp, target))
            with os.fdopen(fd, "wb") as handle:
                handle.write(data)
                handle.flush()
                os.fsync(handle.fileno())
            os.chmod(tmp, mode if mode is not None else 0o666 & ~_umask())
        for tmp, target in temporaries:
            os.replace(tmp, target)
        temporaries = []
    except OSError as exc:
        raise OutputError(f"cannot write {exc.filename or 'the output'}: {exc.strerror or exc}") from None
    finally:
        for tmp, _ in temporaries:
            with contextlib.suppress(OSError):
                os.unlink(tmp)


@contextlib.contextmanager
def _signals_deferred():
    """Hold SIGINT, SIGTERM and SIGHUP until the block ends, then deliver them as if they came
    then. A handler, not a signal mask: a process-directed signal goes to any thread that does
    not block it (numpy's BLAS threads), and its default action ends the whole process."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    pending = []
    previous = {sig: signal.signal(sig, lambda signum, frame: pending.append(signum)) for sig in _DEFERRED}
    try:
        yield
    finally:
        for sig, handler in previous.items():
            signal.signal(sig, handler)
        for sig in dict.fromkeys(pending):
            signal.raise_signal(sig)


_DEFERRED = (signal.SIGINT, signal.SIGTERM, signal.SIGHUP)


def write_atomically(path: Union[str, Path], text: Union[str, bytes]) -> None:
    """Write one file as `write_files` does."""
    write_files({path: text})


def _umask() -> int:
    mask = os.umask(0o022)
    os.umask(mask)
    return mask
