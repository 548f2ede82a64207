"""Unit tests of dem_mobility_tools.sweep (no ROS, no C++ build): the runs are a small stand-in python
command that writes a result YAML (or fails, hangs, crashes, as its case says).

    PYTHONPATH=python python3 -m unittest discover -s test/python -v      (from the repository root)
"""
import io
import os
import shutil
import socket
import sys
import tempfile
import time
import types
import unittest

import yaml

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
from dem_mobility_tools import sweep as dm_sweep

# the stand-in run: its case's mode says what it does; it appends 'start/end <name> <time> <port>'
# to the journal and writes its result to DM_SWEEP_RESULT
STAND_IN = r'''
import os, sys, time, yaml
mode, sleep, journal = sys.argv[1], float(sys.argv[2]), sys.argv[3]
name, port = os.environ['DM_SWEEP_CASE'], os.environ['ROS_MASTER_URI'].rsplit(':', 1)[1]
def note(what):
    with open(journal, 'a') as fh:
        fh.write('%s %s %.6f %s\n' % (what, name, time.time(), port))
note('start')
print('run %s: progress: half way' % name, flush=True)
if mode == 'killed_once':  # killed mid-case (SIGKILL, no clean-up) the first time, fine after
    flag = journal + '.' + name + '.killed'
    if not os.path.exists(flag):
        open(flag, 'w').close()
        os.kill(os.getpid(), 9)
if mode == 'orphan':  # killed (SIGKILL) leaving a child of its own behind, as a killed roslaunch leaves its nodes
    import subprocess
    child = subprocess.Popen(['sleep', '60'])
    open(journal + '.' + name + '.pid', 'w').write(str(child.pid))
    os.kill(os.getpid(), 9)
if mode == 'hang':
    import subprocess
    child = subprocess.Popen(['sleep', '60'])
    open(journal + '.' + name + '.pid', 'w').write(str(child.pid))
    time.sleep(60)
time.sleep(sleep)
note('end')
if mode == 'crash':
    sys.exit(3)
doc = {'status': 'ok', 'value': float(sys.argv[4]) * 2, 'wall_time': sleep, 'error': ''}
if mode == 'fail':
    doc = {'status': 'error', 'error': 'the soil gave way'}
if mode == 'empty':
    doc['value'] = None
if mode == 'sunk':
    doc.update(status='sunk', error='the wheel sank 0.3 m')
with open(os.environ['DM_SWEEP_RESULT'], 'w') as fh:
    yaml.safe_dump(doc, fh)
if mode == 'exit_after_result':  # a good result, then a failing exit
    sys.exit(5)
'''


# a sweep driven from a process of its own (the SIGTERM test)
DRIVER = r"""import sys
from dem_mobility_tools import sweep as dm_sweep
cases = dm_sweep.cases([{'mode': 'ok', 'x': 1}, {'mode': 'hang', 'x': 2}])
cmd = lambda case, run: [sys.executable, %r, case.params['mode'], '0', %r, str(case.params['x'])]
s = dm_sweep.Sweep(cases, cmd, %r, jobs=1, poll=0.02, progress='plain', port=%d, timeout=60)
try:
    s.run()
except KeyboardInterrupt:
    print('STOPPED', [(o.name, o.ok, o.error) for o in s.outcomes], flush=True)
    sys.exit(4)
"""


class Base(unittest.TestCase):
    def setUp(self):
        self.tmp = tempfile.mkdtemp(prefix='dm_sweep_test_')
        self.addCleanup(shutil.rmtree, self.tmp, True)
        self.script = os.path.join(self.tmp, 'stand_in.py')
        with open(self.script, 'w') as fh:
            fh.write(STAND_IN)
        self.journal = os.path.join(self.tmp, 'journal')
        self.runs = os.path.join(self.tmp, 'runs')
        self.out = io.StringIO()

    def command(self, sleep=0.0):
        def cmd(case, run):
            return [sys.executable, self.script, case.params.get('mode', 'ok'), str(case.params.get('sleep', sleep)),
                    self.journal, str(case.params.get('x', 0))]
        return cmd

    def sweep(self, cases, **kw):
        opts = dict(jobs=2, port=free_port_base(), poll=0.02, status_every=None, progress='plain', stream=self.out,
                    timeout=20)
        opts.update(kw)
        return dm_sweep.Sweep(cases, opts.pop('command', self.command()), self.runs, **opts)

    def journal_rows(self):
        if not os.path.exists(self.journal):
            return []
        with open(self.journal) as fh:
            return [(w, n, float(t), int(p)) for w, n, t, p in (line.split() for line in fh)]

    def starts(self):
        return [r[1] for r in self.journal_rows() if r[0] == 'start']


def free_port_base():
    """A port p with p .. p + 40 free now (the tests' ROS master ports; nothing listens on them)."""
    for base in range(23000, 60000, 97):
        if all(dm_sweep.port_free(base + k) for k in range(0, 41, 2)):
            return base
    raise RuntimeError('no free ports')


class Grid(unittest.TestCase):
    def test_product_names_and_order(self):
        cases = dm_sweep.grid([('mu', [0.1, 0.05]), ('f', [2, 0.3, 12.0])])
        self.assertEqual([c.name for c in cases],
                         ['mu0.1_f2', 'mu0.1_f0.3', 'mu0.1_f12', 'mu0.05_f2', 'mu0.05_f0.3', 'mu0.05_f12'])
        self.assertEqual([c.index for c in cases], list(range(6)))
        self.assertEqual(cases[1].params, {'mu': 0.1, 'f': 0.3})
        self.assertEqual((cases[1]['mu'], cases[1].f), (0.1, 0.3))
        with self.assertRaises(AttributeError):
            cases[0].slip

    def test_stable_names(self):
        a = dm_sweep.grid({'slip': [0.1, 1e-5], 'load': [100], 'soil': ['clay loam', 'sand/dry']})
        b = dm_sweep.grid({'slip': [0.1, 1e-5], 'load': [100], 'soil': ['clay loam', 'sand/dry']})
        self.assertEqual([c.name for c in a], [c.name for c in b])
        self.assertEqual(a[0].name, 'slip0.1_load100_soilclay-loam')
        self.assertEqual(a[3].name, 'slip1e-05_load100_soilsand-dry')

    def test_custom_names(self):
        cases = dm_sweep.grid([('slope', [10, 20]), ('ci', [50])], name='s{slope:02d}_ci{ci}')
        self.assertEqual([c.name for c in cases], ['s10_ci50', 's20_ci50'])
        cases = dm_sweep.grid([('a', [1])], name=lambda p: 'case-%d' % p['a'])
        self.assertEqual(cases[0].name, 'case-1')

    def test_design_not_product(self):
        cases = dm_sweep.cases([{'slope': 10, 'ci': 50}, {'slope': 25, 'ci': 80}])
        self.assertEqual([c.name for c in cases], ['slope10_ci50', 'slope25_ci80'])

    def test_repeats_and_empty(self):
        with self.assertRaises(ValueError):
            dm_sweep.grid([('f', [1, 1.0])])
        with self.assertRaises(ValueError):
            dm_sweep.grid([('f', [1]), ('f', [2])])
        self.assertEqual(dm_sweep.grid([('f', [1, 2]), ('mu', [])]), [])


class Pool(Base):
    def test_a_run_that_ends_is_seen_at_once_not_at_the_next_poll(self):
        # (SIGCHLD wakes the pool: three runs one after the other at a 5 s poll end in far less
        # than the 15 s three polls would take)
        t0 = time.time()
        s = self.sweep(dm_sweep.grid([('x', [1, 2, 3])]), jobs=1, poll=5.0)
        s.run()
        self.assertEqual(s.exit_status(), 0, self.out.getvalue())
        self.assertLess(time.time() - t0, 10.0)

    def test_failures_reported_others_kept(self):
        cases = dm_sweep.cases([{'mode': 'ok', 'x': 1}, {'mode': 'fail', 'x': 2}, {'mode': 'hang', 'x': 3},
                                {'mode': 'crash', 'x': 4}, {'mode': 'ok', 'x': 5}])
        s = self.sweep(cases, timeout=1.5, kill_grace=5)
        t = time.time()
        s.run()
        self.assertLess(time.time() - t, 15)
        by = {o.case['x']: o for o in s.outcomes}
        self.assertTrue(by[1].ok and by[5].ok)
        self.assertEqual(by[1].result['value'], 2.0)
        self.assertEqual(by[5].result['value'], 10.0)
        self.assertEqual(by[2].error, 'the soil gave way')
        self.assertTrue(by[3].timed_out)
        self.assertRegex(by[3].error, r'^timed out after \d+ s$')
        self.assertRegex(by[4].error, r'^no result file \(.*\); see .*modecrash_x4\.log$')
        self.assertEqual(by[4].returncode, 3)
        self.assertEqual([o.name for o in s.failed()], ['modefail_x2', 'modehang_x3', 'modecrash_x4'])
        self.assertEqual(s.exit_status(), 1)
        # the whole process group of the late run is gone, its child included
        with open(self.journal + '.modehang_x3.pid') as fh:
            child = int(fh.read())
        time.sleep(0.2)
        self.assertFalse(os.path.exists('/proc/%d' % child) and 'Z' not in _proc_state(child))
        # every run's console output is in its log
        for o in s.outcomes:
            with open(o.log) as fh:
                self.assertIn('run %s: progress: half way' % o.name, fh.read())
        # a line per finished run
        text = self.out.getvalue()
        self.assertEqual(text.count(' done '), 5)
        self.assertIn('FAILED: the soil gave way', text)
        self.assertIn('[5/5]', text)

    def test_a_killed_worker_is_failed_naming_the_signal_and_resume_reruns_only_it(self):
        cases = dm_sweep.cases([{'mode': 'ok', 'x': 1}, {'mode': 'killed_once', 'x': 2}, {'mode': 'ok', 'x': 3}])
        s = self.sweep(cases)
        s.run()
        by = {o.case['x']: o for o in s.outcomes}
        self.assertTrue(by[1].ok and by[3].ok)
        self.assertFalse(by[2].ok)
        self.assertEqual(by[2].returncode, -9)
        self.assertRegex(by[2].error, r'^killed by SIGKILL mid-case; see .*modekilled-once_x2\.log$')
        self.assertEqual(s.exit_status(), 1)
        # --resume keeps the finished cases and runs the killed one again
        again = self.sweep(cases)
        kept = again.resume()
        self.assertEqual(sorted(o.name for o in kept), ['modeok_x1', 'modeok_x3'])
        again.run()
        self.assertTrue(all(o.ok for o in again.outcomes))
        starts = self.starts()  # (two at a time: the first three in any order)
        self.assertEqual(sorted(starts[:3]), ['modekilled-once_x2', 'modeok_x1', 'modeok_x3'])
        self.assertEqual(starts[3:], ['modekilled-once_x2'])

    def test_an_error_of_the_sweep_itself_stops_its_runs_before_it_goes_on(self):
        # a callback that raises (here describe, once the first case is done) while another case
        # runs: the error goes on to the caller, and the running case and its child are stopped
        # first, its error naming why, instead of being left computing with nothing watching
        cases = dm_sweep.cases([{'mode': 'ok', 'x': 1, 'sleep': 1.0}, {'mode': 'hang', 'x': 2}])

        def describe(o):
            raise RuntimeError('a callback failed')
        s = self.sweep(cases, describe=describe)
        with self.assertRaises(RuntimeError):
            s.run()
        by = {o.case['x']: o for o in s.outcomes}
        self.assertTrue(by[2].error.startswith('the sweep stopped: RuntimeError'), by[2].error)
        with open(self.journal + '.modehang_x2.pid') as fh:
            child = int(fh.read())
        time.sleep(0.2)
        self.assertFalse(os.path.exists('/proc/%d' % child) and 'Z' not in _proc_state(child))

    def test_what_a_killed_run_leaves_in_its_group_is_stopped(self):
        cases = dm_sweep.cases([{'mode': 'orphan', 'x': 1}])
        s = self.sweep(cases)
        s.run()
        self.assertEqual(s.outcomes[0].returncode, -9)
        with open(self.journal + '.modeorphan_x1.pid') as fh:
            child = int(fh.read())
        time.sleep(0.2)
        self.assertFalse(os.path.exists('/proc/%d' % child) and 'Z' not in _proc_state(child), 'the child was left')

    def test_sigterm_stops_the_sweep_and_its_runs_within_a_second(self):
        # a sweep in a process of its own, SIGTERM once its second (hanging) case has started: the
        # running case and its child are stopped, its error says interrupted, the finished case is
        # kept, and the sweep process ends within a second or two
        import signal
        import subprocess
        driver = os.path.join(self.tmp, 'driver.py')
        with open(driver, 'w') as fh:
            fh.write(DRIVER % (self.script, self.journal, self.runs, free_port_base()))
        p = subprocess.Popen([sys.executable, driver], stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
        pid_file = self.journal + '.modehang_x2.pid'
        t0 = time.time()
        while not os.path.exists(pid_file) and time.time() - t0 < 30:
            time.sleep(0.05)
        self.assertTrue(os.path.exists(pid_file), 'the hanging case never started')
        time.sleep(0.2)
        with open(pid_file) as fh:
            child = int(fh.read())
        t = time.time()
        p.send_signal(signal.SIGTERM)
        out, _ = p.communicate(timeout=10)
        # (well under the 30 s of the kill grace a run that ignored SIGTERM would get: the bound
        # tells a stop from a wait, with room for a loaded machine)
        self.assertLess(time.time() - t, 5.0)
        self.assertEqual(p.returncode, 4, out)
        self.assertIn("('modeok_x1', True, None)", out)
        self.assertIn("('modehang_x2', False, 'interrupted')", out)
        time.sleep(0.2)
        self.assertFalse(os.path.exists('/proc/%d' % child) and 'Z' not in _proc_state(child))

    def test_summary_file(self):
        cases = dm_sweep.grid([('mode', ['ok', 'fail']), ('x', [1])])
        s = self.sweep(cases)
        s.run()
        path = s.write_summary(os.path.join(self.tmp, 'out', 'sweep.yaml'))
        with open(path) as fh:
            doc = yaml.safe_load(fh)
        self.assertEqual((doc['cases'], doc['failed'], doc['jobs']), (2, 1, 2))
        self.assertGreaterEqual(doc['wall_time'], 0)
        self.assertEqual([r['name'] for r in doc['runs']], ['modeok_x1', 'modefail_x1'])
        ok, bad = doc['runs']
        self.assertEqual(ok['params'], {'mode': 'ok', 'x': 1})
        self.assertTrue(ok['ok'])
        self.assertIsNone(ok['error'])
        self.assertFalse(ok['kept'])
        self.assertEqual(ok['returncode'], 0)
        self.assertTrue(ok['result'].endswith('runs/modeok_x1.result.yaml'))
        self.assertTrue(ok['log'].endswith('runs/modeok_x1.log'))
        self.assertFalse(bad['ok'])
        self.assertEqual(bad['error'], 'the soil gave way')
        # a sweep's own format: header and rows
        s.write_summary(path, header={'level': 'tiny'}, row=lambda o: {'x': o.case['x'], 'ok': o.ok})
        with open(path) as fh:
            self.assertEqual(yaml.safe_load(fh), {'level': 'tiny', 'runs': [{'x': 1, 'ok': True}, {'x': 1, 'ok': False}]})

    def test_check_and_describe(self):
        cases = dm_sweep.cases([{'mode': 'ok', 'x': 1}, {'mode': 'empty', 'x': 2}])
        s = self.sweep(cases, check=lambda case, res: None if res.get('value') else 'no value',
                       describe=lambda o: 'value %.1f' % o.result['value'] if o.ok else 'FAILED: ' + o.error)
        s.run()
        self.assertTrue(s.outcomes[0].ok)
        self.assertRegex(s.outcomes[1].error, r'^no value; see .*modeempty_x2\.log$')
        self.assertIn('value 2.0', self.out.getvalue())

    def test_parallelism(self):
        # each run lasts well beyond the start-up of a python process on a loaded machine
        for jobs, n, sleep in ((1, 3, 0.3), (3, 6, 1.0)):
            with self.subTest(jobs=jobs):
                if os.path.exists(self.journal):
                    os.remove(self.journal)
                cases = dm_sweep.grid([('x', list(range(n)))])
                s = self.sweep(cases, jobs=jobs, command=self.command(sleep=sleep))
                s.run()
                self.assertEqual(s.exit_status(), 0)
                events = sorted((t, w, n, p) for w, n, t, p in self.journal_rows())
                running, most = {}, 0
                for t, w, n, p in events:
                    if w == 'start':
                        self.assertNotIn(p, running.values(), 'two runs at once on port %d' % p)
                        running[n] = p
                        most = max(most, len(running))
                    else:
                        del running[n]
                self.assertEqual(most, jobs)
                ports = {o.port for o in s.outcomes}
                self.assertEqual(ports, {s.port + 2 * k for k in range(jobs)})

    def test_busy_port_skipped(self):
        base = free_port_base()
        busy = socket.socket()
        busy.bind(('127.0.0.1', base))
        busy.listen(1)
        self.addCleanup(busy.close)
        self.assertFalse(dm_sweep.port_free(base))
        s = self.sweep(dm_sweep.grid([('x', [1, 2])]), jobs=1, port=base)
        s.run()
        self.assertEqual(s.exit_status(), 0)
        self.assertEqual({o.port for o in s.outcomes}, {base + 2})

    def test_command_template_and_env(self):
        cases = dm_sweep.grid([('x', [7])])
        cmd = [sys.executable, self.script, 'ok', '0', self.journal, '{x}']
        s = self.sweep(cases, command=cmd)
        s.run()
        self.assertEqual(s.outcomes[0].result['value'], 14.0)
        self.assertEqual(self.journal_rows()[0][3], s.port)

    def test_missing_program(self):
        s = self.sweep(dm_sweep.grid([('x', [1])]), command=['/nonexistent/dm_rig'])
        s.run()
        self.assertRegex(s.outcomes[0].error, r'^cannot start /nonexistent/dm_rig: ')
        self.assertEqual(s.exit_status(), 1)

    def test_outputs_removed_before_a_run(self):
        cases = dm_sweep.grid([('x', [1])])
        stale = os.path.join(self.tmp, 'x1.bag')
        os.makedirs(self.runs)
        for p in (stale, os.path.join(self.runs, 'x1.result.yaml')):
            with open(p, 'w') as fh:
                fh.write('status: ok\n')
        s = self.sweep(cases, outputs=lambda case: [os.path.join(self.tmp, case.name + '.bag')])
        s.run()
        self.assertFalse(os.path.exists(stale))
        self.assertEqual(s.outcomes[0].result['value'], 2.0)


class Resume(Base):
    def test_done_cases_not_rerun(self):
        cases = dm_sweep.cases([{'mode': 'ok', 'x': 1}, {'mode': 'fail', 'x': 2}, {'mode': 'ok', 'x': 3}])
        first = self.sweep(cases)
        first.run()
        self.assertEqual(first.exit_status(), 1)
        self.assertEqual(sorted(self.starts()), ['modefail_x2', 'modeok_x1', 'modeok_x3'])
        os.remove(self.journal)
        # a third case that never ran and one whose result is broken
        cases.append(dm_sweep.Case({'mode': 'ok', 'x': 4}, index=3))
        with open(os.path.join(self.runs, 'modeok_x3.result.yaml'), 'w') as fh:
            fh.write('status: [unclosed\n')
        second = self.sweep(cases)
        kept = second.resume()
        self.assertEqual([o.name for o in kept], ['modeok_x1'])
        self.assertTrue(kept[0].kept and kept[0].ok)
        self.assertEqual(kept[0].result['value'], 2.0)
        self.assertIn('kept   modeok_x1      ok (from ', self.out.getvalue())
        second.run()
        self.assertEqual(sorted(self.starts()), ['modefail_x2', 'modeok_x3', 'modeok_x4'])
        self.assertIn('[4/4]', self.out.getvalue())
        path = second.write_summary(os.path.join(self.tmp, 'sweep.yaml'))
        with open(path) as fh:
            rows = {r['name']: r for r in yaml.safe_load(fh)['runs']}
        self.assertTrue(rows['modeok_x1']['kept'])
        self.assertEqual(rows['modeok_x1']['wall_time'], 0.0)  # the stand-in's wall_time
        self.assertFalse(rows['modeok_x3']['kept'])
        self.assertFalse(rows['modefail_x2']['ok'])

    def test_a_good_result_of_a_run_that_failed_is_not_kept(self):
        # the run wrote a good result and then exited with 5: failed; a resume runs it again
        cases = dm_sweep.cases([{'mode': 'ok', 'x': 1}, {'mode': 'exit_after_result', 'x': 2}])
        first = self.sweep(cases)
        first.run()
        by = {o.case['x']: o for o in first.outcomes}
        self.assertIn('exited with 5', by[2].error)
        os.remove(self.journal)
        second = self.sweep(cases)
        self.assertEqual([o.name for o in second.resume()], ['modeok_x1'])
        second.run()
        self.assertEqual(self.starts(), ['modeexit-after-result_x2'])

    def test_accept_and_check(self):
        cases = dm_sweep.grid([('x', [1, 2])])
        self.sweep(cases).run()
        os.remove(self.journal)
        s = self.sweep(cases)
        self.assertEqual([o.name for o in s.resume(accept=lambda case, res: case['x'] == 2)], ['x2'])
        s.run()
        self.assertEqual(self.starts(), ['x1'])
        # a check the old results fail: everything reruns
        s = self.sweep(cases, check=lambda case, res: 'too small' if res['value'] < 10 else None)
        self.assertEqual(s.resume(), [])


    def test_accepted_status(self):
        cases = dm_sweep.cases([{'mode': 'sunk', 'x': 1}, {'mode': 'ok', 'x': 2}])
        plain = self.sweep(cases)
        plain.run()
        self.assertEqual([o.name for o in plain.failed()], ['modesunk_x1'])
        self.assertIn('the wheel sank', plain.failed()[0].error)
        os.remove(self.journal)
        # a sunk wheel is a measurement: good, kept on resume, with its error in the result
        s = self.sweep(cases, accept_status=('sunk',))
        self.assertEqual([o.name for o in s.resume()], ['modesunk_x1', 'modeok_x2'])
        s.run()
        self.assertEqual(self.starts(), [])
        self.assertEqual(s.exit_status(), 0)
        self.assertEqual(s.outcomes[0].result['error'], 'the wheel sank 0.3 m')
        # the sweep's check still applies to it
        s = self.sweep(cases, accept_status=('sunk',), check=lambda case, res: 'no' if case['x'] == 1 else None)
        self.assertEqual([o.name for o in s.resume()], ['modeok_x2'])
        with self.assertRaises(ValueError):
            self.sweep(cases, accept_status=('sunk', 'error'))


class Progress(Base):
    def test_plain_lines(self):
        p = dm_sweep.Progress(3, mode='plain', stream=self.out)
        self.assertIsNone(p.bar)
        p.line('one')
        p.advance()
        p.close()
        self.assertEqual(self.out.getvalue(), 'one\n')

    def test_tqdm_when_importable(self):
        made = []

        class FakeTqdm:
            def __init__(self, total, initial, unit, file):
                self.total, self.n, self.closed, self.lines = total, initial, False, []
                made.append(self)

            def update(self, k):
                self.n += k

            def write(self, text, file):
                self.lines.append(text)
                file.write(text + '\n')

            def close(self):
                self.closed = True

        saved = sys.modules.get('tqdm')
        sys.modules['tqdm'] = types.SimpleNamespace(tqdm=FakeTqdm)
        try:
            cases = dm_sweep.cases([{'mode': 'ok', 'x': 1}, {'mode': 'fail', 'x': 2}])
            s = self.sweep(cases, progress='tqdm')
            s.run()
        finally:
            if saved is None:
                del sys.modules['tqdm']
            else:
                sys.modules['tqdm'] = saved
        self.assertEqual(len(made), 1)
        bar = made[0]
        self.assertEqual((bar.total, bar.n, bar.closed), (2, 2, True))
        self.assertEqual(sum(' done ' in t for t in bar.lines), 2)
        self.assertIn(' done ', self.out.getvalue())

    def test_without_tqdm(self):
        saved = sys.modules.get('tqdm')
        sys.modules['tqdm'] = None  # import tqdm raises ImportError
        try:
            self.assertIsNone(dm_sweep.load_tqdm())
            self.assertIsNone(dm_sweep.Progress(1, mode='tqdm').bar)
        finally:
            if saved is None:
                del sys.modules['tqdm']
            else:
                sys.modules['tqdm'] = saved

    def test_status_lines_from_logs(self):
        s = self.sweep(dm_sweep.grid([('x', [1])]), status_every=0.0, command=self.command(sleep=0.4))
        s.run()
        self.assertIn('...    x1             half way', self.out.getvalue())
        log = os.path.join(self.tmp, 'log')
        with open(log, 'w') as fh:
            fh.write('\x1b[0m[ INFO] terrain: progress: t = 0.20 s\x1b[0m\nother\n')
        self.assertEqual(dm_sweep.last_progress(log), 't = 0.20 s')
        self.assertEqual(dm_sweep.last_progress(os.path.join(self.tmp, 'none')), '')


class RunSweep(Base):
    def test_all_ok(self):
        cases = dm_sweep.grid([('x', [1, 2, 3])])
        summary = os.path.join(self.tmp, 'sweep.yaml')
        s = dm_sweep.run_sweep(cases, self.command(), self.runs, summary=summary, jobs=2, port=free_port_base(),
                               poll=0.02, progress='plain', stream=self.out)
        self.assertEqual(s.exit_status(), 0)
        with open(summary) as fh:
            self.assertEqual(yaml.safe_load(fh)['failed'], 0)
        text = self.out.getvalue()
        self.assertTrue(text.startswith('sweep: 3 cases (0 kept, 3 to run), 2 at a time\n'), text)
        self.assertRegex(text, r'sweep: 3 runs in \d+ s, 0 failed\n$')
        # again with resume: nothing runs
        os.remove(self.journal)
        s = dm_sweep.run_sweep(cases, self.command(), self.runs, summary=summary, resume=True, poll=0.02,
                               progress='plain', stream=self.out)
        self.assertEqual(s.exit_status(), 0)
        self.assertEqual(self.starts(), [])

    def test_failure_listed(self):
        cases = dm_sweep.cases([{'mode': 'ok'}, {'mode': 'crash'}])
        s = dm_sweep.run_sweep(cases, self.command(), self.runs, summary=os.path.join(self.tmp, 's.yaml'), poll=0.02,
                               port=free_port_base(), progress='plain', stream=self.out)
        self.assertEqual(s.exit_status(), 1)
        self.assertIn('1 failed\n  failed: modecrash: no result file', self.out.getvalue())


def _proc_state(pid):
    try:
        with open('/proc/%d/stat' % pid) as fh:
            return fh.read().split(')')[-1].split()[0]
    except OSError:
        return 'gone'


if __name__ == '__main__':
    unittest.main()
