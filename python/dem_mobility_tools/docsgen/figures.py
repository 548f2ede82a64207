"""The docs' plots of measured data, redrawn from the committed files behind them (`dm-docs --figures`).

| plot (docs/)                                   | data                                                  |
|------------------------------------------------|-------------------------------------------------------|
| vehicle-on-soil-study.png                      | docs/vehicle-on-soil-study.yaml                       |
| cone-ci-vs-f-sizes.png                         | config/calibration/cone_index_mu0.1_d*.yaml           |
| cone-ci-vs-f-dD.png (one per table)            | config/calibration/cone_index_mu0.1_dD.yaml           |
| single-wheel-{dp,torque,sinkage}-vs-slip.png   | docs/data/single-wheel-slip-sweep.yaml                |
| single-wheel-calibrated-dp-vs-slip.png         | docs/data/single-wheel-calibrated.yaml                |
"""
import glob
import os
import re

import yaml

from .make import DocsError


def _pyplot():
    import matplotlib
    matplotlib.use('Agg')
    import matplotlib.pyplot as plt
    return plt


def _load(root, rel):
    path = os.path.join(root, rel)
    try:
        with open(path) as f:
            return yaml.safe_load(f)
    except (OSError, yaml.YAMLError) as e:
        raise DocsError('{}: {}'.format(rel, e))


def _paper_table():
    from ..calibration.cone_index import PAPER_TABLE  # the paper's table 3, (CI, f) rows
    return PAPER_TABLE


def fidelity_study(root):
    from ..fidelity import plot
    png = os.path.join(root, 'docs', 'vehicle-on-soil-study.png')
    plot.main([os.path.join(root, 'docs', 'vehicle-on-soil-study.yaml'), png])
    return png


def _finish(plt, fig, ax, title, png, **legend):
    ax.set_title(title)
    ax.grid(alpha=0.3, which='both')
    ax.legend(fontsize=8, **legend)
    fig.tight_layout()
    fig.savefig(png, dpi=110)
    plt.close(fig)
    return png


def cone_table(root, table_rel, png_name, title):
    """CI against f from a calibration table: every run, the means with their std over the seeds,
    the table, and the paper's table 3."""
    t = _load(root, table_rel)
    for key in ('runs', 'points', 'table'):
        if key not in t:
            raise DocsError('{}: missing key {}'.format(table_rel, key))
    plt = _pyplot()
    fig, ax = plt.subplots(figsize=(8, 5))
    ax.plot(t['runs']['f'], t['runs']['ci'], 'o', mfc='none', label='runs')
    p = t['points']
    ax.errorbar(p['f'], p['ci_mean'], yerr=p.get('ci_std') or None, fmt='s', capsize=3,
                label='mean and std over the seeds')
    ax.plot([r[1] for r in t['table']], [r[0] for r in t['table']], '-', label='table')
    paper = _paper_table()
    ax.plot([r[1] for r in paper], [r[0] for r in paper], 'k--', lw=1, label='paper, table 3 (mu = 0.1)')
    ax.set_xscale('log')
    ax.set_xlabel('cohesion factor f')
    ax.set_ylabel('cone index [psi]')
    return _finish(plt, fig, ax, title, os.path.join(root, 'docs', png_name))


def cone_sizes(root):
    """Every installed mu 0.1 table on one axis: the mean CI per f with its std over the seeds and
    the table, one colour per particle size, beside the paper's table 3."""
    tables = []
    for path in glob.glob(os.path.join(root, 'config', 'calibration', 'cone_index_mu0.1_d*.yaml')):
        t = _load(root, os.path.relpath(path, root))
        tables.append(t)
    if not tables:
        raise DocsError('config/calibration: no cone_index_mu0.1_d*.yaml')
    tables.sort(key=lambda t: t['particle_diameter'])
    plt = _pyplot()
    fig, ax = plt.subplots(figsize=(8, 5))
    for t in tables:
        p = t['points']
        label = 'd = {:g} m ({})'.format(t['particle_diameter'], t['fidelity'])
        line = ax.errorbar(p['f'], p['ci_mean'], yerr=p.get('ci_std') or None, fmt='o', capsize=3, label=label)
        ax.plot([r[1] for r in t['table']], [r[0] for r in t['table']], '-', color=line[0].get_color(), lw=1)
    paper = _paper_table()
    ax.plot([r[1] for r in paper], [r[0] for r in paper], 'k--', lw=1, label='paper, table 3 (d = 0.03 m)')
    ax.set_xscale('log')
    ax.set_xlabel('cohesion factor f')
    ax.set_ylabel('cone index [psi]')
    return _finish(plt, fig, ax, 'CI versus f at 0.1 m/s per particle size, mu 0.1 (paper table 3)',
                   os.path.join(root, 'docs', 'cone-ci-vs-f-sizes.png'))


_NUM = re.compile(r'^\s*(-?[0-9.]+)\s*(?:\((-?[0-9.]+)\))?')


def _num(cell, rel, key):
    """'0.085 (0.053)' -> (0.085, 0.053); '-' or '' -> (None, None)."""
    if isinstance(cell, (int, float)):
        return float(cell), None
    cell = str(cell)
    m = re.search(r'slip (-?[0-9.]+)', cell)  # 'towed (slip -0.055)'
    if m:
        return float(m.group(1)), None
    m = _NUM.match(cell)
    if not m:
        if cell.strip() in ('-', ''):
            return None, None
        raise DocsError('{}: {}: not a number: {!r}'.format(rel, key, cell))
    return float(m.group(1)), (float(m.group(2)) if m.group(2) else None)


def wheel_sweep(root):
    """DP/W, T/(W r) and sinkage against slip from the coarse sweep, beside the references."""
    rel = 'docs/data/single-wheel-slip-sweep.yaml'
    rows = _load(root, rel)['rows']
    pts = []
    for r in rows:
        slip = _num(r['slip'], rel, 'slip')[0]
        dp, dp_sd = _num(r['dp_w_std'], rel, 'dp_w_std')
        tq, tq_sd = _num(r['t_w_r_std'], rel, 't_w_r_std')
        vti = _num(r['vti_dp_w_rigid_ci_100'], rel, 'vti_dp_w_rigid_ci_100')[0]
        gt = _num(r['vti_gt_w_ci_100'], rel, 'vti_gt_w_ci_100')[0]
        band = re.findall(r'-?[0-9.]+', str(r['band_dp_w_ci_100']))
        pts.append(dict(slip=slip, dp=dp, dp_sd=dp_sd or 0.0, tq=tq, tq_sd=tq_sd or 0.0,
                        sink=_num(r['sinkage_m'], rel, 'sinkage_m')[0], vti=vti, gt=gt,
                        band=[float(b) for b in band] if len(band) == 2 else None))
    plt = _pyplot()
    out = []
    fig, ax = plt.subplots(figsize=(7, 4.5))
    ax.errorbar([p['slip'] for p in pts], [p['dp'] for p in pts], yerr=[p['dp_sd'] for p in pts], fmt='o',
                capsize=3, label='DEM, coarse, f 3.2455 (std of the samples)')
    ref = [p for p in pts if p['vti'] is not None]
    ax.plot([p['slip'] for p in ref], [p['vti'] for p in ref], 's--', label='VTI, rigid tire, CI 100')
    band = [p for p in pts if p['band']]
    ax.fill_between([p['slip'] for p in band], [p['band'][0] for p in band], [p['band'][1] for p in band],
                    alpha=0.2, label='band of the references, CI 100')
    ax.set_xlabel('slip')
    ax.set_ylabel('DP/W')
    out.append(_finish(plt, fig, ax, 'Drawbar pull against slip',
                       os.path.join(root, 'docs', 'single-wheel-dp-vs-slip.png')))
    fig, ax = plt.subplots(figsize=(7, 4.5))
    driven = [p for p in pts if p['tq'] is not None]
    ax.errorbar([p['slip'] for p in driven], [p['tq'] for p in driven], yerr=[p['tq_sd'] for p in driven],
                fmt='o', capsize=3, label='DEM T/(W r)')
    ref = [p for p in pts if p['gt'] is not None]
    ax.plot([p['slip'] for p in ref], [p['gt'] for p in ref], 's--', label='VTI GT/W, CI 100')
    ax.set_xlabel('slip')
    ax.set_ylabel('T/(W r)')
    out.append(_finish(plt, fig, ax, 'Drive torque against slip',
                       os.path.join(root, 'docs', 'single-wheel-torque-vs-slip.png')))
    fig, ax = plt.subplots(figsize=(7, 4.5))
    ax.plot([p['slip'] for p in pts], [p['sink'] for p in pts], 'o-', label='DEM sinkage')
    ax.set_xlabel('slip')
    ax.set_ylabel('sinkage [m]')
    out.append(_finish(plt, fig, ax, 'Sinkage against slip',
                       os.path.join(root, 'docs', 'single-wheel-sinkage-vs-slip.png')))
    return out


def _cell(cell, rel, key):
    """A number of the calibrated table's cell ('0.069 (0.040)' -> 0.069, 0.040); '—' -> None."""
    if str(cell).strip() in ('—', '-', ''):
        return None, None
    return _num(cell, rel, key)


def wheel_calibrated(root):
    """DP/W against slip on each calibrated soil (coarse), beside VTI (rigid) and Brixius at its CI."""
    rel = 'docs/data/single-wheel-calibrated.yaml'
    soils = {}
    for r in _load(root, rel)['rows']:
        ci = str(r['ci']).split()[0]
        if not str(r['case']).startswith('slip'):
            continue
        slip = float(str(r['case']).split()[1])
        dp, sd = _cell(r['dp_w'], rel, 'dp_w')
        soils.setdefault(ci, []).append((slip, dp, sd or 0.0, _cell(r['vti_dp_w'], rel, 'vti_dp_w')[0],
                                         _cell(r['brixius_dp_w'], rel, 'brixius_dp_w')[0]))
    plt = _pyplot()
    fig, ax = plt.subplots(figsize=(10, 5))
    for ci, pts in sorted(soils.items(), key=lambda kv: float(kv[0])):
        pts.sort()
        line = ax.errorbar([p[0] for p in pts], [p[1] for p in pts], yerr=[p[2] for p in pts], fmt='o-', capsize=3,
                           label='DEM, CI %s (std of the samples)' % ci)
        color = line[0].get_color()
        vti = [p for p in pts if p[3] is not None]
        ax.plot([p[0] for p in vti], [p[3] for p in vti], 's--', color=color, lw=1, mfc='none',
                label='VTI rigid, CI %s' % ci)
        ax.plot([p[0] for p in pts], [p[4] for p in pts], '^:', color=color, lw=1, mfc='none',
                label='Brixius rigid, CI %s' % ci)
    ax.axhline(0.0, color='0.6', lw=0.8)
    ax.set_xlabel('slip')
    ax.set_ylabel('DP/W')
    return _finish(plt, fig, ax, 'The wheel on the calibrated soils (coarse, 0.06 m) against the empirical models',
                   os.path.join(root, 'docs', 'single-wheel-calibrated-dp-vs-slip.png'),
                   loc='center left', bbox_to_anchor=(1.02, 0.5))


def draw_all(root):
    """Redraws every plot; returns their paths."""
    out = [fidelity_study(root), cone_sizes(root)]
    for path in sorted(glob.glob(os.path.join(root, 'config', 'calibration', 'cone_index_mu0.1_d*.yaml'))):
        d = os.path.basename(path)[len('cone_index_mu0.1_d'):-len('.yaml')]
        out.append(cone_table(root, os.path.relpath(path, root), 'cone-ci-vs-f-d{}.png'.format(d),
                              'CI versus f at 0.1 m/s, {} m particles, mu 0.1'.format(d)))
    return out + wheel_sweep(root) + [wheel_calibrated(root)]
