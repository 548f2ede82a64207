"""dm-calibrate's plots of a sweep's runs (matplotlib, Agg)."""
import os


def plots(runs, out, mus, fits):
    """The sweep's plots in OUT: CI against time per mu (fig. 13) and CI against f with the tables and
    the paper's table 3 (fig. 14). Returns the files written."""
    from .cone_index import PAPER_TABLE, mean_points
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
            ax.plot(h['t'], h['cone_index_psi'], lw=1.2, label='f = %g, seed %d%s' % (r.f, r.seed, '' if r.ok() else ' (failed)'))
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
        line = ax.plot([p[0] for p in pts], [p[1] for p in pts], 'o', mfc='none', label='runs, mu = %g' % mu)[0]
        mp = mean_points(pts)
        ax.errorbar([p[0] for p in mp], [p[1] for p in mp], yerr=[p[2] or 0.0 for p in mp], fmt='s',
                    color=line.get_color(), capsize=3, label='mean and std over the seeds, mu = %g' % mu)
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
