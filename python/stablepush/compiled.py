"""The compiled core, `stablepush._core` (cpp/; its types in _core.pyi), as the library imports it.

The import graph that checks the layers (import-linter's grimp) reads Python files only, so a
module's `from stablepush import _core` reads there as an import of the package's root, which
re-exports every layer. The library's modules import the core from here instead
(`from stablepush.compiled import _core`), and this module's is the one such import that
pyproject.toml's [tool.importlinter] exempts.
"""
from stablepush import _core

__all__ = ["_core"]
