"""dm-plot-speed: the speed time history of a run, as in the paper's figures 21/22: the vehicle's speed and the
driver's speed command against time from the driver's start, with the speed-made-good (road and
soil runs alike: the same odom, driver_command and result topics).

    dm-plot-speed RUN.bag [-o RUN.png] [--ns /mobility]
"""
import argparse
import os
import sys

from ..sweep.figures import save_figure


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument('bag')
    ap.add_argument('-o', '--out', help='PNG file (default: the bag with .png)')
    ap.add_argument('--ns', default='/mobility', help='namespace of the run (default /mobility)')
    a = ap.parse_args(argv)
    import matplotlib
    matplotlib.use('Agg')
    import matplotlib.pyplot as plt
    import rosbag
    ns = a.ns.rstrip('/') + '/'
    out = a.out or os.path.splitext(a.bag)[0] + '.png'
    t, v, tc, vc, wot = [], [], [], [], []
    result = None
    try:
        bag = rosbag.Bag(a.bag)
    except Exception as e:  # missing, truncated or not a bag
        sys.exit('dm-plot-speed: cannot read %s: %s' % (a.bag, e))
    with bag:
        for topic, m, _ in bag.read_messages(topics=[ns + 'odom', ns + 'driver_command', ns + 'result']):
            if topic.endswith('odom'):
                t.append(m.header.stamp.to_sec())
                v.append(m.twist.twist.linear.x)
            elif topic.endswith('driver_command'):
                tc.append(m.header.stamp.to_sec())
                vc.append(m.speed_command)
                wot.append(m.wot_limited)
            else:
                result = m
    if not t:
        sys.exit('dm-plot-speed: %s has no %sodom messages' % (a.bag, ns))
    t0 = tc[0] if tc else 0.0  # the driver's start
    fig, ax = plt.subplots(figsize=(8, 4.5))
    ax.plot([x - t0 for x in t], v, label='vehicle speed', color='tab:blue')
    if tc:
        ax.plot([x - t0 for x in tc], vc, '--', label='speed command', color='tab:gray')
        lim = [x - t0 for x, w in zip(tc, wot) if w]
        if lim:
            ax.axvspan(min(lim), max(lim), color='tab:orange', alpha=0.12, label='full throttle (WOT)')
    title = 'speed time history'
    if result is not None:
        title = '%s: grade %.1f deg, speed-made-good %.2f m/s (%s)' % (
            os.path.basename(result.scene), result.grade_deg, result.speed_made_good, result.status)
        if getattr(result, 'fidelity', ''):  # a DEM soil (bags of older runs have no such field)
            ci = result.cone_index_psi
            title += '\nsoil level %s, cone index %s' % (result.fidelity, 'unknown' if ci != ci else '%.0f psi' % ci)
        if result.status in ('steady', 'command_limited'):
            ax.axhline(result.speed_made_good, color='tab:red', lw=0.8, label='speed-made-good')
    ax.set_title(title, fontsize=10)
    ax.set_xlabel('time since the driver started [s]')
    ax.set_ylabel('speed [m/s]')
    ax.set_xlim(left=0)
    ax.set_ylim(bottom=min(0.0, min(v)))
    ax.grid(alpha=0.3)
    ax.legend(loc='lower right', fontsize=8)
    fig.tight_layout()
    save_figure(fig, out, 'dm-plot-speed')
    print(out)


if __name__ == '__main__':
    main()
