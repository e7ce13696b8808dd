"""The files of a lab's robot model as they are read (URDF or MJCF): the XML decoded as it
declares, an MJCF's includes put in place, and every file it names checked and protected as an
input, before MuJoCo (stablepush.kinematics.robot) compiles it. The task loads a model through here, so
a model that cannot be read is refused as the task file is, before any work.
"""
from __future__ import annotations

import codecs
import os
import re
import stat
import xml.etree.ElementTree as ET
from pathlib import Path
from typing import List

from stablepush.errors import TaskError
from stablepush.inputs import read_capped
from stablepush.outputs import protect_input


class RobotError(TaskError):
    """A robot model that cannot carry the project's jaws (a model MuJoCo cannot compile, no such
    flange, a floating base, an unnamed joint): names the field of environment.robot."""


MAX_MODEL_BYTES = 16_000_000  # a robot model file, and each file it includes
MAX_INCLUDE_DEPTH = 8
_ASSET_DIRS = ("meshdir", "texturedir", "assetdir")


def read_model_xml(path: "str | Path", what: str = "a robot model") -> ET.Element:
    """The XML of a robot model file (or a file it includes), decoded as it declares (UTF-8,
    UTF-16, ISO-8859-1), from a regular file of at most MAX_MODEL_BYTES: RobotError naming
    environment.robot.model otherwise."""
    try:
        data = read_capped(path, MAX_MODEL_BYTES)
    except (OSError, ValueError) as exc:
        raise RobotError("environment.robot.model", f"cannot read {str(path)!r:.120}: {exc}") from None
    protect_input(path, what)
    try:
        return ET.fromstring(data)
    except (ET.ParseError, LookupError) as exc:  # LookupError: an encoding Python does not know
        raise RobotError("environment.robot.model", f"{str(path)!r:.120} is not XML "
                                                    f"({' '.join(str(exc).split())[:200]})") from None


def read_model_text(path: "str | Path") -> str:
    """A robot model file's text as written, decoded as its BOM or XML declaration says (the
    URDF a recording carries as /robot_description)."""
    read_model_xml(path)  # refused as the model is, if it is not XML
    data = read_capped(path, MAX_MODEL_BYTES)
    for boms, codec in (((codecs.BOM_UTF8,), "utf-8-sig"), ((codecs.BOM_UTF16_LE, codecs.BOM_UTF16_BE), "utf-16"),
                        ((b"<\x00",), "utf-16-le"), ((b"\x00<",), "utf-16-be")):
        if data.startswith(boms):
            return data.decode(codec)
    declared = re.match(rb"<\?xml[^>]*encoding=[\"']([A-Za-z0-9._-]+)", data)
    return data.decode(declared.group(1).decode() if declared else "utf-8")


def model_source(path: "str | Path") -> ET.Element:
    """A lab's model as MuJoCo should read it from any working folder: its XML decoded
    (read_model_xml), an MJCF's includes put in place (each a regular file, read and protected as
    an input; at most MAX_INCLUDE_DEPTH deep), and the folders its meshes and textures are
    found in made absolute: the model's folder, as MuJoCo takes a file's relative paths."""
    folder = Path(path).resolve().parent
    root = read_model_xml(path)
    if root.tag == "robot":
        extension = root.find("mujoco")
        compiler = None if extension is None else extension.find("compiler")
        if compiler is None:
            compiler = ET.SubElement(extension if extension is not None else ET.SubElement(root, "mujoco"),
                                     "compiler")
        meshdir = str(folder / compiler.get("meshdir", ""))
        compiler.set("meshdir", meshdir)
        meshes = Path(meshdir)
        _regular_files([meshes / Path(m.get("filename", "")).name for m in root.iter("mesh") if m.get("filename")])
        return root
    _inline_includes(root, folder, depth=0)
    compilers = root.findall("compiler") or [ET.SubElement(root, "compiler")]
    for compiler in compilers:
        for key in _ASSET_DIRS:
            value = compiler.get(key)
            if value is not None:
                compiler.set(key, str(folder / value))
    first = compilers[0]
    if first.get("assetdir") is None:
        for key in ("meshdir", "texturedir"):
            if all(c.get(key) is None for c in compilers):
                first.set(key, str(folder))
    found = {key: Path(value) for c in compilers for key in _ASSET_DIRS if (value := c.get(key))}
    meshes, textures = (found.get(key, found.get("assetdir", folder)) for key in ("meshdir", "texturedir"))
    _regular_files([(textures if e.tag == "texture" else meshes) / file for e in root.iter()
                    if e.tag in ("mesh", "skin", "hfield", "texture") and (file := e.get("file"))])
    return root


def _regular_files(paths: List[Path]) -> None:
    """Each file a model names that exists is a regular file: MuJoCo's open of a FIFO would wait
    for a writer forever. A missing one MuJoCo names itself."""
    for path in paths:
        try:
            mode = os.stat(path).st_mode
        except OSError:
            continue
        if not stat.S_ISREG(mode):
            raise RobotError("environment.robot.model", f"{str(path)!r:.120} is not a regular file (a device, a "
                                                        f"FIFO or a directory)")
        protect_input(path, "a file the robot model names")


def _inline_includes(element: ET.Element, folder: Path, depth: int) -> None:
    """Each <include file=...> under `element` replaced by the children of the file's <mujoco>
    (MuJoCo's include, paths relative to the main model's folder)."""
    for parent in list(element.iter()):
        for k, child in reversed(list(enumerate(parent))):
            if child.tag != "include":
                continue
            name = child.get("file")
            if not name:
                raise RobotError("environment.robot.model", "an <include> names no file")
            if depth >= MAX_INCLUDE_DEPTH:
                raise RobotError("environment.robot.model", f"includes nest more than {MAX_INCLUDE_DEPTH} deep "
                                                            f"(at {name!r:.80}): a loop?")
            included = read_model_xml(folder / name, "a file the robot model includes")
            _inline_includes(included, folder, depth + 1)
            parent.remove(child)
            for offset, grandchild in enumerate(list(included)):
                parent.insert(k + offset, grandchild)
