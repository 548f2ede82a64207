"""dm-doe's subcommands (plan, run, status, case, nrmm, map): what each does with the parsed
command line; dem_mobility_tools.doe.cli builds the command line."""
import datetime
import os
import sys
import time

import numpy as np
import yaml

from .. import paths
from .. import sweep as dm_sweep
from ..paths import ROOT
from ..sweep.args import git_commit, ros_package
from ..terramechanics import nrmm
from . import maps, plan, raster, runner, slurm
from .design import COSTS, NRMM_VEHICLE, UsageError, cells_of, design, grid_of, print_plan, run_cost
from .table import read_table, speed_plots, write_table

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

