"""dm-docs-cone: writes the docs' data files of one cone index table (docs/data/cone-seeds-dD.yaml
and cone-table-dD.yaml) from the table dm-calibrate installed, for dm-docs to render; with
--tables, the overview of every table installed (docs/data/cone-tables.yaml) and f per CI of the
paper's table 3 at every size (docs/data/cone-sizes.yaml).

    dm-docs-cone config/calibration/cone_index_mu0.1_d0.06.yaml --machine "..." [--beside TABLE ...]
    dm-docs-cone --tables config/calibration --machine "..."

The seeds table has a row per f: every seed's CI, the mean, the std over the seeds and its
relative size, and (--beside) the mean CI of other tables at the same f; the table has the
installed CI -> f rows. The provenance is the table's own (commit, date, command, conditions).
"""
import argparse
import os
import sys

import yaml

from .make import DocsError, default_root, write_data


def _load(path):
    try:
        with open(path) as f:
            t = yaml.safe_load(f)
    except (OSError, yaml.YAMLError) as e:
        raise DocsError('{}: {}'.format(path, e))
    for key in ('particle_diameter', 'friction', 'fidelity', 'runs', 'points', 'table', 'provenance'):
        if not isinstance(t, dict) or key not in t:
            raise DocsError('{}: missing key {}'.format(path, key))
    return t


def _key(title):
    return ''.join(c if c.isalnum() else '_' for c in title).strip('_').lower()


def _g(v, digits=2):
    """A number as the docs print it: fixed digits, as a string where YAML would drop a zero."""
    s = '{:.{}f}'.format(v, digits)
    return s if s.endswith('0') else float(s)


def _mean_at(table, f):
    p = table['points']
    for fi, ci in zip(p['f'], p['ci_mean']):
        if abs(fi - f) < 1e-9:
            return ci
    return None


def seeds_rows(t, beside):
    """Rows of the seeds table: {cohesion_factor, [time_step,] seed_k..., mean, std_over_the_seeds, relative,
    beside...}; the time step per f when some f ran at a step of its own (conditions.time_step_at)."""
    runs = t['runs']
    seeds = sorted(set(runs['seed']))
    rows = []
    p = t['points']
    cond = t['provenance'].get('conditions', {})
    steps = {float(f): dt for f, dt in (cond.get('time_step_at') or {}).items()}
    for f, mean, std, n in zip(p['f'], p['ci_mean'], p['ci_std'], p['seeds']):
        row = {'cohesion_factor': f}
        if steps:
            row['time_step'] = '{:g}'.format(steps.get(float(f), cond.get('time_step')))
        for s in seeds:
            ci = [c for fi, si, c in zip(runs['f'], runs['seed'], runs['ci']) if abs(fi - f) < 1e-9 and si == s]
            row['seed_%d' % s] = _g(ci[0]) if ci else '—'
        row['mean'] = '**{:.1f}**'.format(mean)
        row['std_over_the_seeds'] = _g(std, 1)
        row['relative'] = '{:.1f} %'.format(100.0 * std / mean) if mean else '—'
        for title, other in beside:
            m = _mean_at(other, f)
            row[_key(title)] = _g(m, 1) if m is not None else '—'
        rows.append(row)
    columns = [{'key': 'cohesion_factor', 'title': 'f'}]
    if steps:
        columns.append({'key': 'time_step', 'title': 'dt [s]'})
    columns += [{'key': 'seed_%d' % s, 'title': 'seed %d' % s} for s in seeds]
    columns += [{'key': 'mean', 'title': 'mean'}, {'key': 'std_over_the_seeds', 'title': 'std over the seeds'},
                {'key': 'relative', 'title': 'relative'}]
    columns += [{'key': _key(title), 'title': title} for title, _ in beside]
    return columns, rows


def table_rows(t):
    d, mu = t['particle_diameter'], t['friction']
    columns = [{'key': 'cone_index_psi', 'title': 'CI [psi]'}]
    row = {'cone_index_psi': 'f ({:g} m, mu {:g}, {:g} m/s)'.format(
        d, mu, t['provenance'].get('conditions', {}).get('cone_speed', float('nan')))}
    for ci, f in t['table']:
        title = '{:g}'.format(ci)
        columns.append({'key': _key(title), 'title': title})
        row[_key(title)] = _g(f)
    return columns, [row]


def write(root, table_path, machine, command=None, beside=(), conditions=None, soil_law=None):
    """Writes docs/data/cone-seeds-dD.yaml and cone-table-dD.yaml; returns their paths."""
    t = _load(table_path)
    prov = t['provenance']
    d = '{:g}'.format(t['particle_diameter'])
    rel = os.path.relpath(os.path.abspath(table_path), root)
    base = {
        'doc': 'cone-penetrometer.md',
        'provenance': {
            'commit': '{} (the table file\'s provenance)'.format(str(prov.get('commit', '?'))[:7]),
            'machine': machine,
            'date': str(prov.get('date', '?')),
            'command': command or prov.get('command') or 'dm-calibrate --fidelity {} (see {})'.format(t['fidelity'], rel),
            'recorded_in': '{} (runs, points, table); its runs under config/calibration/runs/{}'.format(
                rel, t['fidelity']),
        },
    }
    if conditions:
        base['provenance']['conditions'] = conditions
    if soil_law:
        base['provenance']['soil_law'] = soil_law
    out = []
    for name, (columns, rows) in (('seeds', seeds_rows(t, beside)), ('table', table_rows(t))):
        data = dict(table='cone/{}_d{}'.format(name, d), **base, columns=columns, rows=rows)
        out.append(write_data(root, 'cone-{}-d{}.yaml'.format(name, d), data))
    return out


def _wall_times(root, t):
    """min-max (mean) of the kept runs' wall times [min], '—' without kept runs."""
    import glob
    w = []
    for path in glob.glob(os.path.join(root, 'config', 'calibration', 'runs', t['fidelity'], 'mu*_f*_s*.yaml')):
        with open(path) as f:
            r = yaml.safe_load(f)
        if isinstance(r, dict) and r.get('friction') == t['friction'] and isinstance(r.get('wall_time'), (int, float)):
            w.append(r['wall_time'] / 60.0)
    if not w:
        return '—'
    return '{:.1f}–{:.1f} min (mean {:.1f}, {} runs)'.format(min(w), max(w), sum(w) / len(w), len(w))


def write_overview(root, folder, machine, soil_law=None):
    """docs/data/cone-tables.yaml: a row per table in `folder` (sorted by mu, then d)."""
    import glob
    tables = [(_load(p), p) for p in sorted(glob.glob(os.path.join(folder, 'cone_index_mu*_d*.yaml')))]
    if not tables:
        raise DocsError('{}: no cone_index_mu*_d*.yaml'.format(folder))
    tables.sort(key=lambda tp: (tp[0]['friction'], tp[0]['particle_diameter']))
    rows, dates, commits = [], set(), set()
    for t, path in tables:
        p, prov = t['points'], t['provenance']
        dates.add(str(prov.get('date', '?')))
        commits.add(str(prov.get('commit', '?'))[:7])
        cond = prov.get('conditions', {})
        rows.append({
            'table': '`{}`'.format(os.path.basename(path)),
            'level': t['fidelity'],
            'd_m': t['particle_diameter'],
            'mu': t['friction'],
            'cone_m_s': cond.get('cone_speed', '—'),
            'container_m': cond.get('container_diameter', '—'),
            'f_points': ', '.join('{:g}'.format(f) for f in p['f']),
            'seeds_per_f': ', '.join(str(n) for n in p['seeds']),
            'ci_mean_std_per_f': ', '.join('{:.1f} ({:.1f})'.format(m, s) for m, s in zip(p['ci_mean'], p['ci_std'])),
            'ci_range': '{:.1f}–{:.1f}'.format(t['table'][0][0], t['table'][-1][0]),
            'band': '{:.1f} %'.format(100.0 * t['band']) if isinstance(t.get('band'), (int, float)) else '—',
            'wall_time_per_run': _wall_times(root, t),
        })
    titles = (('table', 'table'), ('level', 'level'), ('d_m', 'd [m]'), ('mu', 'mu'), ('cone_m_s', 'cone [m/s]'),
              ('container_m', 'container [m]'), ('f_points', 'f points'), ('seeds_per_f', 'seeds per f'),
              ('ci_mean_std_per_f', 'CI mean (std) per f [psi]'), ('ci_range', 'CI range [psi]'), ('band', 'band'),
              ('wall_time_per_run', 'wall time per run (1 thread)'))
    data = {
        'table': 'cone/tables',
        'doc': 'cone-penetrometer.md',
        'provenance': {
            'commit': ', '.join(sorted(commits)) + ' (the tables\' provenance)',
            'machine': machine,
            'date': ', '.join(sorted(dates)),
            'command': 'dm-calibrate --fidelity LEVEL ... --install config/calibration (each table\'s own command: '
                       'its runs folder\'s sweep_options.yaml)',
            'recorded_in': '{}/cone_index_mu*_d*.yaml; wall times from config/calibration/runs/LEVEL'.format(
                os.path.relpath(os.path.abspath(folder), root)),
        },
        'columns': [{'key': k, 'title': v} for k, v in titles],
        'rows': rows,
    }
    return write_data(root, 'cone-tables.yaml', data, soil_law)


def _f_text(f):
    return '{:.2f}'.format(f) if f >= 0.1 else '{:.2g}'.format(f)


def size_row(t, cis):
    """f per CI of `cis` from a table's rows (the sweep writes a row at each of table 3's CIs inside
    its range); outside the range, what the table reaches instead."""
    rows = t['table']
    out = {}
    for c in cis:
        lo, hi = rows[0], rows[-1]
        if c < lo[0]:
            out['ci_{:g}'.format(c)] = '— ({:.1f} at f {:g})'.format(lo[0], lo[1])
        elif c > hi[0]:
            out['ci_{:g}'.format(c)] = '— ({:.1f} at f {:g})'.format(hi[0], hi[1])
        else:
            at = [f for ci, f in rows if abs(ci - c) < 1e-9]
            if not at:
                raise DocsError('the table for d = {:g} m has no row at CI {:g}'.format(t['particle_diameter'], c))
            out['ci_{:g}'.format(c)] = _f_text(at[0])
    return out


def write_sizes(root, folder, machine, soil_law=None):
    """docs/data/cone-sizes.yaml: f per CI of the paper's table 3, the paper's row and one per mu 0.1
    table in `folder` (by particle size)."""
    import glob
    from ..calibration.cone_index import PAPER_TABLE
    tables = [_load(p) for p in sorted(glob.glob(os.path.join(folder, 'cone_index_mu0.1_d*.yaml')))]
    if not tables:
        raise DocsError('{}: no cone_index_mu0.1_d*.yaml'.format(folder))
    tables.sort(key=lambda t: t['particle_diameter'])
    cis = [c for c, _ in PAPER_TABLE]
    rows = [dict({'source': 'paper (0.03 m, table 3)'}, **{'ci_{:g}'.format(c): '{:g}'.format(f) for c, f in PAPER_TABLE})]
    for t in tables:
        rows.append(dict({'source': '{:g} m (`{}`)'.format(t['particle_diameter'], t['fidelity'])}, **size_row(t, cis)))
    data = {
        'table': 'cone/sizes',
        'doc': 'cone-penetrometer.md',
        'provenance': {
            'commit': ', '.join(sorted({str(t['provenance'].get('commit', '?'))[:7] for t in tables})) +
                      " (the tables' provenance)",
            'machine': machine,
            'date': ', '.join(sorted({str(t['provenance'].get('date', '?')) for t in tables})),
            'command': 'dm-calibrate --fidelity LEVEL ... --install config/calibration',
            'recorded_in': '{}/cone_index_mu0.1_d*.yaml (their rows at table 3\'s CIs); the paper\'s table 3'.format(
                os.path.relpath(os.path.abspath(folder), root)),
        },
        'columns': [{'key': 'source', 'title': 'CI [psi]'}] + [{'key': 'ci_{:g}'.format(c), 'title': '{:g}'.format(c)}
                                                             for c in cis],
        'rows': rows,
    }
    return write_data(root, 'cone-sizes.yaml', data, soil_law)


def main(argv=None):
    p = argparse.ArgumentParser(prog='dm-docs-cone', description=__doc__.split('\n')[0])
    p.add_argument('table', nargs='?', help='a table dm-calibrate installed (config/calibration/cone_index_mu*_d*.yaml)')
    p.add_argument('--tables', metavar='FOLDER', default=None,
                   help='write the overview of every table in FOLDER instead (docs/data/cone-tables.yaml) and f per paper CI per size (docs/data/cone-sizes.yaml)')
    p.add_argument('--machine', required=True, help='the machine the runs were made on')
    p.add_argument('--command', default=None, help='the command that made the table (default: its provenance\'s)')
    p.add_argument('--conditions', default=None, help='how the runs were made (one line)')
    p.add_argument('--soil-law', default=None, help='the reading of the soil law the runs were made with (one line)')
    p.add_argument('--beside', action='append', default=[], metavar='TITLE=TABLE',
                   help='another table whose mean CI at the same f gets a column TITLE')
    p.add_argument('--root', default=None, help='the checkout (default: the working folder)')
    a = p.parse_args(argv)
    root = a.root or default_root()
    try:
        if a.tables:
            print(os.path.relpath(write_overview(root, a.tables, a.machine, a.soil_law), root))
            print(os.path.relpath(write_sizes(root, a.tables, a.machine, a.soil_law), root))
            return 0
        if not a.table:
            raise DocsError('name a table, or --tables FOLDER')
        beside = []
        for b in a.beside:
            title, sep, path = b.rpartition('=')
            if not sep:
                raise DocsError('--beside {}: want TITLE=TABLE'.format(b))
            beside.append((title, _load(path)))
        for path in write(root, a.table, a.machine, a.command, beside, a.conditions, a.soil_law):
            print(os.path.relpath(path, root))
    except DocsError as e:
        print('dm-docs-cone: {}'.format(e), file=sys.stderr)
        return 1
    return 0


if __name__ == '__main__':
    sys.exit(main())
