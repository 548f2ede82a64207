"""The DOE's runs (docs/doe.md): the DOE folder and its plan, one case's worker (`doe case`), the
local pool backend (`doe run`), `doe status`, and the case table.

The folder OUT:
  doe.yaml                      the plan: grid, level, runner, the cases in run order, each with
                                its estimated cost; written once (a resume must ask for the same)
  runs/<case>.result.yaml       every case's result: a simulated run's (written by the run), or an
                                implied case's (status `implied`, `simulated: false`, the outcome
                                and the case that fixes it); never both
  runs/<case>.bag, .log         a simulated run's bag (roslaunch runner) and console output
  runs/<case>.running           while a worker runs the case (host, pid, start)
  doe_table.csv/.yaml           the case table with provenance; doe_speed_vs_ci/grade.png

One worker per case decides, when the case's turn comes, whether the cases finished so far fix its
outcome (dm_doe.plan.implied); cases in flight that could still contradict that bound make it run.
The decision and the `running` marker are taken under a lock on OUT/doe.lock, so workers side by
side (the local pool, or the tasks of a Slurm job array) see each other.
"""
import contextlib
import datetime
import fcntl
import hashlib
import os
import signal
import socket
import subprocess
import sys
import time

import yaml

from ..names import OLD, OldNameError, refuse_old_keys
from ..paths import ROOT, tool_command
from ..runs import free_port, read_result as _read_result, scene_command
from ..sweep.args import git_commit

from . import plan

# `doe case`, as a worker (the pool's or a Slurm task) runs it
DOE_CASE = tool_command('dem_mobility_tools.doe') + ['case']
PLAN_FILE = 'doe.yaml'
IMPLIED = 'implied'
# a simulated case's statuses that are outcomes (dm_run_scene / the vehicle nodelet)
OUTCOMES = ('steady', 'command_limited', 'no_go', 'not_steady')
SCENES = {'soil': ('soil_slope.launch', 'soil_slope.yaml'), 'road': ('road_slope.launch', 'road_slope.yaml')}


class RunnerError(ValueError):
    pass


def case_name(grade, ci):
    return 'g%g_ci%g' % (grade, ci)


# -- the plan -------------------------------------------------------------------------------------

def own_scene(doc, kind):
    """The plan's own scene file for the `kind` cases (doe run --soil-scene, --road-scene), or None."""
    own = (doc.get('scenes') or {}).get(kind)
    return own['file'] if own else None


def scene_file(doc, kind):
    """The scene file of a case of `kind` (soil or road): the plan's own or the shipped one."""
    return own_scene(doc, kind) or os.path.join(ROOT, 'config', 'scenes', SCENES[kind][1])


def check_scene_file(path, kind):
    """{'file': absolute path, 'sha256': of its bytes} of a scene file given for the `kind` cases;
    RunnerError unless it is a YAML scene of that kind (soil_slope or road_slope)."""
    want = SCENES[kind][1][:-len('.yaml')]
    try:
        with open(path, 'rb') as fh:
            data = fh.read()
        doc = yaml.safe_load(data)
    except OSError as e:
        raise RunnerError('--%s-scene %s: %s' % (kind, path, e.strerror))
    except yaml.YAMLError as e:
        raise RunnerError('--%s-scene %s: not YAML (%s)' % (kind, path, str(e).splitlines()[0]))
    if not isinstance(doc, dict) or doc.get('scene') != want:
        raise RunnerError('--%s-scene %s: scene: %r, where the %s cases take a scene of kind %s' % (
            kind, path, doc.get('scene') if isinstance(doc, dict) else None, kind, want))
    return {'file': os.path.abspath(path), 'sha256': hashlib.sha256(data).hexdigest()}


def make_plan(grid, level, runner, dem_threads, duration, prune, cost_of, provenance=None, scenes=None):
    """The plan document: the cases in the grid's run order (dm_doe.plan.Grid.order), each with its
    estimated cost [s] from cost_of(grade, ci); `scenes`: {kind: check_scene_file(...)} for the
    kinds whose cases run a scene file of the user's instead of the shipped one."""
    cases = []
    for k, (i, j) in enumerate(grid.order()):
        g, c = grid.grades[i], grid.cone_indices[j]
        cases.append({'index': k, 'name': case_name(g, c), 'cell': [i, j], 'grade_deg': g, 'cone_index_psi': c,
                      'scene': 'road' if c >= plan.ROAD_CONE_INDEX else 'soil',
                      'estimated_cost': round(float(cost_of(g, c)), 1)})
    doc = {'grades': grid.grades, 'cone_indices': grid.cone_indices, 'level': level, 'runner': runner,
           'dem_threads': dem_threads, 'duration': duration, 'prune': bool(prune), 'scenes': dict(scenes or {}),
           'commit': git_commit(ROOT), 'created': utc_now()}
    doc.update(provenance or {})
    doc['cases'] = cases
    return doc


def designed(doc):
    """The plan as asked, before any refinement: the grid the user gave and the options."""
    d = dict(doc)
    d.update(doc.get('design') or {})
    return d


def same_design(a, b):
    """None if two plans ask for the same runs (the grid as asked, before refinements), else what
    differs."""
    a, b = designed(a), designed(b)
    for k in ('grades', 'cone_indices', 'level', 'runner', 'dem_threads', 'duration', 'prune', 'scenes'):
        if (a.get(k) or None) != (b.get(k) or None):
            return '%s: %r in the folder, %r asked' % (k, a.get(k), b.get(k))
    return None


def refine_plan(out, doc, total, cost_of):
    """`doe run --refine N`: the plan with refinement lines added until it holds `total` (none
    if it has them already): dm_doe.plan.refinements of the finished table, the cases of the
    new lines pending, the finished ones kept (their files go by name). Every case must be done
    (simulated or implied). The Slurm jobs so far are set aside (their task indices are the old
    plan's). Returns (the new plan, the lines added), the plan written."""
    done = doc.get('refinements') or []
    if total <= len(done):
        return doc, []
    states = scan(out, doc)
    open_cases = [c['name'] for c in doc['cases'] if states[c['index']][0] not in ('simulated', 'implied')]
    if open_cases:
        raise RunnerError('--refine: the grid is not finished (%s): refinement goes by the finished table'
                          % ', '.join(open_cases[:5]))
    speed = {(r['grade_deg'], r['cone_index_psi']): r['speed_made_good'] for r in table_rows(out, doc, states)}
    g, c = doc['grades'], doc['cone_indices']
    matrix = [[speed[(x, y)] for y in c] for x in g]
    picks = plan.refinements(g, c, matrix, total - len(done))
    if not picks:
        return doc, []
    grades = sorted(g + [v for axis, v, _, _ in picks if axis == 'grade_deg'])
    cis = sorted(c + [v for axis, v, _, _ in picks if axis == 'cone_index_psi'])
    own = ('grades', 'cone_indices', 'level', 'runner', 'dem_threads', 'duration', 'prune', 'scenes', 'commit',
           'created', 'cases', 'design', 'refinements')
    new = make_plan(plan.Grid(grades, cis), doc['level'], doc['runner'], doc['dem_threads'], doc['duration'],
                    doc['prune'], cost_of, {k: v for k, v in doc.items() if k not in own}, doc.get('scenes'))
    new['design'] = doc.get('design') or {'grades': g, 'cone_indices': c}
    new['refinements'] = done + [{'axis': axis, 'value': v, 'between': list(between), 'jump': round(float(jump), 4),
                                  'made': utc_now()} for axis, v, between, jump in picks]
    jobs = os.path.join(out, 'slurm', 'jobs.yaml')
    if os.path.exists(jobs):
        os.replace(jobs, os.path.join(out, 'slurm', 'jobs_before_refinement_%d.yaml' % len(new['refinements'])))
    write_yaml(os.path.join(out, PLAN_FILE), new)
    return new, picks


def write_yaml(path, doc):
    """Atomically (a reader never sees half a file)."""
    tmp = '%s.tmp%d' % (path, os.getpid())
    with open(tmp, 'w') as fh:
        yaml.safe_dump(doc, fh, sort_keys=False)
    os.replace(tmp, path)


def load_plan(out):
    path = os.path.join(out, PLAN_FILE)
    try:
        with open(path) as fh:
            doc = yaml.safe_load(fh)
    except OSError as e:
        raise RunnerError('%s: no DOE here (%s); start one with doe run --out %s' % (path, e.strerror, out))
    except yaml.YAMLError as e:
        raise RunnerError('%s: not a DOE plan (%s)' % (path, e))
    if not isinstance(doc, dict) or not isinstance(doc.get('cases'), list):
        raise RunnerError('%s: not a DOE plan (no cases)' % path)
    try:
        for k, case in enumerate(doc['cases']):
            refuse_old_keys(case, path, 'cases[%d]' % k)
        for k, line in enumerate(doc.get('refinements') or []):
            if isinstance(line, dict) and line.get('axis') in OLD:
                raise OldNameError('%s: refinements[%d]: axis %r is an old name: it is %r now (a file written by '
                                   'an older version of the tools)' % (path, k, line['axis'], OLD[line['axis']]))
    except OldNameError as e:
        raise RunnerError(str(e))
    return doc


def utc_now():
    return datetime.datetime.utcnow().strftime('%Y-%m-%dT%H:%M:%SZ')


def runs_dir(out):
    return os.path.join(out, 'runs')


def result_path(out, case):
    return os.path.join(runs_dir(out), case['name'] + '.result.yaml')


def provenance_path(out, case):
    return os.path.join(runs_dir(out), case['name'] + '.provenance.yaml')


def marker_path(out, case):
    return os.path.join(runs_dir(out), case['name'] + '.running')


@contextlib.contextmanager
def locked(out):
    fh = open(os.path.join(out, 'doe.lock'), 'a')
    try:
        fcntl.flock(fh, fcntl.LOCK_EX)
        yield
    finally:
        fcntl.flock(fh, fcntl.LOCK_UN)
        fh.close()


# -- the state of the cases -----------------------------------------------------------------------

def read_result(path):
    """The mapping in a file of the DOE's folder (a result, a provenance, a marker), or None when
    there is none to use (runs.read_result says why; here a missing file is a case's state)."""
    return _read_result(path)[0]


def verdict(case, result):
    """None if `result` is a good result of `case`, else why not."""
    if result is None:
        return 'no result'
    status = result.get('status')
    if status == IMPLIED:
        return None if result.get('implied_status') in (plan.NO_GO, plan.COMMAND_LIMITED) else 'implied without outcome'
    if result.get('error') or status in ('error', 'interrupted'):
        return str(result.get('error') or status)
    if status not in OUTCOMES:
        return 'status %r' % status
    kind = 'soil_slope' if case['scene'] == 'soil' else 'road_slope'
    if result.get('kind') != kind:
        return 'the result is of kind %r, not %s' % (result.get('kind'), kind)
    try:
        if abs(float(result.get('grade_deg')) - case['grade_deg']) > 1e-9:
            return 'grade %s deg, not %g' % (result.get('grade_deg'), case['grade_deg'])
    except (TypeError, ValueError):
        return 'no grade in the result'
    return None


def marker_alive(path):
    """A `running` marker's worker: alive (this host and its pid exists; another host's: taken as
    alive, a Slurm task's until `reconcile` finds its task ended), or stale."""
    doc = read_result(path)
    if doc is None:
        return False
    if doc.get('host') != socket.gethostname():
        return True
    try:
        pid = int(doc.get('pid', -1))
        os.kill(pid, 0)
    except (OSError, ValueError, TypeError):
        return False
    try:  # a killed worker not yet reaped (a zombie) is gone too
        with open('/proc/%d/stat' % pid) as fh:
            return fh.read().rsplit(')', 1)[1].split()[0] != 'Z'
    except (OSError, IndexError):
        return True


def scan(out, doc):
    """{index: (state, result)}: state 'simulated', 'implied', 'failed' (its run ended without a good
    result), 'running', 'interrupted' (its worker was killed mid-run: a `running` marker whose
    process is gone) or 'pending'."""
    states = {}
    for case in doc['cases']:
        r = read_result(result_path(out, case))
        prov = read_result(provenance_path(out, case)) if r is not None and r.get('status') != IMPLIED else None
        exited = prov.get('exit_status') if prov else 0
        if r is not None and verdict(case, r) is None and exited == 0:
            states[case['index']] = ('implied' if r.get('status') == IMPLIED else 'simulated', r)
        elif r is not None and r.get('status') == 'interrupted' and r.get('kind') == 'doe_case':
            states[case['index']] = ('interrupted', r)
        elif os.path.exists(marker_path(out, case)):
            states[case['index']] = ('running' if marker_alive(marker_path(out, case)) else 'interrupted', r)
        elif r is not None or os.path.exists(os.path.join(runs_dir(out), case['name'] + '.log')):
            states[case['index']] = ('failed', r)
        else:
            states[case['index']] = ('pending', None)
    return states


def outcome(result):
    """(status, speed) of a simulated result, for the bounds."""
    return result.get('status'), float(result.get('speed_made_good') or 0.0)


def decide(case, doc, states):
    """(status, speed, by-case) if the finished simulated cases fix this case's outcome and no case
    in flight could contradict the bound, else None."""
    if not doc.get('prune', True):
        return None
    cells = {c['index']: tuple(c['cell']) for c in doc['cases']}
    finished = {cells[k]: outcome(r) for k, (s, r) in states.items() if s == 'simulated' and k != case['index']}
    x = plan.implied(tuple(case['cell']), finished)
    if x is None:
        return None
    i, j = case['cell']
    for k, (s, _) in states.items():
        if s != 'running' or k == case['index']:
            continue
        a, b = cells[k]
        harder, easier = a >= i and b <= j, a <= i and b >= j
        if (x[0] == plan.NO_GO and harder) or (x[0] == plan.COMMAND_LIMITED and easier):
            return None  # its outcome could still contradict the bound: run this case
    by = next(c for c in doc['cases'] if tuple(c['cell']) == x[2])
    return x[0], x[1], by


# -- one case -------------------------------------------------------------------------------------

def case_command(doc, case, out, port, dm_run_scene=None):
    """The argv of a case's run: roslaunch of the scene's launch file (what a user runs) or the
    core runner dm_run_scene."""
    launch = SCENES[case['scene']][0]
    result = os.path.abspath(result_path(out, case))
    base = result[:-len('.result.yaml')]
    params = [('grade_deg', float(case['grade_deg'])), ('duration', float(doc['duration']) if doc.get('duration') else None)]
    if case['scene'] == 'soil':
        params += [('fidelity', doc['level']), ('cone_index', float(case['cone_index_psi'])),
                   ('dem_threads', int(doc['dem_threads']))]
    # roslaunch takes the launch file's own scene unless the plan has its own; the core runner a file
    scene = own_scene(doc, case['scene']) if doc['runner'] == 'roslaunch' else scene_file(doc, case['scene'])
    return scene_command(doc['runner'], launch, params, scene=scene, port=port, bag=base + '.bag', result=result,
                         history=base + '.history.csv', dm_run_scene=dm_run_scene)


def port_from_env(default=11611):
    uri = os.environ.get('ROS_MASTER_URI', '')
    try:
        return int(uri.rsplit(':', 1)[1].strip('/'))
    except (IndexError, ValueError):
        return default


def wait_pid(pid, timeout):
    """Waits up to `timeout` s for child `pid` to end: its exit status (-N: killed by signal N),
    or None if it has not ended. (From a signal handler that interrupted a Popen.wait: that wait
    holds the Popen's lock, so Popen.wait(timeout) would only time out.)"""
    deadline = time.time() + timeout
    while True:
        try:
            done, status = os.waitpid(pid, os.WNOHANG)
        except ChildProcessError:
            return None
        if done:
            return os.waitstatus_to_exitcode(status)
        if time.time() >= deadline:
            return None
        time.sleep(0.02)


def claim(out, doc, case, stream):
    """The case's turn, under the lock: 0 if it needs no run (done before, or its outcome fixed by
    the finished cases: recorded implied now), else None with its `running` marker written."""
    index = case['index']
    with locked(out):
        states = scan(out, doc)
        state = states[index][0]
        if state in ('simulated', 'implied'):
            print('%s: done before (%s)' % (case['name'], state), file=stream)
            return 0
        if state == 'running':
            raise RunnerError('case %s is running already (%s)' % (case['name'], marker_path(out, case)))
        x = decide(case, doc, states)
        if x is not None:
            status, speed, by = x
            write_yaml(result_path(out, case), {
                'kind': 'doe_implied', 'status': IMPLIED, 'simulated': False, 'implied_status': status,
                'speed_made_good': speed, 'speed_made_good_mph': speed / 0.44704, 'implied_by': by['name'],
                'grade_deg': case['grade_deg'], 'cone_index_psi': case['cone_index_psi'], 'fidelity': doc['level'],
                'made': utc_now(),
                'why': ('an easier case (grade %g deg, CI %g psi) was stuck' if status == plan.NO_GO else
                        'a harder case (grade %g deg, CI %g psi) reached the command') % (by['grade_deg'], by['cone_index_psi'])})
            print('%s: implied %s by %s (not simulated)' % (case['name'], status, by['name']), file=stream)
            return 0
        for p in (result_path(out, case),):
            if os.path.exists(p):
                os.remove(p)
        write_yaml(marker_path(out, case), {'host': socket.gethostname(), 'pid': os.getpid(), 'start': utc_now(),
                                            'slurm_job': os.environ.get('SLURM_JOB_ID')})
    return None


def run_case(out, index, port=None, dm_run_scene=None, stream=None):
    """`doe case`: the case's turn. Exit status 0 if it is done (simulated now or before, or
    implied), 1 if its run failed."""
    stream = stream or sys.stdout
    doc = load_plan(out)
    if not 0 <= index < len(doc['cases']):
        raise RunnerError('--index %d: the DOE in %s has cases 0-%d' % (index, out, len(doc['cases']) - 1))
    case = doc['cases'][index]
    os.makedirs(runs_dir(out), exist_ok=True)
    if claim(out, doc, case, stream) == 0:
        return 0
    if port is None:  # (a port given is the pool's slot's or the array task's own: taken as it is)
        port = free_port(port_from_env())  # (its master and the next port: 2 apart, as the pool's)
    argv = case_command(doc, case, out, port, dm_run_scene)
    log = os.path.join(runs_dir(out), case['name'] + '.log')
    # the checkout the run starts from (the provenance's commit: a commit made while a case runs
    # is not the code it ran)
    commit = git_commit(ROOT)
    t0 = time.time()
    child = []

    def stopped(signum, frame):
        # SIGTERM (the pool's timeout or Ctrl-C, Slurm's time limit or scancel): the run stops, the
        # case is recorded interrupted (resume runs it again; a timeout is made a failure by
        # whoever set it), the marker goes. A run that had written its good result already (the
        # signal came while it was ending: roslaunch takes down its nodes after the result) keeps
        # it: a finished case is never replaced
        own_exit = wait_pid(child[0].pid, 0) if child else None  # None: the run had not ended by itself
        for c in child:
            with contextlib.suppress(OSError):
                c.terminate()
            wait_pid(c.pid, 20)
        if own_exit in (None, 0) and verdict(case, read_result(result_path(out, case))) is None:
            write_yaml(provenance_path(out, case), {
                'commit': commit, 'host': socket.gethostname(), 'slurm_job': os.environ.get('SLURM_JOB_ID'),
                'argv': argv, 'wall_time': round(time.time() - t0, 1), 'exit_status': 0,
                'signal_after_result': signum})
            with contextlib.suppress(OSError):
                os.remove(marker_path(out, case))
            print('%s: stopped by signal %d after its result was written: the result kept' % (case['name'], signum),
                  file=stream)
            stream.flush()
            os._exit(0)
        write_yaml(result_path(out, case), {
            'kind': 'doe_case', 'status': 'interrupted', 'grade_deg': case['grade_deg'],
            'cone_index_psi': case['cone_index_psi'], 'error': 'the case was stopped (signal %d) after %.0f s; see %s'
            % (signum, time.time() - t0, log)})
        with contextlib.suppress(OSError):
            os.remove(marker_path(out, case))
        os._exit(128 + signum)
    signal.signal(signal.SIGTERM, stopped)
    try:
        with open(log, 'w') as fh:
            fh.write('$ %s\n' % ' '.join(argv))
            fh.flush()
            try:
                env = dict(os.environ, ROS_MASTER_URI='http://127.0.0.1:%d' % port)
                child.append(subprocess.Popen(argv, stdout=fh, stderr=subprocess.STDOUT, env=env))
                rc = child[0].wait()
            except OSError as e:
                fh.write('cannot start %s: %s\n' % (argv[0], e))
                rc = 127
    finally:
        signal.signal(signal.SIGTERM, signal.SIG_DFL)
        with contextlib.suppress(OSError):
            os.remove(marker_path(out, case))
    write_yaml(provenance_path(out, case), {'commit': commit, 'host': socket.gethostname(),
                                            'slurm_job': os.environ.get('SLURM_JOB_ID'), 'argv': argv,
                                            'wall_time': round(time.time() - t0, 1), 'exit_status': rc})
    r = read_result(result_path(out, case))
    why = verdict(case, r)
    if why is None and rc != 0:
        why = '%s exited with %d' % (os.path.basename(argv[0]), rc)
    if why is not None:
        print('%s: FAILED after %.0f s: %s; see %s' % (case['name'], time.time() - t0, why, log), file=stream)
        return 1
    print('%s: %s, %.3f m/s (%.0f s)' % (case['name'], r.get('status'), float(r.get('speed_made_good') or 0.0),
                                         time.time() - t0), file=stream)
    return 0


def record_failure(out, doc, case, error, kind='doe_case', status='error'):
    """Records that a case failed (a timeout, a lost Slurm task), under the lock, unless a good
    result is there by now (it is never replaced). True if recorded."""
    with locked(out):
        states = scan(out, doc)
        if states[case['index']][0] in ('simulated', 'implied'):
            return False
        write_yaml(result_path(out, case), {'kind': kind, 'status': status, 'grade_deg': case['grade_deg'],
                                            'cone_index_psi': case['cone_index_psi'], 'error': error})
        with contextlib.suppress(OSError):
            os.remove(marker_path(out, case))
    return True


# -- the table ------------------------------------------------------------------------------------

def table_rows(out, doc, states=None):
    states = states or scan(out, doc)
    rows = []
    for case in doc['cases']:
        state, r = states[case['index']]
        row = {'grade_deg': case['grade_deg'], 'cone_index_psi': case['cone_index_psi'], 'state': state,
               'speed_made_good': None, 'speed_made_good_mph': None, 'status': None, 'source': None,
               'error_estimate': None, 'wall_time': None, 'calibration_table': None, 'commit': None, 'error': None}
        if state == 'simulated':
            v = float(r.get('speed_made_good') or 0.0)
            prov = read_result(provenance_path(out, case)) or {}
            row.update(speed_made_good=v, speed_made_good_mph=round(v / 0.44704, 4), status=r.get('status'),
                       source='simulated (%s, %s)' % (case['scene'], r.get('fidelity', 'rigid road')),
                       error_estimate=r.get('speed_error_estimate', 'rigid road: no soil level' if case['scene'] == 'road' else None),
                       wall_time=prov.get('wall_time', r.get('wall_time')), calibration_table=r.get('calibration_table'), commit=prov.get('commit'))
        elif state == 'implied':
            row.update(speed_made_good=float(r['speed_made_good']), speed_made_good_mph=round(float(r['speed_made_good']) / 0.44704, 4),
                       status=r['implied_status'], source='implied by %s' % r['implied_by'],
                       error_estimate='as the case that implies it', wall_time=0.0)
        elif state == 'failed':
            row['error'] = (r or {}).get('error') or verdict(case, r) or 'the run left no result'
        rows.append(row)
    rows.sort(key=lambda x: (x['grade_deg'], x['cone_index_psi']))
    return rows


def write_doe_table(out, doc, rows):
    """doe_table.csv and doe_table.yaml (the speed matrix that doe map reads, cases without a speed
    as null) with provenance."""
    import csv
    cols = ['grade_deg', 'cone_index_psi', 'speed_made_good', 'speed_made_good_mph', 'status', 'source', 'error_estimate',
            'wall_time', 'state', 'error']
    stem = os.path.join(out, 'doe_table')
    with open(stem + '.csv', 'w', newline='') as fh:
        w = csv.writer(fh)
        w.writerow(cols)
        for r in rows:
            w.writerow(['' if r[c] is None else r[c] for c in cols])
    grades, cis = doc['grades'], doc['cone_indices']
    speed = [[None] * len(cis) for _ in grades]
    for r in rows:
        speed[grades.index(r['grade_deg'])][cis.index(r['cone_index_psi'])] = r['speed_made_good']
    tables = sorted({r['calibration_table'] for r in rows if r['calibration_table']})
    commits = sorted({r['commit'] for r in rows if r['commit']})
    n_sim = sum(1 for r in rows if r['state'] == 'simulated')
    n_imp = sum(1 for r in rows if r['state'] == 'implied')
    summary = {'model': 'physics', 'level': doc['level'], 'runner': doc['runner'], 'plan_commit': doc.get('commit'),
               'run_commits': commits, 'calibration_tables': tables,
               'scene_files': {k: scene_file(doc, k) for k in SCENES},
               'duration': doc.get('duration'), 'made': utc_now(),
               'cases': len(rows), 'simulated': n_sim, 'implied': n_imp, 'runs_saved': n_imp,
               'failed': sum(1 for r in rows if r['state'] == 'failed'),
               'not_run': sum(1 for r in rows if r['state'] in ('pending', 'running', 'interrupted')),
               'grades': grades, 'cone_indices': cis, 'speed': speed, 'cases_table': rows}
    write_yaml(stem + '.yaml', summary)
    return stem + '.yaml', summary


# -- status ---------------------------------------------------------------------------------------

def eta_seconds(doc, states, parallel, elapsed_ratio=None):
    """Estimated wall seconds left: the pending cases' estimated cost over `parallel` runs at once,
    scaled by how the finished runs compared with their estimates (elapsed_ratio)."""
    left = sum(c['estimated_cost'] for c in doc['cases'] if states[c['index']][0] in ('pending', 'running', 'interrupted'))
    return left / max(1, parallel) * (elapsed_ratio or 1.0)


def measured_ratio(out, doc, states):
    """Wall time of the simulated cases over their estimates (None before any)."""
    est = wall = 0.0
    for c in doc['cases']:
        s, r = states[c['index']]
        if s == 'simulated':
            prov = read_result(provenance_path(out, c)) or {}
            try:
                wall += float(prov['wall_time'])
                est += c['estimated_cost']
            except (KeyError, TypeError, ValueError):
                pass
    return wall / est if est > 0 else None


def status_text(out, doc, states, parallel=1):
    counts = {}
    for s, _ in states.values():
        counts[s] = counts.get(s, 0) + 1
    n = len(doc['cases'])
    ratio = measured_ratio(out, doc, states)
    lines = ['doe %s: %d cases (%d grades x %d cone indices), level %s, runner %s' % (
        out, n, len(doc['grades']), len(doc['cone_indices']), doc['level'], doc['runner'])]
    lines.append('  simulated %d, implied %d (runs saved), failed %d, running %d, pending %d%s' % (tuple(
        counts.get(k, 0) for k in ('simulated', 'implied', 'failed', 'running', 'pending')) + (
        ', interrupted %d (stopped mid-run: --resume runs them again)' % counts['interrupted'] if 'interrupted' in counts
        else '',)))
    left = counts.get('pending', 0) + counts.get('running', 0) + counts.get('interrupted', 0)
    if left:
        lines.append('  ETA ~%.0f min for the %d cases left at most (%d at a time; estimates %s)' % (
            eta_seconds(doc, states, parallel, ratio) / 60.0, left, parallel,
            'x %.2f as measured so far' % ratio if ratio else 'from %s' % 'config/doe/run_costs.yaml'))
    for c in doc['cases']:
        s, r = states[c['index']]
        if s == 'failed':
            lines.append('  failed: %s: %s (log runs/%s.log)' % (
                c['name'], (r or {}).get('error') or verdict(c, r) or 'no result', c['name']))
    return '\n'.join(lines)
