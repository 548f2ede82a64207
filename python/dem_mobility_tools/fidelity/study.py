"""dm-fidelity-study: the fidelity study of the vehicle on the moving soil patch: runs the soil scene through
roslaunch (soil_slope.launch, the launch file and nodelets a user runs) for every fidelity level
and case (grade, cone index), one run at a time by default, and writes into OUT:

  runs/<level>_g<grade>_ci<ci>.bag (+ .result.yaml, .log)   every run
  study.yaml     per case and level: speed-made-good, status, wall time (preparation included),
                 simulated time, particles, and the error against the finest level that ran; per
                 level its error estimate (the largest of those errors: levels.<level>.speed_error
                 of config/terrains/soil_patch.yaml) and the default level by the rule: the
                 cheapest level within 1 m/s of the finest in every case
  study.md       the same as a Markdown table and list (docs/vehicle-on-soil.md takes it)
  study.png      speed-made-good against wall time, one line per case, the finest level marked
  histories.png  speed, command and lateral offset against time of every run (--runner core)

    dm-fidelity-study --levels tiny,coarse --cases 12:100,0:50 --out results/soil_fidelity

--runner core runs dm_run_scene (dem_mobility_tools.paths) instead of roslaunch: the same core loop in one
process, without the ROS layer and without a bag (a developer's check, or a study on a machine
where the ROS build is not wanted). Its runs keep a checkpoint (runs/<case>.ckpt, every
--checkpoint-every wall seconds): a run that was stopped goes on from it, bit for bit, when the
study runs again with --resume (its wall time counts the parts it ran, not the pause; the log of
each part before is kept as runs/<case>.part<N>.log). A failed
run is reported and the others are kept; the exit status is 1 if any run failed.
"""
import argparse
import os
import sys

import yaml

from .. import names, paths
from .. import sweep as dm_sweep
from ..paths import ROOT
from ..runs import scene_command
from ..sweep.args import keep_options
from ..sweep.figures import save_figure

# particle diameter of each level (config/terrains/soil_patch.yaml), finest first
LEVEL_ORDER = ['paper', 'fine', 'medium', 'coarse', 'tiny']
STATUSES = ('steady', 'command_limited', 'no_go', 'not_steady')


def parse_cases(text):
    out = []
    for item in text.split(','):
        try:
            g, ci = item.split(':')
            out.append((float(g), float(ci)))
        except ValueError:
            raise argparse.ArgumentTypeError('expected GRADE:CI pairs separated by commas, got %r' % item)
    return out


def case_name(p):
    return '%s_g%g_ci%g' % (p['level'], p['grade_deg'], p['cone_index_psi'])


def case_params(a, case):
    """A case's parameters of soil_slope.launch (runs.LAUNCHES)."""
    return [('fidelity', case['level']), ('grade_deg', float(case['grade_deg'])),
            ('cone_index', float(case['cone_index_psi'])),
            ('dem_threads', a.dem_threads), ('duration', float(a.duration))]


def roslaunch_command(a, case, port):
    return scene_command('roslaunch', 'soil_slope.launch', case_params(a, case), scene=a.scene, port=port,
                         bag=os.path.join(a.out, 'runs', case.name + '.bag'),
                         launch_args=[('cloud_rate', float(a.cloud_rate))])


def core_command(a, case, result_file):
    """dm_run_scene for one case, with its checkpoint beside its result (--checkpoint-every): a run
    that was stopped (a signal, a timeout, the machine going down) is taken up from its checkpoint,
    bit for bit, when the case runs again (--resume)."""
    checkpoint = os.path.abspath(result_file.replace('.result.yaml', '.ckpt'))
    options = []
    if a.checkpoint_every > 0:
        options += ['--checkpoint', checkpoint, '--checkpoint-every', '%g' % a.checkpoint_every]
        if os.path.exists(checkpoint):
            options += ['--restart', checkpoint]
            # the log of the part before is kept (the sweep writes the case's log afresh)
            log = result_file.replace('.result.yaml', '.log')
            if os.path.exists(log):
                k = 1
                while os.path.exists(log[:-4] + '.part%d.log' % k):
                    k += 1
                os.rename(log, log[:-4] + '.part%d.log' % k)
    return scene_command('core', 'soil_slope.launch', case_params(a, case), scene=a.scene, result=result_file,
                         history=result_file.replace('.result.yaml', '.history.csv'), core_options=options,
                         dm_run_scene=a.dm_run_scene)


def check(case, result):
    if result.get('kind') != 'soil_slope':
        return 'the result is of kind %r, not soil_slope' % result.get('kind')
    if result.get('status') not in STATUSES:
        return 'status %r' % result.get('status')
    return None


def same_run(a):
    """accept(case, old result) for --resume: a result of this scene, level, grade and cone index;
    names.OldNameError for a result of an older version (a key under its old name)."""
    def accept(case, old):
        names.refuse_old_keys(old, os.path.join(a.out, 'runs', case_name(case) + '.result.yaml'))
        try:
            return (os.path.realpath(str(old.get('scene'))) == os.path.realpath(a.scene)
                    and old.get('fidelity') == case['level']
                    and abs(float(old.get('grade_deg')) - case['grade_deg']) < 1e-9
                    and abs(float(old.get('requested_cone_index_psi')) - case['cone_index_psi']) < 1e-9)
        except (TypeError, ValueError):
            return False
    return accept


def check_options(a, out):
    """The options a result depends on and no result file holds (the driving time, the runner, the
    scene), kept in OUT; --resume with others is refused naming the option."""
    try:
        keep_options(out, {'--scene': os.path.abspath(a.scene), '--duration': a.duration, '--runner': a.runner},
                     a.resume)
    except ValueError as e:
        raise SystemExit('dm-fidelity-study: %s' % e)


def number(x):
    try:
        return float(x)
    except (TypeError, ValueError):
        return float('nan')


def summarize(sweep, cases_gs):
    """Per case: the levels' figures and their error against the finest level that ran."""
    rows = []
    for g, ci in cases_gs:
        runs = {}
        for o in sweep.outcomes:
            if o.case['grade_deg'] == g and o.case['cone_index_psi'] == ci and o.ok:
                r = o.result
                runs[o.case['level']] = {
                    'speed_made_good': number(r.get('speed_made_good')),
                    'status': r.get('status'),
                    'wall_time': number(r.get('wall_time')) + number(r.get('soil_prepare_wall_time') or 0.0),
                    'run_wall_time': number(r.get('wall_time')),
                    'prepare_wall_time': number(r.get('soil_prepare_wall_time')),
                    'simulated_time': number(r.get('simulated_time')),
                    'particles': int(number(r.get('particles'))),
                    'particle_diameter': number(r.get('particle_diameter')),
                    'patch_density_ratio': number(r.get('patch_density_ratio')),
                    'cohesion_factor': number(r.get('cohesion_factor')),
                }
        finest = next((l for l in LEVEL_ORDER if l in runs), None)
        for level in LEVEL_ORDER:
            if level not in runs:
                continue
            x = runs[level]
            x['reference'] = finest
            x['error_vs_finest'] = abs(x['speed_made_good'] - runs[finest]['speed_made_good'])
            rows.append(dict(grade_deg=g, cone_index_psi=ci, level=level, **x))
    return rows


def level_summary(rows, tolerance=1.0):
    """Per level: its largest |error| against the finest level over the cases where a finer level
    ran (its error estimate), and the default level by the issue's rule: the cheapest level whose
    speed-made-good is within `tolerance` m/s of the finest level run in every case. Only a level
    that ran every case is a candidate; each case's own finest run is its reference (a finer level
    that ran one case only still rules out a candidate that is off in that case). The choice is
    'provisional' while the chosen level is itself the finest run in some case (nothing finer to
    compare it with there)."""
    cases = sorted({(r['grade_deg'], r['cone_index_psi']) for r in rows})
    ran = {}
    for r in rows:
        ran.setdefault(r['level'], {})[(r['grade_deg'], r['cone_index_psi'])] = r
    complete = [l for l in LEVEL_ORDER if l in ran and all(c in ran[l] for c in cases)]
    finest = {c: next(l for l in LEVEL_ORDER if l in ran and c in ran[l]) for c in cases}
    levels = {}
    for level in LEVEL_ORDER:
        if level not in ran:
            continue
        compared = [x for x in ran[level].values() if x['reference'] != level]
        levels[level] = {
            'cases_run': len(ran[level]),
            'cases_compared': len(compared),
            'speed_error': max((x['error_vs_finest'] for x in compared), default=None),
            'reference': sorted({x['reference'] for x in compared}),
            'wall_time': sum(x['wall_time'] for x in ran[level].values()),
        }
    out = {'tolerance': tolerance, 'cases': [list(c) for c in cases], 'levels': levels, 'default_level': None,
           'rule': 'the cheapest level (wall time over all cases) within %g m/s of the finest level run in every case'
           % tolerance}
    if not complete:
        out['why'] = 'no level ran every case'
        return out
    out['reference_level'] = complete[0]
    within = [l for l in complete
              if all(abs(ran[l][c]['speed_made_good'] - ran[finest[c]][c]['speed_made_good']) <= tolerance
                     for c in cases)]
    if not within:
        out['why'] = ('no level that ran every case is within %g m/s of the finest run in every case' % tolerance)
        return out
    chosen = min(within, key=lambda l: levels[l]['wall_time'])
    out['default_level'] = chosen
    alone = ['%g deg, CI %g' % c for c in cases if finest[c] == chosen]
    out['provisional'] = bool(alone)
    if alone:
        out['why'] = '%s is the finest level run at %s: its own error is not measured' % (chosen, '; '.join(alone))
    return out


def write_table(rows, path):
    with open(path, 'w') as fh:
        fh.write('| grade [deg] | CI [psi] | level | d [m] | particles | speed-made-good [m/s] | status | '
                 '|error| vs finest [m/s] | wall time [s] (preparation) | simulated [s] | re-emitted density ratio |\n')
        fh.write('|---|---|---|---|---|---|---|---|---|---|---|\n')
        for r in rows:
            fh.write('| %g | %g | %s | %g | %d | %.3f | %s | %s | %.0f (%.0f) | %.2f | %.3f |\n' % (
                r['grade_deg'], r['cone_index_psi'], r['level'], r['particle_diameter'], r['particles'], r['speed_made_good'],
                r['status'], 'reference' if r['level'] == r['reference'] else '%.3f' % r['error_vs_finest'],
                r['wall_time'], r['prepare_wall_time'], r['simulated_time'], r['patch_density_ratio']))


def summary_text(summary):
    lines = []
    for level, x in summary['levels'].items():
        err = ('%.3f m/s over %d case(s) against %s' % (x['speed_error'], x['cases_compared'], ', '.join(x['reference']))
               if x['speed_error'] is not None else 'none (no finer level ran its cases)')
        lines.append('- %s: largest |error| vs finest %s; wall time over its %d case(s) %.0f s' % (
            level, err, x['cases_run'], x['wall_time']))
    if summary['default_level']:
        lines.append('- default level by the rule (%s): **%s**%s' % (
            summary['rule'], summary['default_level'],
            ' (provisional: %s)' % summary['why'] if summary.get('provisional') else ''))
    else:
        lines.append('- no default level: %s' % summary['why'])
    return '\n'.join(lines) + '\n'


def plot_histories(runs_dir, names, path):
    """Speed (and command) and lateral offset against time of the runs that wrote a history
    (--runner core's <run>.history.csv): what each run did, one colour per run."""
    import csv
    import matplotlib
    matplotlib.use('Agg')
    import matplotlib.pyplot as plt
    fig, (ax, ay) = plt.subplots(2, 1, figsize=(8, 6), sharex=True, gridspec_kw={'height_ratios': [2, 1]})
    drawn = 0
    for name in names:
        f = os.path.join(runs_dir, name + '.history.csv')
        if not os.path.exists(f):
            continue
        with open(f) as fh:
            rows = list(csv.DictReader(fh))
        if not rows:
            continue
        t = [float(r['t']) for r in rows]
        line, = ax.plot(t, [float(r['speed']) for r in rows], lw=1.2, label=name)
        ax.plot(t, [float(r['speed_command']) for r in rows], lw=0.8, ls='--', color=line.get_color())
        ay.plot(t, [float(r['y']) for r in rows], lw=1.0, color=line.get_color())
        drawn += 1
    if not drawn:
        plt.close(fig)
        return None
    ax.set_ylabel('speed [m/s] (dashed: command)')
    ax.set_title('The study runs: speed and lateral offset')
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize=8)
    ay.set_xlabel('time since the brakes were let go [s]')
    ay.set_ylabel('lateral offset y [m]')
    ay.grid(True, alpha=0.3)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return path


def plot(rows, path, unfinished=()):
    """Speed-made-good against wall time, a line per case; `unfinished`: runs stopped before their
    verdict (rows with grade_deg, cone_index_psi, level, wall_time and the speed reached, speed_reached),
    drawn as open markers with an arrow up: the speed-made-good is at least that, the wall time
    more than that."""
    import matplotlib
    matplotlib.use('Agg')
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(figsize=(7, 4.5))
    for key in sorted({(r['grade_deg'], r['cone_index_psi']) for r in list(rows) + list(unfinished)}):
        rs = [r for r in rows if (r['grade_deg'], r['cone_index_psi']) == key]
        line, = ax.plot([r['wall_time'] for r in rs], [r['speed_made_good'] for r in rs], 'o-',
                        label='%g deg, CI %g psi' % key)
        for r in rs:
            ax.annotate(r['level'] + (' (ref)' if r['level'] == r['reference'] else ''),
                        (r['wall_time'], r['speed_made_good']), textcoords='offset points', xytext=(5, 5), fontsize=8)
        for u in [u for u in unfinished if (u['grade_deg'], u['cone_index_psi']) == key]:
            x, y = u['wall_time'], u['speed_reached']
            if rs:  # (dotted: the case's line to a bound, not to a value)
                ax.plot([rs[-1]['wall_time'], x], [rs[-1]['speed_made_good'], y], ':', color=line.get_color())
            ax.plot([x], [y], 'o', mfc='none', color=line.get_color())
            ax.annotate('', xy=(x, y + 1.5), xytext=(x, y), arrowprops=dict(arrowstyle='->', color=line.get_color()))
            ax.annotate('%s: not finished, >= %.1f m/s\n(%.1f s driven, still rising)' % (u['level'], y, u['simulated_time']),
                        (x, y), textcoords='offset points', xytext=(-125, -4), fontsize=8)
            lo, hi = ax.get_ylim()
            ax.set_ylim(lo, max(hi, y + 2.0))
    ax.set_xscale('log')
    ax.set_xlabel('wall time of the run, preparation included [s] (2-core machine)')
    ax.set_ylabel('speed-made-good [m/s]')
    ax.set_title('Speed-made-good against run time per fidelity level')
    ax.grid(True, which='both', alpha=0.3)
    ax.legend(loc='lower right')
    fig.tight_layout()
    save_figure(fig, path, 'dm-fidelity-study')
    plt.close(fig)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument('--scene', default=os.path.join(ROOT, 'config', 'scenes', 'soil_slope.yaml'))
    ap.add_argument('--levels', default='tiny,coarse', help='fidelity levels (default tiny,coarse)')
    ap.add_argument('--cases', type=parse_cases, default=parse_cases('12:100,0:50'),
                    help='GRADE:CI pairs: grade [deg], cone index [psi] (default 12:100,0:50)')
    ap.add_argument('--duration', type=float, default=40.0, help='longest driving time [s] (the run ends when steady)')
    ap.add_argument('--jobs', type=int, default=1)
    ap.add_argument('--dem-threads', type=int, default=1)
    ap.add_argument('--cloud-rate', type=float, default=2.0, help='particle clouds per simulated second in each bag')
    ap.add_argument('--timeout', type=float, default=6 * 3600.0, help='longest a run may take [s]')
    ap.add_argument('--port', type=int, default=11511)
    ap.add_argument('--runner', choices=('roslaunch', 'core'), default='roslaunch')
    ap.add_argument('--dm-run-scene', default=None,
                    help='--runner core: ' + paths.RUNNER_HELP)
    ap.add_argument('--resume', action='store_true', help='keep the runs whose result is already good')
    ap.add_argument('--checkpoint-every', type=float, default=600.0,
                    help='--runner core: wall seconds between checkpoints of a run (0: none); a run that was '
                         'stopped goes on from its checkpoint when it runs again')
    ap.add_argument('--out', default='results/soil_fidelity')
    a = ap.parse_args(argv)
    levels = [l for l in a.levels.split(',') if l]
    bad = [l for l in levels if l not in LEVEL_ORDER]
    if bad:
        ap.error('unknown level(s) %s (have %s)' % (', '.join(bad), ', '.join(LEVEL_ORDER)))
    params = [dict(level=l, grade_deg=g, cone_index_psi=ci) for g, ci in a.cases for l in levels]
    cases = dm_sweep.cases(params, name=case_name)
    if a.runner == 'core':
        a.dm_run_scene = paths.dm_run_scene(a.dm_run_scene)
        if not os.access(a.dm_run_scene, os.X_OK):
            ap.error('--runner core: ' + paths.missing_runner_message(a.dm_run_scene))
        command = lambda case, o: core_command(a, case, o.result_file)  # noqa: E731
    else:
        command = lambda case, o: roslaunch_command(a, case, o.port)  # noqa: E731
    check_options(a, a.out)
    try:
        sweep = dm_sweep.run_sweep(cases, command, os.path.join(a.out, 'runs'), resume=a.resume, accept=same_run(a),
                                   jobs=a.jobs,
                                   port=a.port, timeout=a.timeout, check=check, accept_status=STATUSES,
                                   summary=os.path.join(a.out, 'sweep.yaml'))
    except names.OldNameError as e:
        sys.exit('dm-fidelity-study: --resume: %s' % e)
    except KeyboardInterrupt:  # (Ctrl-C or SIGTERM: the runs were stopped and the summary written)
        sys.exit('dm-fidelity-study: interrupted; the finished runs are in %s; the same command with '
                 '--resume goes on%s' % (os.path.join(a.out, 'runs'),
                                         ' (a stopped run from its checkpoint)' if a.runner == 'core' and
                                         a.checkpoint_every > 0 else ''))
    rows = summarize(sweep, a.cases)
    summary = level_summary(rows)
    with open(os.path.join(a.out, 'study.yaml'), 'w') as fh:
        yaml.safe_dump({'runner': a.runner, 'levels': levels, 'rows': rows, 'summary': summary}, fh,
                       sort_keys=False)
    if rows:
        write_table(rows, os.path.join(a.out, 'study.md'))
        with open(os.path.join(a.out, 'study.md'), 'a') as fh:
            fh.write('\n' + summary_text(summary))
        plot(rows, os.path.join(a.out, 'study.png'))
        plot_histories(os.path.join(a.out, 'runs'), [c.name for c in cases], os.path.join(a.out, 'histories.png'))
        print(open(os.path.join(a.out, 'study.md')).read())
    return sweep.exit_status()


if __name__ == '__main__':
    sys.exit(main())
