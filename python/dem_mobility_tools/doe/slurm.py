"""The Slurm backend of `doe run` (docs/doe.md): the cases to run as one job array (`sbatch
--array`, one case per task, at most --jobs at once), each task `doe case --out OUT --index K` on
the shared DOE folder; the tasks' states from `sacct`; the wait with progress and ETA.

States: `sacct -j JOB -X` where the cluster keeps accounting (slurmdbd); else `sacct -c` (the job
completion log, jobcomp/filetxt: finished tasks, by their raw job ids) joined with `squeue -t all`
for the array task ids; else `squeue -t all` alone (tasks within MinJobAge). The results always
come from the cases' own files.
"""
import math
import os
import shlex
import subprocess
import sys
import time

from ..paths import PYTHON_DIR
from . import runner

ARRAY_SCRIPT = 'doe_array.sh'
DONE_STATES = {'COMPLETED', 'FAILED', 'CANCELLED', 'TIMEOUT', 'NODE_FAIL', 'OUT_OF_MEMORY', 'PREEMPTED',
               'BOOT_FAIL', 'DEADLINE'}


class SlurmError(runner.RunnerError):
    pass


def ranges(indices):
    """'0-3,5,7-8' for [0, 1, 2, 3, 5, 7, 8]."""
    out, xs = [], sorted(set(indices))
    k = 0
    while k < len(xs):
        j = k
        while j + 1 < len(xs) and xs[j + 1] == xs[j] + 1:
            j += 1
        out.append('%d' % xs[k] if j == k else '%d-%d' % (xs[k], xs[j]))
        k = j + 1
    return ','.join(out)


def _call(argv, what):
    try:
        p = subprocess.run(argv, capture_output=True, text=True, timeout=60)
    except FileNotFoundError:
        raise SlurmError('%s: %s not found (install slurm-client; scripts/lib.sh DM_SLURM_PACKAGES)' % (what, argv[0]))
    except subprocess.TimeoutExpired:
        raise SlurmError('%s: %s did not answer in 60 s' % (what, ' '.join(argv)))
    return p


def write_array_script(out, doc, base_port=11711):
    """The job array's script: each task runs its case (`doe case`) with its own ROS master port."""
    d = os.path.join(out, 'slurm')
    os.makedirs(d, exist_ok=True)
    path = os.path.join(d, ARRAY_SCRIPT)
    with open(path, 'w') as fh:
        fh.write('#!/bin/bash\n')
        fh.write('# one case of the DOE in %s per task (doe run --backend slurm wrote this)\n' % os.path.abspath(out))
        fh.write('#SBATCH --job-name=dm_doe\n')
        fh.write('#SBATCH --output=%s/%%A_%%a.out\n' % os.path.abspath(d))
        fh.write('#SBATCH --cpus-per-task=%d\n' % int(doc.get('dem_threads', 1)))
        # the package as this process imports it (a worker node may start with another PYTHONPATH)
        fh.write('export PYTHONPATH=%s${PYTHONPATH:+:$PYTHONPATH}\n' % shlex.quote(PYTHON_DIR))
        fh.write('exec %s --out %s --index "$SLURM_ARRAY_TASK_ID" --port $((%d + 2 * (SLURM_ARRAY_TASK_ID %% 500)))\n'
                 % (' '.join(shlex.quote(x) for x in runner.DOE_CASE), shlex.quote(os.path.abspath(out)), base_port))
    os.chmod(path, 0o755)
    return path


def submit(out, doc, indices, parallel, partition=None, time_limit=None, extra=()):
    """Submits the cases `indices` as one job array, at most `parallel` tasks at once. Returns the
    job id (also appended to OUT/slurm/jobs.yaml)."""
    script = write_array_script(out, doc)
    argv = ['sbatch', '--parsable', '--array=%s%%%d' % (ranges(indices), parallel), '--chdir', os.path.abspath(out)]
    if partition:
        argv += ['--partition', partition]
    if time_limit:
        argv += ['--time', '%d' % max(1, math.ceil(time_limit / 60.0))]  # whole minutes, never below the limit
    argv += list(extra) + [script]
    p = _call(argv, 'sbatch')
    if p.returncode != 0:
        raise SlurmError('sbatch refused the job array (%s): %s' % (' '.join(argv), p.stderr.strip()))
    job = p.stdout.strip().split(';')[0]
    if not job.isdigit():
        raise SlurmError('sbatch answered %r, not a job id' % p.stdout.strip())
    jobs = runner.read_result(os.path.join(out, 'slurm', 'jobs.yaml')) or {'jobs': []}
    jobs['jobs'].append({'job': job, 'tasks': ranges(indices), 'parallel': parallel, 'submitted': runner.utc_now(),
                         'argv': argv})
    runner.write_yaml(os.path.join(out, 'slurm', 'jobs.yaml'), jobs)
    return job


def recorded_jobs(out):
    return [j['job'] for j in (runner.read_result(os.path.join(out, 'slurm', 'jobs.yaml')) or {}).get('jobs', [])]


def _squeue(job):
    """{task: (state, raw job id)} from squeue -t all."""
    p = _call(['squeue', '-h', '-j', job, '-t', 'all', '-r', '-o', '%K|%T|%A'], 'squeue')
    out = {}
    if p.returncode != 0:
        return out
    for line in p.stdout.splitlines():
        f = line.strip().split('|')
        if len(f) == 3 and f[0].isdigit():
            out[int(f[0])] = (f[1], f[2])
    return out


def task_states(job):
    """({task index: state}, source): the array's tasks' Slurm states (PENDING, RUNNING,
    COMPLETED, FAILED, TIMEOUT, ...)."""
    p = _call(['sacct', '-j', job, '-X', '-n', '-P', '-o', 'JobID,State'], 'sacct')
    if p.returncode == 0 and p.stdout.strip():
        states = {}
        for line in p.stdout.splitlines():
            jid, _, state = line.partition('|')
            base, _, task = jid.partition('_')
            if base == job and task.isdigit():
                states[int(task)] = state.split()[0]
        return states, 'sacct'
    q = _squeue(job)
    states = {k: v[0] for k, v in q.items()}
    p = _call(['sacct', '-c', '-n', '-P', '-o', 'JobID,State'], 'sacct')
    if p.returncode == 0 and p.stdout.strip():
        raw = {}
        for line in p.stdout.splitlines():
            jid, _, state = line.partition('|')
            raw[jid.strip()] = state.split()[0] if state.strip() else ''
        for k, (_, rid) in q.items():
            if rid in raw and raw[rid]:
                states[k] = raw[rid]
        return states, 'sacct -c (job completion log) and squeue'
    return states, 'squeue'


def wait(out, doc, job, indices, parallel, poll=2.0, stream=None, timeout=None):
    """Waits until Slurm reports every task of `indices` ended, printing a line per case finished
    (from the cases' files) with the ETA; returns the final task states. Ctrl-C cancels the job
    (scancel) and raises."""
    stream = stream or sys.stdout
    t0 = time.time()
    seen = {k for k, (s, _) in runner.scan(out, doc).items() if s in ('simulated', 'implied')}
    try:
        while True:
            time.sleep(poll)
            states = runner.scan(out, doc)
            for k, (s, r) in sorted(states.items()):
                if s in ('simulated', 'implied') and k not in seen:
                    seen.add(k)
                    c = doc['cases'][k]
                    what = ('implied %s by %s' % (r['implied_status'], r['implied_by']) if s == 'implied' else
                            '%s %.3f m/s' % (r.get('status'), float(r.get('speed_made_good') or 0.0)))
                    left = sum(1 for x, _ in states.values() if x in ('pending', 'running', 'interrupted'))
                    print('[%6.0f s] done   %-14s %s  [%d left]  ETA ~%.0f min' % (
                        time.time() - t0, c['name'], what, left,
                        runner.eta_seconds(doc, states, parallel, runner.measured_ratio(out, doc, states)) / 60.0),
                        file=stream, flush=True)
            ts, _ = task_states(job)
            if set(indices) <= set(ts) and all(ts[k] in DONE_STATES for k in indices):
                break
            if timeout is not None and time.time() - t0 > timeout:
                raise SlurmError('job %s: not finished after %.0f s' % (job, timeout))
    except KeyboardInterrupt:
        _call(['scancel', job], 'scancel')
        raise
    return task_states(job)


def record_lost_tasks(out, doc, indices, states):
    """A task that ended (in Slurm's view) without its case's result (killed, timed out, a worker
    that could not start): its case is recorded as failed with the task's state and output file
    (under the lock; a result there by now is never replaced), so that status and --resume see
    it. Returns the cases recorded."""
    lost = []
    now = runner.scan(out, doc)
    for k in indices:
        s = states.get(k)
        if s in DONE_STATES and now[k][0] in ('pending', 'running', 'interrupted'):
            c = doc['cases'][k]
            if runner.record_failure(out, doc, c, 'the Slurm task ended %s without the case\'s result; see %s' % (
                    s, os.path.join(out, 'slurm', '*_%d.out' % k)), kind='doe_task'):
                lost.append(k)
    return lost


def reconcile(out, doc):
    """Before `doe status` and `doe run --resume`: the recorded jobs' tasks that ended without a
    result are recorded as failed (a task killed by its time limit or scancel leaves its marker).
    Returns (tasks still pending or running, lines to print)."""
    active, lines = 0, []
    for job in recorded_jobs(out):
        try:
            tasks, source = task_states(job)
        except SlurmError as e:
            lines.append('slurm job %s: %s' % (job, e))
            continue
        active += sum(1 for v in tasks.values() if v not in DONE_STATES)
        lost = record_lost_tasks(out, doc, sorted(tasks), tasks)
        counts = {}
        for v in tasks.values():
            counts[v] = counts.get(v, 0) + 1
        lines.append('slurm job %s: %s (from %s)%s' % (
            job, ', '.join('%d %s' % (n, k) for k, n in sorted(counts.items())) or 'no task known (finished long ago?)',
            source, '; %d ended without a result: recorded failed' % len(lost) if lost else ''))
    lines += record_forgotten_tasks(out, doc)
    return active, lines


def record_forgotten_tasks(out, doc):
    """A `running` marker of a Slurm task (its raw job id in the marker) whose job Slurm no longer
    has pending or running: squeue lists it no more (it forgets a finished job after MinJobAge,
    and without accounting sacct cannot name it), so the task ended; its case is recorded failed
    (a result there by now is never replaced). Without this a task killed on another host would
    leave a marker that counts as alive for ever. Returns the lines to print."""
    lines = []
    for k, (state, _) in sorted(runner.scan(out, doc).items()):
        if state != 'running':
            continue
        case = doc['cases'][k]
        rid = (runner.read_result(runner.marker_path(out, case)) or {}).get('slurm_job')
        if not rid:
            continue
        p = _call(['squeue', '-h', '-j', str(rid), '-o', '%T'], 'squeue')
        gone = (p.returncode == 0 and not p.stdout.strip()) or (p.returncode != 0 and 'Invalid job id' in p.stderr)
        if gone and runner.record_failure(out, doc, case, 'its Slurm task (job %s) ended without the case\'s result; '
                                          'see %s' % (rid, os.path.join(out, 'slurm', '*_%d.out' % k)),
                                          kind='doe_task'):
            lines.append('%s: its Slurm task (job %s) is no longer pending or running: recorded failed'
                         % (case['name'], rid))
    return lines
