"""dm-plot-fidelity: draws the fidelity study's speed-made-good against wall time from a file of measured runs
(docs/vehicle-on-soil-study.yaml: `runs`, finished, and `unfinished`, stopped before their verdict),
with the study's own plot (dm-fidelity-study): each case's finest finished run is its
reference.

    dm-plot-fidelity docs/vehicle-on-soil-study.yaml docs/vehicle-on-soil-study.png
"""
import argparse

import yaml

from .. import names
from . import study


def rows_of(runs, name):
    """The study's rows: per case, each run's error against the case's finest finished run."""
    rows = []
    for r in runs:
        try:
            names.refuse_old_keys(r, name, 'runs')
        except names.OldNameError as e:
            raise SystemExit(str(e))
        for key in ('grade_deg', 'cone_index_psi', 'level', 'speed_made_good', 'wall_time'):
            if key not in r:
                raise SystemExit('%s: a run lacks %s: %s' % (name, key, r))
        if r['level'] not in study.LEVEL_ORDER:
            raise SystemExit('%s: unknown level %r (have %s)' % (name, r['level'], ', '.join(study.LEVEL_ORDER)))
    for r in runs:
        case = [x for x in runs if (x['grade_deg'], x['cone_index_psi']) == (r['grade_deg'], r['cone_index_psi'])]
        finest = min(case, key=lambda x: study.LEVEL_ORDER.index(x['level']))
        rows.append(dict(r, reference=finest['level'],
                         error_vs_finest=abs(r['speed_made_good'] - finest['speed_made_good'])))
    return rows


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument('runs', help='YAML file of measured runs')
    ap.add_argument('png', help='the plot to write')
    a = ap.parse_args(argv)
    try:
        with open(a.runs) as f:
            data = yaml.safe_load(f)
    except (OSError, yaml.YAMLError) as e:
        raise SystemExit('%s: %s' % (a.runs, e))
    if not isinstance(data, dict) or not isinstance(data.get('runs'), list):
        raise SystemExit('%s: expected a map with a list `runs`' % a.runs)
    for u in data.get('unfinished') or []:
        try:
            names.refuse_old_keys(u, a.runs, 'unfinished')
        except names.OldNameError as e:
            raise SystemExit(str(e))
        for key in ('grade_deg', 'cone_index_psi', 'level', 'speed_reached', 'simulated_time', 'wall_time'):
            if key not in u:
                raise SystemExit('%s: an unfinished run lacks %s' % (a.runs, key))
    study.plot(rows_of(data['runs'], a.runs), a.png, unfinished=data.get('unfinished') or [])
    print(a.png)


if __name__ == '__main__':
    main()
