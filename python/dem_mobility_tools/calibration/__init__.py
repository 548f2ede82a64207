"""The cone index calibration: the sweep over cohesion factors that makes the CI -> f tables
(cone_index, dm-calibrate)."""
