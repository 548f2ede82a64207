"""dm-docs-wheel: writes the docs' data file of the calibrated-wheel study (docs/data/single-wheel-calibrated.yaml)
from the runs dm-wheel-sweep kept (--keep DIR, one folder per seed), for dm-docs to render.

    dm-docs-wheel docs/data/single-wheel-runs/coarse_s1 [more kept folders: other seeds] --machine "..."

A row per cone index and case (towed, then each slip): DP/W and T/(W r) of the first folder's run
(the std of its 10 ms samples), where other folders hold the same case their seeds' mean and std,
the sinkage, and at the same CI, tire and load the empirical references (nrmm-baseline.md section 4):
VTI for the rigid tire (DP/W, GT/W), Brixius bias-ply rigid (NT/W, GT/W) and the band of every member,
and the cone index at which VTI would pull what the DEM wheel pulls (the seeds' mean where there are several).
The references are empirical fits for pneumatic tires: the table reports the difference, nothing is
tuned to them.
"""
import argparse
import glob
import math
import os
import statistics
import sys

import yaml

from ..terramechanics import wheel_numerics as wn
from .make import DocsError, default_root, write_data

TABLE = 'single-wheel/calibrated'
COLUMNS = (('ci', 'CI [psi] (f)'), ('case', 'case'), ('dp_w', 'DP/W (std of the samples)'),
           ('dp_w_seeds', 'DP/W over the seeds (mean, std)'), ('vti_dp_w', 'VTI DP/W (rigid)'),
           ('brixius_dp_w', 'Brixius NT/W (rigid)'), ('band_dp_w', 'band DP/W'), ('t_w_r', 'T/(W r) (std)'),
           ('vti_gt_w', 'VTI GT/W'), ('brixius_gt_w', 'Brixius GT/W'), ('sinkage_m', 'sinkage [m]'),
           ('vti_ci', 'CI at which VTI pulls the same [psi]'))


def _load_runs(folder):
    """{(requested CI, case): result} of a kept folder, and its options (sweep_options.yaml)."""
    runs = {}
    for path in sorted(glob.glob(os.path.join(folder, 'ci*_*.yaml'))):
        try:
            with open(path) as f:
                r = yaml.safe_load(f)
        except (OSError, yaml.YAMLError) as e:
            raise DocsError('{}: {}'.format(path, e))
        if not isinstance(r, dict) or r.get('kind') != 'single_wheel':
            raise DocsError('{}: not a single-wheel result'.format(path))
        for key in ('requested_cone_index_psi', 'drive', 'dp_over_w', 'tire_radius', 'tire_width', 'load'):
            if key not in r:
                raise DocsError('{}: missing key {}'.format(path, key))
        case = 'towed' if r['drive'] == 'towed' else 'slip %g' % r['slip_commanded']
        runs[(float(r['requested_cone_index_psi']), case)] = r
    if not runs:
        raise DocsError('{}: no kept single-wheel run (ci*_*.yaml)'.format(folder))
    try:
        with open(os.path.join(folder, 'sweep_options.yaml')) as f:
            options = yaml.safe_load(f) or {}
    except OSError:
        options = {}
    return runs, options


def _f(v, digits=3):
    return '{:.{}f}'.format(v, digits) if v is not None and v == v else '—'


def _case_key(case):
    return -1.0 if case == 'towed' else float(case.split()[1])


def references(ci, r, case):
    """(VTI DP/W, Brixius NT/W, band [lo, hi], VTI GT/W, Brixius GT/W) for a run's case at CI; the
    towed row: minus each model's towed resistance (GT/W none)."""
    b, d, w = float(r['tire_width']), 2.0 * float(r['tire_radius']), float(r['load'])
    if case == 'towed':
        band = wn.reference_band([0.0], ci, b, d, w)
        rigid = wn.vti(ci, b, d, w, 0.0)
        return (-rigid['mr_towed'], -wn.brixius(0.0, ci, b, d, w)[0], (band['towed_lo'], band['towed_hi']),
                None, None)
    s = float(r['slip_commanded'])
    band = wn.reference_band([s], ci, b, d, w)
    vti = wn.member_curves('vti', [s], ci, b, d, w)
    _, bgt, bnt = wn.brixius(s, ci, b, d, w)
    return (vti['dp_over_w'][0], bnt, (band['dp_lo'][0], band['dp_hi'][0]), vti['gt_over_w'][0], bgt)


def vti_equivalent_ci(dp_w, s, b, d, w, lo=5.0, hi=2000.0):
    """The cone index at which VTI (rigid tire) gives DP/W = dp_w at slip s (s > 0), by bisection
    (VTI's pull rises with CI); None outside [lo, hi] psi."""
    def pull(ci):
        v = wn.vti(ci, b, d, w, 0.0)
        return wn.vti_dp_over_w(s, v['nc'], b, d, v['ssp'])
    if not s > 0 or not pull(lo) <= dp_w <= pull(hi):
        return None
    for _ in range(60):
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if pull(mid) < dp_w else (lo, mid)
    return 0.5 * (lo + hi)


def rows(loaded):
    """The table's rows from the kept folders' runs (_load_runs of each; the first: every case; the
    others: more seeds)."""
    first, others = loaded[0][0], [runs for runs, _ in loaded[1:]]
    out = []
    for (ci, case) in sorted(first, key=lambda k: (k[0], _case_key(k[1]))):
        r = first[(ci, case)]
        vti_dp, bx_dp, band, vti_gt, bx_gt = references(ci, r, case)
        seeds = [r['dp_over_w']] + [o[(ci, case)]['dp_over_w'] for o in others if (ci, case) in o]
        sunk = r.get('status') == 'sunk'
        row = {
            'ci': '{:g} ({:.3g})'.format(ci, float(r.get('cohesion_factor', float('nan')))),
            'case': case + (' (sunk)' if sunk else '') + (' (slip {:.3f})'.format(r['slip']) if case == 'towed' else ''),
            'dp_w': '{} ({})'.format(_f(r['dp_over_w']), _f(r.get('dp_over_w_std'))),
            'dp_w_seeds': ('{} ({}; {} seeds)'.format(_f(statistics.mean(seeds)), _f(statistics.stdev(seeds)), len(seeds))
                           if len(seeds) > 1 else '—'),
            'vti_dp_w': _f(vti_dp),
            'brixius_dp_w': _f(bx_dp),
            'band_dp_w': '[{}, {}]'.format(_f(band[0], 2), _f(band[1], 2)),
            't_w_r': ('0' if case == 'towed' else '{} ({})'.format(_f(r.get('torque_over_wr')),
                                                                    _f(r.get('torque_over_wr_std')))),
            'vti_gt_w': _f(vti_gt),
            'brixius_gt_w': _f(bx_gt),
            'sinkage_m': _f(r.get('sinkage')),
            'vti_ci': '—',
        }
        if case != 'towed':  # of the seeds' mean where there are several
            eq = vti_equivalent_ci(statistics.mean(seeds), float(r['slip_commanded']), float(r['tire_width']),
                                   2.0 * float(r['tire_radius']), float(r['load']))
            row['vti_ci'] = '{:.0f}'.format(eq) if eq is not None else '—'
        out.append(row)
    return out


def write(root, folders, machine, date, command=None, soil_law=None):
    """Writes docs/data/single-wheel-calibrated.yaml; returns its path."""
    loaded = [_load_runs(f) for f in folders]
    first, options = loaded[0]
    any_run = next(iter(first.values()))
    walls = [r['wall_time'] / 60.0 for runs, _ in loaded for r in runs.values()
             if isinstance(r.get('wall_time'), (int, float))]
    seeds = [str(opts.get('--seed')) for _, opts in loaded]
    rel = [os.path.relpath(os.path.abspath(f), root) for f in folders]
    data = {
        'table': TABLE,
        'doc': 'single-wheel.md',
        'provenance': {
            'commit': '{} (the kept runs\' kept_from_commit)'.format(
                ', '.join(sorted({str(r.get('kept_from_commit', '?'))[:7] for runs, _ in loaded
                                  for r in runs.values()}))),
            'machine': machine,
            'date': date,
            'command': command or 'dm-wheel-sweep --fidelity {} --ci ... --keep {} (see its sweep_options.yaml)'.format(
                any_run.get('fidelity'), rel[0]),
            'recorded_in': '; '.join('{} (seed {})'.format(f, s) for f, s in zip(rel, seeds)),
            'conditions': 'level {}, {:g} m particles, {} in the bin, load {:g} kg (W {:.0f} N), {:g} m/s, window {} m of '
                          'travel; {} runs, {:.1f}-{:.1f} min each'.format(
                              any_run.get('fidelity'), any_run.get('particle_diameter', float('nan')),
                              any_run.get('particles', '?'), any_run.get('load_mass', float('nan')),
                              any_run.get('load', float('nan')), any_run.get('carriage_speed', float('nan')),
                              any_run.get('window'), len(walls), min(walls) if walls else math.nan,
                              max(walls) if walls else math.nan),
        },
        'columns': [{'key': k, 'title': t} for k, t in COLUMNS],
        'rows': rows(loaded),
    }
    if options.get('--seed') is None:
        data['provenance']['conditions'] += '; the scene\'s seed'
    return write_data(root, 'single-wheel-calibrated.yaml', data, soil_law)


def main(argv=None):
    p = argparse.ArgumentParser(prog='dm-docs-wheel', description=__doc__.split('\n')[0])
    p.add_argument('kept', nargs='+', help='folders of kept runs (dm-wheel-sweep --keep), the first with every case')
    p.add_argument('--machine', required=True, help='the machine the runs were made on')
    p.add_argument('--date', required=True, help='when the runs were made')
    p.add_argument('--command', help='the sweep commands (default: named from the first folder)')
    p.add_argument('--soil-law', help='which reading of the soil law the runs were made with')
    p.add_argument('--root', default=default_root())
    a = p.parse_args(argv)
    try:
        print(write(a.root, a.kept, a.machine, a.date, a.command, a.soil_law))
    except DocsError as e:
        sys.exit('dm-docs-wheel: {}'.format(e))
    return 0


if __name__ == '__main__':
    sys.exit(main())
