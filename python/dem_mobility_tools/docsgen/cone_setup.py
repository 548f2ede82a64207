"""dm-docs-cone-setup: writes the docs' data file of a cone set-up study (docs/data/cone-setup-dD.yaml) from
the runs dm-calibrate kept: the table's own runs at a level (its --keep folder) and, for each set-up
knob, a folder of runs made with `--no-table --set KEY=VALUE` (or the runs of another table of the
level made in another set-up), for dm-docs to render.

    dm-docs-cone-setup config/calibration/runs/coarse_cal docs/data/cone-setup-runs/coarse_cal_container2.4 \\
        [more set-up folders] --machine "..." [--name setup_d0.06]

What a folder changed is read from its sweep options (the level's conditions, with its --set applied)
against the table folder's: each key that differs, the table's value in brackets. Per f of the
set-up runs: the table's run of each seed (its CI, and the std over the table's seeds at that f), then
each knob's run of the same f and seed, its CI and its change against the table's run of that seed; a
knob run at several seeds gets a row of the means too. A change is only read against the table's run
of the same seed: the seeds' own scatter is in the table's row.
"""
import argparse
import glob
import os
import re
import statistics
import subprocess
import sys

import yaml

from .make import DocsError, default_root, write_data

COLUMNS = (('what', 'set-up'), ('f', 'f'), ('seeds', 'seeds'), ('ci', 'CI [psi]'), ('change', 'change'),
           ('seed_scatter', 'std over seeds [psi]'))
# the set-up's values a cone result names (so that a row can say what the table's was)
RESULT_KEYS = {'container_diameter': ('container', 'm'), 'soil_depth': ('soil poured', 'm deep'),
               'cone_speed': ('cone at', 'm/s'), 'ci_window': ('CI window', 'm'), 'time_step': ('time step', 's'),
               'approach_speed': ('approach at', 'm/s'), 'approach_depth': ('approach down to', 'm'),
               'settle_time': ('settled for', 's'), 'hold_time': ('lid held for', 's')}


def _runs(folder):
    """{(f, seed): result} of a kept folder, and its options (sweep_options.yaml)."""
    runs = {}
    for path in sorted(glob.glob(os.path.join(folder, 'mu*_f*_s*.yaml'))):
        try:
            with open(path) as fh:
                r = yaml.safe_load(fh)
        except (OSError, yaml.YAMLError) as e:
            raise DocsError('{}: {}'.format(path, e))
        if not isinstance(r, dict) or r.get('kind') != 'cone_penetrometer' or r.get('status') != 'ok':
            raise DocsError('{}: not the result of a cone run that ended well'.format(path))
        for key in ('cohesion_factor', 'seed', 'cone_index_psi', 'particle_diameter', 'fidelity'):
            if key not in r:
                raise DocsError('{}: missing key {}'.format(path, key))
        runs[(float(r['cohesion_factor']), int(r['seed']))] = r
    if not runs:
        raise DocsError('{}: no kept cone run (mu*_f*_s*.yaml)'.format(folder))
    try:
        with open(os.path.join(folder, 'sweep_options.yaml')) as fh:
            options = yaml.safe_load(fh) or {}
    except (OSError, yaml.YAMLError) as e:
        raise DocsError('{}: sweep_options.yaml: {}'.format(folder, e))
    return runs, options


def _kept_date(folders):
    """The latest date a file of the folders was committed (the runs' keeping), or None outside git."""
    dates = []
    for folder in folders:
        p = subprocess.run(['git', '-C', os.path.abspath(folder), 'log', '-1', '--format=%cs', '--', '.'],
                           capture_output=True, text=True)
        if p.returncode == 0 and p.stdout.strip():
            dates.append(p.stdout.strip())
    return max(dates) if dates else None


def _pct(x):
    return '{:+.1f} %'.format(100.0 * x)


def _effective(options):
    """The set-up a kept folder's runs were made in: its level's conditions with its --set applied
    ({key: value}; a --set of the level's own key goes by that key, any other by its dotted key)."""
    level = options.get('--fidelity')
    cond = dict(options.get('conditions') or {})
    for s in options.get('--set') or []:
        key, _, value = s.partition('=')
        prefix = 'levels.{}.'.format(level)
        cond[key[len(prefix):] if key.startswith(prefix) else key] = yaml.safe_load(value)
    return cond


def _value(v):
    if isinstance(v, (list, tuple)):
        return '-'.join(_value(x) for x in v)
    if isinstance(v, float) and v != 0 and abs(v) < 1e-3:
        return '{:g}'.format(v)
    return str(v)


def _knob(mine, table):
    """What a set-up changed against the table's, in words ('container 2.4 m (2)'), or '' if nothing."""
    words = []
    for key in sorted(set(mine) | set(table)):
        a, b = mine.get(key), table.get(key)
        if a == b:
            continue
        title, unit = RESULT_KEYS.get(key, (key, ''))
        words.append('{} {}{} ({})'.format(title, _value(a) if a is not None else '—', ' ' + unit if unit else '',
                                           _value(b) if b is not None else '—'))
    return '; '.join(words)


def _scatter(cis):
    if len(cis) < 2:
        return '—'
    mean, std = statistics.mean(cis), statistics.stdev(cis)
    return '{:.1f} ({:.1f} %; {} seeds: {})'.format(std, 100.0 * std / mean, len(cis), ', '.join('%.1f' % c for c in cis))


def rows(table_runs, knobs):
    """The data file's rows: per f, the table's runs, then each knob's (see the module's text)."""
    out = []
    fs = sorted({f for _, runs in knobs for f, _ in runs})
    for f in fs:
        seeds = sorted(s for g, s in table_runs if g == f)
        cis = [float(table_runs[(f, s)]['cone_index_psi']) for s in seeds]
        if not cis:
            raise DocsError('f = {:g}: the table\'s folder holds no run at that f'.format(f))
        first = table_runs[(f, seeds[0])]
        out.append({'what': "the table's runs ({} m container, {} m poured, {} m/s)".format(
                        first.get('container_diameter'), first.get('soil_depth'), first.get('cone_speed')),
                    'f': f, 'seeds': ', '.join(map(str, seeds)), 'ci': round(statistics.mean(cis), 1),
                    'change': '—', 'seed_scatter': _scatter(cis)})
        for what, runs in knobs:
            mine = sorted(s for g, s in runs if g == f)
            changes = []
            for s in mine:
                if (f, s) not in table_runs:
                    raise DocsError('f = {:g}, seed {}: the table\'s folder holds no run of that seed to compare with'
                                    .format(f, s))
                ci, ref = float(runs[(f, s)]['cone_index_psi']), float(table_runs[(f, s)]['cone_index_psi'])
                changes.append((ci, ref))
                out.append({'what': what, 'f': f, 'seeds': str(s), 'ci': round(ci, 1), 'change': _pct(ci / ref - 1.0),
                            'seed_scatter': '—'})
            if len(changes) > 1:
                ci, ref = statistics.mean(c for c, _ in changes), statistics.mean(r for _, r in changes)
                out.append({'what': what + ", the seeds' means (the table's runs of the same seeds: %.1f)" % ref,
                            'f': f, 'seeds': ', '.join(map(str, mine)), 'ci': round(ci, 1),
                            'change': _pct(ci / ref - 1.0), 'seed_scatter': _scatter([c for c, _ in changes])})
    return out


def write(root, table_folder, folders, machine, soil_law=None, name=None):
    """Writes docs/data/cone-NAME.yaml (NAME: setup-dD unless given, '_' read as '-'); returns its path."""
    table_runs, table_options = _runs(table_folder)
    d = float(next(iter(table_runs.values()))['particle_diameter'])
    level = table_options.get('--fidelity')
    table_setup = _effective(table_options)
    knobs, commits = [], set()
    for folder in folders:
        runs, options = _runs(folder)
        if options.get('--fidelity') != level:
            raise DocsError('{}: runs at level {}, not the table\'s {}'.format(folder, options.get('--fidelity'), level))
        what = _knob(_effective(options), table_setup)
        if not what:
            raise DocsError('{}: made in the set-up of the table\'s runs ({}): not a set-up study\'s runs'.format(
                folder, table_folder))
        knobs.append((what, runs))
        commits |= {str(r.get('kept_from_commit', '?')) for r in runs.values()}
    name = name or 'setup_d{:g}'.format(d)
    data = {
        'table': 'cone/' + name, 'doc': 'cone-penetrometer.md',
        'provenance': {
            'commit': ', '.join(sorted(commits)) + ' (the builds the set-up runs were made with)',
            'machine': machine,
            'date': _kept_date(folders),
            'command': 'dm-calibrate --fidelity {} --no-table --f F --seeds S --set KEY=VALUE --keep FOLDER'.format(level),
            'recorded_in': ', '.join(os.path.relpath(os.path.abspath(f), root) for f in [table_folder] + list(folders)),
            'conditions': '{} ({:g} m particles): one knob at a time; each run against the table\'s run of the same f and '
                          'seed'.format(level, d)},
        'columns': [{'key': k, 'title': t} for k, t in COLUMNS],
        'rows': rows(table_runs, knobs)}
    if data['provenance']['date'] is None:
        del data['provenance']['date']
    return write_data(root, 'cone-{}.yaml'.format(name.replace('_', '-')), data, soil_law)


def main(argv=None):
    p = argparse.ArgumentParser(prog='dm-docs-cone-setup', description=__doc__.split('\n')[0])
    p.add_argument('table_runs', help="the table's kept runs (config/calibration/runs/LEVEL)")
    p.add_argument('setup_runs', nargs='+', help='folders of set-up runs (dm-calibrate --no-table --set ... --keep)')
    p.add_argument('--machine', required=True, help='the machine the runs were made on')
    p.add_argument('--soil-law', default=None, help='the reading of the soil law the runs were made with (one line)')
    p.add_argument('--name', default=None,
                   help="the generated block's name, cone/NAME (default setup_dD; its data file docs/data/cone-NAME.yaml)")
    p.add_argument('--root', default=None, help='the checkout (default: the working folder)')
    a = p.parse_args(argv)
    root = a.root or default_root()
    if a.name is not None and not re.fullmatch(r'[a-z0-9_.]+', a.name):
        p.error('--name {!r}: lower-case letters, digits, _ and . only'.format(a.name))
    try:
        print(os.path.relpath(write(root, a.table_runs, a.setup_runs, a.machine, a.soil_law, a.name), root))
    except DocsError as e:
        print('dm-docs-cone-setup: {}'.format(e), file=sys.stderr)
        return 1
    return 0


if __name__ == '__main__':
    sys.exit(main())
