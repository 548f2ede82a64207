"""dm-wheel-sweep: the single-wheel slip sweep: runs the single-wheel rig through roslaunch
(single_wheel.launch, the launch file and nodelets a user runs) for every slip and soil (cone
index, or cohesion factor f), optionally a towed run per soil, several runs at a time in parallel
processes (each with its own ROS master), and writes into OUT:

  runs/<case>.bag (+ .result.yaml, .log)   every run: its bag, result (with its history) and console
  summary.yaml                             every case's key figures, status and wall time; per soil
                                           DP/W and T/(W r) versus slip with their scatter, the
                                           reference band and the VTI curve at the same slips, and
                                           the difference sim - VTI; the failed cases
  dp_over_w_vs_slip.png                    DP/W versus slip, one line per soil, beside its band and VTI
  torque_over_wr_vs_slip.png               T/(W r) versus slip, beside the band and VTI curve of GT/W
  sinkage_vs_slip.png                      sinkage versus slip, beside VTI's sinkage
  histories_<soil>.png                     DP/W, T/(W r) and sinkage versus travel, the window shaded

    dm-wheel-sweep --fidelity coarse --ci 60,100 --slip 0.05,0.1,0.2,0.3,0.5 \\
        --towed --jobs 2 --out results/single_wheel

The references (dem_mobility_tools.terramechanics.wheel_numerics, nrmm-baseline.md section 4) are empirical fits
for pneumatic tires: the plots and the summary report the difference, nothing is tuned to them.
A run whose wheel sank (status sunk) is a result, shown with its own marker; a failed run is
reported and the others are kept; the exit status is 1 if any run failed.

--runner core runs dm_run_scene (dem_mobility_tools.paths) instead of roslaunch: a developer's quick check of
the sweep without the ROS build, NOT the launch files users run (no bag is written).
"""
import argparse
import math
import os
import sys
import time

import yaml

from .. import names, paths
from .. import sweep as dm_sweep
from ..paths import ROOT
from ..runs import scene_command
from ..sweep import keep as dm_keep
from ..sweep.args import floats, git_commit, keep_options, ros_package, sha256
from ..terramechanics import wheel_numerics as wn
from .plots import LABEL_PREFIX, plots, soil_label  # noqa: F401

PROG = 'dm-wheel-sweep'


def band_text(dh):
    return 'the band: min-max over %s' % ', '.join(m[0] for m in wn.band_members(dh))


WES_TEXT = ('WES clay numeric (4.2) not in the band: no closed-form pull in the baseline, '
            'and N_c = 0 for a rigid tire (its N_c at delta/h 0.15 is in summary.yaml)')
GT_TEXT = ('T/(W r) compared with the gross traction GT/W = DP/W + MR/W: the empirical GT is the '
           'drive torque over the rolling radius, which for a rigid wheel is taken as its radius r')


# -- the cases



def case_name(p):
    """ci100_slip0.2, ci100_towed, f1.5_slip0.2."""
    soil = soil_label(p['soil_key'], p['soil'])
    return soil + ('_towed' if p['drive'] == 'towed' else '_slip%g' % p['slip'])


def make_cases(soil_key, soils, slips, towed=False):
    """Per soil (soil_key cone_index_psi: cone indices [psi]; cohesion_factor: f; in the order given)
    the slips, then the towed run."""
    if soil_key not in (names.CONE_INDEX, names.COHESION_FACTOR):
        raise ValueError('soil key %r: expected %s or %s' % (soil_key, names.CONE_INDEX, names.COHESION_FACTOR))
    params = []
    for v in soils:
        params += [{'soil_key': soil_key, 'soil': v, 'drive': 'slip', 'slip': s} for s in slips]
        if towed:
            params.append({'soil_key': soil_key, 'soil': v, 'drive': 'towed', 'slip': None})
    return dm_sweep.cases(params, name=case_name)


def bag_path(out, name):
    return os.path.join(out, 'runs', name + '.bag')


def case_params(a, case):
    """A case's parameters of single_wheel.launch (runs.LAUNCHES), None where the scene's value holds."""
    return [('fidelity', a.fidelity),
            ('cone_index' if case['soil_key'] == names.CONE_INDEX else 'cohesion_factor', float(case['soil'])),
            ('slip', float(case['slip']) if case['drive'] == 'slip' else None),
            ('drive', case['drive']),
            ('dem_threads', a.dem_threads),
            ('friction', a.mu), ('load_mass', a.load), ('speed', a.speed), ('seed', a.seed)]


def roslaunch_command(a, case, port):
    """The roslaunch command of a case (single_wheel.launch, a bag per run)."""
    return scene_command('roslaunch', 'single_wheel.launch', case_params(a, case), scene=a.scene, port=port,
                         bag=bag_path(a.out, case.name), launch_args=[('cloud_rate', float(a.cloud_rate))])


def core_command(a, case, result_file):
    """dm_run_scene's command of a case (--runner core, a developer's check)."""
    return scene_command('core', 'single_wheel.launch', case_params(a, case), scene=a.scene, result=result_file,
                         dm_run_scene=a.dm_run_scene)


def command(a, case, run):
    """A case's command for the sweep's runner."""
    if a.runner == 'core':
        return core_command(a, case, run.result_file)
    return roslaunch_command(a, case, run.port)


def check(case, result):
    """A run is good if it measured in its window (or its wheel sank: status sunk)."""
    if result.get('kind', 'single_wheel') != 'single_wheel':
        return 'the result is of kind %r, not single_wheel' % result.get('kind')
    if result.get('status') == 'sunk':
        return None
    return None if result.get('window_samples') else 'no sample in the window'


def _same(x, y):
    try:
        return abs(float(x) - float(y)) < 1e-9
    except (TypeError, ValueError):
        return False


def same_run(a):
    """accept(case, old result) for resume: the same level, soil, drive, slip, and mu, load and
    speed where given."""
    def accept(case, old):
        names.refuse_old_keys(old, os.path.join(a.out, 'runs', case_name(case) + '.result.yaml'))
        if old.get('fidelity') != a.fidelity or old.get('drive') != case['drive']:
            return False
        if case['drive'] == 'slip' and not _same(old.get('slip_commanded'), case['slip']):
            return False
        if case['soil_key'] == names.CONE_INDEX:
            if not _same(old.get('requested_cone_index_psi'), case['soil']):
                return False
        elif 'requested_cone_index_psi' in old or not _same(old.get('cohesion_factor'), case['soil']):
            return False
        for key, v in (('friction', a.mu), ('load_mass', a.load), ('carriage_speed', a.speed)):
            if v is not None and not _same(old.get(key), v):
                return False
        return True
    return accept


def number(x):
    """x as a float, or None if it is none (a string such as 'unknown: ...', NaN, None)."""
    if isinstance(x, bool):
        return None
    try:
        v = float(x)
    except (TypeError, ValueError):
        return None
    return v if math.isfinite(v) else None


def measured(result, key):
    """A window figure of a result, or None if the run measured nothing in its window (a wheel that
    sank before it: its figures are zeros, not measurements) or the value is not a number."""
    if not isinstance(result, dict) or not result.get('window_samples'):
        return None
    return number(result.get(key))


def describe(o):
    if not o.ok:
        return 'FAILED: %s' % o.error
    r = o.result
    fig = 'DP/W %s  T/(Wr) %s  z %s m' % tuple(
        '%.3f' % measured(r, k) if measured(r, k) is not None else '-'
        for k in ('dp_over_w', 'torque_over_wr', 'sinkage'))
    if r.get('status') != 'sunk':
        return fig
    return 'SUNK: %s%s' % (r.get('error') or 'the wheel sank', '; ' + fig if r.get('window_samples') else '')


# -- the summary

def _r(x, n=5):
    v = number(x)
    return None if v is None else round(v, n)


def _m(result, key, n=5):
    v = measured(result, key)
    return None if v is None else round(v, n)


def run_row(o, out, runner):
    """A case's entry in summary.yaml: status, key figures, wall time, files."""
    r = o.result if isinstance(o.result, dict) else {}
    status = r.get('status', 'ok') if o.ok else 'failed'
    row = {'name': o.name, 'soil': soil_label(o.case['soil_key'], o.case['soil']), 'drive': o.case['drive'],
           'slip_commanded': o.case['slip'], 'status': status, 'ok': o.ok, 'kept': o.kept, 'error': o.error,
           'wall_time': round(o.wall_time, 1)}
    for k in ('slip', 'dp_over_w', 'dp_over_w_std', 'torque_over_wr', 'torque_over_wr_std', 'sinkage',
              'sinkage_std', 'drawbar_pull', 'drawbar_pull_std', 'torque', 'torque_std'):
        row[k] = _m(r, k)
    row['window_samples'] = r.get('window_samples')
    row['cone_index_psi'] = r.get('cone_index_psi')
    row['cohesion_factor'] = _r(r.get('cohesion_factor'))
    if o.ok and status == 'sunk':
        row['sunk'] = r.get('error')
    row['result'] = o.result_file
    row['log'] = o.log
    if runner == 'roslaunch':
        row['bag'] = bag_path(out, o.name)
    return row


def point_slip(o):
    """The slip a point is plotted and compared at: measured, else commanded."""
    v = measured(o.result, 'slip')
    return v if v is not None else o.case['slip']


def reference_ci(soil_key, value, results):
    """The cone index [psi] the references use for a soil, or (None, why not)."""
    for r in results:
        ci = number(r.get('cone_index_psi'))
        if ci is not None:
            return ci, None
    if soil_key == names.CONE_INDEX:
        return value, None
    return None, 'no cone index for f = %g: %s' % (value, next(
        (str(r.get('cone_index_psi')) for r in results if r.get('cone_index_psi') is not None), 'no result'))


def soil_summary(soil_key, value, outcomes, nominal_dh=wn.NOMINAL_PNEUMATIC_DH, offset=0.005):
    """A soil's DP/W, T/(W r) and sinkage against slip (finished runs, sunk ones included and marked),
    the references at the same slips and the differences sim - VTI (VTI rigid, delta/h 0)."""
    done = [o for o in outcomes if o.ok and isinstance(o.result, dict)]
    driven = sorted((o for o in done if o.case['drive'] == 'slip'), key=point_slip)
    towed = [o for o in done if o.case['drive'] == 'towed']
    s = {'soil': soil_label(soil_key, value)}
    if soil_key == names.CONE_INDEX:
        s['requested_cone_index_psi'] = value
    results = [o.result for o in done]
    ci, why = reference_ci(soil_key, value, results)
    s['cone_index_psi'] = ci
    s['cohesion_factor'] = (_r(results[0].get('cohesion_factor')) if results else
                            value if soil_key == names.COHESION_FACTOR else None)
    geometry = next(((number(r.get('tire_radius')), number(r.get('tire_width')), number(r.get('load')))
                     for r in results), (None, None, None))
    s['tire_radius'], s['tire_width'], s['load'] = (_r(v, 6) for v in geometry)
    s['failed'] = [o.name for o in outcomes if not o.ok]
    pts = {'name': [o.name for o in driven], 'status': [o.result.get('status', 'ok') for o in driven],
           'slip': [_r(point_slip(o)) for o in driven]}
    for k in ('dp_over_w', 'dp_over_w_std', 'torque_over_wr', 'torque_over_wr_std', 'sinkage', 'sinkage_std'):
        pts[k] = [_m(o.result, k) for o in driven]
    s['points'] = pts
    if ci is None or None in geometry:
        s['reference'] = None
        s['no_reference'] = why or 'no finished run gives the tire and the load'
        s['towed'] = [_towed_row(o, None) for o in towed]
        return s
    radius, b, w = geometry
    d = 2.0 * radius
    rigid = wn.vti(ci, b, d, w, 0.0, offset)
    s['numerics'] = {
        'cone_numeric': _r(wn.cone_numeric(ci, b, d, w)),
        'vti_rigid': {k: _r(v) for k, v in rigid.items()},
        'vti_pneumatic': dict({k: _r(v) for k, v in wn.vti(ci, b, d, w, nominal_dh, offset).items()},
                              delta_over_h=nominal_dh),
        'wes_nc_pneumatic': {'delta_over_h': nominal_dh, 'nc': _r(wn.wes_nc(ci, b, d, w, nominal_dh))},
        'wes_nc_rigid': 0.0,
        'brixius_bn_rigid': _r(wn.brixius_bn(ci, b, d, w, 0.0)),
    }
    slips = [point_slip(o) for o in driven]
    band = wn.reference_band(slips, ci, b, d, w, wn.band_members(nominal_dh), offset)
    vti_dp = [wn.vti_dp_over_w(x, rigid['nc'], b, d, rigid['ssp']) for x in slips]
    vti_gt = [wn.vti_gt_over_w(x, rigid['nc'], b, d, rigid['ssp']) for x in slips]
    ref = {'vti_dp_over_w': [_r(v) for v in vti_dp], 'vti_gt_over_w': [_r(v) for v in vti_gt],
           'band_dp_over_w': [[_r(lo), _r(hi)] for lo, hi in zip(band['dp_lo'], band['dp_hi'])],
           'band_gt_over_w': [[_r(lo), _r(hi)] for lo, hi in zip(band['gt_lo'], band['gt_hi'])],
           'vti_sinkage_powered': _r(rigid['z_over_d_powered'] * d),
           'vti_sinkage_towed': _r(rigid['z_over_d_towed'] * d)}
    s['reference'] = ref

    def diff(sim, refs):
        return [_r(number(x) - y) if number(x) is not None and y == y else None for x, y in zip(sim, refs)]
    s['dp_over_w_minus_vti'] = diff(pts['dp_over_w'], vti_dp)
    s['torque_over_wr_minus_vti_gt'] = diff(pts['torque_over_wr'], vti_gt)
    s['dp_over_w_in_band'] = [None if number(x) is None or lo != lo else bool(lo <= x <= hi)
                              for x, lo, hi in zip(pts['dp_over_w'], band['dp_lo'], band['dp_hi'])]
    s['towed'] = [_towed_row(o, (rigid, band)) for o in towed]
    return s


def _towed_row(o, refs):
    r = o.result
    row = {'name': o.name, 'status': r.get('status', 'ok'), 'slip': _m(r, 'slip')}
    for k in ('dp_over_w', 'dp_over_w_std', 'torque_over_wr', 'torque_over_wr_std', 'sinkage', 'sinkage_std'):
        row[k] = _m(r, k)
    if refs is not None:
        rigid, band = refs
        row['vti_dp_over_w'] = _r(-rigid['mr_towed'])
        row['band_dp_over_w'] = [_r(band['towed_lo']), _r(band['towed_hi'])]
        dp = measured(r, 'dp_over_w')
        row['dp_over_w_minus_vti'] = None if dp is None else _r(dp + rigid['mr_towed'])
    return row


def soils_of(a):
    return (names.CONE_INDEX, a.ci) if a.ci else (names.COHESION_FACTOR, a.f)


def summarise(outcomes, soil_key, soils, opts):
    """The summary document: header, reference definitions, per soil curves, per run rows, the
    failed cases. opts: fidelity, runner, scene, jobs, wall_time, out, nominal_dh, ssp_offset."""
    rows = [run_row(o, opts['out'], opts['runner']) for o in outcomes]
    failed = [o for o in outcomes if not o.ok]
    doc = {'sweep': 'single_wheel', 'runner': opts['runner'], 'fidelity': opts['fidelity'],
           'particle_diameter': next((_r(o.result.get('particle_diameter')) for o in outcomes
                                      if o.ok and isinstance(o.result, dict)), None),
           'scene': opts['scene'], 'jobs': opts['jobs'], 'wall_time': opts['wall_time'], 'cases': len(outcomes),
           'failed': len(failed), 'sunk': sum(1 for r in rows if r['status'] == 'sunk')}
    if opts['runner'] == 'core':
        doc['runner_note'] = 'dm_run_scene (a developer check), not the launch files users run'
    doc['reference'] = {
        'what': 'empirical fits for pneumatic tires on fine-grained soil (nrmm-baseline.md 4): a reference, '
                'not truth; the differences are reported, nothing is tuned to them',
        'vti_curve': 'VTI (Dettwiller et al. 2018, eqs 1-6) at delta/h 0 (the rigid tire), S_sp offset %g'
                     % opts['ssp_offset'],
        'band': band_text(opts['nominal_dh']) + ' (at each slip, members without a value there left out: VTI at s <= 0); '
                'DP/W band for DP/W, GT/W band for T/(W r); a towed run: minus the towed resistances '
                '(VTI eq. 7, Brixius MR/W at s = 0, Wismer-Luth TF/W)',
        'torque': GT_TEXT,
        'wes': WES_TEXT,
        'cone_index_psi': 'CI = RCI (the DEM soil does not remold, RI = 1); b, d, W from the results '
                      '(tire_width, 2 tire_radius, load)',
        'slip': 'the measured slip of each run (the commanded one where none was measured)',
        'difference': 'sim - VTI (rigid): dp_over_w_minus_vti, torque_over_wr_minus_vti_gt',
        'ssp_offset': opts['ssp_offset'],
        'nominal_delta_over_h': opts['nominal_dh'],
    }
    doc['soils'] = [soil_summary(soil_key, v, [o for o in outcomes if o.case['soil'] == v],
                                 opts['nominal_dh'], opts['ssp_offset']) for v in soils]
    doc['runs'] = rows
    doc['failed_cases'] = [{'name': o.name, 'error': o.error or 'not run', 'log': o.log} for o in failed]
    return doc


def write_summary(path, doc):
    with open(path, 'w') as fh:
        fh.write('# Single-wheel slip sweep: written by dm-wheel-sweep. DP/W and T/(W r) against\n'
                 '# slip per soil beside the empirical references (see `reference`); docs/single-wheel.md.\n')
        yaml.safe_dump(doc, fh, sort_keys=False, default_flow_style=None, width=120)
    return path


# -- main

def parser():
    """dm-wheel-sweep's command line."""
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0],
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument('--scene', default=os.path.join(ROOT, 'config', 'scenes', 'single_wheel.yaml'))
    ap.add_argument('--fidelity', default='coarse', help='level of the scene file (default coarse)')
    ap.add_argument('--slip', type=floats, default=floats('0.05,0.1,0.2,0.3,0.5'), help='commanded slips')
    soil = ap.add_mutually_exclusive_group()
    soil.add_argument('--ci', type=floats, help='cone indices [psi] (through the calibration table; default 100)')
    soil.add_argument('--f', type=floats, help='cohesion factors f (dimensionless) instead of cone indices')
    ap.add_argument('--towed', action='store_true', help='also a towed run per soil')
    ap.add_argument('--mu', type=float, help="inter-particle friction (default: the scene's)")
    ap.add_argument('--load', type=float, help="wheel load [kg] (default: the scene's)")
    ap.add_argument('--speed', type=float, help="carriage speed [m/s] (default: the scene's)")
    ap.add_argument('--seed', type=int, help="seed of the poured lattice (default: the scene's)")
    ap.add_argument('--jobs', type=int, default=2, help='runs at a time (default 2: one per core)')
    ap.add_argument('--dem-threads', type=int, default=1, help='OpenMP threads per run (default 1)')
    ap.add_argument('--cloud-rate', type=float, default=5.0, help='particle clouds per simulated second in each bag')
    ap.add_argument('--timeout', type=float, default=7200.0, help='longest a run may take [s]')
    ap.add_argument('--port', type=int, default=11411, help='first ROS master port (one per parallel run)')
    ap.add_argument('--resume', action='store_true',
                    help='keep the runs already in OUT that finished with the same level, soil, drive and slip')
    ap.add_argument('--ssp-offset', type=float, default=0.005,
                    help="VTI's S_sp offset (MAVS code and the baseline's table: 0.005; Dettwiller eq. 3: 0)")
    ap.add_argument('--nominal-deflection', type=float, default=wn.NOMINAL_PNEUMATIC_DH,
                    help='delta/h of the WES numeric reported for a pneumatic tire (default 0.15)')
    ap.add_argument('--runner', choices=('roslaunch', 'core'), default='roslaunch',
                    help='roslaunch single_wheel.launch (default), or core: dm_run_scene, a developer check only')
    ap.add_argument('--dm-run-scene', default=None,
                    help='--runner core: ' + paths.RUNNER_HELP)
    ap.add_argument('--progress', choices=('auto', 'tqdm', 'plain'), default='auto')
    ap.add_argument('--out', default='results/single_wheel')
    ap.add_argument('--keep', metavar='DIR',
                    help="also write each finished run's result (ok or sunk), its histories decimated, into DIR "
                         "(e.g. docs/data/single-wheel-runs/coarse_s1), where --resume takes it as done: a sweep "
                         "that outlives its machine goes on from a fresh clone")
    ap.add_argument('--commit', action='store_true', help='commit each file --keep writes, on its own, as its run ends')
    return ap


def main(argv=None):
    ap = parser()
    a = ap.parse_args(argv)
    for opt, v in (('--ci', a.ci), ('--f', a.f)):
        if v is not None and not v:
            sys.exit('%s: %s: no value given (leave the option out for the default, CI 100)' % (PROG, opt))
    if not a.ci and not a.f:
        a.ci = [100.0]
    if a.jobs < 1 or a.dem_threads < 1:
        sys.exit('%s: --jobs and --dem-threads must be >= 1' % PROG)
    if not a.slip and not a.towed:
        sys.exit('%s: no case: give --slip values or --towed' % PROG)
    bad = [s for s in a.slip if not -1.0 <= s < 1.0]
    if bad:
        sys.exit('%s: slip %g lies outside [-1, 1)' % (PROG, bad[0]))
    if not os.path.isfile(a.scene):
        sys.exit('%s: no scene file %s' % (PROG, a.scene))
    if a.commit and not a.keep:
        sys.exit('%s: --commit commits what --keep DIR writes: name the folder' % PROG)
    if a.runner == 'roslaunch':
        package, why = ros_package()
        if why:
            sys.exit('%s: %s: source the catkin workspace (devel/setup.bash) that built it first' % (PROG, why))
        launch = os.path.join(package, 'launch', 'single_wheel.launch')
        if not os.path.isfile(launch):
            sys.exit('%s: no %s in this checkout' % (PROG, launch))
    else:
        a.dm_run_scene = paths.dm_run_scene(a.dm_run_scene)
        if not os.access(a.dm_run_scene, os.X_OK):
            sys.exit('%s: --runner core: %s' % (PROG, paths.missing_runner_message(a.dm_run_scene)))
    soil_key, soils = soils_of(a)
    try:
        cases = make_cases(soil_key, soils, a.slip, a.towed)
    except ValueError as e:
        sys.exit('%s: %s' % (PROG, e))
    runs_dir = os.path.join(a.out, 'runs')
    os.makedirs(runs_dir, exist_ok=True)

    # a finished run's compact result into --keep (committed with --commit, in the checkout that
    # holds DIR: a sweep run from a pinned build keeps into the working checkout) as it ends
    keep = dm_keep.keeper(a.keep, a.commit, None,
                          lambda o: 'single wheel: run %s at %s (%s)' % (o.name, a.fidelity, describe(o)),
                          {'kept_from_commit': git_commit(ROOT)}, lambda text: sweep.line(text))
    # the progress lines of a running run: the rig nodelet's 'progress: ...', dm_run_scene's '... s wall  ...'
    sweep = dm_sweep.Sweep(cases, lambda case, run: command(a, case, run), runs_dir, jobs=a.jobs, port=a.port, timeout=a.timeout, check=check,
                           outputs=lambda case: [bag_path(a.out, case.name)], describe=describe,
                           progress=a.progress, accept_status=('sunk',), poll=1.0, status_every=20.0,
                           progress_marker='progress:' if a.runner == 'roslaunch' else ' s wall ', on_done=keep)
    if a.runner == 'core':
        print('runner: core (%s): a developer check, NOT the launch files users run; no bags' % a.dm_run_scene,
              flush=True)
    # what the runs depend on and their results do not all hold (the seed, and the scene's values
    # of mu, load and speed where not given): a resume with other options is refused
    # (in --keep, which a resume from another checkout reads, the scene by its hash only)
    options = {'scene_sha256': sha256(a.scene), '--fidelity': a.fidelity, '--seed': a.seed, '--mu': a.mu,
               '--load': a.load, '--speed': a.speed, '--runner': a.runner}
    try:
        keep_options(a.out, dict(options, **{'--scene': os.path.abspath(a.scene)}), a.resume)
        if a.keep:
            keep_options(a.keep, options, a.resume)
    except ValueError as e:
        sys.exit('%s: %s' % (PROG, e))
    if a.resume:
        if a.keep:
            dm_keep.restore_kept(a.keep, runs_dir, [c.name for c in cases], sweep.outcome_file)
        try:
            sweep.resume(accept=same_run(a))
        except names.OldNameError as e:
            sys.exit('%s: --resume: %s' % (PROG, e))
    t0 = time.time()
    todo = sum(1 for o in sweep.outcomes if not o.done)
    print('sweep: %d runs (%s %s x slip %s%s), level %s, %d to run, %d at a time' % (
        len(cases), LABEL_PREFIX[soil_key], ','.join('%g' % v for v in soils), ','.join('%g' % s for s in a.slip),
        ' + towed' if a.towed else '', a.fidelity, todo, a.jobs), flush=True)
    interrupted = False
    try:
        sweep.run(t0)
    except KeyboardInterrupt:
        interrupted = True
    opts = {'fidelity': a.fidelity, 'runner': a.runner, 'scene': os.path.abspath(a.scene), 'jobs': a.jobs,
            'wall_time': round(time.time() - t0, 1), 'out': a.out, 'nominal_dh': a.nominal_deflection,
            'ssp_offset': a.ssp_offset}
    doc = summarise(sweep.outcomes, soil_key, soils, opts)
    path = write_summary(os.path.join(a.out, 'summary.yaml'), doc)
    print('summary: %s' % path)
    if interrupted:
        sys.exit('%s: interrupted; finished runs are in %s (--resume keeps them)' % (PROG, a.out))
    for s in doc['soils']:
        print_soil(s)
    try:
        for p in plots(doc, sweep.outcomes, a.out):
            print('plot: %s' % p)
    except ImportError as e:
        print('%s: no plots (%s): install python3-matplotlib and python3-numpy' % (PROG, e))
    print(sweep.report())
    sys.exit(sweep.exit_status())


def print_soil(s):
    head = '%s: CI %s psi' % (s['soil'], '%.1f' % s['cone_index_psi'] if s['cone_index_psi'] is not None else '?')
    if s.get('reference') is None:
        print('%s; no reference: %s' % (head, s.get('no_reference')))
    else:
        n = s['numerics']
        print('%s; VTI (rigid) N_c %.2f, S_sp %.3f; WES N_c %.2f at delta/h %g (0 rigid)' % (
            head, n['vti_rigid']['nc'], n['vti_rigid']['ssp'], n['wes_nc_pneumatic']['nc'],
            n['wes_nc_pneumatic']['delta_over_h']))
    print('   slip    DP/W (std)        VTI    band          T/(Wr) (std)      GT/W VTI  z [m]    status')
    p = s['points']
    ref = s.get('reference') or {}

    def f(v, fmt='%6.3f'):
        return fmt % v if v is not None else '%6s' % '-'
    for i, x in enumerate(p['slip']):
        band = ref.get('band_dp_over_w', [[None, None]] * len(p['slip']))[i]
        print('   %5.3f  %s (%s)  %s  [%s,%s]  %s (%s)  %s    %s  %s' % (
            x, f(p['dp_over_w'][i]), f(p['dp_over_w_std'][i], '%5.3f'),
            f(ref.get('vti_dp_over_w', [None] * len(p['slip']))[i]), f(band[0], '%5.2f'), f(band[1], '%5.2f'),
            f(p['torque_over_wr'][i]), f(p['torque_over_wr_std'][i], '%5.3f'),
            f(ref.get('vti_gt_over_w', [None] * len(p['slip']))[i]), f(p['sinkage'][i], '%6.3f'), p['status'][i]))
    for t in s['towed']:
        band = t.get('band_dp_over_w') or [None, None]
        print('   towed (slip %s): DP/W %s (%s), VTI %s, band [%s,%s], %s' % (
            f(t['slip']), f(t['dp_over_w']), f(t['dp_over_w_std'], '%5.3f'), f(t.get('vti_dp_over_w')),
            f(band[0], '%5.2f'), f(band[1], '%5.2f'), t['status']))


if __name__ == '__main__':
    sys.exit(main())
