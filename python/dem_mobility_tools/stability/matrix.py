#!/usr/bin/env python3
"""The stability matrix (issue 16, docs/stability.md): the road scene, the single-wheel rig and the
vehicle on the soil patch (tiny level), each run on stiff and extreme cases through the core runner
(dm_run_scene), every cell judged:

  stable              the run ended without error, every figure of its result finite, no watchdog
                      tripped, and its energy ledgers bounded: the energy dissipated (the work put
                      in less the change of the system's energy: the vehicle's, the soil's) never
                      fell below zero by more than LEDGER_TOLERANCE of the energy that passed through
  refused             before the run (exit 1) or during it (exit 3) with an error naming the limit
                      (a critical time step, a watchdog, a parameter's range, the calibration table)
  SILENT BLOW-UP      the run ended without error but a ledger went negative or a figure is not
                      finite: a defect (the script exits 2)
  FAILED              anything else (an error that names no limit, a crash): a defect (exit 2)

The cells: time step at 0.5, 0.9, 1.1 and 2 x the critical step the guard reports (the vehicle's on
the road, the soil's on soil; 1.1 and 2 also with the guard off, `time_step_guard: false`, to show
what it prevents); contact (road) and particle (soil) stiffness x 10; the DOE's steepest grade (39
deg) and a 20 deg side slope; CI 30 and CI 400 (outside the tiny table; and f 0.05 and 12 directly); the vehicle at 25 m/s
entering the soil (started rolling at speed, full throttle; the rig's carriage at 25 m/s); a drop
from 0.5 m; particles of the paper's size (3 cm) at f 12, at the level's step and at the paper's.

    dm-stability [--scenes road,wheel,soil] [--cheap] [--out results/stability]

--cheap runs the cells of a few seconds each (the road, the rig's refusals and the soil's
refusals): the test suite's subset. Writes OUT/cells/<cell>.result.yaml and .log, OUT/matrix.yaml
and OUT/matrix.md (the table of docs/stability.md).
"""
import argparse
import concurrent.futures
import math
import os
import re
import subprocess
import sys
import time

import yaml

from .. import paths
from ..paths import CONFIG, ROOT
from ..runs import read_result, scene_command

# the launch file of each scene (runs.LAUNCHES; the matrix runs the core runner only)
LAUNCH = {'road': 'road_slope.launch', 'wheel': 'single_wheel.launch', 'soil': 'soil_slope.launch'}
# how far the dissipated energy may fall below zero, as a fraction of the energy through the ledger
# (the work put in and the largest kinetic energy): velocity Verlet's energy error, well above
# round-off; a blow-up takes it far past this (docs/stability.md)
LEDGER_TOLERANCE = 1e-3
# what an error must name to count as a refusal with its limit
LIMIT_WORDS = re.compile(r'critical step|watchdog|overlaps a neighbour|more than half the skin|non-finite|'
                         r'outside the allowed range|calibration|narrower than|not a whole multiple|must be|'
                         r'limit|sank|off the (soil|road)', re.I)
CRITICAL = re.compile(r'above the critical step ([0-9.eE+-]+) s')
# what a run stopped for instability says (the energy watchdog, the DEM's watchdogs)
UNSTABLE = re.compile(r'integration is unstable|non-finite|more than half the skin|overlaps a neighbour')


def scene_file(name):
    return os.path.join(CONFIG, 'scenes', name + '.yaml')


# the scenes of the matrix: scene file, base overrides (short, cheap runs), the key of the time step
# the cells scale and the probe that makes the guard report its critical step
SOIL_BASE = ['terrain_overrides.fidelity=tiny', 'terrain_overrides.threads=1', 'terrain_overrides.track_strip_width=0.9',
             'terrain_overrides.levels.tiny.length=6', 'terrain_overrides.patch.check_window=[0.3,0.7]',
             'grade_deg=4', 'duration=2', 'settle_time=0.3']
SCENES = {
    'road': dict(file=scene_file('road_slope'), base=['grade_deg=12', 'duration=5'], step='time_step',
                 probe=['time_step=0.01']),
    'wheel': dict(file=scene_file('single_wheel'), base=['fidelity=tiny', 'threads=1'],
                  step='levels.tiny.time_step', probe=['levels.tiny.time_step=9e-4']),
    'soil': dict(file=scene_file('soil_slope'), base=SOIL_BASE, step='terrain_overrides.levels.tiny.time_step',
                 probe=['terrain_overrides.levels.tiny.time_step=9e-4']),
}


def stiff_soil(out):
    """A copy of the nominal soil with its repulsion (and with it the tangential spring) ten times
    stiffer."""
    src = os.path.join(CONFIG, 'soils', 'nominal_clay.yaml')
    with open(src) as f:
        soil = yaml.safe_load(f)
    soil['stiffness_stress'] = 10.0 * float(soil['stiffness_stress'])  # (PyYAML reads 4.42e7 as text)
    path = os.path.join(out, 'soils', 'nominal_clay_stiffness_x10.yaml')
    os.makedirs(os.path.dirname(path), exist_ok=True)
    with open(path, 'w') as f:
        f.write('# config/soils/nominal_clay.yaml with stiffness_stress x 10 (stability matrix)\n')
        yaml.safe_dump(soil, f, sort_keys=False)
    return path


def road_contact_x10():
    with open(os.path.join(CONFIG, 'terrains', 'rigid_road.yaml')) as f:
        c = yaml.safe_load(f)['contact']
    return ['terrain_overrides.contact.k_n=%g' % (10 * float(c['k_n'])), 'terrain_overrides.contact.k_t=%g' % (10 * float(c['k_t']))]


def cells(scene, crit, out):
    """(name, what, overrides, cheap) of a scene; `crit` the guard's critical step."""
    step = SCENES[scene]['step']
    rows = []
    for f in (0.5, 0.9, 1.1, 2.0):
        rows.append(('dt%g' % f, 'time step %g x critical' % f, ['%s=%.6g' % (step, f * crit)], scene != 'soil' or f > 1))
    # (the cells at 0.5 and 0.9 are `guarded`: see main)
    for f in (1.1, 2.0):
        guard = 'time_step_guard=false' if scene == 'road' else (
            'time_step_guard=false' if scene == 'wheel' else 'terrain_overrides.time_step_guard=false')
        rows.append(('dt%g_noguard' % f, 'time step %g x critical, guard off' % f, ['%s=%.6g' % (step, f * crit), guard],
                     scene == 'road'))
    if scene == 'road':
        rows += [('stiff10', 'tire-road contact stiffness x 10', road_contact_x10(), True),
                 ('grade39', '39 deg grade', ['grade_deg=39'], True),
                 ('side20', '20 deg side slope (grade 0)', ['grade_deg=0', 'side_slope_deg=20'], True),
                 ('speed25', 'arriving at 25 m/s, full throttle', ['start_speed=25', 'settle_time=0',
                                                                    'driver.full_throttle=true', 'grade_deg=0'], True),
                 ('drop05', 'dropped from 0.5 m', ['start_height=0.5'], True)]
    elif scene == 'wheel':
        rows += [('stiff10', 'particle stiffness x 10', ['soil=' + stiff_soil(out)], True),
                 ('stiff10_step', 'particle stiffness x 10, the level\'s step 8e-5 s (under its critical step)',
                  ['soil=' + stiff_soil(out), 'levels.tiny.time_step=8e-5'], True),
                 ('ci30', 'CI 30', ['cone_index=30', 'cohesion_factor=~'], True),
                 ('ci400', 'CI 400', ['cone_index=400', 'cohesion_factor=~'], True),
                 ('f0.05', 'f 0.05', ['cohesion_factor=0.05'], True),
                 ('f12', 'f 12', ['cohesion_factor=12'], True),
                 ('speed25', 'carriage at 25 m/s', ['wheel.speed=25'], True),
                 ('paper_f12_tiny_dt', '3 cm particles at f 12, the level\'s step', [
                     'levels.tiny.particle_diameter=0.03', 'cohesion_factor=12'], True),
                 ('paper_f12', '3 cm particles at f 12, the paper\'s step (1.5e-5 s), a 2.6 x 0.6 m bin 0.25 m deep', [
                     'levels.tiny.particle_diameter=0.03', 'levels.tiny.time_step=1.5e-5', 'levels.tiny.length=2.6',
                     'levels.tiny.soil_depth=0.25', 'cohesion_factor=12', 'carriage.window=[0.8,1.2]'], False)]
    else:
        t = 'terrain_overrides.'
        rows += [('stiff10', 'particle stiffness x 10', [t + 'soil=' + stiff_soil(out)], True),
                 ('stiff10_step', 'particle stiffness x 10, the level\'s step 8e-5 s (under its critical step)',
                  [t + 'soil=' + stiff_soil(out), t + 'levels.tiny.time_step=8e-5'], False),
                 # (on soil over the box's width: a vehicle sliding or rolling back leaves the strips)
                 ('grade39', '39 deg grade (soil over the width)', ['grade_deg=39', t + 'track_strip_width=0'], False),
                 ('side20', '20 deg side slope (grade 0; soil over the width)',
                  ['grade_deg=0', 'side_slope_deg=20', t + 'track_strip_width=0'], False),
                 ('ci30', 'CI 30', [t + 'cone_index=30'], False),
                 ('ci400', 'CI 400', [t + 'cone_index=400'], True),
                 ('f0.05', 'f 0.05', [t + 'cone_index=~', t + 'cohesion_factor=0.05'], False),
                 ('f12', 'f 12', [t + 'cone_index=~', t + 'cohesion_factor=12'], False),
                 ('speed25', 'arriving at 25 m/s, full throttle (soil over the width)',
                  ['start_speed=25', 'settle_time=0', 'driver.full_throttle=true', 'grade_deg=0', t + 'track_strip_width=0'],
                  False),
                 ('drop05', 'dropped from 0.5 m', ['start_height=0.5'], False),
                 ('paper_f12_tiny_dt', '3 cm particles at f 12, the level\'s step', [
                     t + 'levels.tiny.particle_diameter=0.03', t + 'cone_index=~', t + 'cohesion_factor=12'], True)]
    return rows


def run(cmd, log, timeout):
    t0 = time.time()
    with open(log, 'w') as f:
        try:
            rc = subprocess.run(cmd, stdout=f, stderr=subprocess.STDOUT, timeout=timeout).returncode
        except subprocess.TimeoutExpired:
            rc = 'timeout'
    with open(log) as f:
        text = f.read()
    return rc, text, time.time() - t0


def probe_critical(runner, scene, out):
    s = SCENES[scene]
    log = os.path.join(out, 'cells', scene + '_probe.log')
    cmd = scene_command('core', LAUNCH[scene], scene=s['file'], core_args=s['base'] + s['probe'], core_options=['--quiet'],
                        dm_run_scene=runner)
    rc, text, _ = run(cmd, log, 600)
    m = CRITICAL.search(text)
    if rc != 1 or not m:
        raise SystemExit('dm-stability: the %s probe did not report a critical step (exit %s; %s)' % (scene, rc, log))
    return float(m.group(1))


# the figures a run computes from its state (not those left NaN when nothing was measured, such as
# the patch's checks of a run too short for the patch to follow)
STATE_FIGURES = re.compile(r'^(speed_made_good|traction_coefficient|motion_resistance_coefficient|drawbar_margin|slip|'
                           r'sinkage|vehicle_energy_.*|soil_energy_.*|dp_over_w|torque_over_wr|drawbar_pull|'
                           r'vertical_force|simulated_time|critical_time_step)$')


def finite_figures(node):
    if isinstance(node, dict):
        return all(finite_figures(v) for k, v in node.items() if STATE_FIGURES.match(str(k)))
    values = node if isinstance(node, list) else [node]
    return all(math.isfinite(v) for v in values if isinstance(v, float))


def ledger(r, prefix):
    """(least, scale) of a ledger in a result, or None."""
    if prefix + '_dissipated_least' not in r:
        return None
    return r[prefix + '_dissipated_least'], r[prefix + '_scale']


def judge(rc, text, result, guarded=False):
    """(verdict, detail) of a cell. `guarded`: a cell the guard let run (at or below the critical
    step): stopping during it for instability means the guard let an unstable step through."""
    r = result or {}
    status = r.get('status')
    err = (r.get('error') or '').strip()
    if rc == 1:
        msg = [l for l in text.splitlines() if 'error' in l.lower()]
        msg = msg[-1] if msg else text.strip().splitlines()[-1:] or ['']
        msg = msg if isinstance(msg, str) else msg[0]
        return ('refused before the run' if LIMIT_WORDS.search(msg) else 'FAILED'), msg
    if rc == 3 or status == 'error':
        if guarded and UNSTABLE.search(err):
            return 'FAILED', 'the guard let an unstable step through: ' + err
        return ('refused during the run' if LIMIT_WORDS.search(err) else 'FAILED'), err
    if rc != 0 or not result:
        return 'FAILED', 'exit %s: %s' % (rc, text.strip().splitlines()[-1:] if text.strip() else '')
    if not finite_figures(r):
        return 'SILENT BLOW-UP', 'a figure of the result is not finite'
    notes = []
    for name in ('vehicle_energy', 'soil_energy'):
        l = ledger(r, name)
        if l is None:
            continue
        least, scale = l
        notes.append('%s: least dissipated %.3g J of %.3g J through' % (name.split('_')[0], least, scale))
        if least < -LEDGER_TOLERANCE * scale:
            return 'SILENT BLOW-UP', '; '.join(notes) + ' (below -%g of it)' % LEDGER_TOLERANCE
    figures = []
    if 'speed_made_good' in r:
        figures.append('%s, %.2f m/s' % (r.get('verdict', status), r['speed_made_good']))
    if 'dp_over_w' in r:
        figures.append('%s, DP/W %.3f' % (status, r['dp_over_w']))
    return 'stable', '; '.join(figures + notes)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split('\n')[0], formatter_class=argparse.RawDescriptionHelpFormatter,
                                 epilog=__doc__[__doc__.index('\n'):])
    ap.add_argument('--scenes', default='road,wheel,soil')
    ap.add_argument('--cells', default='', help='only these cells (comma-separated names, e.g. dt0.5,grade39)')
    ap.add_argument('--cheap', action='store_true', help='only the cheap cells (seconds each)')
    ap.add_argument('--jobs', type=int, default=1)
    ap.add_argument('--timeout', type=float, default=3600.0, help='longest a cell may take [s]')
    ap.add_argument('--dm-run-scene', default=None,
                    help=paths.RUNNER_HELP)
    ap.add_argument('--out', default=os.path.join(ROOT, 'results', 'stability'))
    a = ap.parse_args(argv)
    a.dm_run_scene = paths.dm_run_scene(a.dm_run_scene)
    if not os.access(a.dm_run_scene, os.X_OK):
        ap.error(paths.missing_runner_message(a.dm_run_scene))
    a.out = os.path.abspath(a.out)  # (the cells name files in it from the scenes' folders)
    os.makedirs(os.path.join(a.out, 'cells'), exist_ok=True)
    wanted = set(c for c in a.cells.split(',') if c)
    plan = []
    crit = {}
    for scene in a.scenes.split(','):
        if scene not in SCENES:
            ap.error('unknown scene %r (%s)' % (scene, ', '.join(SCENES)))
        crit[scene] = probe_critical(a.dm_run_scene, scene, a.out)
        print('%s: the guard\'s critical step %.4g s' % (scene, crit[scene]), flush=True)
        for name, what, overrides, cheap in cells(scene, crit[scene], a.out):
            if (a.cheap and not cheap) or (wanted and name not in wanted):
                continue
            plan.append((scene, name, what, overrides))

    def one(item):
        scene, name, what, overrides = item
        s = SCENES[scene]
        base = os.path.join(a.out, 'cells', '%s_%s' % (scene, name))
        result_file = base + '.result.yaml'
        if os.path.exists(result_file):
            os.remove(result_file)
        cmd = scene_command('core', LAUNCH[scene], scene=s['file'], core_args=s['base'] + overrides, result=result_file,
                            core_options=['--quiet'], dm_run_scene=a.dm_run_scene)
        rc, text, wall = run(cmd, base + '.log', a.timeout)
        result, _ = read_result(result_file)  # (None when the run left none: judge says what the run did)
        verdict, detail = judge(rc, text, result, guarded=name in ('dt0.5', 'dt0.9'))
        return dict(scene=scene, cell=name, what=what, overrides=overrides, exit=rc, verdict=verdict, detail=detail,
                    wall_time=round(wall, 1))

    rows = []
    with concurrent.futures.ThreadPoolExecutor(max_workers=a.jobs) as pool:
        for row in pool.map(one, plan):
            rows.append(row)
            print('%-5s %-18s %-24s %s' % (row['scene'], row['cell'], row['verdict'], row['detail'][:150]), flush=True)
    with open(os.path.join(a.out, 'matrix.yaml'), 'w') as f:
        yaml.safe_dump({'critical_time_step': crit, 'ledger_tolerance': LEDGER_TOLERANCE, 'cells': rows}, f, sort_keys=False)
    with open(os.path.join(a.out, 'matrix.md'), 'w') as f:
        f.write('| scene | cell | verdict | what the run or the refusal says | wall [s] |\n|---|---|---|---|---|\n')
        for r in rows:
            f.write('| %s | %s | %s | %s | %s |\n' % (r['scene'], r['what'], r['verdict'],
                                                    r['detail'].replace('|', '/').replace('\n', ' '), r['wall_time']))
    bad = [r for r in rows if r['verdict'] in ('SILENT BLOW-UP', 'FAILED')]
    print('stability matrix: %d cells, %d stable, %d refused, %d defects (%s)' % (
        len(rows), sum(r['verdict'] == 'stable' for r in rows), sum(r['verdict'].startswith('refused') for r in rows),
        len(bad), os.path.join(a.out, 'matrix.md')))
    return 2 if bad else 0


if __name__ == '__main__':
    sys.exit(main())
