"""Plots of single runs: a run's speed from its bag (speed, dm-plot-speed) and a compression test
from its result (compression, dm-plot-compression)."""
