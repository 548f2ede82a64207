"""The design of experiments over grade x cone index and what it feeds (dm-doe, docs/doe.md): the
grid, its run order and the cases the finished ones fix (plan), the runs (runner: the local pool;
slurm: a job array; local_cluster: a one-node Slurm to try it), interpolation of the table at the
map's cells (interp), the rasters in and out (raster, GDAL) and the maps (maps). The NRMM-style
empirical model beside the physics one is terramechanics.nrmm."""
from ..terramechanics.nrmm import NrmmError, Vehicle
from .plan import COMMAND_LIMITED, NO_GO, PAPER_CONE_INDICES, PAPER_GRADES, Grid, PlanError, implied, replay

__all__ = ['NrmmError', 'Vehicle', 'COMMAND_LIMITED', 'NO_GO', 'PAPER_CONE_INDICES', 'PAPER_GRADES', 'Grid',
           'PlanError', 'implied', 'replay']
