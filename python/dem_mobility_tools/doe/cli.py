"""`dm-doe`: the design of experiments over grade x cone index, from a raster to a map (docs/doe.md).

    dm-doe plan  --elevation DEM.tif [--ci CI.tif | --ci-seed N] --level tiny
    dm-doe run   --out DIR [--grades ... --cone-indices ...] --level tiny --jobs 2 [--backend slurm] [--resume] [--dry-run]
                 [--refine N]
    dm-doe status --out DIR
    dm-doe nrmm  --out DIR [--grades ... --cone-indices ...]
    dm-doe map   --table TABLE.yaml --elevation DEM.tif [--ci CI.tif | --ci-seed N] --out DIR [--compare OTHER.yaml]

Every command has --help. Bad input (a raster without CRS, an empty grid, a CI outside the range
a level can simulate) is refused naming the input, with exit status 2.
"""
import argparse
import csv
import datetime
import os
import sys
import time

import numpy as np
import yaml

from ..sweep.args import floats, git_commit, ros_package

from .. import sweep as dm_sweep

from ..terramechanics import nrmm
from . import maps, plan, raster, runner, slurm

from .. import paths
from ..names import OldNameError, refuse_old_keys
from ..paths import CONFIG, ROOT
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


# -- the NRMM table ---------------------------------------------------------------------------

def write_table(path_stem, grid, rows, provenance):
    """The case table as CSV and YAML (with provenance)."""
    cols = ['grade_deg', 'cone_index_psi', 'speed_made_good', 'speed_made_good_mph', 'status', 'source']
    with open(path_stem + '.csv', 'w', newline='') as fh:
        w = csv.writer(fh)
        w.writerow(cols)
        for r in rows:
            w.writerow([r[c] for c in cols])
    doc = dict(provenance, grades=grid.grades, cone_indices=grid.cone_indices,
               speed=[[None] * len(grid.cone_indices) for _ in grid.grades], cases=rows)
    for r in rows:
        doc['speed'][grid.grades.index(r['grade_deg'])][grid.cone_indices.index(r['cone_index_psi'])] = r['speed_made_good']
    with open(path_stem + '.yaml', 'w') as fh:
        yaml.safe_dump(doc, fh, sort_keys=False)
    return path_stem + '.yaml'


def read_table(path):
    """A case table (doe run's doe_table.yaml, doe nrmm's nrmm_table.yaml): its grades, cone
    indices and the speed matrix (a row per grade), checked; UsageError naming the file."""
    try:
        with open(path) as fh:
            doc = yaml.safe_load(fh)
    except OSError as e:
        raise UsageError('%s: cannot read the table (%s)' % (path, e.strerror))
    except yaml.YAMLError as e:
        raise UsageError('%s: not YAML (%s)' % (path, str(e).replace('\n', ' ')))
    for k in ('grades', 'cone_indices', 'speed'):
        if not isinstance(doc, dict) or k not in doc:
            raise UsageError('%s: not a case table (no %s)' % (path, k))
    try:
        plan.Grid(doc['grades'], doc['cone_indices'])
    except (plan.PlanError, TypeError, ValueError) as e:
        raise UsageError('%s: grades/cone_indices: %s' % (path, e))
    rows = doc['speed']
    shape = (len(doc['grades']), len(doc['cone_indices']))
    if not isinstance(rows, list) or len(rows) != shape[0] or \
            any(not isinstance(row, list) or len(row) != shape[1] for row in rows):
        raise UsageError('%s: speed: not a %d x %d matrix (a row of %d speeds per grade)' % (path, shape[0], shape[1],
                                                                                             shape[1]))
    try:
        s = np.array([[np.nan if v is None else float(v) for v in row] for row in rows], dtype=float)
    except (TypeError, ValueError) as e:
        raise UsageError('%s: speed: a value that is not a number (%s)' % (path, e))
    # the rows: nrmm_table's `cases`, doe_table's `cases_table` (its `cases` is their number)
    for where in ('cases', 'cases_table'):
        rows = doc.get(where)
        for k, row in enumerate(rows if isinstance(rows, list) else []):
            try:
                refuse_old_keys(row, path, '%s[%d]' % (where, k))
            except OldNameError as e:
                raise UsageError(str(e))
    if np.isnan(s).any():
        raise UsageError('%s: the table has cases without a speed (the DOE is not finished)' % path)
    if (s < 0).any() or not np.isfinite(s).all():
        raise UsageError('%s: speed: a speed below 0 or infinite' % path)
    return dict(doc, speed=s)


def speed_plots(out_dir, name, grid, speed, title):
    """Figs. 23/24: speed-made-good against CI per grade and against grade per CI."""
    import matplotlib
    matplotlib.use('Agg')
    import matplotlib.pyplot as plt
    s = np.asarray(speed) / maps.MPH
    paths = []
    for what in ('ci', 'grade'):
        fig, ax = plt.subplots(figsize=(7, 4.5))
        if what == 'ci':
            for i, g in enumerate(grid.grades):
                ax.plot(grid.cone_indices, s[i], 'o-', ms=3, label='%g deg' % g)
            ax.set_xlabel('cone index [psi]')
        else:
            for j, c in enumerate(grid.cone_indices):
                ax.plot(grid.grades, s[:, j], 'o-', ms=3, label='CI %g' % c)
            ax.set_xlabel('grade [deg]')
        ax.set_ylabel('speed-made-good [mph]')
        ax.set_title(title, fontsize=10)
        ax.grid(True, alpha=0.3)
        ax.legend(fontsize=7, ncol=2)
        fig.tight_layout()
        p = os.path.join(out_dir, '%s_speed_vs_%s.png' % (name, what))
        fig.savefig(p, dpi=110)
        plt.close(fig)
        paths.append(p)
    return paths


def cmd_nrmm(a):
    v = nrmm.Vehicle.load(a.vehicle)
    grid = grid_of(a)
    os.makedirs(a.out, exist_ok=True)
    rows = []
    for g in grid.grades:
        for c in grid.cone_indices:
            r = v.speed(g, c)
            rows.append({'grade_deg': g, 'cone_index_psi': c, 'speed_made_good': round(r['speed'], 6),
                         'speed_made_good_mph': round(r['speed'] / maps.MPH, 4), 'status': r['status'],
                         'source': 'nrmm (%s)' % r['limit']})
    prov = {'model': 'nrmm', 'vehicle': os.path.abspath(a.vehicle), 'commit': git_commit(ROOT),
            'made': datetime.datetime.utcnow().strftime('%Y-%m-%dT%H:%MZ'),
            'mobility_index': round(v.mobility_index(), 3), 'vci1_psi': round(v.vci1(), 3),
            'vci50_psi': round(v.vci50(), 3),
            'relations': 'MI/VCI1 (Priddy & Willoughby 2006), VTI fine-grained traction (Dettwiller et al. 2018), '
                         'WOT-limited speed on the grade (docs/doe.md)'}
    path = write_table(os.path.join(a.out, 'nrmm_table'), grid, rows, prov)
    speed = [[r['speed_made_good'] for r in rows[i * len(grid.cone_indices):(i + 1) * len(grid.cone_indices)]]
             for i in range(len(grid.grades))]
    speed_plots(a.out, 'nrmm', grid, speed, 'NRMM-style speed-made-good (MI %.1f, VCI1 %.1f psi)'
                % (v.mobility_index(), v.vci1()))
    print('nrmm: MI %.1f, VCI1 %.1f psi, VCI50 %.1f psi; %d x %d table: %s' % (
        v.mobility_index(), v.vci1(), v.vci50(), len(grid.grades), len(grid.cone_indices), path))
    return 0


# -- maps -------------------------------------------------------------------------------------

def cmd_map(a):
    table = read_table(a.table)
    other = read_table(a.compare) if a.compare else None  # refused before anything is written
    cells, slope, ci, source = cells_of(a)
    os.makedirs(a.out, exist_ok=True)
    t0 = time.time()
    speed = maps.speed_map(table, slope, ci, clamp_ci=a.clamp_ci)
    t_map = time.time() - t0
    top = float(np.nanmax(table['speed'])) if a.top_speed is None else a.top_speed
    if not top > 0:
        raise UsageError('the ROS map needs a top speed above 0 m/s (the table\'s highest is %g): give --top-speed'
                         % float(np.nanmax(table['speed'])))
    label = table.get('model', 'physics')
    name = a.name or ('%s_smg' % label)
    title = '%s speed-made-good [mph], %d x %d cells of %g m; CI: %s' % (
        label, cells.shape[1], cells.shape[0], cells.cell_size, os.path.basename(source) if a.ci else 'generated')
    out = maps.write_all(a.out, name, speed, cells, title, top)
    raster.write_geotiff(os.path.join(a.out, 'cells_max_slope_deg.tif'), slope, cells.gt, cells.wkt, 'max slope [deg]')
    raster.write_geotiff(os.path.join(a.out, 'cells_min_ci_psi.tif'), ci, cells.gt, cells.wkt, 'min CI [psi]')
    beyond = int(np.sum(np.isnan(speed) & ~np.isnan(slope)))
    report = {'table': os.path.abspath(a.table), 'elevation': os.path.abspath(a.elevation), 'cone_index_source': source,
              'cells': list(cells.shape), 'cell_size': cells.cell_size, 'oversample': cells.oversample,
              'reprojected_to_utm': cells.reprojected, 'interpolation_wall_time': round(t_map, 4),
              'cells_beyond_the_table': beyond, 'outputs': out}
    if other is not None:
        s2 = maps.speed_map(other, slope, ci, clamp_ci=a.clamp_ci)
        diff = speed - s2
        dname = '%s_minus_%s' % (label, other.get('model', 'other'))
        raster.write_geotiff(os.path.join(a.out, dname + '.tif'), diff, cells.gt, cells.wkt, dname + ' [m/s]')
        maps.write_difference_png(os.path.join(a.out, dname + '.png'), diff, cells.cell_size,
                                  '%s minus %s speed-made-good [mph]' % (label, other.get('model', 'other')))
        report['difference'] = {'geotiff': os.path.join(a.out, dname + '.tif'), 'png': os.path.join(a.out, dname + '.png'),
                                'mean_mph': round(float(np.nanmean(diff)) / maps.MPH, 3)}
    with open(os.path.join(a.out, 'map.yaml'), 'w') as fh:
        yaml.safe_dump(report, fh, sort_keys=False)
    print('map: %d x %d cells interpolated in %.3f s (%d beyond the table: no value); %s' % (
        cells.shape[1], cells.shape[0], t_map, beyond, ', '.join(out.values())))
    return 0


# -- plan -------------------------------------------------------------------------------------

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


def cmd_plan(a):
    print_plan(a, *design(a))
    return 0


# -- run, status, case ------------------------------------------------------------------------

def run_pending(a, doc):
    """The plan's cases not done yet, on the pool or as a Slurm job array: True if interrupted
    (Ctrl-C), None if submitted without waiting (--no-wait)."""
    active, lines = slurm.reconcile(a.out, doc)
    for line in lines:
        print(line)
    if active:
        raise UsageError('%s: %d tasks of its Slurm jobs are still pending or running: wait (dm-doe status), or scancel '
                         'them, before --resume' % (a.out, active))
    states = runner.scan(a.out, doc)
    for k, (s, r) in states.items():
        if s == 'running':
            raise UsageError('case %s is running (runs/%s.running): another dm-doe run on %s?' % (
                doc['cases'][k]['name'], doc['cases'][k]['name'], a.out))
    failed = [c for c in doc['cases'] if states[c['index']][0] == 'failed']
    todo = [c for c in doc['cases'] if states[c['index']][0] in ('pending', 'interrupted') or (a.retry_failed and c in failed)]
    for c in failed:
        if not a.retry_failed:
            print('failed before: %s: %s (--retry-failed runs it again)' % (
                c['name'], (states[c['index']][1] or {}).get('error') or 'no result'))
    print('doe: %d cases: %d done, %d to run (%d at a time, runner %s)' % (
        len(doc['cases']), len(doc['cases']) - len(todo) - (0 if a.retry_failed else len(failed)), len(todo), a.jobs,
        a.runner))
    interrupted = False
    if todo and a.backend == 'slurm':
        indices = [c['index'] for c in todo]
        job = slurm.submit(a.out, doc, indices, a.jobs, a.partition, a.timeout)
        print('dm-doe: submitted job array %s: %d tasks, at most %d at once (states: dm-doe status --out %s)' % (
            job, len(indices), a.jobs, a.out), flush=True)
        if a.no_wait:
            return None
        try:
            tasks, source = slurm.wait(a.out, doc, job, indices, a.jobs)
            lost = slurm.record_lost_tasks(a.out, doc, indices, tasks)
            counts = {}
            for v in tasks.values():
                counts[v] = counts.get(v, 0) + 1
            print('doe: job %s: %s (from %s)%s' % (job, ', '.join('%d %s' % (n, k) for k, n in sorted(counts.items())),
                                                   source, '; %d tasks ended without a result' % len(lost) if lost else ''))
        except KeyboardInterrupt:
            interrupted = True
    elif todo:
        by_index = {c['index']: c for c in doc['cases']}
        cases = dm_sweep.cases([{'index': c['index']} for c in todo], name=lambda p: by_index[p['index']]['name'])

        def describe(o):
            if not o.ok:
                return 'FAILED: %s' % o.error
            r = o.result
            if r.get('status') == runner.IMPLIED:
                return 'implied %s by %s' % (r['implied_status'], r['implied_by'])
            return '%s %.3f m/s' % (r.get('status'), float(r.get('speed_made_good') or 0.0))
        command = runner.DOE_CASE + ['--out', os.path.abspath(a.out), '--index', '{index}',
                   '--port', '{port}']
        sweep = dm_sweep.Sweep(
            cases, command, os.path.join(a.out, 'workers'), jobs=a.jobs, port=a.port, timeout=a.timeout,
            check=lambda case, r: runner.verdict(by_index[case['index']], r), accept_status=(runner.IMPLIED,),
            result_of=lambda case: runner.result_path(a.out, by_index[case['index']]),
            weight=lambda case: by_index[case['index']]['estimated_cost'], describe=describe,
            progress=a.progress, status_every=None, clear_result=False)
        try:
            sweep.run()
        except KeyboardInterrupt:
            interrupted = True
        for o in sweep.outcomes:
            if o.timed_out:
                runner.record_failure(a.out, doc, by_index[o.case['index']], o.error)
    return interrupted


def cmd_run(a):
    # the core runner as found here ($DM_RUN_SCENE, $DM_BUILD or the checkout's build/), absolute for
    # the cases (a Slurm task starts in the DOE folder)
    os.environ['DM_RUN_SCENE'] = paths.dm_run_scene()
    if a.jobs < 1:
        raise UsageError('--jobs %d: at least 1' % a.jobs)
    if a.dem_threads < 1:
        raise UsageError('--dem-threads %d: at least 1' % a.dem_threads)
    if a.refine < 0:
        raise UsageError('--refine %d: the number of refinement lines is 0 or more' % a.refine)
    if a.duration is not None and not 0 < a.duration <= 40.0:
        raise UsageError('--duration %g: the driving time is in (0, 40] s (the paper\'s run is 40 s)' % a.duration)
    grid, costs, prior, limits = design(a)
    cells = {(grid.grades[i], grid.cone_indices[j]): (i, j) for i, j in grid.cells()}

    def cost_of(g, c):
        return run_cost(costs, a.level, prior(cells[(g, c)])[0], c)
    prov = {'nrmm_prior': NRMM_VEHICLE, 'costs': COSTS, 'calibration_table': os.path.relpath(limits[2], ROOT)}
    if a.elevation:
        prov['elevation'] = os.path.abspath(a.elevation)
    scenes = {}
    for kind in ('soil', 'road'):
        f = getattr(a, kind + '_scene')
        if f:
            try:
                scenes[kind] = runner.check_scene_file(f, kind)
            except runner.RunnerError as e:
                raise UsageError(str(e))
    doc = runner.make_plan(grid, a.level, a.runner, a.dem_threads, a.duration, not a.no_prune, cost_of, prov, scenes)
    path = os.path.join(a.out, runner.PLAN_FILE)
    if os.path.exists(path):
        old = runner.load_plan(a.out)
        if not a.resume:
            raise UsageError('%s holds a DOE already: --resume to go on with it, or another --out' % a.out)
        diff = runner.same_design(old, doc)
        if diff:
            raise UsageError('%s holds another DOE (%s): --resume takes the same grid, level and runner' % (a.out, diff))
        doc = old
    elif a.resume:
        raise UsageError('--resume: %s holds no DOE (%s)' % (a.out, path))
    print_plan(a, grid, costs, prior, limits)
    if a.dry_run:
        print('dry run: nothing run')
        return 0
    if doc['runner'] == 'roslaunch':
        _, problem = ros_package()
        if problem:
            raise UsageError('--runner roslaunch: %s. Source the catkin workspace first (after a build: '
                             'source ~/.cache/dem_mobility/ws-*/devel/setup.bash, as the README says), '
                             'or run the cases in one process with --runner core' % problem)
    os.makedirs(runner.runs_dir(a.out), exist_ok=True)
    if not os.path.exists(path):
        runner.write_yaml(path, doc)
    interrupted = run_pending(a, doc)
    if interrupted is None:
        return 0
    states = runner.scan(a.out, doc)
    unfinished = [c['name'] for c in doc['cases'] if states[c['index']][0] not in ('simulated', 'implied')]
    if a.refine > len(doc.get('refinements') or []) and unfinished and not interrupted:
        print('doe: --refine waits for a finished grid (%d cases are not done: %s)' % (
            len(unfinished), ', '.join(unfinished[:5])))
    elif a.refine and not interrupted:
        v = nrmm.Vehicle.load(NRMM_VEHICLE)
        doc, picks = runner.refine_plan(a.out, doc, a.refine,
                                        lambda g, c: run_cost(costs, a.level, v.speed(g, c)['status'], c))
        for axis, value, between, jump in picks:
            print('doe: refinement: %s %g between %g and %g (the speed changes by up to %.2f m/s across them)' % (
                'grade' if axis == 'grade_deg' else 'cone index', value, between[0], between[1], jump))
        if picks:
            interrupted = run_pending(a, doc)
            if interrupted is None:
                return 0
    states = runner.scan(a.out, doc)
    rows = runner.table_rows(a.out, doc, states)
    table, summary = runner.write_doe_table(a.out, doc, rows)
    speed = np.array([[np.nan if v is None else v for v in row] for row in summary['speed']], dtype=float)
    speed_plots(a.out, 'doe', plan.Grid(doc['grades'], doc['cone_indices']), speed,
                'speed-made-good, level %s (%d simulated, %d implied)' % (a.level, summary['simulated'], summary['implied']))
    print(runner.status_text(a.out, doc, states, a.jobs))
    print('doe: table %s; %d of %d runs saved by pruning' % (table, summary['implied'], summary['cases']))
    if interrupted:
        print('dm-doe: interrupted; dm-doe run --resume --out %s goes on' % a.out, file=sys.stderr)
        return 130
    return 1 if summary['failed'] or summary['not_run'] else 0


def cmd_status(a):
    doc = runner.load_plan(a.out)
    _, lines = slurm.reconcile(a.out, doc)
    states = runner.scan(a.out, doc)
    print(runner.status_text(a.out, doc, states, a.jobs))
    for line in lines:
        print('  ' + line)
    if a.table:
        path, _ = runner.write_doe_table(a.out, doc, runner.table_rows(a.out, doc, states))
        print('table: %s' % path)
    return 0


def cmd_case(a):
    return runner.run_case(a.out, a.index, a.port)


# -- the command line -------------------------------------------------------------------------

def parser():
    ap = argparse.ArgumentParser(prog='dm-doe', description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    sub = ap.add_subparsers(dest='command', metavar='COMMAND')
    sub.required = True

    def grid_args(p):
        p.add_argument('--grades', type=floats, help='grades [deg], rising (default: the paper\'s 0, 3, ..., 39)')
        p.add_argument('--cone-indices', type=floats,
                       help='cone indices [psi], rising (default: the paper\'s 12 of table 3, 30-300)')

    def map_args(p, required=True):
        p.add_argument('--elevation', required=required, help='elevation raster (GeoTIFF or anything GDAL reads; with a CRS)')
        p.add_argument('--ci', help='cone index raster [psi] (any grid and CRS); default: a generated one')
        p.add_argument('--ci-seed', type=int, default=1, help='seed of the generated CI field (default 1)')
        p.add_argument('--cell-size', type=float, default=20.0, help='map cell size [m] (default 20)')
        p.add_argument('--oversample', type=int, default=2, help='slope posts per cell side (default 2)')

    def design_args(p):  # the design's: plan and run take the same
        grid_args(p)
        map_args(p, required=False)
        p.add_argument('--grid', choices=('paper', 'map'), default='paper',
                       help='paper: 14 x 12 (default); map: --grid-size values over the ranges found on the map')
        p.add_argument('--grid-size', type=grid_size, default=[14, 12], help='G x C for --grid map (default 14x12)')
        p.add_argument('--level', default='tiny', help='soil fidelity level of the runs (default tiny)')

    p = sub.add_parser('plan', help='the grid, its run order and the estimated cost with and without pruning',
                       description='Prints the design: the grid (the paper\'s, the map\'s ranges or given), the '
                       'order the cases run in, and the estimated cost with and without pruning (a dry run: '
                       'nothing is simulated).')
    design_args(p)
    p.set_defaults(func=cmd_plan)

    p = sub.add_parser('run', help='runs the DOE\'s cases on a local pool or as a Slurm job array (resume, pruning, table, plots)',
                       description='Runs every case of the design (the plan as dm-doe plan prints it) through the '
                       'same launch files and nodelets a user runs (soil_slope.launch; road_slope.launch for CI 300), '
                       '--jobs at a time, in the plan\'s order, on a local pool or as one Slurm job array; a case whose outcome the finished ones fix is '
                       'recorded as implied, not run. Writes OUT/doe.yaml, OUT/runs/ (a result, log and bag per '
                       'case), OUT/doe_table.csv/.yaml and the plots. --resume keeps the finished cases.')
    design_args(p)
    p.add_argument('--runner', choices=('roslaunch', 'core'), default='roslaunch',
                   help='roslaunch (default: the launch files, a bag per case) or core (dm_run_scene, the same loop '
                   'in one process, no bag; ' + paths.RUNNER_HELP + ')')
    p.add_argument('--backend', choices=('local', 'slurm'), default='local',
                   help='local: a process pool here (default); slurm: one job array (sbatch --array), a task per '
                   'case, in --out (a folder every node sees)')
    p.add_argument('--jobs', type=int, default=1, help='cases at a time: the pool\'s size, or the array\'s %%N (default 1)')
    p.add_argument('--partition', help='slurm: the partition (default: the cluster\'s)')
    p.add_argument('--no-wait', action='store_true', help='slurm: submit and return (dm-doe status follows it)')
    p.add_argument('--dem-threads', type=int, default=1, help='soil threads of each run (default 1; slurm: --cpus-per-task)')
    p.add_argument('--duration', type=float, help='longest driving time [s] (default: the scenes\' 40 s)')
    p.add_argument('--soil-scene', help='a scene file of kind soil_slope for the soil cases, instead of '
                   'config/scenes/soil_slope.yaml (e.g. soil only under the tracks, a shorter box, your vehicle); '
                   'the DOE still sets grade, level, cone index, soil threads and duration')
    p.add_argument('--road-scene', help='a scene file of kind road_slope for the CI 300 cases, instead of '
                   'config/scenes/road_slope.yaml')
    p.add_argument('--no-prune', action='store_true', help='run every case (no implied cases)')
    p.add_argument('--refine', type=int, default=0, metavar='N',
                   help='once the grid is finished, add grid lines (N in all) where the speed changes fastest '
                        'between neighbours, at the midpoints, and run their cases (default 0)')
    p.add_argument('--resume', action='store_true', help='go on with the DOE in --out: finished cases are kept')
    p.add_argument('--retry-failed', action='store_true', help='with --resume: run the failed cases again')
    p.add_argument('--dry-run', action='store_true', help='print the plan and its estimated cost, run nothing')
    p.add_argument('--timeout', type=float, help='longest a case may take [s] (slurm: the tasks\' --time)')
    p.add_argument('--port', type=int, default=11611, help='first ROS master port of the pool (default 11611)')
    p.add_argument('--progress', choices=('auto', 'tqdm', 'plain'), default='auto',
                   help='a progress bar (tqdm, in s of estimated cost) on a terminal; plain: lines only')
    p.add_argument('--out', required=True, help='the DOE folder')
    p.set_defaults(func=cmd_run)

    p = sub.add_parser('status', help='what the DOE in a folder has done: cases simulated, implied, failed, left; ETA',
                       description='Prints the state of every case of the DOE in --out (from its files: it works '
                       'while a dm-doe run is going on), the failed ones with their error, and the ETA.')
    p.add_argument('--out', required=True, help='the DOE folder')
    p.add_argument('--jobs', type=int, default=1, help='cases at a time, for the ETA (default 1)')
    p.add_argument('--table', action='store_true', help='also write the case table as it stands')
    p.set_defaults(func=cmd_status)

    p = sub.add_parser('case', help='one case\'s turn (what dm-doe run\'s pool and a Slurm array task run)',
                       description='Runs case --index of the DOE in --out, unless it is done or the finished cases '
                       'fix its outcome (then it is recorded as implied). Exit status 0 when the case is done, 1 '
                       'when its run failed.')
    p.add_argument('--out', required=True, help='the DOE folder')
    p.add_argument('--index', type=int, required=True, help='the case\'s place in the plan\'s order')
    p.add_argument('--port', type=int, help='ROS master port (default: ROS_MASTER_URI\'s, else 11611)')
    p.set_defaults(func=cmd_case)

    p = sub.add_parser('nrmm', help='the NRMM-style speed table on the grid, with its plots',
                       description='Writes the NRMM-style model\'s speed-made-good table (CSV, YAML) on the grid '
                       'and its plots against CI per grade and against grade per CI (docs/doe.md).')
    grid_args(p)
    p.add_argument('--vehicle', default=NRMM_VEHICLE, help='the vehicle\'s NRMM inputs (default %(default)s)')
    p.add_argument('--out', required=True, help='output folder')
    p.set_defaults(func=cmd_nrmm)

    p = sub.add_parser('map', help='a speed-made-good map from a finished table',
                       description='Interpolates a finished case table at every cell\'s (maximum slope, minimum '
                       'CI) and writes the map as GeoTIFF, PNG and ROS map (and, with --compare, the difference '
                       'map against another table).')
    map_args(p)
    p.add_argument('--table', required=True, help='a case table (YAML: dm-doe nrmm, or a finished DOE)')
    p.add_argument('--compare', help='another table: writes the difference map (table minus it)')
    p.add_argument('--clamp-ci', action='store_true', help='take CIs above the table\'s highest as its last column (a CI below its lowest keeps no value)')
    p.add_argument('--top-speed', type=float, help='the ROS map\'s free speed [m/s] (default: the table\'s highest)')
    p.add_argument('--name', help='file name stem of the map')
    p.add_argument('--out', required=True, help='output folder')
    p.set_defaults(func=cmd_map)
    return ap


def main(argv=None):
    ap = parser()
    a = ap.parse_args(argv)
    try:
        return a.func(a)
    except (UsageError, plan.PlanError, nrmm.NrmmError, raster.RasterError, runner.RunnerError) as e:
        print('dm-doe %s: %s' % (a.command, e), file=sys.stderr)
        return 2
