"""The local pool of a sweep: runs a command per case, N at a time, each in its own process group
with its own ROS master port, a timeout and its console output in a log file; a run's outcome is
read from the result YAML it writes; resume keeps the cases whose result is already good."""
import os
import re
import select
import signal
import threading
import subprocess
import time

import yaml

from ..runs import port_free, read_result
from .progress import Progress


def last_progress(log, marker='progress:'):
    """The text after `marker` on the last line of the log holding it (ANSI colours removed);
    'starting' if no line holds it yet, '' if the log cannot be read."""
    try:
        with open(log, 'rb') as fh:
            fh.seek(0, 2)
            fh.seek(max(0, fh.tell() - 4000))
            lines = fh.read().decode('utf-8', 'replace').splitlines()
    except OSError:
        return ''
    for line in reversed(lines):
        k = line.find(marker)
        if k >= 0:
            return re.sub(r'\x1b\[[0-9;]*m', '', line[k + len(marker):]).strip()
    return 'starting'


class _Wake:
    """The pool's pause between looks at its runs: up to `poll` seconds, cut short when a child
    process ends. On the main thread SIGCHLD is routed to a pipe (signal.set_wakeup_fd: written by
    the interpreter itself, so the handler takes no lock a signal could interrupt) that the pause
    selects on; elsewhere, a plain sleep."""

    def __init__(self, poll):
        self.poll = poll
        self.fds = None
        if threading.current_thread() is not threading.main_thread():
            return
        r, w = os.pipe()
        os.set_blocking(r, False)
        os.set_blocking(w, False)
        try:
            self.old_fd = signal.set_wakeup_fd(w)
        except ValueError:
            os.close(r)
            os.close(w)
            return
        self.old_chld = signal.signal(signal.SIGCHLD, lambda signum, frame: None)
        self.fds = (r, w)

    def nap(self):
        if self.fds is None:
            time.sleep(self.poll)
            return
        select.select([self.fds[0]], [], [], self.poll)
        try:  # (drained before the look at the runs: a run that ends after it writes again)
            while os.read(self.fds[0], 512):
                pass
        except BlockingIOError:
            pass

    def close(self):
        if self.fds is None:
            return
        signal.signal(signal.SIGCHLD, self.old_chld)
        signal.set_wakeup_fd(self.old_fd)
        for fd in self.fds:
            os.close(fd)
        self.fds = None


class Outcome:
    """What became of a case: its result document, its error (None if it succeeded), its times, its
    port, its log and result files, whether it was kept from an earlier sweep (resume)."""

    def __init__(self, case, result_file, log):
        self.case = case
        self.name = case.name
        self.result_file = result_file
        self.log = log
        self.port = None
        self.slot = None
        self.proc = None
        self.logf = None
        self.argv = None
        self.start = self.end = None
        self.result = None
        self.error = None
        self.returncode = None
        self.kept = False
        self.timed_out = False

    @property
    def done(self):
        return self.kept or self.end is not None

    @property
    def ok(self):
        return self.done and self.error is None

    @property
    def wall_time(self):
        return (self.end or 0) - (self.start or 0)

    def __repr__(self):
        return 'Outcome(%s, %s)' % (self.name, 'ok' if self.ok else self.error or 'not run')


class Sweep:
    """Runs cases through a command, `jobs` at a time.

    command: a callable (case, outcome) -> argv (outcome.port, .result_file and .log are set), or a
      list of strings formatted with the case's parameters and name, port, result, log, runs_dir
      (e.g. ['my_rig', '--slip={slip}', '--out={result}']).
    runs_dir: where each case's result (<name>.result.yaml) and console log (<name>.log) go.
    port: the first ROS master port; the runs at a time take port, port + 2, ... (a port something
      already listens on is replaced by one further up); each run's environment has ROS_MASTER_URI
      on its port, DM_SWEEP_CASE (its name) and DM_SWEEP_RESULT (its result file).
    timeout: longest a run may take [s] (None: no limit); a late run's process group is terminated.
    check: callable (case, result) -> None if the result document is good, else why not ("no sample
      in the window"); applied after the generic checks (the document has no non-empty `error` and
      its `status` is not 'error').
    accept_status: statuses a finished run may report besides 'ok' although its `error` says why
      (e.g. ('sunk',): the wheel sank, a measurement, not a failure); such a run is good (check
      still applies) and resume keeps it. 'error' and 'interrupted' cannot be accepted.
    outputs: callable case -> more files of a run to delete before it starts (e.g. its bag).
    env: extra environment variables (a dict, or a callable (case, outcome) -> dict).
    describe: callable outcome -> the text after a finished run's name (default 'ok' or
      'FAILED: <error>').
    result_of: callable case -> the path of its result file (default <runs_dir>/<name>.result.yaml).
    clear_result: delete a run's result file before it starts (default; False where the command
      itself decides, e.g. `doe case` under its lock).
    on_done: callable outcome -> None, called as each run of this sweep finishes (good or not), before
      the next starts: e.g. keeping a good run's result in git (dm_sweep.keep).
    weight: callable case -> its estimated cost [s] (default 1 each): the progress bar counts in it
      and each finished run's line gives an ETA (the weight left, at the rate of the weight done so
      far in this sweep).
    progress: 'auto', 'tqdm' or 'plain' (see dm_sweep.progress); poll: seconds between checks;
      status_every: seconds between the lines of the running runs' progress (None: never), read
      from their logs after `progress_marker`.
    """

    def __init__(self, cases, command, runs_dir, jobs=1, port=11411, timeout=None, check=None, outputs=None,
                 env=None, describe=None, progress='auto', poll=1.0, status_every=20.0,
                 progress_marker='progress:', kill_grace=30.0, stream=None, accept_status=(), result_of=None,
                 weight=None, clear_result=True, on_done=None):
        if jobs < 1:
            raise ValueError('jobs must be >= 1')
        self.accept_status = tuple(accept_status)
        if set(self.accept_status) & {'error', 'interrupted'}:
            raise ValueError('accept_status %r: error and interrupted are failures' % (self.accept_status,))
        names = [c.name for c in cases]
        if len(set(names)) != len(names):
            raise ValueError('case names repeat in %r' % names)
        self.cases = list(cases)
        self.command = command
        self.runs_dir = runs_dir
        self.jobs = jobs
        self.port = port
        self.timeout = timeout
        self.check = check
        self.outputs = outputs
        self.env = env
        self.describe = describe or (lambda o: 'ok' if o.ok else 'FAILED: %s' % o.error)
        self.progress_mode = progress
        self.poll = poll
        self.status_every = status_every
        self.progress_marker = progress_marker
        self.kill_grace = kill_grace
        self.stream = stream
        self.t0 = None
        self.result_of = result_of
        self.clear_result = clear_result
        self.on_done = on_done
        self.weighted = weight is not None
        self.weight = weight or (lambda case: 1.0)
        self.outcomes = [Outcome(c, self.result_path(c), self.log_path(c)) for c in self.cases]
        self._progress = None
        os.makedirs(runs_dir, exist_ok=True)

    # -- files and verdicts
    def result_path(self, case):
        if self.result_of is not None:
            return self.result_of(case)
        return os.path.join(self.runs_dir, case.name + '.result.yaml')

    def log_path(self, case):
        return os.path.join(self.runs_dir, case.name + '.log')

    def line(self, text):
        if self._progress is not None:
            self._progress.line(text)
        else:
            import sys
            print(text, file=self.stream or sys.stdout, flush=True)

    def verdict(self, case, result, log):
        """None if a run's result document is good, else the error."""
        if not isinstance(result, dict):
            return 'the result file holds no mapping; see %s' % log
        err = result.get('error') or ''
        if result.get('status') in self.accept_status:
            err = ''  # it only explains the status
        if err or result.get('status') == 'error':
            return str(err) if err else 'the run failed; see %s' % log
        if self.check is not None:
            why = self.check(case, result)
            if why:
                return '%s; see %s' % (why, log)
        return None

    # -- resume
    def resume(self, accept=None):
        """Keeps the cases whose result file exists and is good (and accepted by accept(case,
        result), e.g. the same level and parameters); prints a 'kept' line for each. Returns the kept
        outcomes; the others run in run()."""
        kept = []
        for o in self.outcomes:
            if o.done:
                continue
            old, _ = read_result(o.result_file)
            if not isinstance(old, dict) or self.verdict(o.case, old, o.log) is not None:
                continue
            # how the run that left it ended: a good result of a run that exited non-zero, timed
            # out or was stopped is not kept (the result itself is judged again, by this sweep's
            # checks; no outcome file: a run of an older sweep)
            ended, _ = read_result(self._outcome_file(o))
            if isinstance(ended, dict) and not ended.get('ended_well'):
                continue
            if accept is not None and not accept(o.case, old):
                continue
            try:
                wall = float(old.get('wall_time', 0.0))
            except (TypeError, ValueError):
                wall = 0.0
            o.result, o.start, o.end, o.kept = old, 0.0, wall, True
            kept.append(o)
            self.line('kept   %-14s %s (from %s)' % (o.name, self.describe(o), o.result_file))
        return kept

    # -- the pool
    def _argv(self, o):
        if callable(self.command):
            return [str(a) for a in self.command(o.case, o)]
        fields = dict(o.case.params, name=o.name, port=o.port, result=o.result_file, log=o.log,
                      runs_dir=self.runs_dir)
        return [a.format(**fields) for a in self.command]

    def _take_port(self, ports, busy):
        slot = ports.pop(0)
        port = slot
        for k in range(64):
            port = slot + 2 * self.jobs * k
            if port not in busy and port_free(port):
                break
        return slot, port

    def outcome_file(self, name):
        """Where the end of the run of case `name` is kept (ok, error, exit status), for a later resume."""
        return os.path.join(self.runs_dir, name + '.outcome.yaml')

    def _outcome_file(self, o):
        return self.outcome_file(o.name)

    def _record(self, o, stopped=False):
        """How the run's process ended (not what its result says: a later sweep judges that by its
        own checks)."""
        ended_well = o.proc is not None and o.returncode == 0 and not o.timed_out and not stopped
        try:
            with open(self._outcome_file(o), 'w') as fh:
                yaml.safe_dump({'ended_well': ended_well, 'returncode': o.returncode, 'timed_out': bool(o.timed_out),
                                'stopped': stopped}, fh, sort_keys=False)
        except OSError:
            pass  # (the outcome is in the summary too; a resume then judges by the result alone)

    def _launch(self, o):
        for p in ([self._outcome_file(o)] + (list(self.outputs(o.case)) if self.outputs else []) +
                  ([o.result_file] if self.clear_result else [])):
            if os.path.exists(p):
                os.remove(p)
        env = dict(os.environ, ROS_MASTER_URI='http://127.0.0.1:%d' % o.port, PYTHONUNBUFFERED='1',
                   ROSCONSOLE_STDOUT_LINE_BUFFERED='1', DM_SWEEP_CASE=o.name,
                   DM_SWEEP_RESULT=os.path.abspath(o.result_file))
        if self.env:
            env.update({k: str(v) for k, v in (self.env(o.case, o) if callable(self.env) else self.env).items()})
        o.argv = self._argv(o)
        o.logf = open(o.log, 'w')
        o.start = time.time()
        try:
            o.proc = subprocess.Popen(o.argv, stdout=o.logf, stderr=subprocess.STDOUT, env=env,
                                      start_new_session=True)
        except OSError as e:
            o.proc = None
            o.error = 'cannot start %s: %s' % (o.argv[0] if o.argv else '(empty command)', e)

    def _kill(self, o, wait=True):
        if o.proc is None or o.proc.poll() is not None:
            return
        try:
            os.killpg(o.proc.pid, signal.SIGTERM)
        except ProcessLookupError:
            pass
        if not wait:
            return
        try:
            o.proc.wait(self.kill_grace)
        except subprocess.TimeoutExpired:
            try:
                os.killpg(o.proc.pid, signal.SIGKILL)
            except ProcessLookupError:
                pass
            o.proc.wait()

    def _reap_group(self, o, grace=2.0):
        """Whatever is left of a run's process group once its leader has ended (a roslaunch
        killed with SIGKILL leaves its master and nodes): SIGTERM, then SIGKILL after `grace` s."""
        if o.proc is None or o.proc.poll() is None:
            return
        for sig in (signal.SIGTERM, signal.SIGKILL):
            try:
                os.killpg(o.proc.pid, sig)
            except (ProcessLookupError, PermissionError):
                return  # the group is gone
            deadline = time.time() + grace
            while time.time() < deadline:
                try:
                    os.killpg(o.proc.pid, 0)
                except (ProcessLookupError, PermissionError):
                    return
                time.sleep(0.05)

    def _finish(self, o):
        o.end = time.time()
        if o.logf is not None:
            o.logf.close()
            o.logf = None
        if o.proc is None:  # it could not start: o.error says why
            return
        o.returncode = o.proc.returncode
        if o.timed_out:
            o.error = 'timed out after %.0f s' % (o.end - o.start)
        elif o.returncode is not None and o.returncode < 0:
            # killed from outside (SIGKILL, the OOM killer, ...): whatever result it left is not a whole run's
            try:
                name = signal.Signals(-o.returncode).name
            except ValueError:
                name = 'signal %d' % -o.returncode
            o.error = 'killed by %s mid-case; see %s' % (name, o.log)
        result, why = read_result(o.result_file)
        o.result = result
        if why is not None:
            if not o.error:
                o.error = '%s (%s); see %s' % ('no result file' if not os.path.exists(o.result_file) else
                                               'no usable result', why, o.log)
        elif not o.error:
            o.error = self.verdict(o.case, result, o.log)
        if not o.error and o.returncode not in (0, None):
            o.error = '%s exited with %d; see %s' % (os.path.basename(o.argv[0]), o.returncode, o.log)
        self._record(o)

    def run(self, t0=None):
        """Runs every case not done yet (not kept by resume), `jobs` at a time, and returns the
        outcomes in case order. A failed run is reported and the others go on. Ctrl-C (and SIGTERM,
        as a batch system or `kill` sends it) terminates the running runs (their error says
        'interrupted') and raises KeyboardInterrupt."""
        self.t0 = time.time() if t0 is None else t0
        restore = None
        if threading.current_thread() is threading.main_thread():
            def terminated(signum, frame):
                raise KeyboardInterrupt('SIGTERM')
            restore = signal.signal(signal.SIGTERM, terminated)
        wake = _Wake(self.poll)
        pending = [o for o in self.outcomes if not o.done]
        running = []
        finished = len(self.outcomes) - len(pending)
        ports = [self.port + 2 * k for k in range(self.jobs)]
        last_status = 0.0
        w_all = sum(self.weight(o.case) for o in self.outcomes)
        w_left = sum(self.weight(o.case) for o in pending)
        w_done = 0.0
        self._progress = Progress(w_all, w_all - w_left, self.progress_mode, self.stream,
                                  unit='s' if self.weighted else 'run')
        try:
            while pending or running:
                while pending and len(running) < self.jobs:
                    o = pending.pop(0)
                    o.slot, o.port = self._take_port(ports, {r.port for r in running})
                    running.append(o)  # before it starts: a signal inside _launch must find it
                    self._launch(o)
                    self.line('[%6.0f s] start  %-14s (port %d)' % (time.time() - self.t0, o.name, o.port))
                wake.nap()
                for o in list(running):
                    alive = o.proc is not None and o.proc.poll() is None
                    late = self.timeout is not None and time.time() - o.start > self.timeout
                    if alive and not late:
                        continue
                    if alive and late:
                        o.timed_out = True
                        self._kill(o)
                    self._reap_group(o)
                    self._finish(o)
                    running.remove(o)
                    ports.append(o.slot)
                    if self.on_done is not None:
                        self.on_done(o)
                    finished += 1
                    w = self.weight(o.case)
                    w_done += w
                    w_left -= w
                    self._progress.advance(w)
                    eta = ''
                    if w_left > 0 and w_done > 0:
                        eta = '  ETA ~%.0f min' % ((time.time() - self.t0) * w_left / w_done / 60.0)
                    self.line('[%6.0f s] done   %-14s %s (%.0f s)  [%d/%d]%s' %
                              (time.time() - self.t0, o.name, self.describe(o), o.end - o.start, finished,
                               len(self.outcomes), eta))
                if running and self.status_every is not None and time.time() - last_status > self.status_every:
                    last_status = time.time()
                    for o in running:
                        self.line('           ...    %-14s %s' % (o.name, last_progress(o.log, self.progress_marker)))
        except BaseException as e:
            # Ctrl-C, SIGTERM, or any error of the sweep itself (a callback, a file it cannot
            # write): the running runs are stopped and finished before it goes on, so that none is
            # left computing with nothing watching it; a second signal meanwhile waits
            main = threading.current_thread() is threading.main_thread()
            if main:
                blocked = signal.pthread_sigmask(signal.SIG_BLOCK, {signal.SIGINT, signal.SIGTERM})
            try:
                for o in running:
                    self._kill(o, wait=False)
                for o in running:
                    self._kill(o)
                    self._reap_group(o)
                    self._finish(o)
                    o.error = 'interrupted' if isinstance(e, KeyboardInterrupt) else 'the sweep stopped: %r' % e
                    self._record(o, stopped=True)
            finally:
                if main:
                    signal.pthread_sigmask(signal.SIG_SETMASK, blocked)
            raise
        finally:
            self._progress.close()
            self._progress = None
            if restore is not None:
                signal.signal(signal.SIGTERM, restore)
            wake.close()
        return self.outcomes

    # -- the outcome
    def failed(self):
        """The outcomes that did not succeed (cases never run included)."""
        return [o for o in self.outcomes if not o.ok]

    def exit_status(self):
        return 1 if self.failed() else 0

    def row(self, o):
        """A case's entry in the default summary."""
        return {'name': o.name, 'params': dict(o.case.params), 'ok': o.ok, 'kept': o.kept, 'error': o.error,
                'wall_time': round(o.wall_time, 1), 'returncode': o.returncode, 'result': o.result_file,
                'log': o.log}

    def write_summary(self, path, header=None, row=None):
        """Writes every case's outcome, failures included, to a YAML file: the header mapping
        (default: cases, failed, jobs, wall_time) and `runs`, a list of row(outcome) (default
        Sweep.row)."""
        if header is None:
            header = {'cases': len(self.outcomes), 'failed': len(self.failed()), 'jobs': self.jobs,
                      'wall_time': round(time.time() - (self.t0 or time.time()), 1)}
        doc = dict(header)
        doc['runs'] = [(row or self.row)(o) for o in self.outcomes]
        d = os.path.dirname(os.path.abspath(path))
        os.makedirs(d, exist_ok=True)
        with open(path, 'w') as fh:
            yaml.safe_dump(doc, fh, sort_keys=False)
        return path

    def report(self):
        """'sweep: N runs in T s, F failed' and a line per failed case."""
        failed = self.failed()
        return 'sweep: %d runs in %.0f s, %d failed%s' % (
            len(self.outcomes), time.time() - (self.t0 or time.time()), len(failed),
            ''.join('\n  failed: %s: %s' % (o.name, o.error or 'not run') for o in failed))


def run_sweep(cases, command, runs_dir, summary=None, resume=False, accept=None, **options):
    """The whole sweep for a new script: resume (if asked), a header line, the runs, the summary
    file (if a path is given) and the closing report. Returns the Sweep; exit with
    sweep.exit_status() (1 if any case failed). Options as Sweep's. Ctrl-C: the summary is still
    written, then KeyboardInterrupt goes on."""
    sweep = Sweep(cases, command, runs_dir, **options)
    if resume:
        sweep.resume(accept)
    todo = sum(1 for o in sweep.outcomes if not o.done)
    sweep.t0 = time.time()
    sweep.line('sweep: %d cases (%d kept, %d to run), %d at a time' %
               (len(sweep.outcomes), len(sweep.outcomes) - todo, todo, sweep.jobs))
    try:
        sweep.run(sweep.t0)
    finally:
        if summary:
            sweep.write_summary(summary)
    sweep.line(sweep.report())
    return sweep
