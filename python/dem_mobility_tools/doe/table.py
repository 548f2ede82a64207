"""dm-doe's case tables (doe nrmm's nrmm_table, doe run's doe_table): written as CSV and YAML with
their provenance, read back checked (a table of an older version refused naming its old key), and
their speed plots (figs. 23/24)."""
import csv
import os

import numpy as np
import yaml

from ..names import OldNameError, refuse_old_keys
from ..runs import read_result
from . import maps, plan
from .design import UsageError

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
    doc, why = read_result(path)
    if doc is None and 'not YAML' in why:
        raise UsageError(why)
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

