"""A package's face whose names load their modules when first used (PEP 562), so that importing
the package (or one module of it) loads no more than it needs: a command line can name the
simulator's engines without loading MuJoCo, and the arm protocol without the executor."""
from __future__ import annotations

import importlib
from typing import Any, Callable, Dict


def lazy_exports(package: str, exports: Dict[str, str]) -> Callable[[str], Any]:
    """The module `__getattr__` of `package` for `exports` (name -> the module that defines it)."""

    def __getattr__(name: str) -> Any:
        if name not in exports:
            raise AttributeError(f"module {package!r} has no attribute {name!r}")
        return getattr(importlib.import_module(exports[name]), name)

    return __getattr__
