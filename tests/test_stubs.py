"""The compiled modules' type stubs (python/stablepush/_core.pyi, sim/mujoco/_pad_friction.pyi) are what
scripts/stubs.py generates from the built modules now, and ship with the package with py.typed."""
import importlib.util

import pytest

from conftest import ROOT


def _stubs():
    spec = importlib.util.spec_from_file_location("stubs", ROOT / "scripts" / "stubs.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_the_stubs_are_the_modules_as_built_now(tmp_path):
    stubs = _stubs()
    stubs.generate(tmp_path)
    for module in stubs.MODULES:
        expected = stubs.stub_path(module, tmp_path).read_text(encoding="utf-8")
        committed = stubs.stub_path(module, stubs.PACKAGE_ROOT)
        assert committed.exists(), f"{committed} is missing; generate it with `{stubs.REGENERATE}`"
        if committed.read_text(encoding="utf-8") != expected:
            diff = "\n".join(stubs.differences())
            shown = "\n".join(diff.splitlines()[:40])
            pytest.fail(f"{committed.name} is not current; regenerate it with `{stubs.REGENERATE}`\n{shown}",
                        pytrace=False)


def test_the_stubs_say_what_the_bindings_accept():
    from stablepush import _core

    text = (ROOT / "python" / "stablepush" / "_core.pyi").read_text(encoding="utf-8")
    assert "GravityFrame = GravityFrame.gripper" in text  # an enum default rendered, not `...`
    assert "def stop(self) -> StopFlag | None" in text
    # a tuple converts to a Pose, a Motion and a StepSize, and they iterate and index as floats
    q = _core.Pose((1.0, 2.0, 3.0))
    assert _core.steps_between((0.0, 0.0, 0.0), q, (1.0, 1.0)) > 0
    assert [type(v) for v in q] == [float] * 3 and q[-1] == 3.0
    settings = _core.PlannerSettings(start=(0, 0, 0), goal=q, step=(1e-3, 0.01), tolerance=(1e-3, 0.01))
    assert settings.stop is None
    settings.stop = _core.StopFlag()
    assert settings.stop is not None
    settings.stop = None
    assert settings.stop is None


@pytest.mark.parametrize("package", ["python/stablepush", "cli/stablepush_cli"])
def test_the_packages_are_marked_typed(package):
    # pyproject.toml's wheel.packages copies each package folder whole: the markers and the stubs
    # go into the wheel with the modules
    assert (ROOT / package / "py.typed").is_file()

