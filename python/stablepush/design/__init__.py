"""Fixture layouts: from a part and a regrasp to ranked layouts, each a task with a verified plan
(`stablepush design`; layouts.py), the best ones' measured odds (odds.py), and the folder the
designs are written to (folder.py)."""
from stablepush.design.folder import check_designs_folder, write_designs
from stablepush.design.layouts import (
    DEFAULT_RANK,
    RANK_KEYS,
    Design,
    DesignStudy,
    LayoutSearch,
    design,
    design_files,
    design_task,
    designs_folder,
    layout_task,
    measure_layout,
    parse_rank,
)
from stablepush.design.odds import DesignOdds, evaluate_designs

__all__ = ["design", "LayoutSearch", "evaluate_designs", "DesignOdds", "design_files", "check_designs_folder",
           "write_designs", "designs_folder", "design_task", "layout_task", "measure_layout", "parse_rank", "Design",
           "DesignStudy", "RANK_KEYS", "DEFAULT_RANK"]
