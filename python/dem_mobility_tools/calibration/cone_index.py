"""dm-calibrate: the cone index calibration sweep (paper section 3, figs. 13-14, table 3): runs the cone penetrometer
scene through roslaunch (the launch file and nodelets a user runs) for every cohesion factor f,
inter-particle friction mu and seed, several runs at a time in parallel processes (each with its
own ROS master), and writes into OUT:

  runs/mu<mu>_f<f>_s<seed>.bag (+ .result.yaml, .log)  every run: its bag, result and console output
  ci_vs_time_mu<mu>.png                 CI versus time per run (fig. 13)
  ci_vs_f.png                           CI versus f for every mu (fig. 14): runs, means, the fit
  cone_index_mu<mu>_d<d>.yaml           the table CI -> f (table 3) for the level's particle
                                        diameter d: a monotone cubic through the mean CI per f
                                        (and the paper's least-squares cubic beside it), the
                                        mean and scatter over the seeds per f, every run, the
                                        provenance (commit, seeds, soil file sha256, scene, date,
                                        conditions) and the level's error against the finest level
                                        (--finest); the file soil scenes read (`cone_index:`)
  sweep.yaml                            every run's outcome, failures included

    dm-calibrate --fidelity coarse --seeds 1,2,3 --jobs 1 \
        --out results/calibration --install config/calibration

A failed run is reported and the others are kept; the exit status is 1 if any run failed.
"""
import argparse
import math
import os
import shutil
import sys
import time

import yaml

from .. import sweep as dm_sweep
from ..sweep import keep as dm_keep
from ..sweep.checkpoints import checkpoint_path, keep_bag_part, refused_checkpoint
from .figures import plots
from ..paths import CONFIG, ROOT
from ..runs import scene_command
from ..sweep.args import floats, git_commit, ints, keep_options, ros_package, sha256

PAPER_TABLE = [(30, 0.06), (40, 0.15), (50, 0.5), (60, 0.84), (70, 1.18), (80, 1.52), (100, 2.24),
               (120, 3.03), (150, 4.46), (200, 7.85), (242, 12.1)]
PAPER_CUBIC = [9.148e-7, -1.783e-4, 4.555e-2, -1.445]


def seeds_at(text):
    """'12=1,3,4' -> (12.0, [1, 3, 4])."""
    try:
        f, seeds = text.split('=', 1)
        return float(f), ints(seeds)
    except ValueError:
        raise argparse.ArgumentTypeError('expected F=SEED,SEED,..., got %r' % text)


def time_step_at(text):
    """'30=6e-5' -> (30.0, 6e-05)."""
    try:
        f, dt = text.split('=', 1)
        f, dt = float(f), float(dt)
    except ValueError:
        raise argparse.ArgumentTypeError('expected F=TIME_STEP, got %r' % text)
    if not 0.0 < dt <= 1e-3:
        raise argparse.ArgumentTypeError('%r: the time step must lie in (0, 1e-3] s' % text)
    return f, dt


# the keys a sweep sets per case (or for all of them): --set may not set them
SWEEP_KEYS = ('fidelity', 'cohesion_factor', 'friction', 'seed', 'threads', 'time_step', 'cone_index', 'f', 'mu')


def scene_setting(text):
    """--set KEY=VALUE: a dotted key of the scene file and a YAML value ('levels.coarse_cal.container_diameter=2.0')."""
    key, eq, value = text.partition('=')
    if not eq or not key or not value or any(not part for part in key.split('.')):
        raise argparse.ArgumentTypeError('%r: KEY=VALUE, a dotted key of the scene file' % text)
    if key.split('.')[0] in SWEEP_KEYS:
        raise argparse.ArgumentTypeError('%r: %s is set by the sweep itself (its own options)' % (text, key.split('.')[0]))
    try:
        parsed = yaml.safe_load(value)
    except yaml.YAMLError as e:
        raise argparse.ArgumentTypeError('%r: the value is no YAML: %s' % (text, e))
    return key, parsed, value


def settings_yaml(settings):
    """The --set keys as one YAML map in flow style, the launch files' `overrides:=` ('' none)."""
    tree = {}
    for key, value, _ in settings:
        node = tree
        parts = key.split('.')
        for part in parts[:-1]:
            node = node.setdefault(part, {})
            if not isinstance(node, dict):
                raise ValueError('--set %s: %s is set to a value and is a map too' % (key, part))
        node[parts[-1]] = value
    return yaml.safe_dump(tree, default_flow_style=True, width=1 << 20).strip() if tree else ''


def case_name(mu, f, seed):
    return 'mu%g_f%g_s%d' % (mu, f, seed)


def bag_path(out, name):
    return os.path.join(out, 'runs', name + '.bag')


class Run:
    """A run's outcome (dm_sweep.Outcome) as the fit, the tables and the plots see it."""

    def __init__(self, outcome, out):
        self.outcome = outcome
        self.mu, self.f, self.seed = outcome.case['mu'], outcome.case['f'], outcome.case['seed']
        self.name = outcome.name
        self.bag = bag_path(out, self.name)
        self.result_file, self.log = outcome.result_file, outcome.log
        self.result, self.error = outcome.result, outcome.error
        self.start, self.end = outcome.start, outcome.end

    def ok(self):
        return self.error is None

    def ci(self):
        return float(self.result['cone_index_psi'])


def write_summary(a, runs, t0, interrupted=False):
    """OUT/sweep.yaml: every run's outcome (a run the sweep did not finish: ok false, `not run`)."""
    doc = {'fidelity': a.fidelity, 'wall_time': round(time.time() - t0, 1), 'jobs': a.jobs, 'seeds': a.seeds}
    if interrupted:
        doc['interrupted'] = True
    doc['runs'] = []
    for r in runs:
        done = r.outcome.done
        ok = done and r.ok()
        doc['runs'].append({'f': r.f, 'mu': r.mu, 'seed': r.seed, 'ok': ok,
                            'cone_index_psi': r.ci() if ok else None,
                            'wall_time': round((r.end or 0) - (r.start or 0), 1),
                            'error': r.error if done else 'not run (the sweep was interrupted)', 'bag': r.bag})
    with open(os.path.join(a.out, 'sweep.yaml'), 'w') as fh:
        yaml.safe_dump(doc, fh, sort_keys=False)


def mean_points(runs):
    """Per f: (f, mean CI, sample standard deviation over the seeds (None for one seed), seeds)."""
    by_f = {}
    for f, ci in runs:
        by_f.setdefault(f, []).append(ci)
    out = []
    for f in sorted(by_f):
        v = by_f[f]
        m = sum(v) / len(v)
        sd = math.sqrt(sum((x - m) ** 2 for x in v) / (len(v) - 1)) if len(v) > 1 else None
        out.append((f, m, sd, len(v)))
    return out



def scene_level(scene, fidelity):
    """The soil file and the level's conditions from the scene file."""
    with open(scene) as fh:
        doc = yaml.safe_load(fh)
    try:
        level = doc['levels'][fidelity]
    except (KeyError, TypeError):
        raise ValueError('%s: no level %r under levels:' % (scene, fidelity))
    soil = os.path.normpath(os.path.join(os.path.dirname(os.path.abspath(scene)), doc['soil']))
    keys = ['container_diameter', 'soil_depth', 'cone_speed', 'approach_speed', 'approach_depth', 'time_step',
            'ci_window', 'settle_time', 'hold_time']
    return soil, float(level['particle_diameter']), {k: level[k] for k in keys if k in level}


def load_finest(path):
    """The finest level's runs for --finest (a YAML file: level, friction, particle_diameter,
    points {f, ci}, source), read and checked before any run; ValueError naming what is wrong."""
    with open(path) as fh:
        ref = yaml.safe_load(fh)
    try:
        ref['friction'] = float(ref['friction'])
        fs, cis = [float(v) for v in ref['points']['f']], [float(v) for v in ref['points']['ci']]
        str(ref['level'])
        if ref.get('particle_diameter') is not None:
            ref['particle_diameter'] = float(ref['particle_diameter'])
            if not ref['particle_diameter'] > 0:
                raise ValueError('particle_diameter %g is not a size' % ref['particle_diameter'])
    except (TypeError, KeyError, ValueError) as e:
        raise ValueError('%s: not a finest-level file (level, friction, points.f, points.ci): %s' % (path, e))
    if len(fs) != len(cis) or not fs:
        raise ValueError('%s: points.f and points.ci must be lists of the same, non-zero length' % path)
    ref['points'] = {'f': fs, 'ci': cis}
    return ref


def error_vs_finest(finest, ref, table, fidelity, mu, diameter=None):
    """The table's relative CI error against the finest level's runs (ref: load_finest(finest)), at
    the f values inside the table; without one, one at another friction, or one whose particles are
    not smaller than this table's (`diameter`), a note that says so."""
    if not finest:
        return {'level': fidelity, 'note': 'only this level (%s) was run for this table: its error against a finer '
                                           'level is not known' % fidelity}
    if abs(ref['friction'] - mu) > 1e-9:
        return {'level': fidelity, 'note': 'the finest level\'s runs (%s) are at friction %g, not this table\'s %g: '
                                           'not compared' % (os.path.basename(finest), ref['friction'], mu)}
    d_ref = ref.get('particle_diameter')
    if diameter is not None and d_ref is not None and not d_ref < diameter - 1e-12:
        return {'level': fidelity, 'note': 'the finest level\'s runs (%s) are of particles %g m across, not finer than '
                                           'this table\'s %g m: not compared' % (os.path.basename(finest), d_ref,
                                                                                  diameter)}
    fs, cis = ref['points']['f'], ref['points']['ci']
    tf, tci = [r[1] for r in table], [r[0] for r in table]
    rel = []
    for f, ci in zip(fs, cis):
        if tf[0] <= f <= tf[-1]:
            rel.append((f, ci, float(interp(f, tf, tci)), ))
    if not rel:
        return {'level': ref['level'], 'note': 'the finest level\'s runs (%s) lie outside the table\'s f range' % finest}
    errs = [(t - c) / c for f, c, t in rel]
    note = ('mean over f of (table CI - %s CI) / %s CI; %s; from %s: %s' %
            (ref['level'], ref['level'], ', '.join('f %g: table %.1f psi vs %.1f psi (%+.0f %%)' % (f, t, c, 100 * (t - c) / c)
                                                   for f, c, t in rel),
             os.path.basename(finest), ref.get('source', '')))
    return {'level': ref['level'], 'relative': round(sum(errs) / len(errs), 4), 'note': note}


def interp(x, xs, ys):
    for k in range(1, len(xs)):
        if x <= xs[k]:
            s = (x - xs[k - 1]) / (xs[k] - xs[k - 1])
            return ys[k - 1] + s * (ys[k] - ys[k - 1])
    return ys[-1]


def fit(points, table_ci):
    """The table rows at the paper's cone indices inside the measured range (points: (f, mean CI)):
    a monotone cubic (PCHIP) through the means, f against CI; and the paper's form beside it, the
    least-squares cubic f(CI) (lower degree with fewer points) with its residual. Returns (cubic,
    table, band, method, cubic_residual); cubic_residual is the largest relative CI by which the
    cubic misses a mean."""
    import numpy as np
    from scipy.interpolate import PchipInterpolator
    ci = np.array([p[1] for p in points])
    f = np.array([p[0] for p in points])
    deg = min(3, len(points) - 1)
    coef = np.polyfit(ci, f, deg)
    cubic = [0.0] * (3 - deg) + [float(c) for c in coef]
    lo, hi = float(ci.min()), float(ci.max())
    rows = [c for c in table_ci if lo <= c <= hi]
    if not rows or rows[0] > lo:
        rows = [round(lo, 1)] + rows
    if rows[-1] < hi:
        rows.append(round(hi, 1))
    # the cubic's miss at the means, relative in CI: from each mean to the nearest CI at which the
    # cubic gives its f (the cubic need not be monotone; where it never gives f, to its closest)
    fine = np.linspace(lo, hi, 4001)
    fc = np.polyval(coef, fine)
    miss = []
    for fv, cv in zip(f, ci):
        d = fc - fv
        cross = np.nonzero(np.sign(d[:-1]) != np.sign(d[1:]))[0]
        at = fine[cross] if len(cross) else fine[[int(np.argmin(np.abs(d)))]]
        miss.append(float(np.min(np.abs(at - cv))) / cv)
    cubic_residual = float(max(miss)) if miss else None
    order = np.argsort(ci)
    cs, fs = ci[order], f[order]
    if np.all(np.diff(cs) > 0) and np.all(np.diff(fs) > 0):
        # A cubic through 20-270 psi misses five-seed means by several per cent (more than their
        # standard error) where the curve bends: the table follows the means instead, monotone
        # between them (PCHIP keeps the data's monotony, no overshoot)
        # (the end rows are the means rounded to 0.1 psi: clamped to the f range run)
        vals = [min(max(float(v), float(fs[0])), float(fs[-1])) for v in PchipInterpolator(cs, fs)(rows)]
        method = 'monotone cubic (PCHIP) through the mean CI per f, f against CI'
    else:
        # the means are not monotone in f (scatter larger than a step in f): interpolate linearly
        # in log f over the CI-sorted means made monotone
        lf = np.maximum.accumulate(np.log(fs))
        vals = [float(np.exp(np.interp(c, cs, lf))) for c in rows]
        keep = [0] + [k for k in range(1, len(vals)) if vals[k] > vals[k - 1]]
        rows, vals = [rows[k] for k in keep], [vals[k] for k in keep]
        method = 'piecewise-linear in log f over the means (the means are not monotone in f)'
    table = [[float(c), float(v)] for c, v in zip(rows, vals)]
    # scatter of the runs about the table, relative in CI
    res = []
    for fv, cv in points:
        if table[0][1] <= fv <= table[-1][1]:
            pred = float(np.interp(fv, [r[1] for r in table], [r[0] for r in table]))
            res.append((cv - pred) / cv)
    band = float(math.sqrt(sum(r * r for r in res) / len(res))) if res else 0.0
    return cubic, table, band, method, cubic_residual


def parser():
    """dm-calibrate's command line."""
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument('--scene', default=os.path.join(CONFIG, 'scenes', 'cone_penetrometer.yaml'))
    ap.add_argument('--fidelity', default='coarse', help='level of the scene file (default coarse)')
    ap.add_argument('--f', type=floats, default=floats('0.05,0.3,1.5,5,12'), help='cohesion factors')
    ap.add_argument('--mu', type=floats, default=floats('0.1,0.05'), help='inter-particle friction coefficients')
    ap.add_argument('--seeds', type=ints, default=ints('1'),
                    help='seeds of the poured lattice, each f and mu is run with every one (default 1; a table '
                         'point wants at least 3)')
    ap.add_argument('--seeds-at', type=seeds_at, action='append', default=[], metavar='F=SEEDS',
                    help='other seeds at one f (e.g. 12=1,3,4 when seed 2 fails there); may be repeated')
    ap.add_argument('--time-step-at', type=time_step_at, action='append', default=[], metavar='F=DT',
                    help="the DEM time step [s] at one f instead of the level's (a soil whose adhesion ramp the "
                         "level's step cannot follow: the step the guard names); may be repeated")
    ap.add_argument('--note', help="a note for the table's provenance (e.g. where runs kept by --resume were made)")
    ap.add_argument('--finest', help="YAML of the finest level's runs (level, friction, particle_diameter, "
                                     "points: {f: [...], ci: [...]}, source) to give the table its error against")
    ap.add_argument('--jobs', type=int, default=2, help='runs at a time (default 2: one per core)')
    ap.add_argument('--dem-threads', type=int, default=1, help='OpenMP threads per run (default 1)')
    ap.add_argument('--cloud-rate', type=float, default=5.0, help='particle clouds per simulated second in each bag')
    ap.add_argument('--timeout', type=float, default=3600.0, help='longest a run may take [s]')
    ap.add_argument('--port', type=int, default=11411, help='first ROS master port (one per parallel run)')
    ap.add_argument('--checkpoint-every', type=float, default=300.0,
                    help='wall seconds between a run\'s checkpoints in OUT/checkpoints (default 300); a run '
                         'stopped before its end (the sweep stopped, its machine gone) is taken up from its '
                         'checkpoint by --resume, by the same build')
    ap.add_argument('--table-ci', type=floats, default=floats(','.join(str(c) for c, _ in PAPER_TABLE)),
                    help="cone indices of the table's rows (the paper's by default)")
    ap.add_argument('--install', help='also copy the tables into this directory (e.g. config/calibration), or '
                                      'the mu = 0.1 table to this file')
    ap.add_argument('--set', type=scene_setting, action='append', default=[], metavar='KEY=VALUE',
                    help='any other key of the scene file for every run (dotted, a YAML value), e.g. '
                         'levels.coarse_cal.container_diameter=2.0 for a set-up study (with --no-table); may be '
                         'repeated; kept in the folder\'s options, so a --resume with others is refused')
    ap.add_argument('--no-table', action='store_true',
                    help='the runs alone, no table (e.g. one f at another time step, to compare with a table\'s '
                         'run); one f is then enough')
    ap.add_argument('--resume', action='store_true',
                    help='keep the runs already in OUT that succeeded with the same level, f, mu and seed (rerun the rest)')
    ap.add_argument('--out', default='results/calibration')
    ap.add_argument('--keep', metavar='DIR',
                    help='also write each good run\'s result, its history decimated, into DIR (e.g. '
                         'config/calibration/runs/coarse_cal), where --resume takes it as done: a sweep that '
                         'outlives its machine goes on from a fresh clone')
    ap.add_argument('--commit', action='store_true',
                    help='commit each file --keep writes, on its own, as its run ends')
    return ap


def check_args(a):
    """Exits naming the option if the command line asks for no table or a bad one; the finest
    level's runs (--finest), or None."""
    if a.jobs < 1 or a.dem_threads < 1:
        sys.exit('dm-calibrate: --jobs and --dem-threads must be >= 1')
    if not 1.0 <= a.checkpoint_every <= 1e7:
        sys.exit('dm-calibrate: --checkpoint-every %g: wall seconds between checkpoints are from 1 to 1e7'
                 % a.checkpoint_every)
    if not a.seeds or len(set(a.seeds)) != len(a.seeds) or min(a.seeds) < 0:
        sys.exit('dm-calibrate: --seeds must list distinct seeds >= 0')
    if not os.path.isfile(a.scene):
        sys.exit('dm-calibrate: no scene file %s' % a.scene)
    for option, given in (('--seeds-at', a.seeds_at), ('--time-step-at', a.time_step_at)):
        stray = [f for f, _ in given if f not in a.f]
        if stray:
            sys.exit('dm-calibrate: %s %g: not one of the --f values' % (option, stray[0]))
    if a.commit and not a.keep:
        sys.exit('dm-calibrate: --commit commits what --keep DIR writes: name the folder')
    if a.install and a.install.endswith(os.sep) and not os.path.isdir(a.install):
        sys.exit('dm-calibrate: --install %s: no such directory' % a.install)
    if (len(set(a.f)) < 2 and not a.no_table) or not a.mu:
        sys.exit('dm-calibrate: --f needs two cohesion factors at least (a table is a fit; --no-table for runs '
                 'alone) and --mu one friction at least')
    if a.no_table and (a.install or a.finest):
        sys.exit('dm-calibrate: --no-table makes no table to --install or to compare with --finest')
    finest_ref = None
    if a.finest:
        try:
            finest_ref = load_finest(a.finest)
        except OSError as e:
            sys.exit('dm-calibrate: --finest %s: %s' % (a.finest, e.strerror))
        except (ValueError, yaml.YAMLError) as e:
            sys.exit('dm-calibrate: --finest: %s' % e)
    return finest_ref


def make_sweep(a, conditions, scene_sha, soil_sha):
    """The sweep's cases and its Sweep (the runs kept by --resume taken in)."""
    os.makedirs(os.path.join(a.out, 'runs'), exist_ok=True)
    os.makedirs(os.path.join(a.out, 'checkpoints'), exist_ok=True)
    try:
        at = dict(a.seeds_at)
        cases = dm_sweep.cases([{'mu': mu, 'f': f, 'seed': sd} for mu in a.mu for f in a.f for sd in at.get(f, a.seeds)],
                               name=lambda p: case_name(p['mu'], p['f'], p['seed']))
    except ValueError as e:
        sys.exit('dm-calibrate: %s' % e)

    steps = dict(a.time_step_at)
    try:
        overrides = settings_yaml(a.set)
    except ValueError as e:
        sys.exit('dm-calibrate: %s' % e)
    if not a.resume:  # (a sweep started afresh takes up no run of an earlier one)
        for c in cases:
            if os.path.exists(checkpoint_path(a.out, c.name)):
                os.remove(checkpoint_path(a.out, c.name))

    def command(case, run):
        step = [('time_step', steps[case['f']])] if case['f'] in steps else []
        ck = checkpoint_path(a.out, case.name)
        restart = ck if os.path.isfile(ck) else ''
        if restart:
            keep_bag_part(a.out, case.name)
            sweep.line('           ...    %-14s taken up from its checkpoint %s' % (case.name, ck))
        return scene_command('roslaunch', 'cone_penetrometer.launch',
                             [('fidelity', a.fidelity), ('cohesion_factor', float(case['f'])),
                              ('friction', float(case['mu'])), ('seed', int(case['seed'])), ('dem_threads', a.dem_threads)]
                             + step,
                             scene=a.scene, port=run.port, bag=bag_path(a.out, case.name),
                             launch_args=[('cloud_rate', float(a.cloud_rate)), ('overrides', overrides), ('checkpoint', ck),
                                          ('checkpoint_every', float(a.checkpoint_every)), ('restart', restart)])

    def check(case, result):
        return None if result.get('window_samples') else 'no CI sample in the window'

    def describe(run):
        return 'CI %.1f psi' % float(run.result['cone_index_psi']) if run.ok else 'FAILED: ' + run.error

    def same_run(case, old):
        """A kept run was made with the same level, f, mu, seed and time step."""
        dt = steps.get(case['f'], conditions.get('time_step'))
        try:
            return (old.get('fidelity') == a.fidelity and abs(old.get('cohesion_factor', -1) - case['f']) < 1e-12
                    and abs(old.get('friction', -1) - case['mu']) < 1e-12 and old.get('seed') == case['seed']
                    and (dt is None or abs(old.get('time_step', -1) - dt) <= 1e-9 * dt))
        except TypeError:
            return False

    # the scene, its level and soil as the runs are made with them: a resume with others is refused
    # (and in --keep, which a resume from another checkout reads: the scene by its hash there)
    options = {'scene_sha256': scene_sha, 'soil_sha256': soil_sha, '--fidelity': a.fidelity, 'conditions': conditions,
               '--set': ['%s=%s' % (k, text) for k, _, text in a.set]}
    try:
        # (a folder from before --set was made without one)
        keep_options(a.out, dict(options, **{'--scene': os.path.abspath(a.scene)}), a.resume, {'--set': []})
        if a.keep:
            keep_options(a.keep, options, a.resume, {'--set': []})
    except ValueError as e:
        sys.exit('dm-calibrate: %s' % e)
    commit = git_commit(ROOT)

    # a good run's compact result into --keep (committed with --commit, in the checkout that holds
    # DIR: a sweep run from a pinned build keeps into the working checkout) as it ends
    keep = dm_keep.keeper(a.keep, a.commit, None,
                          lambda o: 'calibration: run %s at %s (%s)' % (o.name, a.fidelity, describe(o)),
                          {'kept_from_commit': commit}, lambda text: sweep.line(text))

    def done(o):
        keep(o)
        refused_checkpoint(o, checkpoint_path(a.out, o.name), sweep.line)

    # (a run taken up from its checkpoint keeps the bag of its part before: keep_bag_part)
    sweep = dm_sweep.Sweep(cases, command, os.path.join(a.out, 'runs'), jobs=a.jobs, port=a.port,
                           timeout=a.timeout, check=check,
                           outputs=lambda case: ([] if os.path.isfile(checkpoint_path(a.out, case.name))
                                                 else [bag_path(a.out, case.name)]),
                           describe=describe, poll=1.0, status_every=20.0, on_done=done)
    if a.resume:
        if a.keep:
            dm_keep.restore_kept(a.keep, sweep.runs_dir, [c.name for c in cases], sweep.outcome_file)
        sweep.resume(accept=same_run)
    return cases, sweep


def write_table(a, mu, runs, finest_ref, diameter, prov):
    """The table of friction `mu` from the finished runs: fitted, written into OUT (and installed
    with --install), printed; its fit (cubic, table, band, method), or None with fewer than two f
    values run well. prov: (commit, soil file, its sha256, the scene's sha256, the level's
    conditions, the checkout)."""
    commit, soil_file, soil_sha, scene_sha, conditions, root = prov
    done = sorted(((r.f, r.ci(), r.seed) for r in runs if r.mu == mu and r.ok()))
    points = mean_points([(f, ci) for f, ci, _ in done])
    if len(points) < 2:
        print('mu %g: successful runs at %d f value(s): no fit' % (mu, len(points)))
        return None
    made = fit([(f, m) for f, m, _, _ in points], a.table_ci)
    cubic, table, band, method, cubic_residual = made
    # the scatter of every run about the table (seeds included), relative in CI
    res = [(ci - interp(f, [t[1] for t in table], [t[0] for t in table])) / ci
           for f, ci, _ in done if table[0][1] <= f <= table[-1][1]]
    band = math.sqrt(sum(r * r for r in res) / len(res)) if res else 0.0
    pts = {'f': [f for f, _, _, _ in points], 'ci_mean': [round(m, 3) for _, m, _, _ in points]}
    if any(n > 1 for _, _, _, n in points):
        pts['ci_std'] = [round(sd, 3) if sd is not None else 0.0 for _, _, sd, _ in points]
    pts['seeds'] = [n for _, _, _, n in points]
    err = error_vs_finest(a.finest, finest_ref, table, a.fidelity, mu, diameter)
    doc = {
        'particle_diameter': diameter,
        'friction': mu,
        'fidelity': a.fidelity,
        'method': method + '; cubic: the paper\'s least-squares cubic f(CI) of the means, for comparison',
        'cubic': cubic,
        'band': round(band, 4),
        'table': [[round(c, 2), round(v, 4)] for c, v in table],
        'points': pts,
        'runs': {'f': [f for f, _, _ in done], 'seed': [sd for _, _, sd in done],
                 'ci': [round(ci, 3) for _, ci, _ in done]},
        'provenance': {
            'commit': commit,
            'seeds': sorted(set(sd for _, _, sd in done)),
            'soil_file': os.path.relpath(soil_file, root),
            'soil_sha256': soil_sha,
            'scene_file': os.path.relpath(os.path.abspath(a.scene), root),
            'scene_sha256': scene_sha,
            'date': time.strftime('%Y-%m-%d'),
            'conditions': dict(conditions, **({'time_step_at': {f: dt for f, dt in sorted(a.time_step_at)}}
                                              if a.time_step_at else {})),
        },
        'error_vs_finest': err,
    }
    if cubic_residual is not None:
        doc['cubic_residual'] = round(cubic_residual, 4)
    if a.note:
        doc['provenance']['note'] = a.note
    path = os.path.join(a.out, 'cone_index_mu%g_d%g.yaml' % (mu, diameter))
    with open(path, 'w') as fh:
        fh.write('# Cone index calibration: CI [psi] -> cohesion factor f at mu = %g for particles of %g m\n'
                 '# (level %s), written by dm-calibrate.\n'
                 '# table: [CI, f] rows, a monotone cubic through the mean CI per f; cubic: f = c0 CI^3 +\n'
                 '# c1 CI^2 + c2 CI + c3, the paper\'s least-squares fit of the means, for comparison, and\n'
                 '# cubic_residual its largest relative CI miss at a mean; band: relative rms CI scatter\n'
                 '# of every run about the table; points: per f, the\n'
                 '# mean CI over the seeds, its sample std and the number of seeds; runs: every run (f,\n'
                 '# seed, CI); provenance: where it came from; error_vs_finest: the level\'s CI error against\n'
                 '# the finest level run.\n' % (mu, diameter, a.fidelity))
        yaml.safe_dump(doc, fh, default_flow_style=None, sort_keys=False, width=110)
    print('mu %g: %s; band %.1f %%; table -> %s' % (mu, method, 100 * band, path))
    print('   f        CI mean [psi]  std over seeds  seeds')
    for f, m, sd, n in points:
        print('   %-8g %8.1f      %s      %d' % (f, m, '%8.2f' % sd if sd is not None else '       -', n))
    print('   CI [psi]   f (ours)   f (paper, mu 0.1)')
    paper = dict(PAPER_TABLE)
    for c, v in table:
        print('   %7.1f   %8.3f   %s' % (c, v, '%.2f' % paper[c] if c in paper else '-'))
    if a.install:
        if os.path.isdir(a.install):
            dest = os.path.join(a.install, os.path.basename(path))
        elif abs(mu - 0.1) < 1e-12:
            dest = a.install
            os.makedirs(os.path.dirname(os.path.abspath(dest)), exist_ok=True)
        else:
            return made
        shutil.copyfile(path, dest)
        print('   installed as %s' % dest)
    return made


def main(argv=None):
    a = parser().parse_args(argv)
    finest_ref = check_args(a)
    # the commit and the files' hashes as the runs start (a checkout changed during the sweep
    # does not change what ran)
    root = ROOT
    commit = git_commit(root)
    try:
        soil_file, diameter, conditions = scene_level(a.scene, a.fidelity)
        soil_sha, scene_sha = sha256(soil_file), sha256(a.scene)
    except (OSError, ValueError, KeyError, TypeError, yaml.YAMLError) as e:
        sys.exit('dm-calibrate: %s' % e)
    _, why = ros_package()
    if why:
        sys.exit('dm-calibrate: %s: source the catkin workspace (devel/setup.bash) that built it first' % why)
    cases, sweep = make_sweep(a, conditions, scene_sha, soil_sha)
    t0 = time.time()
    print('sweep: %d runs (f %s x mu %s x seeds %s), level %s, %d at a time' %
          (len(cases), ','.join('%g' % f for f in a.f), ','.join('%g' % m for m in a.mu),
           ','.join('%d' % s for s in a.seeds), a.fidelity, a.jobs), flush=True)
    try:
        sweep.run(t0)
    except KeyboardInterrupt:
        # the summary of this sweep, not the one a sweep before left there
        write_summary(a, [Run(o, a.out) for o in sweep.outcomes], t0, interrupted=True)
        sys.exit('dm-calibrate: interrupted; finished runs are in %s' % a.out)
    runs = [Run(o, a.out) for o in sweep.outcomes]
    fits = {}
    for mu in ([] if a.no_table else a.mu):
        made = write_table(a, mu, runs, finest_ref, diameter,
                           (commit, soil_file, soil_sha, scene_sha, conditions, root))
        if made is not None:
            fits[mu] = made
    for p in plots(runs, a.out, a.mu, fits):
        print('plot: %s' % p)
    failed = [r for r in runs if not r.ok()]
    write_summary(a, runs, t0)
    print('sweep: %d runs in %.0f s, %d failed%s' % (len(runs), time.time() - t0, len(failed),
                                                    ''.join('\n  failed: %s: %s' % (r.name, r.error) for r in failed)))
    no_table = [mu for mu in a.mu if mu not in fits and not a.no_table]
    if no_table:
        print('dm-calibrate: no table for mu %s (fewer than two f values with a good run)'
              % ', '.join('%g' % mu for mu in no_table), file=sys.stderr)
    sys.exit(1 if failed or no_table else 0)


if __name__ == '__main__':
    sys.exit(main())
