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
from typing import Dict, Mapping, Optional, Tuple, Union

from stablepush.errors import OutputError

FIGURE_SUFFIXES = (".png", ".pdf", ".svg")  # what a figure is written as, by the file name's ending
# The files this process has read a task from (task files and their meshes): file identity -> what
# it is. write_files never replaces one, whoever asks (sp.save_plan(plan, "x.json", "t.yaml") wrote
# a CSV over the task file; the CLI's own check of its inputs was not in the library).
_INPUTS: Dict[Tuple[int, int], str] = {}
# The existing files the running command named as its outputs (check_outputs): file identity ->
# the option. A file a task names (its mesh, its robot model) is read only as the task loads, after
# the outputs were checked; protect_input refuses it then, before any work.
_DECLARED: Dict[Tuple[int, int], str] = {}


def protect_input(path: Union[str, Path], what: str) -> None:
    """Remember that `path` (as it is now) is an input, `what` says which ("a task file"), so
    that no output of this process replaces it; OutputError when the running command named it as
    an output (check_outputs)."""
    try:
        info = os.stat(path)
    except OSError:
        return
    key = (info.st_dev, info.st_ino)
    _INPUTS[key] = what
    if key in _DECLARED:
        raise OutputError(f"{_DECLARED[key]} {path}: {_read_input(what)}", output=path)


def forget_outputs() -> None:
    """The running command is over: the outputs check_outputs was given are no longer its."""
    _DECLARED.clear()


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
        target, how, mode = _writable(path)
        plan.append((path, target, content, how, mode))
    with _signals_deferred():
        _write_and_rename(plan)


def _writable(path: Union[str, Path], inputs_read: bool = True):
    """(target, "stream" or "replace", the replaced file's permissions or None) for an output path,
    by write_files' rules; OutputError naming the path where it would refuse (`inputs_read`: also
    where it is an input this process read, protect_input)."""
    fault = _not_a_file_name(path)
    if fault is not None:
        raise OutputError(f"{str(path)!r}: {fault}", output=path)
    try:  # the path as given: /dev/stdout into a pipe resolves to no file name, but stats as the pipe
        mode = os.stat(path).st_mode
    except FileNotFoundError:
        mode = None
    except OSError as exc:
        raise OutputError(f"{path}: cannot write ({exc.strerror})", output=path) from None
    if mode is not None and (stat.S_ISCHR(mode) or stat.S_ISFIFO(mode)):
        return Path(path), "stream", None
    target = Path(os.path.realpath(path))
    if mode is not None and not stat.S_ISREG(mode):
        raise OutputError(f"{path}: not a regular file; refusing to replace it", output=path)
    read = _INPUTS.get(_identity(path)) if mode is not None and inputs_read else None
    if read is not None:
        raise OutputError(f"{path}: {_read_input(read)}", output=path)
    if not target.parent.is_dir():
        raise OutputError(f"{path}: the directory {target.parent} does not exist", output=path)
    if not os.access(target.parent, os.W_OK | os.X_OK):  # a new file is made in it, then renamed
        raise OutputError(f"{path}: the directory {target.parent} is not writable", output=path)
    return target, "replace", stat.S_IMODE(mode) if mode is not None else None


def _not_a_file_name(path: Union[str, Path]) -> Optional[str]:
    """Why `path`, as given, names no file to write, or None. A name that ends in a slash (or in
    `.` or `..`) names a directory: `out.json/` was written as the file out.json, and said so; an
    empty name was taken as no output at all, and nothing was written."""
    text = os.fsdecode(os.fspath(path)) if isinstance(path, (str, bytes, os.PathLike)) else None
    if text is None:
        return f"an output is a path, not {type(path).__name__}"
    if not text:
        return "an empty file name; name the file to write"
    if text.endswith(os.sep) or (os.altsep and text.endswith(os.altsep)):
        return f"ends in {text[-1]!r}, so it names a directory; name the file to write (without the {text[-1]})"
    if os.path.basename(text) in (".", ".."):
        return "names a directory; name the file to write"
    return None


def check_outputs(outputs: Mapping[str, Optional[Union[str, Path]]],
                  inputs: Optional[Mapping[str, Optional[Union[str, Path]]]] = None) -> None:
    """Before any work is done: each output (option name -> path; None: not asked for) can be
    written by write_files' rules, and none is one of the inputs (name -> path) or another output.
    A plan written over its task file, or a CSV over its JSON, would lose a file without a word.
    Streams (/dev/null, a FIFO) may be named more than once. OutputError names the option. The
    outputs are remembered until forget_outputs, so that an input read later is refused too.
    """
    forget_outputs()
    seen = {}  # file identity -> what it already is
    for name, path in (inputs or {}).items():
        if path is not None and os.path.exists(path):
            seen[_identity(path)] = f"the input {name}; refusing to write over it"
    for name, path in outputs.items():
        if path is None:
            continue
        try:
            _, how, _ = _writable(path, inputs_read=False)  # the inputs named here are said so first
        except OutputError as exc:
            raise OutputError(f"{name} {exc}") from None
        if how == "stream":
            continue
        key = _identity(path)
        if key in seen:
            raise OutputError(f"{name} {path}: is {seen[key]}")
        if key in _INPUTS:
            raise OutputError(f"{name} {path}: {_read_input(_INPUTS[key])}")
        seen[key] = f"also the output of {name}; give each output a file of its own"
        if os.path.exists(path):
            _DECLARED[key] = name


def _read_input(what: str) -> str:
    return f"is {what} this process read; refusing to write over it"


def require_suffix(name: str, path: Optional[Union[str, Path]], suffixes) -> None:
    """Refuse an output whose file name does not end in one of `suffixes` (OutputError naming the
    option): the file's kind is taken from it."""
    suffixes = tuple(suffixes)
    if path is None:
        return
    file_name = Path(path).name
    match = next((s for s in suffixes if file_name.lower().endswith(s) and len(file_name) > len(s)), None)
    if match is None:
        listed = suffixes[0] if len(suffixes) == 1 else f"{', '.join(suffixes[:-1])} or {suffixes[-1]}"
        raise OutputError(f"{name} {path}: the file name must end in {listed}, after a name")
    if match == ".mcap" and not file_name.endswith(match):  # rosbag2's readers take the storage from it
        raise OutputError(f"{name} {path}: a bag's name must end in .mcap in lower case, which ROS 2's readers "
                          f"take as its format")


def same_file(a: Union[str, Path], b: Union[str, Path]) -> bool:
    """Whether two paths name one file (as check_outputs tells them: hard links and symlinks too)."""
    return _identity(a) == _identity(b)


def check_output(path: Union[str, Path]) -> None:
    """OutputError naming `path` unless write_files could write it (for a writer of its own, such as
    a bag's, which renames a file made elsewhere into place)."""
    _writable(path)


def is_stream(path: Union[str, Path]) -> bool:
    """Whether write_files writes `path` as a stream (/dev/null, a FIFO), not by replacing a file."""
    return _writable(path)[1] == "stream"


def _identity(path: Union[str, Path]):
    """What makes two paths one file: device and inode when it exists (hard links too), else the
    resolved path."""
    try:
        info = os.stat(path)
        return (info.st_dev, info.st_ino)
    except OSError:
        return os.path.realpath(path)


def _write_and_rename(plan) -> None:
    import tempfile  # here, not at the top: it costs every command's start-up about 20 ms

    temporaries = []  # written, not yet renamed: removed on any failure
    path = None  # the output being written, for the message: not its temporary file's name
    try:
        for path, target, content, how, mode in plan:
            data = content.encode() if isinstance(content, str) else content
            if how == "stream":
                with open(target, "wb") as handle:
                    handle.write(data)
                continue
            fd, tmp = tempfile.mkstemp(prefix=f".{target.name}.", suffix=".tmp", dir=target.parent)
            temporaries.append((tmp, target, path))
            with os.fdopen(fd, "wb") as handle:
                handle.write(data)
                handle.flush()
                os.fsync(handle.fileno())
            os.chmod(tmp, mode if mode is not None else 0o666 & ~_umask())
        for tmp, target, path in temporaries:
            os.replace(tmp, target)
        temporaries = []
    except OSError as exc:
        raise OutputError(f"{path or 'the output'}: cannot write ({exc.strerror or exc})", output=path) from None
    finally:
        for tmp, _, _ in temporaries:
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
        for signum in dict.fromkeys(pending):
            signal.raise_signal(signum)


_DEFERRED = (signal.SIGINT, signal.SIGTERM, signal.SIGHUP)


def write_atomically(path: Union[str, Path], text: Union[str, bytes]) -> None:
    """Write one file as `write_files` does."""
    write_files({path: text})


def _umask() -> int:
    mask = os.umask(0o022)
    os.umask(mask)
    return mask
