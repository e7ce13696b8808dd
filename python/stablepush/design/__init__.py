"""Fixture layouts: from a part and a regrasp to ranked layouts, each a task with a verified plan
(`stablepush design`; layouts.py)."""
from stablepush.design.layouts import (
    DEFAULT_RANK,
    RANK_KEYS,
    Design,
    DesignStudy,
    design,
    design_files,
    design_task,
    designs_folder,
    layout_task,
    measure_layout,
    parse_rank,
)

__all__ = ["design", "design_files", "designs_folder", "design_task", "layout_task", "measure_layout", "parse_rank",
           "Design", "DesignStudy", "RANK_KEYS", "DEFAULT_RANK"]
