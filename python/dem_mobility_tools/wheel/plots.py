"""The single-wheel slip sweep's PNG plots (dm-wheel-sweep): DP/W and T/(W r) against
slip beside the empirical reference band, sinkage against slip, and each soil's histories."""
import os

from .. import names
from ..terramechanics import wheel_numerics as wn

HISTORY_KEYS = ('dp_over_w', 'torque_over_wr', 'sinkage')


# a soil's label (and its cases' file names): ci100 for a cone index of 100 psi, f1.5 for f = 1.5
LABEL_PREFIX = {names.CONE_INDEX: 'ci', names.COHESION_FACTOR: 'f'}


def soil_label(soil_key, value):
    return '%s%g' % (LABEL_PREFIX[soil_key], value)


def _title(doc, what):
    s = next((s for s in doc['soils'] if s.get('load')), None)
    text = '%s, level %s' % (what, doc['fidelity'])
    if doc.get('particle_diameter'):
        text += ' (d = %g m)' % doc['particle_diameter']
    if s:
        text += '\nW = %.2f kN, rigid tire %.3g x %.3g m' % (s['load'] * 1e-3, 2 * s['tire_radius'], s['tire_width'])
    if doc['runner'] == 'core':
        text += '  [runner: core, a developer check]'
    return text


def _dense(soil):
    """Positive slips over the driven points (the towed reference is a bar at the towed run)."""
    import numpy as np
    xs = [x for x in soil['points']['slip'] if x is not None and x > 0]
    lo = min([0.02] + [0.8 * x for x in xs])
    hi = max(xs + [0.1]) * 1.05
    return np.unique(np.concatenate([np.linspace(lo, hi, 200), np.geomspace(lo, hi, 100)]))


def _draw_soil_vs_slip(ax, doc, soil, key, band_key, c):
    """One soil on a DP/W or T/(W r) figure: its points (sunk and towed marked), its reference
    band and VTI curve."""
    p = soil['points']
    good = [i for i, st in enumerate(p['status']) if st != 'sunk' and p[key][i] is not None]
    sunk = [i for i, st in enumerate(p['status']) if st == 'sunk']
    label = 'DEM, %s' % soil['soil']
    if soil['cone_index_psi'] is not None and not soil['soil'].startswith('ci'):
        label += ' (CI %.1f psi)' % soil['cone_index_psi']
    if good:
        ax.errorbar([p['slip'][i] for i in good], [p[key][i] for i in good],
                    yerr=[p[key + '_std'][i] or 0.0 for i in good], fmt='o-', color=c, capsize=3, lw=1.5,
                    label=label)
    else:
        ax.plot([], [], 'o-', color=c, label=label + ' (no point)')
    for i in sunk:
        y = p[key][i]
        if y is None:
            ax.plot([p['slip'][i]], [0.02], 'X', color=c, ms=11, mec='k',
                    transform=ax.get_xaxis_transform())
        else:
            ax.plot([p['slip'][i]], [y], 'X', color=c, ms=11, mec='k')
    for t in soil['towed']:
        if t['slip'] is None:
            continue
        if t[key] is not None:
            ax.errorbar([t['slip']], [t[key]], yerr=[t[key + '_std'] or 0.0], fmt='X' if t['status'] == 'sunk'
                        else 's', color=c, ms=8, capsize=3, mec='k')
        if key == 'dp_over_w' and t.get('band_dp_over_w'):
            ax.vlines([t['slip']], *t['band_dp_over_w'], color=c, lw=8, alpha=0.25)
    if soil.get('reference') is None:
        return
    x = _dense(soil)
    ci, b, w, d = soil['cone_index_psi'], soil['tire_width'], soil['load'], 2 * soil['tire_radius']
    ref = doc['reference']
    band = wn.reference_band(x, ci, b, d, w, wn.band_members(ref['nominal_delta_over_h']), ref['ssp_offset'])
    ax.fill_between(x, band[band_key + '_lo'], band[band_key + '_hi'], color=c, alpha=0.15, lw=0)
    nc, ssp = soil['numerics']['vti_rigid']['nc'], soil['numerics']['vti_rigid']['ssp']
    f = wn.vti_dp_over_w if key == 'dp_over_w' else wn.vti_gt_over_w
    ax.plot(x, [f(v, nc, b, d, ssp) for v in x], '--', color=c, lw=1.2)


def _slip_legend(ax, key, dh):
    """The legend of a DP/W or T/(W r) figure: the runs and what the lines and marks mean."""
    from matplotlib.lines import Line2D
    from matplotlib.patches import Patch
    handles, labels = ax.get_legend_handles_labels()
    extra = [(Line2D([], [], ls='--', color='grey'), 'VTI (delta/h 0, rigid)' +
              (': GT/W = DP/W + MR/W' if key != 'dp_over_w' else '')),
             (Patch(color='grey', alpha=0.25), 'band: min-max of VTI (delta/h 0, %g),\n' % dh +
              'Brixius (delta/h 0), Wismer-Luth' + (' (GT/W)' if key != 'dp_over_w' else '')),
             (Line2D([], [], ls='', marker='X', color='grey', mec='k', ms=9),
              'sunk (at the bottom: no window)'),
             (Line2D([], [], ls='', marker='s', color='grey', mec='k'), 'towed'
              + (' (shaded bar: towed band)' if key == 'dp_over_w' else '')),
             (Line2D([], [], ls=''), 'WES (4.2) not in the band: no closed-form\npull; N_c = 0 for a rigid tire'),
             (Line2D([], [], ls=''), 'error bars: std over the window')]
    if key != 'dp_over_w':
        extra.append((Line2D([], [], ls=''), 'T/(W r) ~ GT/W: rolling radius = r'))
    ax.legend(handles + [e[0] for e in extra], labels + [e[1] for e in extra], fontsize=7.5, loc='best')


def _slip_figure(plt, doc, key, band_key, what, ylabel, colors):
    """DP/W (key dp_over_w) or T/(W r) (torque_over_wr) against slip, one line per soil, beside its
    reference band and VTI curve."""
    fig, ax = plt.subplots(figsize=(9, 6))
    for k, soil in enumerate(doc['soils']):
        _draw_soil_vs_slip(ax, doc, soil, key, band_key, colors[k % len(colors)])
    ax.axhline(0.0, color='k', lw=0.6)
    _slip_legend(ax, key, doc['reference']['nominal_delta_over_h'])
    ax.set_xlabel('slip s')
    ax.set_ylabel(ylabel)
    ax.set_title(_title(doc, what), fontsize=10)
    ax.grid(alpha=0.3)
    return fig


def _sinkage_figure(plt, doc, colors):
    """Sinkage against slip, beside VTI's sinkage."""
    from matplotlib.lines import Line2D
    fig, ax = plt.subplots(figsize=(9, 6))
    for k, soil in enumerate(doc['soils']):
        c = colors[k % len(colors)]
        p = soil['points']
        good = [i for i, st in enumerate(p['status']) if st != 'sunk' and p['sinkage'][i] is not None]
        if good:
            ax.errorbar([p['slip'][i] for i in good], [p['sinkage'][i] for i in good],
                        yerr=[p['sinkage_std'][i] or 0.0 for i in good], fmt='o-', color=c, capsize=3,
                        label='DEM, %s' % soil['soil'])
        for i, st in enumerate(p['status']):
            if st == 'sunk' and p['sinkage'][i] is not None:
                ax.plot([p['slip'][i]], [p['sinkage'][i]], 'X', color=c, ms=11, mec='k')
            elif st == 'sunk':
                ax.plot([p['slip'][i]], [0.97], 'X', color=c, ms=11, mec='k', transform=ax.get_xaxis_transform())
        for t in soil['towed']:
            if t['sinkage'] is not None and t['slip'] is not None:
                ax.errorbar([t['slip']], [t['sinkage']], yerr=[t['sinkage_std'] or 0.0],
                            fmt='X' if t['status'] == 'sunk' else 's', color=c, ms=8, mec='k', capsize=3)
        if soil.get('reference'):
            ax.axhline(soil['reference']['vti_sinkage_powered'], color=c, ls='--', lw=1.2)
            ax.axhline(soil['reference']['vti_sinkage_towed'], color=c, ls=':', lw=1.2)
    handles, labels = ax.get_legend_handles_labels()
    extra = [(Line2D([], [], ls='--', color='grey'), 'VTI sinkage, powered (eq. 9, delta/h 0; no slip term)'),
             (Line2D([], [], ls=':', color='grey'), 'VTI sinkage, towed'),
             (Line2D([], [], ls='', marker='X', color='grey', mec='k', ms=9), 'sunk (at the top: no window)'),
             (Line2D([], [], ls='', marker='s', color='grey', mec='k'), 'towed')]
    ax.legend(handles + [e[0] for e in extra], labels + [e[1] for e in extra], fontsize=8)
    ax.set_xlabel('slip s')
    ax.set_ylabel('sinkage z [m] (window mean; bars: std)')
    ax.set_title(_title(doc, 'sinkage versus slip'), fontsize=10)
    ax.grid(alpha=0.3)
    return fig


def _history_figure(plt, doc, soil, runs, colors):
    """DP/W, T/(W r) and sinkage against travel of a soil's runs, the window shaded."""
    fig, axes = plt.subplots(3, 1, figsize=(9, 9), sharex=True)
    window = None
    for k, o in enumerate(sorted(runs, key=lambda o: (o.case['drive'] == 'towed', o.case['slip'] or 0))):
        h = o.result['history']
        label = 'towed' if o.case['drive'] == 'towed' else 's = %g' % o.case['slip']
        if o.result.get('status') == 'sunk':
            label += ' (sunk)'
        for ax, key in zip(axes, HISTORY_KEYS):
            if key in h and 'travel' in h:
                ax.plot(h['travel'], h[key], lw=0.9, color=colors[k % len(colors)], label=label)
        window = window or o.result.get('window')
    for ax, ylabel in zip(axes, ('DP/W', 'T/(W r)', 'sinkage z [m]')):
        if window:
            ax.axvspan(window[0], window[1], color='grey', alpha=0.12)
        ax.set_ylabel(ylabel)
        ax.grid(alpha=0.3)
    axes[0].legend(fontsize=7, ncol=3)
    axes[-1].set_xlabel('carriage travel [m] (shaded: the measuring window)')
    axes[0].set_title(_title(doc, 'histories, %s' % soil['soil']), fontsize=10)
    return fig


def plots(doc, outcomes, out):
    """The PNG plots of a summary document; returns their paths."""
    import matplotlib
    matplotlib.use('Agg')
    import matplotlib.pyplot as plt

    written = []
    colors = plt.rcParams['axes.prop_cycle'].by_key()['color']

    def save(fig, name):
        p = os.path.join(out, name)
        fig.tight_layout()
        fig.savefig(p, dpi=110)
        plt.close(fig)
        written.append(p)

    for key, band_key, what, ylabel in (
            ('dp_over_w', 'dp', 'DP/W versus slip', 'net traction DP/W'),
            ('torque_over_wr', 'gt', 'T/(W r) versus slip', 'torque coefficient T/(W r); references: GT/W')):
        save(_slip_figure(plt, doc, key, band_key, what, ylabel, colors), key + '_vs_slip.png')
    save(_sinkage_figure(plt, doc, colors), 'sinkage_vs_slip.png')
    for soil in doc['soils']:  # the histories, per soil
        runs = [o for o in outcomes if o.ok and isinstance(o.result, dict) and isinstance(o.result.get('history'), dict)
                and soil_label(o.case['soil_key'], o.case['soil']) == soil['soil']]
        if runs:
            save(_history_figure(plt, doc, soil, runs, colors), 'histories_%s.png' % soil['soil'])
    return written
