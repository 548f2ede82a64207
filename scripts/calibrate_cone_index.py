#!/usr/bin/env python3
"""Cone index calibration sweep (paper section 3, figs. 13-14, table 3): runs the cone penetrometer
scene through roslaunch (the launch file and nodelets a user runs) for every cohesion factor f and
inter-particle friction mu, several runs at a time in parallel processes (each with its own ROS
master), and writes into OUT:

  runs/mu<mu>_f<f>.bag (+ .result.yaml, .log)   every run: its bag, result and console output
  ci_vs_time_mu<mu>.png                          CI versus time per run (fig. 13)
  ci_vs_f.png                                    CI versus f for every mu (fig. 14), with the fit
  cone_index_mu<mu>.yaml                         the cubic fit f(CI) and a table CI -> f (table 3),
                                                 the file soil scenes read (`cone_index:`)
  sweep.yaml                                     every run's outcome, failures included

    python3 scripts/calibrate_cone_index.py --fidelity coarse --jobs 2 --out results/calibration

A failed run is reported and the others are kept; the exit status is 1 if any run failed.
"""
import argparse
import math
import os
import shutil
import subprocess
import sys
import time

import yaml

# dm_sweep lives beside this script (also when run through catkin's relay in devel/lib)
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import dm_sweep  # noqa: E402

PAPER_TABLE = [(30, 0.06), (40, 0.15), (50, 0.5), (60, 0.84), (70, 1.18), (80, 1.52), (100, 2.24),
               (120, 3.03), (150, 4.46), (200, 7.85), (242, 12.1)]
PAPER_CUBIC = [9.148e-7, -1.783e-4, 4.555e-2, -1.445]


def floats(text):
    try:
        return [float(v) for v in text.split(',') if v.strip()]
    except ValueError:
        raise argparse.ArgumentTypeError('expected a comma-separated list of numbers, got %r' % text)


def case_name(mu, f):
    return 'mu%g_f%g' % (mu, f)


def bag_path(out, name):
    return os.path.join(out, 'runs', name + '.bag')


class Run:
    """A run's outcome (dm_sweep.Outcome) as the fit, the tables and the plots see it."""

    def __init__(self, outcome, out):
        self.outcome = outcome
        self.mu, self.f = outcome.case['mu'], outcome.case['f']
        self.name = outcome.name
        self.bag = bag_path(out, self.name)
        self.result_file, self.log = outcome.result_file, outcome.log
        self.result, self.error = outcome.result, outcome.error
        self.start, self.end = outcome.start, outcome.end

    def ok(self):
        return self.error is None

    def ci(self):
        return float(self.result['cone_index_psi'])


def fit(points, table_ci):
    """Cubic f(CI) by least squares (lower degree with fewer points) and the table rows at the
    paper's cone indices inside the measured range."""
    import numpy as np
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
    method = 'cubic fit f(CI) (degree %d), as the paper, clamped to the f range run' % deg
    # clamped to the f range run: at the ends of the range the runs themselves are exact, and a
    # least-squares cubic in f misses a small f by far more than its size (f(30.6) = 0.007 for
    # a run at f = 0.05), which the scenes would refuse
    vals = [min(max(float(np.polyval(coef, c)), float(f.min())), float(f.max())) for c in rows]
    if any(v <= 0 for v in vals) or any(b <= a for a, b in zip(vals, vals[1:])):
        # the cubic is not monotone (or not positive) over the range: interpolate the runs instead,
        # linearly in log f over the CI-sorted points made monotone
        order = np.argsort(ci)
        cs, fs = ci[order], np.log(f[order])
        fs = np.maximum.accumulate(fs)
        vals = [float(np.exp(np.interp(c, cs, fs))) for c in rows]
        keep = [0] + [k for k in range(1, len(vals)) if vals[k] > vals[k - 1]]
        rows, vals = [rows[k] for k in keep], [vals[k] for k in keep]
        method = 'piecewise-linear in log f over the runs (the cubic was not monotone over the range)'
    table = [[float(c), float(v)] for c, v in zip(rows, vals)]
    # scatter of the runs about the table, relative in CI
    res = []
    for fv, cv in points:
        if table[0][1] <= fv <= table[-1][1]:
            pred = float(np.interp(fv, [r[1] for r in table], [r[0] for r in table]))
            res.append((cv - pred) / cv)
    band = float(math.sqrt(sum(r * r for r in res) / len(res))) if res else 0.0
    return cubic, table, band, method


def plots(runs, out, mus, fits):
    import matplotlib
    matplotlib.use('Agg')
    import matplotlib.pyplot as plt
    import numpy as np
    written = []
    for mu in mus:
        done = [r for r in runs if r.mu == mu and r.result and r.result.get('history')]
        if not done:
            continue
        fig, ax = plt.subplots(figsize=(8, 5))
        for r in sorted(done, key=lambda r: r.f):
            h = r.result['history']
            ax.plot(h['t'], h['ci_psi'], lw=1.2, label='f = %g%s' % (r.f, '' if r.ok() else ' (failed)'))
        ax.set_xlabel('time since the cone started [s]')
        ax.set_ylabel('cone index [psi]')
        ax.set_title('CI versus time, mu = %g (paper fig. 13)' % mu)
        ax.grid(alpha=0.3)
        ax.legend(fontsize=8)
        p = os.path.join(out, 'ci_vs_time_mu%g.png' % mu)
        fig.tight_layout()
        fig.savefig(p, dpi=110)
        plt.close(fig)
        written.append(p)
    fig, ax = plt.subplots(figsize=(8, 5))
    for mu in mus:
        pts = sorted((r.f, r.ci()) for r in runs if r.mu == mu and r.ok())
        if not pts:
            continue
        line = ax.plot([p[0] for p in pts], [p[1] for p in pts], 'o', label='runs, mu = %g' % mu)[0]
        if mu in fits:
            table = fits[mu][1]
            ax.plot([t[1] for t in table], [t[0] for t in table], '-', color=line.get_color(),
                    label='table (fit), mu = %g' % mu)
    ax.plot([t[1] for t in PAPER_TABLE], [t[0] for t in PAPER_TABLE], 'k--', lw=1, label='paper, table 3 (mu = 0.1)')
    ax.set_xscale('log')
    ax.set_xlabel('cohesion factor f')
    ax.set_ylabel('cone index [psi]')
    ax.set_title('CI versus cohesion factor (paper fig. 14)')
    ax.grid(alpha=0.3, which='both')
    ax.legend(fontsize=8)
    p = os.path.join(out, 'ci_vs_f.png')
    fig.tight_layout()
    fig.savefig(p, dpi=110)
    plt.close(fig)
    written.append(p)
    return written


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    here = os.path.dirname(os.path.abspath(__file__))
    ap.add_argument('--scene', default=os.path.join(here, '..', 'config', 'scenes', 'cone_penetrometer.yaml'))
    ap.add_argument('--fidelity', default='coarse', help='level of the scene file (default coarse)')
    ap.add_argument('--f', type=floats, default=floats('0.05,0.3,1.5,5,12'), help='cohesion factors')
    ap.add_argument('--mu', type=floats, default=floats('0.1,0.05'), help='inter-particle friction coefficients')
    ap.add_argument('--jobs', type=int, default=2, help='runs at a time (default 2: one per core)')
    ap.add_argument('--dem-threads', type=int, default=1, help='OpenMP threads per run (default 1)')
    ap.add_argument('--cloud-rate', type=float, default=5.0, help='particle clouds per simulated second in each bag')
    ap.add_argument('--timeout', type=float, default=3600.0, help='longest a run may take [s]')
    ap.add_argument('--port', type=int, default=11411, help='first ROS master port (one per parallel run)')
    ap.add_argument('--table-ci', type=floats, default=floats(','.join(str(c) for c, _ in PAPER_TABLE)),
                    help="cone indices of the table's rows (the paper's by default)")
    ap.add_argument('--install', help='also copy the mu = 0.1 table to this file (e.g. config/calibration/cone_index_mu0.1.yaml)')
    ap.add_argument('--resume', action='store_true',
                    help='keep the runs already in OUT that succeeded with the same level, f and mu (rerun the rest)')
    ap.add_argument('--out', default='results/calibration')
    a = ap.parse_args()
    if a.jobs < 1 or a.dem_threads < 1:
        sys.exit('calibrate_cone_index: --jobs and --dem-threads must be >= 1')
    if not os.path.isfile(a.scene):
        sys.exit('calibrate_cone_index: no scene file %s' % a.scene)
    if shutil.which('roslaunch') is None:
        sys.exit('calibrate_cone_index: roslaunch not found: source the catkin workspace (devel/setup.bash) first')
    if subprocess.run(['rospack', 'find', 'dem_mobility'], stdout=subprocess.DEVNULL,
                      stderr=subprocess.DEVNULL).returncode != 0:
        sys.exit('calibrate_cone_index: ROS does not know the package dem_mobility: '
                 'source the catkin workspace (devel/setup.bash) that built it first')
    os.makedirs(os.path.join(a.out, 'runs'), exist_ok=True)
    try:
        cases = dm_sweep.grid([('mu', a.mu), ('f', a.f)], name=lambda p: case_name(p['mu'], p['f']))
    except ValueError as e:
        sys.exit('calibrate_cone_index: %s' % e)

    def command(case, run):
        return ['roslaunch', '-p', str(run.port), 'dem_mobility', 'cone_penetrometer.launch',
                'scene:=' + os.path.abspath(a.scene), 'fidelity:=' + a.fidelity, 'f:=%g' % case['f'],
                'mu:=%g' % case['mu'], 'dem_threads:=%d' % a.dem_threads,
                'bag:=' + os.path.abspath(bag_path(a.out, case.name)), 'cloud_rate:=%g' % a.cloud_rate]

    def check(case, result):
        return None if result.get('window_samples') else 'no CI sample in the window'

    def describe(run):
        return 'CI %.1f psi' % float(run.result['cone_index_psi']) if run.ok else 'FAILED: ' + run.error

    def same_run(case, old):
        """A kept run was made with the same level, f and mu."""
        try:
            return (old.get('fidelity') == a.fidelity and abs(old.get('cohesion_factor', -1) - case['f']) < 1e-12
                    and abs(old.get('friction', -1) - case['mu']) < 1e-12)
        except TypeError:
            return False

    sweep = dm_sweep.Sweep(cases, command, os.path.join(a.out, 'runs'), jobs=a.jobs, port=a.port,
                           timeout=a.timeout, check=check, outputs=lambda case: [bag_path(a.out, case.name)],
                           describe=describe, poll=1.0, status_every=20.0)
    if a.resume:
        sweep.resume(accept=same_run)
    t0 = time.time()
    print('sweep: %d runs (f %s x mu %s), level %s, %d at a time' %
          (len(cases), ','.join('%g' % f for f in a.f), ','.join('%g' % m for m in a.mu), a.fidelity, a.jobs), flush=True)
    try:
        sweep.run(t0)
    except KeyboardInterrupt:
        sys.exit('calibrate_cone_index: interrupted; finished runs are in %s' % a.out)
    runs = [Run(o, a.out) for o in sweep.outcomes]
    fits = {}
    for mu in a.mu:
        pts = sorted((r.f, r.ci()) for r in runs if r.mu == mu and r.ok())
        if len(pts) < 2:
            print('mu %g: %d successful run(s): no fit' % (mu, len(pts)))
            continue
        fits[mu] = fit(pts, a.table_ci)
        cubic, table, band, method = fits[mu]
        doc = {
            'friction': mu,
            'fidelity': a.fidelity,
            'scene': os.path.relpath(os.path.abspath(a.scene), os.path.dirname(here)),
            'date': time.strftime('%Y-%m-%d'),
            'method': method,
            'cubic': cubic,
            'band': round(band, 4),
            'table': [[round(c, 2), round(v, 4)] for c, v in table],
            'runs': [[r.f, round(r.ci(), 3)] for r in sorted(runs, key=lambda r: r.f) if r.mu == mu and r.ok()],
        }
        path = os.path.join(a.out, 'cone_index_mu%g.yaml' % mu)
        with open(path, 'w') as fh:
            fh.write('# Cone index calibration: CI [psi] -> cohesion factor f at mu = %g (level %s).\n'
                     '# cubic: f = c0 CI^3 + c1 CI^2 + c2 CI + c3; table: [CI, f] rows; band: relative rms\n'
                     '# CI scatter of the runs about the table; runs: [f, CI] measured.\n'
                     '# Written by scripts/calibrate_cone_index.py.\n' % (mu, a.fidelity))
            yaml.safe_dump(doc, fh, default_flow_style=None, sort_keys=False)
        print('mu %g: %s; band %.1f %%; table -> %s' % (mu, method, 100 * band, path))
        print('   CI [psi]   f (ours)   f (paper, mu 0.1)')
        paper = dict(PAPER_TABLE)
        for c, v in table:
            print('   %7.1f   %8.3f   %s' % (c, v, '%.2f' % paper[c] if c in paper else '-'))
        if a.install and abs(mu - 0.1) < 1e-12:
            os.makedirs(os.path.dirname(os.path.abspath(a.install)), exist_ok=True)
            shutil.copyfile(path, a.install)
            print('   installed as %s' % a.install)
    for p in plots(runs, a.out, a.mu, fits):
        print('plot: %s' % p)
    failed = [r for r in runs if not r.ok()]
    with open(os.path.join(a.out, 'sweep.yaml'), 'w') as fh:
        yaml.safe_dump({'fidelity': a.fidelity, 'wall_time': round(time.time() - t0, 1), 'jobs': a.jobs,
                        'runs': [{'f': r.f, 'mu': r.mu, 'ok': r.ok(),
                                  'cone_index_psi': r.ci() if r.ok() else None,
                                  'wall_time': round((r.end or 0) - (r.start or 0), 1),
                                  'error': r.error, 'bag': r.bag} for r in runs]}, fh, sort_keys=False)
    print('sweep: %d runs in %.0f s, %d failed%s' % (len(runs), time.time() - t0, len(failed),
                                                    ''.join('\n  failed: %s: %s' % (r.name, r.error) for r in failed)))
    sys.exit(1 if failed else 0)


if __name__ == '__main__':
    main()
