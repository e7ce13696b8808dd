"""Generate the type stubs of the compiled modules (stablepush._core, stablepush.sim.mujoco._pad_friction).

    python scripts/stubs.py --write     # python/stablepush/_core.pyi and sim/mujoco/_pad_friction.pyi
    python scripts/stubs.py --check     # exit 1 when a stub is not current (tests/test_stubs.py)
    python scripts/stubs.py --out DIR   # written under DIR instead (DIR/stablepush/_core.pyi, ...)

pybind11-stubgen (the `test` extra) reads the installed modules, so build them first (pip install
-e .). Its output is kept as it is but for two things it cannot know: Pose, Motion and StepSize
convert implicitly from a tuple or a list, and Pose and Motion from a NumPy array too
(cpp/bindings/types.cpp), so a parameter of those types also takes those; and a class with __eq__ but no hash
sets `__hash__ = None`, which type checkers accept in a stub only with an ignore (as typeshed
writes it). Everything else it renders is fixed in
the bindings (py::arg_v for an enum default, py::typing for iterators and optionals), so that
pybind11-stubgen runs with --exit-code: an unrenderable signature fails here, not silently.
"""
import argparse
import difflib
import re
import subprocess
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
PACKAGE_ROOT = ROOT / "python"
MODULES = ("stablepush._core", "stablepush.sim.mujoco._pad_friction")
REGENERATE = "python scripts/stubs.py --write"

# A parameter (not a return value) annotated with one of the value classes that a sequence
# converts to: `name: Pose` before `,`, `)` or ` =`.
_CONVERTIBLE = re.compile(r"(\w+: )(Pose|Motion|StepSize)(?=[,)]| =)")
_SEQUENCE = "collections.abc.Sequence[typing.SupportsFloat]"
_ARRAY = "numpy.typing.NDArray[numpy.float64]"
_ALSO = {"Pose": f"{_SEQUENCE} | {_ARRAY}", "Motion": f"{_SEQUENCE} | {_ARRAY}", "StepSize": _SEQUENCE}
# Defaults that name an enum value (py::arg_v's text in the bindings), which pybind11-stubgen would
# otherwise print as `...` since it cannot evaluate them.
_ENUM_DEFAULTS = r"GravityFrame\.\w+$"


def stub_path(module: str, root: Path) -> Path:
    return root.joinpath(*module.split(".")).with_suffix(".pyi")


def _fix(text: str) -> str:
    lines = []
    for line in text.splitlines(keepends=True):
        if line.lstrip().startswith("def "):
            line = _CONVERTIBLE.sub(lambda m: f"{m.group(1)}{m.group(2)} | {_ALSO[m.group(2)]}", line)
        elif line.strip() == "__hash__: typing.ClassVar[None] = None":
            line = line.rstrip("\n") + "  # type: ignore[assignment]\n"
        lines.append(line)
    return "".join(lines)


def generate(out: Path) -> list[Path]:
    """The stubs of MODULES written under `out`; their paths."""
    subprocess.run([sys.executable, "-m", "pybind11_stubgen", "--exit-code", "--print-safe-value-reprs", _ENUM_DEFAULTS,
                    "-o", str(out), *MODULES], check=True,
                   stdout=subprocess.DEVNULL)
    paths = []
    for module in MODULES:
        path = stub_path(module, out)
        path.write_text(_fix(path.read_text(encoding="utf-8")), encoding="utf-8")
        paths.append(path)
    return paths


def differences() -> list[str]:
    """A unified diff per stub in python/ that is not what generate() writes now."""
    out = []
    with tempfile.TemporaryDirectory() as tmp:
        generate(Path(tmp))
        for module in MODULES:
            expected = stub_path(module, Path(tmp)).read_text(encoding="utf-8")
            path = stub_path(module, PACKAGE_ROOT)
            actual = path.read_text(encoding="utf-8") if path.exists() else ""
            if actual != expected:
                name = str(path.relative_to(ROOT))
                out.append("\n".join(difflib.unified_diff(actual.splitlines(), expected.splitlines(), name,
                                                          "pybind11-stubgen", lineterm="", n=1)))
    return out


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    action = parser.add_mutually_exclusive_group(required=True)
    action.add_argument("--write", action="store_true", help="write the stubs into python/")
    action.add_argument("--check", action="store_true", help="exit 1 when a stub in python/ is not current")
    action.add_argument("--out", type=Path, help="write the stubs under this folder")
    args = parser.parse_args()
    if args.check:
        diffs = differences()
        for diff in diffs:
            print(diff)
        if diffs:
            print(f"stubs not current; regenerate them with `{REGENERATE}`", file=sys.stderr)
        return 1 if diffs else 0
    for path in generate(args.out or PACKAGE_ROOT):
        print(path)
    return 0


if __name__ == "__main__":
    sys.exit(main())
