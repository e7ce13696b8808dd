"""Fixture layouts: from a part and a regrasp to ranked layouts, each a task with a verified plan
(`stablepush design`; layouts.py), and the best ones' measured odds (odds.py)."""
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
from stablepush.design.odds import evaluate_designs

__all__ = ["design", "evaluate_designs", "design_files", "designs_folder", "design_task", "layout_task",
           "measure_layout", "parse_rank", "Design", "DesignStudy", "RANK_KEYS", "DEFAULT_RANK"]
