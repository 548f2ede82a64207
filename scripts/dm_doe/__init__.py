"""dm_doe: the design of experiments over grade x cone index and what it feeds (issue 14): the grid,
its run order and the cases the finished ones fix (plan), bilinear interpolation of the table at
the map's cells (interp), the rasters in and out (raster, GDAL), the NRMM-style empirical model
beside the physics one (nrmm)."""
from .nrmm import NrmmError, Vehicle
from .plan import COMMAND_LIMITED, NO_GO, PAPER_CONE_INDICES, PAPER_GRADES, Grid, PlanError, implied, replay

__all__ = ['NrmmError', 'Vehicle', 'COMMAND_LIMITED', 'NO_GO', 'PAPER_CONE_INDICES', 'PAPER_GRADES', 'Grid',
           'PlanError', 'implied', 'replay']
