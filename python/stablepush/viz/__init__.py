"""Figures of plans and cones (matplotlib). Imported on demand: `import stablepush` does not load
matplotlib."""
from stablepush.lazy import lazy_exports

_EXPORTS = {name: "stablepush.viz.figures" for name in ("cone_figure", "layouts_figure", "plan_figure", "reach_figure",
                                                         "save_figure", "save_plan_gif")}
__all__ = list(_EXPORTS)
__getattr__ = lazy_exports(__name__, _EXPORTS)
