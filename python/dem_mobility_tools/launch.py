"""dm-launch: roslaunch, with the exit status of the run it launched.

    dm-launch [roslaunch arguments]      e.g. dm-launch dem_mobility soil_slope.launch grade:=20

roslaunch exits 0 whatever its nodes did (a run that failed, a peer killed mid-run, a bag that could
not be written). dm-launch takes the same arguments, finds the result file(s) the launch's nodelets
write (their `result_file` parameters, from `roslaunch --dump-params`), removes stale ones, runs
roslaunch, and exits with what the run's result says:

    0  the run ended with a verdict (ok, steady, command_limited, no_go, not_steady, sunk)
    1  the run failed (status error; the error is printed)
    2  usage, or a launch without a result_file
    3  the run wrote no result (the launch itself failed, or its manager was killed)
    4  the run was interrupted (SIGINT, SIGTERM: both are passed on to roslaunch)
"""
import os
import signal
import subprocess
import sys

import yaml

from .runs import read_result

VERDICTS = {'ok', 'steady', 'command_limited', 'no_go', 'not_steady', 'sunk'}


def result_files(args):
    """The result_file parameters of the launch (none when it cannot be read: roslaunch says why)."""
    p = subprocess.run(['roslaunch', '--dump-params'] + args, capture_output=True, text=True)
    if p.returncode != 0:
        sys.stderr.write(p.stdout + p.stderr)
        return None
    params = yaml.safe_load(p.stdout) or {}
    return sorted({v for k, v in params.items() if k.endswith('/result_file') and isinstance(v, str) and v})


def main(argv=None):
    if argv is None:
        argv = sys.argv[1:]
    if not argv or argv[0] in ('-h', '--help'):
        print(__doc__.strip())
        return 0 if argv else 2
    files = result_files(argv)
    if files is None:
        return 2
    if not files:
        print('dm-launch: the launch names no result_file: nothing to take the run\'s status from', file=sys.stderr)
        return 2
    for f in files:
        if os.path.exists(f):
            os.remove(f)
    # roslaunch in a process group of its own: Ctrl-C reaches dm-launch alone, which passes it on
    # once; roslaunch then stops its nodes with SIGINT
    child = subprocess.Popen(['roslaunch'] + argv, process_group=0)
    for s in (signal.SIGINT, signal.SIGTERM):
        signal.signal(s, lambda sig, _frame: child.send_signal(sig))
    child.wait()
    status = []
    for f in files:
        r, why = read_result(f)
        if r is None or not r.get('status'):
            print('dm-launch: the run wrote no result (%s)' % (why or f + ': no status'), file=sys.stderr)
            return 3
        status.append((r['status'], r.get('error', ''), f))
    for s, err, f in status:
        if s == 'error':
            print('dm-launch: the run failed: %s (%s)' % (err, f), file=sys.stderr)
            return 1
    for s, err, f in status:
        if s == 'interrupted':
            print('dm-launch: the run was interrupted%s (%s)' % (': ' + err if err else '', f), file=sys.stderr)
            return 4
    for s, err, f in status:
        if s not in VERDICTS:
            print('dm-launch: unknown status %r (%s)' % (s, f), file=sys.stderr)
            return 1
    print('dm-launch: %s (%s)' % (', '.join(s for s, _, _ in status), ', '.join(files)))
    return 0


if __name__ == '__main__':
    sys.exit(main())
