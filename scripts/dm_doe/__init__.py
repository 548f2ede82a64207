"""dm_doe: the design of experiments over grade x cone index and what it feeds (issue 14): the
NRMM-style empirical model beside the physics one (nrmm)."""
from .nrmm import NrmmError, Vehicle

__all__ = ['NrmmError', 'Vehicle']
