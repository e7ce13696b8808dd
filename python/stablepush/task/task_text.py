"""A task file written from its mapping with the comments of the file it came from: a design's
(`stablepush design`'s design-<rank>.yaml, from the design file) and a calibrated task
(`stablepush calibrate -o`, from the task file); and the files such a mapping names, named absolutely.

A design's task (layouts.design_task) is the design file's mapping with `candidates` replaced by
the layout's `pushers`, `environment.features` set, and files named relative to the design file
named absolutely. Its text is made from the design file's own text, a top-level section at a time:
- a section whose value is the task's as it is (name, object, gripper, start, goal, planner, ...)
  is kept verbatim, its comments, the ones above it included, with it;
- a section the design changes (environment; object with a file) is edited in place by
  ruamel.yaml's round trip, which keeps the comments within it;
- `candidates` gives way to `pushers` where it stood, without its comments (they are about the
  candidates); a section the task has and the file does not is added at the end.
A section starts at a line at column 0 that is not a comment, a list item or a document marker, and
takes the comment and blank lines at column 0 right above it; the lines before the first section
(the file's own header) are kept. Where the file does not split so (a flow mapping at the top,
several documents, a section that does not parse on its own, as an alias to another section's
anchor does not) or the text made does not load back to the task itself, the task is dumped plainly,
without the comments: the written file always means exactly the task.
"""
from __future__ import annotations

import io
import re
from typing import Any, Dict, List, Optional, Tuple

import yaml

from stablepush.task.model import Task

# A section's first line: a key at column 0 (not a comment, list item, flow collection, directive or
# document marker) followed by a colon.
_SECTION = re.compile(r"^(?![#\-\[{%&*!|>@`'\"?]|\.\.\.)\S.*?:(\s|$)|^(['\"]).*?\2\s*:(\s|$)")
_COMMENT_OR_BLANK = re.compile(r"^(#.*)?\s*$")


def commented_task(design_text: Optional[str], task: Dict[str, Any], header: str) -> str:
    """The task file's text: `header` (comment lines) first, then `task` in the design file's
    words (`design_text`, None: not at hand) with its comments where they apply (module doc), else
    the plain dump of `task`."""
    plain = header + yaml.safe_dump(task, sort_keys=False)
    if design_text is None:
        return plain
    try:
        text = _with_comments(design_text, task)
    except (yaml.YAMLError, ValueError, TypeError, KeyError):
        return plain
    if text is None or yaml.safe_load(text) != task:
        return plain
    return header + text


def _with_comments(design_text: str, task: Dict[str, Any]) -> Optional[str]:
    split = _sections(design_text)
    if split is None:
        return None
    head, sections = split
    out = ["".join(head)]
    done = set()
    for key, above, body in sections:
        if key == "candidates":
            out.append(_dump({"pushers": task["pushers"]}))
            done.add("pushers")
        elif key in task:
            out.append("".join(above))
            value = yaml.safe_load("".join(body))[key]
            out.append("".join(body) if value == task[key] else _edited("".join(body), key, task[key]))
            done.add(key)
    for key, value in task.items():
        if key not in done:
            out.append(_dump({key: value}))
    text = "".join(out)
    return text if text.endswith("\n") else text + "\n"


def _sections(text: str) -> Optional[Tuple[List[str], List[Tuple[Any, List[str], List[str]]]]]:
    """(the lines before the first section, [(key, the comment lines above it, its lines)]), or
    None where the text does not split into sections that each parse to their own key."""
    lines = text.splitlines(keepends=True)
    if lines and not lines[-1].endswith("\n"):
        lines[-1] += "\n"
    if any(line.startswith(("---", "...", "%")) for line in lines):
        return None  # several documents, or directives: not split
    starts = [i for i, line in enumerate(lines) if _SECTION.match(line)]
    if not starts:
        return None
    sections: List[Tuple[List[str], List[str], int, int]] = []
    for n, start in enumerate(starts):
        end = starts[n + 1] if n + 1 < len(starts) else len(lines)
        if n + 1 < len(starts):  # the next section's comments above it are its own
            while end - 1 > start and _COMMENT_OR_BLANK.match(lines[end - 1]):
                end -= 1
        top = start
        if n > 0:
            top = sections[-1][3]
        sections.append((lines[top:start], lines[start:end], start, end))
    parsed = []
    for above, body, _, _ in sections:
        value = yaml.safe_load("".join(body))
        if not isinstance(value, dict) or len(value) != 1:
            return None
        parsed.append((next(iter(value)), above, body))
    whole = yaml.safe_load(text)
    if not isinstance(whole, dict) or [key for key, _, _ in parsed] != list(whole):
        return None
    return lines[:starts[0]], parsed


def _edited(body: str, key: Any, value: Any) -> str:
    """A section's text with its value replaced by `value`, its comments kept (ruamel.yaml's round
    trip: what changed is set, what is gone removed, the rest left as it was written)."""
    from ruamel.yaml import YAML

    rt = YAML()
    rt.width = 4096  # long flow lists are kept on their line, as written
    node = rt.load(body)
    _merge(node, key, value)
    out = io.StringIO()
    rt.dump(node, out)
    return out.getvalue()


def _merge(parent, key, new) -> None:
    old = parent[key]
    if isinstance(old, dict) and isinstance(new, dict):
        for k in [k for k in old if k not in new]:
            del old[k]
        for k, v in new.items():
            if k in old:
                _merge(old, k, v)
            else:
                old[k] = _fresh(v)
    elif old != new:
        parent[key] = _fresh(new)


def _fresh(value):
    """A new value for ruamel.yaml: mappings in block style, lists of scalars on one line."""
    from ruamel.yaml.comments import CommentedMap, CommentedSeq

    if isinstance(value, dict):
        return CommentedMap((k, _fresh(v)) for k, v in value.items())
    if isinstance(value, list):
        seq = CommentedSeq(_fresh(v) for v in value)
        if not any(isinstance(v, (dict, list)) for v in value):
            seq.fa.set_flow_style()
        return seq
    return value


def _dump(mapping: Dict[str, Any]) -> str:
    return yaml.safe_dump(mapping, sort_keys=False, default_flow_style=None, width=4096)


def with_files_named_absolutely(mapping: Dict[str, Any], task: Task) -> Dict[str, Any]:
    """A task file's mapping with the files its `task` read (a mesh, a robot model) named by the
    absolute paths it read them from, so that the file reads the same files from any folder (a
    model `~/arm.urdf` is the home folder's, as the first file read it)."""
    out = dict(mapping)
    if task.object.mesh is not None and isinstance(out.get("object"), dict):
        out["object"] = {**out["object"], "file": task.object.mesh.file}
    environment = out.get("environment")
    if isinstance(environment, dict) and isinstance(environment.get("robot"), dict) \
            and task.environment.robot.model is not None:
        out["environment"] = {**environment, "robot": {**environment["robot"], "model": task.environment.robot.model}}
    return out
