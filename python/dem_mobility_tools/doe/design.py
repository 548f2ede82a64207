"""dm-doe's design (docs/doe.md): the grid of grades [deg] x cone indices [psi] (the paper's, the
map's ranges or given), the map's cells, the cone indices a level can simulate, the estimated cost
of the runs and the plan as `dm-doe plan` prints it."""
import argparse
import os

import numpy as np
import yaml

from ..paths import CONFIG, ROOT
from ..terramechanics import nrmm
from . import plan, raster

NRMM_VEHICLE = os.path.join(CONFIG, 'vehicles', 'hmmwv', 'nrmm.yaml')
COSTS = os.path.join(CONFIG, 'doe', 'run_costs.yaml')


class UsageError(ValueError):
    pass


def grid_size(text):
    try:
        g = [int(x) for x in text.lower().split('x')]
    except ValueError:
        g = []
    if len(g) != 2 or min(g) < 2:
        raise argparse.ArgumentTypeError('expected G x C with G, C >= 2 (e.g. 14x12), got %r' % text)
    return g


MAX_GRADE = 45.0  # [deg] the scenes' grade_deg range (mobility_run.cpp)


def grid_of(a, slope=None, ci=None):
    """The grid: the paper's (default), or the ranges found on the map (--grid map: G x C values
    spanning the cells' slopes and CIs), or the given --grades and --cone-indices."""
    if a.grades is not None or a.cone_indices is not None:
        if a.grades is None or a.cone_indices is None:
            raise UsageError('give both --grades and --cone-indices (or neither)')
        if a.grades and max(a.grades) > MAX_GRADE:
            raise UsageError('--grades: %g deg is steeper than the scenes take (grade_deg up to %g deg)'
                             % (max(a.grades), MAX_GRADE))
        return plan.Grid(a.grades, a.cone_indices)
    if getattr(a, 'grid', 'paper') == 'map':
        if slope is None:
            raise UsageError('--grid map needs the map (--elevation)')
        if len(a.grid_size) != 2 or min(a.grid_size) < 2:
            raise UsageError('--grid-size: expected G x C with G, C >= 2 (e.g. 14x12), got %r' % a.grid_size)
        s_max = float(np.nanmax(slope))
        if s_max > MAX_GRADE:  # steeper cells are beyond the table: no value on the map
            print('plan: the map\'s slopes reach %.1f deg; the grid stops at %g deg (the scenes\' limit)'
                  % (s_max, MAX_GRADE))
            s_max = MAX_GRADE
        c_lo, c_hi = float(np.nanmin(ci)), float(np.nanmax(ci))
        g = [round(s_max * k / (a.grid_size[0] - 1), 3) for k in range(a.grid_size[0])]
        c = [round(c_lo + (c_hi - c_lo) * k / (a.grid_size[1] - 1), 3) for k in range(a.grid_size[1])]
        return plan.Grid(g, c)
    return plan.Grid(plan.PAPER_GRADES, plan.PAPER_CONE_INDICES)


def cells_of(a):
    """The map's cells: (CellGrid, max slope [deg], min CI [psi], CI source)."""
    elev = raster.read(a.elevation, 'elevation')
    cells = raster.CellGrid(elev, a.cell_size, a.oversample)
    slope = cells.max_slope()
    if a.ci:
        ci = cells.min_cone_index(raster.read(a.ci, 'cone index'))
        source = a.ci
        if np.isnan(np.where(np.isnan(slope), np.nan, ci)).all():
            raise UsageError('%s: the cone index raster has no value in any cell of the elevation %s (another '
                             'region, or all nodata)' % (a.ci, a.elevation))
        if np.nanmin(ci) <= 0:
            raise UsageError('%s: cone index %.3g psi: a cone index must be positive' % (a.ci, np.nanmin(ci)))
    else:
        ci = raster.generate_ci(cells, seed=a.ci_seed)
        source = 'generated (smooth random field, seed %d, 30-300 psi)' % a.ci_seed
    ci = np.where(np.isnan(slope), np.nan, ci)
    return cells, slope, ci, source



def level_ci_range(level, terrain=os.path.join(CONFIG, 'terrains', 'soil_patch.yaml')):
    """(lowest, highest CI [psi], table file) a level can simulate: its calibration table's range
    (the table made at the level's particle size and the terrain's inter-particle mu)."""
    with open(terrain) as fh:
        t = yaml.safe_load(fh)
    if level not in t.get('levels', {}):
        raise UsageError('--level %s: %s has no such level (have %s)' % (level, terrain, ', '.join(t['levels'])))
    d, mu = float(t['levels'][level]['particle_diameter']), float(t['friction'])
    folder = os.path.normpath(os.path.join(os.path.dirname(terrain), t['calibration']))
    for name in sorted(os.listdir(folder)):
        path = os.path.join(folder, name)
        if not name.endswith('.yaml') or not os.path.isfile(path):
            continue
        with open(path) as fh:
            c = yaml.safe_load(fh)
        if isinstance(c, dict) and abs(float(c.get('particle_diameter', -1)) - d) < 1e-9 and \
                abs(float(c.get('friction', -1)) - mu) < 1e-9 and c.get('table'):
            cis = [row[0] for row in c['table']]
            return min(cis), max(cis), path
    raise UsageError('--level %s: no calibration table for %g m particles and mu %g in %s: a cone index cannot '
                     'be simulated at this level' % (level, d, mu, folder))


def check_cone_indices(grid, level):
    """Every CI of the grid must be the road's (>= 300 psi) or inside the level's table."""
    lo, hi, table = level_ci_range(level)
    bad = [c for c in grid.cone_indices if c < plan.ROAD_CONE_INDEX and not (lo <= c <= hi)]
    if bad:
        raise UsageError('cone index %s psi: outside the %s level\'s calibration range %g-%g psi (%s); '
                         'CI %g and above is the rigid road' % (', '.join('%g' % c for c in bad), level, lo, hi,
                                                                table, plan.ROAD_CONE_INDEX))
    return lo, hi, table


def run_cost(costs, level, status, ci, road_ci=plan.ROAD_CONE_INDEX):
    """Estimated wall seconds of one case."""
    sim = costs['settle'] + (costs['no_go_duration'] if status == plan.NO_GO else costs['duration'])
    if ci >= road_ci:
        return sim * costs['road']['wall_per_sim_s']
    c = costs['levels'][level]
    return c['prepare'] + sim * c['wall_per_sim_s']


def design(a):
    """(grid, costs, prior, (lo, hi, table)) of a plan or run: the grid (the paper's or the map's
    CIs that the level can simulate, and the road; CIs given with --cone-indices outside the
    level's table are refused), the measured run costs, and the NRMM model standing in for the
    outcomes."""
    with open(COSTS) as fh:
        costs = yaml.safe_load(fh)
    if a.level not in costs['levels']:
        raise UsageError('--level %s: no measured run cost for it in %s (have %s)' % (
            a.level, COSTS, ', '.join(costs['levels'])))
    slope = ci = None
    if a.elevation:
        _, slope, ci, _ = cells_of(a)
    grid = grid_of(a, slope, ci)
    if a.grades is None and a.cone_indices is None:
        lo, hi, table = level_ci_range(a.level)
        keep = [c for c in grid.cone_indices if lo <= c <= hi or c >= plan.ROAD_CONE_INDEX]
        dropped = [c for c in grid.cone_indices if c not in keep]
        if dropped:
            print('plan: the grid\'s CI %s psi lie outside the %s level\'s table (%g-%g psi): left out'
                  % (', '.join('%g' % c for c in dropped), a.level, lo, hi))
        grid = plan.Grid(grid.grades, keep)
    limits = check_cone_indices(grid, a.level)
    v = nrmm.Vehicle.load(NRMM_VEHICLE)

    def prior(cell):  # the NRMM model stands in for the outcomes the runs will have
        r = v.speed(grid.grades[cell[0]], grid.cone_indices[cell[1]])
        return r['status'], r['speed']
    return grid, costs, prior, limits


def print_plan(a, grid, costs, prior, limits):
    lo, hi, table = limits
    sim, imp = plan.replay(grid, prior)
    full = sum(run_cost(costs, a.level, prior(c)[0], grid.cone_indices[c[1]]) for c in grid.cells())
    pruned = sum(run_cost(costs, a.level, s, grid.cone_indices[c[1]]) for c, s, _ in sim)
    upper = sum(run_cost(costs, a.level, 'steady', grid.cone_indices[c[1]]) for c in grid.cells())
    print('plan: %d grades (%s) x %d cone indices (%s), level %s' % (
        len(grid.grades), ', '.join('%g' % g for g in grid.grades), len(grid.cone_indices),
        ', '.join('%g' % c for c in grid.cone_indices), a.level))
    print('  the %s level simulates CI %g-%g psi (%s); CI %g is the rigid road' % (
        a.level, lo, hi, os.path.relpath(table, ROOT), plan.ROAD_CONE_INDEX))
    print('  run order: %s ...' % ', '.join('(%g deg, CI %g)' % (grid.grades[i], grid.cone_indices[j])
                                            for i, j in grid.order()[:6]))
    print('  estimated cost on %s, the NRMM model standing in for the outcomes (%s):' % (costs['machine'], COSTS))
    print('    every case run:        %7.1f h (%d runs; at most %.1f h if none ended early)' % (
        full / 3600, len(grid.cells()), upper / 3600))
    print('    with pruning:          %7.1f h (%d runs, %d implied by their neighbours)' % (
        pruned / 3600, len(sim), len(imp)))
    print('  (the pruning the runs allow depends on their outcomes: the figures are an estimate)')

