"""The folder a design study writes its designs to (`stablepush design --out`): checked before the
search, and left holding this run's designs only.

A design is written as DESIGN_NAME (design-1.yaml the best), its first line DESIGN_HEADER. A
second run into the same folder replaces the earlier run's designs: each it writes is replaced, and
each left over (design-3.yaml of an earlier run of three, where this run found two) is removed, so
that no file in the folder is taken for one of this run's designs. Only files of that name whose
first line is that header are removed: a file of the name that this tool did not write (a task of
one's own called design-3.yaml) is refused before the search, and anything else in the folder is
left alone.
"""
from __future__ import annotations

import contextlib
import os
import re
import stat
import tempfile
from pathlib import Path
from typing import Dict, Iterable, List, Union

from stablepush.errors import OutputError
from stablepush.outputs import write_files

DESIGN_NAME = "design-{rank}.yaml"
DESIGN_HEADER = "# design-{rank} of {source} (stablepush design): "
_NAME = re.compile(r"design-[1-9][0-9]*\.yaml")
_HEADER = re.compile(r"# design-[1-9][0-9]* of .* \(stablepush design\): ")
_HEADER_BYTES = 1024  # the header is one line, shorter than this


def check_designs_folder(folder: Union[str, Path], name: str = "out") -> None:
    """Before any work: `folder` is a directory this process can make files in, or can be made
    (the nearest part of it that exists is such a directory), and holds no file of a design's name
    (DESIGN_NAME) that this tool did not write. OutputError naming `name` and the path."""
    path = Path(folder)
    existing = path
    while not os.path.lexists(existing) and existing != existing.parent:
        existing = existing.parent
    where = f"{name} {folder}:"
    if not existing.is_dir():
        what = "is not a directory" if existing == path else f"cannot be made: {existing} is not a directory"
        raise OutputError(f"{where} {what}", output=str(folder))
    try:  # what the write will do, tried: permissions alone do not say (root, /proc, a read-only mount)
        probe = tempfile.mkdtemp(prefix=".stablepush-", dir=existing)
        os.rmdir(probe)
    except OSError as exc:
        made = "" if existing == path else f" (in {existing}, where it would be made)"
        raise OutputError(f"{where} cannot make files in it{made}: {exc.strerror or exc}", output=str(folder)) \
            from None
    for entry in _designs_in(path):
        if not _written_here(entry):
            raise OutputError(f"{where} holds {entry.name}, which is not a design this tool wrote (its first line is "
                              f"not a design's header); a run replaces the designs in the folder: move it, or name "
                              f"another folder", output=str(folder))


def write_designs(files: Dict[Union[str, Path], str], folder: Union[str, Path]) -> None:
    """Write `files` (outputs.write_files: a design's, and any other output of the study), making
    `folder` when one of them is in it, then remove each design left in `folder` by an earlier run
    (a file of a design's name and header that is not among `files`)."""
    folder = Path(folder)
    keep = {os.path.abspath(path) for path in files}
    if any(Path(os.path.abspath(path)).parent == Path(os.path.abspath(folder)) for path in files):
        try:
            folder.mkdir(parents=True, exist_ok=True)
        except OSError as exc:
            raise OutputError(f"{folder}: cannot make the folder ({exc.strerror or exc})", output=str(folder)) \
                from None
    write_files(files)
    for entry in _designs_in(folder):
        if os.path.abspath(entry) not in keep and _written_here(entry):
            try:
                entry.unlink()
            except FileNotFoundError:
                pass
            except OSError as exc:
                raise OutputError(f"{entry}: an earlier run's design, cannot remove it ({exc.strerror or exc})",
                                  output=str(entry)) from None


def _designs_in(folder: Path) -> List[Path]:
    """The entries of `folder` named as a design is (none where it is not a directory)."""
    try:
        names: Iterable[str] = os.listdir(folder)
    except OSError:
        return []
    return sorted(folder / n for n in names if _NAME.fullmatch(n))


def _written_here(path: Path) -> bool:
    """Whether `path` is a regular file (or a link to one) whose first line is a design's header."""
    with contextlib.suppress(OSError):
        if stat.S_ISREG(os.stat(path).st_mode):
            with open(path, "rb") as handle:
                first = handle.read(_HEADER_BYTES).split(b"\n", 1)[0]
            return _HEADER.match(first.decode("utf-8", "replace")) is not None
    return False
