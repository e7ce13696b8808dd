"""Serial arms made up by the tests, written as a lab would hand them to stablepush: a URDF or an
MJCF file of links and revolute joints with limits, each link a capsule of collision geometry.
Joint counts, link lengths and joint axes vary with the seed; at zero the arm stands straight up.

`urdf_arm(path, seed, axes)` and `mjcf_arm(path, seed, axes)` write one and return its Robot
fields (flange and tcp): G 110 mm past the flange along its z axis, turned half a turn about y so
that the jaws point down the flange's z (the shipped arm's TCP).
"""
from __future__ import annotations

from pathlib import Path
from typing import Dict, List, Sequence

import numpy as np

TCP = (0.0, 0.0, 110.0, 0.0, 180.0, 0.0)  # mm, deg: as the shipped arm's hand carries G
AXES = {"x": (1, 0, 0), "y": (0, 1, 0), "z": (0, 0, 1), "-y": (0, -1, 0), "-x": (-1, 0, 0)}


def link_lengths(seed: int, joints: int) -> List[float]:
    """m: a pedestal, then links long enough together to reach the shipped tasks' home
    (450 mm out, 300 mm up) with the hand pointing down, short ones at the wrist."""
    rng = np.random.default_rng(seed)
    if joints == 6:
        base = [0.16, 0.34, 0.30, 0.0, 0.08, 0.0]
    else:
        base = [0.14, 0.0, 0.34, 0.0, 0.32, 0.0, 0.08]
    return [float(b * rng.uniform(0.92, 1.08)) if b else 0.0 for b in base]


def _limits(axis: str) -> Sequence[float]:
    return (-2.9, 2.9) if axis == "z" else (-2.6, 2.6)


def urdf_arm(path: Path, seed: int, axes: Sequence[str]) -> Dict[str, object]:
    lengths = link_lengths(seed, len(axes))
    out = ['<?xml version="1.0"?>', f'<robot name="generated_{len(axes)}_{seed}">',
           '  <link name="base"><collision><origin xyz="0 0 0.04"/><geometry><cylinder radius="0.07" length="0.08"/>'
           '</geometry></collision><inertial><mass value="4"/><inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" '
           'ixz="0" iyz="0"/></inertial></link>']
    parent, offset = "base", 0.08
    for i, (axis, length) in enumerate(zip(axes, lengths), start=1):
        name = f"link{i}"
        radius = 0.045 - 0.003 * i
        geometry = (f'<collision name="{name}_collision"><origin xyz="0 0 {length / 2!r}"/><geometry><cylinder radius="{radius!r}" '
                    f'length="{max(length, 0.02)!r}"/></geometry></collision>') if length else ""
        out.append(f'  <link name="{name}">{geometry}<inertial><origin xyz="0 0 {length / 2!r}"/>'
                   f'<mass value="{2.5 - 0.25 * i!r}"/><inertia ixx="0.02" iyy="0.02" izz="0.005" ixy="0" ixz="0" '
                   f'iyz="0"/></inertial></link>')
        lo, hi = _limits(axis)
        out.append(f'  <joint name="joint_{i}" type="revolute"><parent link="{parent}"/><child link="{name}"/>'
                   f'<origin xyz="0 0 {offset!r}"/><axis xyz="{" ".join(map(str, AXES[axis]))}"/>'
                   f'<limit lower="{lo}" upper="{hi}" effort="100" velocity="{3.0 - 0.1 * i:.2f}"/></joint>')
        parent, offset = name, length
    out.append('  <link name="tool0"/>')
    out.append(f'  <joint name="flange" type="fixed"><parent link="{parent}"/><child link="tool0"/>'
               f'<origin xyz="0 0 {offset!r}"/></joint>')
    out.append("</robot>")
    path.write_text("\n".join(out) + "\n")
    return {"model": str(path), "flange": "tool0", "tcp": list(TCP)}


def mjcf_arm(path: Path, seed: int, axes: Sequence[str]) -> Dict[str, object]:
    lengths = link_lengths(seed, len(axes))
    body = ""
    for i in reversed(range(len(axes))):
        axis, length = axes[i], lengths[i]
        offset = 0.1 if i == 0 else lengths[i - 1]
        lo, hi = _limits(axis)
        geom = (f'<geom type="capsule" fromto="0 0 0 0 0 {length!r}" size="{0.045 - 0.003 * i!r}" mass="2"/>'
                if length else '<geom type="sphere" size="0.04" mass="1"/>')
        inner = body or '<body name="flange" pos="0 0 {:.6f}"/>'.format(length)
        body = (f'<body name="l{i + 1}" pos="0 0 {offset!r}"><joint name="q{i + 1}" axis="{" ".join(map(str, AXES[axis]))}" '
                f'range="{lo} {hi}"/>{geom}{inner}</body>')
    xml = (f'<mujoco model="generated_{len(axes)}_{seed}"><compiler angle="radian" autolimits="true"/>'
           '<worldbody><body name="pedestal"><geom type="cylinder" size="0.07 0.05" pos="0 0 0.05" mass="4"/>'
           f'{body}</body></worldbody></mujoco>')
    path.write_text(xml + "\n")
    return {"model": str(path), "flange": "flange", "tcp": list(TCP)}
