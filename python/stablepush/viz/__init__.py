"""Figures of plans and cones (matplotlib). Imported on demand: `import stablepush` does not load
matplotlib."""
