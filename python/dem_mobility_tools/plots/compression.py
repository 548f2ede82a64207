"""dm-plot-compression: bulk density versus pressure of a piston-cylinder compression run (paper fig. 9): loading,
unloading and the density once the piston is gone, from dm_run_scene's result YAML.

    dm-plot-compression RESULT.yaml [-o compression.png]
"""
import argparse
import os
import sys

import yaml

from ..sweep.figures import save_figure


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument('result')
    ap.add_argument('-o', '--out', help='PNG file (default: the result with .png)')
    a = ap.parse_args(argv)
    import matplotlib
    matplotlib.use('Agg')
    import matplotlib.pyplot as plt
    try:
        with open(a.result) as fh:
            r = yaml.safe_load(fh)
        load, unload = r['loading'], r['unloading'] or []
        poured = float(r['bulk_density_poured'])
        # every point a (pressure, density) pair of numbers
        load = [(float(p[0]), float(p[1])) for p in load]
        unload = [(float(p[0]), float(p[1])) for p in unload]
        if not load:
            raise ValueError('no loading points')
    except (OSError, yaml.YAMLError, KeyError, TypeError, ValueError, IndexError) as e:
        why = 'no key %s (is it the result of a uniaxial_compression scene?)' % e if isinstance(e, KeyError) else e
        sys.exit('dm-plot-compression: cannot read %s: %s' % (a.result, why))
    fig, ax = plt.subplots(figsize=(7, 4.5))
    ax.plot([p[0] * 1e-3 for p in load], [p[1] for p in load], 'o-', label='loading')
    if unload:
        ax.plot([load[-1][0] * 1e-3] + [p[0] * 1e-3 for p in unload], [load[-1][1]] + [p[1] for p in unload], 's--',
                label='unloading')
    ax.axhline(poured, color='gray', lw=0.8, ls=':', label='poured')
    if r.get('bulk_density_released'):
        ax.axhline(r['bulk_density_released'], color='k', lw=0.8, ls='-.', label='piston removed')
    ax.set_xscale('log')
    ax.set_xlabel('normal pressure [kPa]')
    ax.set_ylabel('bulk density [kg/m^3]')
    ax.set_title('Uniaxial compression, f = %g (paper fig. 9)' % r.get('cohesion_factor', float('nan')))
    ax.grid(alpha=0.3, which='both')
    ax.legend()
    out = a.out or os.path.splitext(a.result)[0] + '.png'
    fig.tight_layout()
    save_figure(fig, out, 'dm-plot-compression')
    print('plot: %s' % out)


if __name__ == '__main__':
    main()
