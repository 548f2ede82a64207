"""Tests of `doe run`, `doe status` and `doe case` (dem_mobility_tools.doe.runner) on the local pool with
real runs: road cases through the core runner (build/core's dm_run_scene, about 9 s each), where the
outcomes are known from the power balance (the rigid road at 0-2 deg: the vehicle reaches the
25 m/s command), so the pruning, resume and retry can be checked against them; and the worker's
decisions (implied or run, with cases in flight) on made-up states.

    PYTHONPATH=python DM_RUN_SCENE=build/core/src/tools/dm_run_scene python3 test/python/test_doe_run.py
"""
import os
import shutil
import subprocess
import sys
import tempfile
import time
import unittest

import yaml

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
from dem_mobility_tools import paths
from dem_mobility_tools.doe import plan, runner, slurm, table
from dem_mobility_tools.doe.local_cluster import LocalCluster

DOE = [sys.executable, '-m', 'dem_mobility_tools.doe']  # dm-doe
DM_RUN_SCENE = paths.dm_run_scene()


def doe(*args, env=None):
    e = dict(os.environ, DM_RUN_SCENE=DM_RUN_SCENE)
    e.update(env or {})
    p = subprocess.run(DOE + list(args), capture_output=True, text=True, env=e)
    return p.returncode, p.stdout, p.stderr


def load(path):
    with open(path) as fh:
        return yaml.safe_load(fh)


class Decisions(unittest.TestCase):
    """runner.decide on made-up states: a 3 x 3 grid (grades 0, 10, 20 x CI 50, 100, 150)."""

    def setUp(self):
        grid = plan.Grid([0.0, 10.0, 20.0], [50.0, 100.0, 150.0])
        self.doc = runner.make_plan(grid, 'tiny', 'core', 1, None, True, lambda g, c: 100.0)
        self.by_cell = {tuple(c['cell']): c for c in self.doc['cases']}

    def states(self, **given):
        """cell name 'i_j' -> (state, result); the others pending."""
        s = {c['index']: ('pending', None) for c in self.doc['cases']}
        for key, (state, status, speed) in given.items():
            i, j = (int(x) for x in key[1:].split('_'))
            s[self.by_cell[(i, j)]['index']] = (state, {'status': status, 'speed_made_good': speed})
        return s

    def test_a_stuck_easier_case_implies_no_go(self):
        # (10 deg, CI 100) stuck: (20 deg, CI 50) is harder, so stuck too
        st = self.states(c1_1=('simulated', 'no_go', 0.0))
        x = runner.decide(self.by_cell[(2, 0)], self.doc, st)
        self.assertEqual((x[0], x[1], x[2]['name']), (plan.NO_GO, 0.0, 'g10_ci100'))
        # not an easier one
        self.assertIsNone(runner.decide(self.by_cell[(0, 2)], self.doc, st))

    def test_a_harder_case_in_flight_makes_it_run(self):
        # (20 deg, CI 100) is implied no_go by (10 deg, CI 100); but a run in flight at (20 deg,
        # CI 50), harder than it, could still move and contradict the bound: the case runs
        st = self.states(c1_1=('simulated', 'no_go', 0.0), c2_0=('running', None, 0.0))
        self.assertIsNone(runner.decide(self.by_cell[(2, 1)], self.doc, st))
        # an easier case in flight cannot contradict a no-go bound
        st = self.states(c1_1=('simulated', 'no_go', 0.0), c0_2=('running', None, 0.0))
        self.assertEqual(runner.decide(self.by_cell[(2, 1)], self.doc, st)[0], plan.NO_GO)

    def test_command_limited_bounds_the_easier_cases_from_below(self):
        st = self.states(c2_0=('simulated', 'command_limited', 24.9))
        x = runner.decide(self.by_cell[(1, 1)], self.doc, st)
        self.assertEqual((x[0], x[1]), (plan.COMMAND_LIMITED, 24.9))
        # an easier case in flight could still fall short of the command
        st = self.states(c2_0=('simulated', 'command_limited', 24.9), c0_2=('running', None, 0.0))
        self.assertIsNone(runner.decide(self.by_cell[(1, 1)], self.doc, st))

    def test_a_plan_of_an_older_version_is_refused_naming_the_old_key_and_the_new(self):
        self.assertEqual({k for c in self.doc['cases'] for k in c} & {'cone_index', 'grade'}, set())
        out = tempfile.mkdtemp()
        self.addCleanup(shutil.rmtree, out)
        old = dict(self.doc, cases=[dict(c) for c in self.doc['cases']])
        old['cases'][4]['cone_index'] = old['cases'][4].pop('cone_index_psi')
        runner.write_yaml(os.path.join(out, runner.PLAN_FILE), old)
        with self.assertRaises(runner.RunnerError) as e:
            runner.load_plan(out)
        self.assertIn("%s: cases[4]: 'cone_index' is an old name: it is 'cone_index_psi' now"
                      % os.path.join(out, runner.PLAN_FILE), str(e.exception))
        old = dict(self.doc, refinements=[{'axis': 'grade', 'value': 5.0, 'between': [0.0, 10.0]}])
        runner.write_yaml(os.path.join(out, runner.PLAN_FILE), old)
        with self.assertRaisesRegex(runner.RunnerError, "refinements\\[0\\]: axis 'grade' is an old name: it is "
                                    "'grade_deg' now"):
            runner.load_plan(out)
        runner.write_yaml(os.path.join(out, runner.PLAN_FILE), self.doc)
        self.assertEqual(runner.load_plan(out)['cases'], self.doc['cases'])

    def test_implied_cases_never_bound_others_and_no_prune_runs_everything(self):
        st = self.states(c1_1=('implied', 'no_go', 0.0))
        self.assertIsNone(runner.decide(self.by_cell[(2, 0)], self.doc, st))
        self.doc['prune'] = False
        st = self.states(c1_1=('simulated', 'no_go', 0.0))
        self.assertIsNone(runner.decide(self.by_cell[(2, 0)], self.doc, st))


class CaseCommands(unittest.TestCase):
    """What a case runs: the launch file (or dm_run_scene) with the DOE's grade, level, CI, threads
    and duration, and the user's scene file where the plan has one (--soil-scene)."""

    def test_the_plans_scene_files_reach_both_runners(self):
        grid = plan.Grid([0.0, 12.0], [50.0, 300.0])
        road = os.path.join(ROOT, 'config', 'scenes', 'road_slope.yaml')
        soil = os.path.join(ROOT, 'config', 'scenes', 'soil_slope.yaml')
        own = runner.check_scene_file(soil, 'soil')
        self.assertEqual(own['file'], soil)
        self.assertEqual(len(own['sha256']), 64)
        with self.assertRaises(runner.RunnerError) as e:
            runner.check_scene_file(road, 'soil')
        self.assertIn("scene: 'road_slope', where the soil cases take a scene of kind soil_slope", str(e.exception))
        for r in ('roslaunch', 'core'):
            plain = runner.make_plan(grid, 'tiny', r, 2, 5.0, True, lambda g, c: 1.0)
            given = runner.make_plan(grid, 'tiny', r, 2, 5.0, True, lambda g, c: 1.0, scenes={'soil': own})
            self.assertIsNone(runner.same_design(plain, plain))
            self.assertIn('scenes', runner.same_design(plain, given))
            by = {(c['grade_deg'], c['cone_index_psi']): c for c in given['cases']}
            s = runner.case_command(given, by[(12.0, 50.0)], '/tmp/doe', 11611, dm_run_scene='/x/dm_run_scene')
            g = runner.case_command(given, by[(12.0, 300.0)], '/tmp/doe', 11611, dm_run_scene='/x/dm_run_scene')
            if r == 'roslaunch':
                self.assertEqual(s[:5], ['roslaunch', '-p', '11611', 'dem_mobility', 'soil_slope.launch'])
                for arg in ('grade:=12', 'scene:=' + soil, 'duration:=5', 'fidelity:=tiny', 'cone_index:=50', 'dem_threads:=2'):
                    self.assertIn(arg, s)
                self.assertEqual(g[4], 'road_slope.launch')
                self.assertFalse([a for a in g if a.startswith('scene:=')])  # the shipped road scene
            else:
                self.assertEqual(s[:3], ['/x/dm_run_scene', soil, 'grade_deg=12'])
                for arg in ('duration=5', 'terrain_overrides.fidelity=tiny', 'terrain_overrides.cone_index=50',
                            'terrain_overrides.threads=2'):
                    self.assertIn(arg, s)
                self.assertEqual(g[1], road)


# a stand-in for dm_run_scene that ends as roslaunch does: `before` s, then a good road result
# written to --out, a file beside it saying so, and `after` s more (roslaunch taking its nodes down)
STAND_IN = r'''
import sys, time
before, after = float(sys.argv[1]), float(sys.argv[2])
out = sys.argv[sys.argv.index('--out') + 1]
time.sleep(before)
with open(out, 'w') as fh:
    fh.write('kind: road_slope\nstatus: command_limited\nerror: ""\ngrade_deg: 0\nspeed_made_good: 25.0\n')
open(out + '.written', 'w').close()
time.sleep(after)
'''


class CaseSignals(unittest.TestCase):
    """`doe case` stopped by SIGTERM (a pool's timeout, Slurm's scancel): a run that had written its
    good result and was still ending keeps it (a finished case is never replaced); a run stopped
    before its result is recorded interrupted."""

    def setUp(self):
        self.tmp = tempfile.mkdtemp(prefix='dm_doe_signal_')
        self.out = os.path.join(self.tmp, 'doe')
        os.makedirs(runner.runs_dir(self.out))
        self.doc = runner.make_plan(plan.Grid([0.0], [300.0]), 'tiny', 'core', 1, 5.0, True, lambda g, c: 1.0)
        runner.write_yaml(os.path.join(self.out, runner.PLAN_FILE), self.doc)
        self.exe = os.path.join(self.tmp, 'stand_in')

    def tearDown(self):
        shutil.rmtree(self.tmp, ignore_errors=True)

    def case_stopped(self, before, after, wait_for_result):
        with open(self.exe, 'w') as fh:
            fh.write('#!/bin/sh\nexec %s -c "$STAND_IN_CODE" %g %g "$@"\n' % (sys.executable, before, after))
        os.chmod(self.exe, 0o755)
        env = dict(os.environ, DM_RUN_SCENE=self.exe, STAND_IN_CODE=STAND_IN)
        p = subprocess.Popen(DOE + ['case', '--out', self.out, '--index', '0'], env=env,
                             stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
        case = self.doc['cases'][0]
        written = runner.result_path(self.out, case) + '.written'
        deadline = time.time() + 30
        while not os.path.exists(written if wait_for_result else runner.marker_path(self.out, case)):
            self.assertLess(time.time(), deadline, 'the case did not start')
            time.sleep(0.05)
        time.sleep(0.3)  # (the stand-in started: its sleep)
        p.terminate()
        so, _ = p.communicate(timeout=60)
        return p.returncode, so, runner.scan(self.out, self.doc)[0], runner.read_result(runner.result_path(self.out, case))

    def test_a_result_written_before_the_signal_is_kept(self):
        rc, so, (state, _), r = self.case_stopped(0.0, 30.0, True)
        self.assertEqual(rc, 0, so)
        self.assertIn('the result kept', so)
        self.assertEqual(state, 'simulated')
        self.assertEqual((r['status'], r['speed_made_good']), ('command_limited', 25.0))
        prov = runner.read_result(runner.provenance_path(self.out, self.doc['cases'][0]))
        self.assertEqual((prov['exit_status'], prov['signal_after_result']), (0, 15))

    def test_a_run_stopped_before_its_result_is_interrupted(self):
        rc, so, (state, _), r = self.case_stopped(30.0, 0.0, False)
        self.assertEqual(rc, 128 + 15, so)
        self.assertEqual(state, 'interrupted')
        self.assertEqual(r['status'], 'interrupted')
        self.assertIn('stopped (signal 15)', r['error'])


# a stand-in for dm_run_scene whose speed-made-good is a known function of the grade: steady at
# 20 - 0.05 g^2 m/s (20, 15 and 0 m/s at 0, 10 and 20 deg), so where the speed changes fastest is known
STEADY_STAND_IN = r'''
import sys
g = float(next(a for a in sys.argv if a.startswith('grade_deg=')).split('=')[1])
out = sys.argv[sys.argv.index('--out') + 1]
with open(out, 'w') as fh:
    fh.write('kind: road_slope\nstatus: steady\nerror: ""\ngrade_deg: %r\nspeed_made_good: %r\n' % (g, 20.0 - 0.05 * g * g))
'''


class Refinement(unittest.TestCase):
    """doe run --refine N: grid lines where the speed changes fastest between neighbours."""

    def test_the_largest_jumps_are_split_at_their_midpoints(self):
        grades, cis = [0.0, 10.0, 20.0], [30.0, 50.0, 100.0, 300.0]
        speed = [[10.0, 12.0, 14.0, 25.0],
                 [6.0, 11.0, 13.0, 25.0],
                 [0.0, 3.0, 12.0, 24.0]]
        # the largest |difference| across each pair: grades 0-10: 4 (at 30 psi), 10-20: 8 (at 50
        # psi); CIs 30-50: 5 (at 10 deg), 50-100: 9 (at 20 deg); 100-300 is the road's
        picks = plan.refinements(grades, cis, speed, 3)
        self.assertEqual([(p[0], p[1], p[2]) for p in picks],
                         [('cone_index_psi', 75.0, (50.0, 100.0)), ('grade_deg', 15.0, (10.0, 20.0)),
                          ('cone_index_psi', 40.0, (30.0, 50.0))])
        self.assertEqual([p[3] for p in picks], [9.0, 8.0, 5.0])
        # the road's column is not split towards the soil (100 -> 300 jumps by 12); nor a pair
        # whose halves would be under the minimum step
        self.assertNotIn(200.0, [p[1] for p in plan.refinements(grades, cis, speed, 10)])
        self.assertEqual(plan.refinements([0.0, 1.5], [50.0], [[5.0], [1.0]], 1), [])
        self.assertEqual(plan.refinements([0.0, 2.0], [50.0, 58.0], [[5.0, 6.0], [1.0, 9.0]], 2),
                         [('grade_deg', 1.0, (0.0, 2.0), 4.0)])

    def test_a_refined_doe_runs_the_new_line_keeps_the_rest_and_resumes(self):
        tmp = tempfile.mkdtemp(prefix='dm_doe_refine_')
        self.addCleanup(shutil.rmtree, tmp, True)
        exe = os.path.join(tmp, 'stand_in')
        with open(exe, 'w') as fh:
            fh.write('#!/bin/sh\nexec %s -c "$STAND_IN_CODE" "$@"\n' % sys.executable)
        os.chmod(exe, 0o755)
        env = {'DM_RUN_SCENE': exe, 'STAND_IN_CODE': STEADY_STAND_IN}
        out = os.path.join(tmp, 'doe')
        grid = ['--grades', '0,10,20', '--cone-indices', '300', '--runner', 'core', '--progress', 'plain']
        rc, so, se = doe('run', '--out', out, '--refine', '1', *grid, env=env)
        self.assertEqual(rc, 0, so + se)
        self.assertIn('refinement: grade 15 between 10 and 20 (the speed changes by up to 15.00 m/s', so)
        t = load(os.path.join(out, 'doe_table.yaml'))
        self.assertEqual(t['grades'], [0.0, 10.0, 15.0, 20.0])
        self.assertEqual([row[0] for row in t['speed']], [20.0, 15.0, 8.75, 0.0])
        self.assertEqual((t['simulated'], t['implied'], t['failed']), (4, 0, 0))
        p = runner.load_plan(out)
        self.assertEqual(p['design']['grades'], [0.0, 10.0, 20.0])
        self.assertEqual([(r['axis'], r['value'], r['between']) for r in p['refinements']], [('grade_deg', 15.0, [10.0, 20.0])])
        # the cases run before were not run again (one log line each), the new one once
        with open(os.path.join(out, 'runs', 'g0_ci300.log')) as fh:
            self.assertEqual(fh.read().count('$ '), 1)
        # resume with the same grid: nothing to run, no new line; --refine 2 adds the next
        rc, so, se = doe('run', '--out', out, '--resume', '--refine', '1', *grid, env=env)
        self.assertEqual(rc, 0, so + se)
        self.assertIn('4 cases: 4 done, 0 to run', so)
        self.assertNotIn('refinement:', so)
        rc, so, se = doe('run', '--out', out, '--resume', '--refine', '2', *grid, env=env)
        self.assertEqual(rc, 0, so + se)
        self.assertIn('refinement: grade 17.5 between 15 and 20', so)  # 8.75 m/s there: the largest now
        self.assertEqual(load(os.path.join(out, 'doe_table.yaml'))['grades'], [0.0, 10.0, 15.0, 17.5, 20.0])
        rc, _, se = doe('run', '--out', out, '--refine', '-1', '--resume', *grid, env=env)
        self.assertEqual(rc, 2)
        self.assertIn('--refine -1', se)


class RoadDoe(unittest.TestCase):
    """A 3 x 1 DOE on the rigid road (grades 0, 1, 2 deg, CI 300): the plan runs 0 and 2 deg first
    (the axis's ends); 2 deg reaches the 25 m/s command, which bounds 1 deg from below: implied."""

    @classmethod
    def setUpClass(cls):
        cls.tmp = tempfile.mkdtemp(prefix='dm_doe_run_')

    @classmethod
    def tearDownClass(cls):
        shutil.rmtree(cls.tmp, ignore_errors=True)

    def test_pruned_road_doe_then_resume_then_failures_and_retry(self):
        out = os.path.join(self.tmp, 'road')
        grid = ['--grades', '0,1,2', '--cone-indices', '300', '--runner', 'core', '--progress', 'plain']
        rc, so, se = doe('run', '--out', out, *grid)
        self.assertEqual(rc, 0, so + se)
        t = load(os.path.join(out, 'doe_table.yaml'))
        self.assertEqual((t['cases'], t['simulated'], t['implied'], t['runs_saved'], t['failed']), (3, 2, 1, 1, 0))
        rows = {r['grade_deg']: r for r in t['cases_table']}
        # the power balance: on 0-2 deg the road vehicle reaches the 25 m/s command
        for g in (0.0, 2.0):
            self.assertEqual(rows[g]['state'], 'simulated')
            self.assertEqual(rows[g]['status'], 'command_limited')
            self.assertAlmostEqual(rows[g]['speed_made_good'], 25.0, delta=0.05)
        self.assertEqual(rows[1.0]['state'], 'implied')
        self.assertEqual(rows[1.0]['source'], 'implied by g2_ci300')
        self.assertEqual(rows[1.0]['speed_made_good'], rows[2.0]['speed_made_good'])
        implied = load(os.path.join(out, 'runs', 'g1_ci300.result.yaml'))
        self.assertEqual((implied['status'], implied['simulated'], implied['implied_status']),
                         ('implied', False, 'command_limited'))
        self.assertFalse(os.path.exists(os.path.join(out, 'runs', 'g1_ci300.log')))  # never run
        self.assertTrue(load(os.path.join(out, 'runs', 'g0_ci300.provenance.yaml'))['commit'])
        self.assertEqual(t['speed'], [[rows[g]['speed_made_good']] for g in (0.0, 1.0, 2.0)])
        for f in ('doe_table.csv', 'doe_speed_vs_ci.png', 'doe_speed_vs_grade.png'):
            self.assertGreater(os.path.getsize(os.path.join(out, f)), 100, f)
        # the table is one `doe map` reads
        self.assertEqual(table.read_table(os.path.join(out, 'doe_table.yaml'))['speed'].shape, (3, 1))
        rc, so, _ = doe('status', '--out', out)
        self.assertEqual(rc, 0)
        self.assertIn('simulated 2, implied 1 (runs saved), failed 0, running 0, pending 0', so)
        # resume: nothing to run; the same folder without --resume, or with another grid: refused
        rc, so, se = doe('run', '--out', out, '--resume', *grid)
        self.assertEqual(rc, 0, se)
        self.assertIn('3 cases: 3 done, 0 to run', so)
        rc, _, se = doe('run', '--out', out, *grid)
        self.assertEqual(rc, 2)
        self.assertIn('holds a DOE already', se)
        rc, _, se = doe('run', '--out', out, '--resume', '--grades', '0,1,3', *grid[2:])
        self.assertEqual(rc, 2)
        self.assertIn('grades', se)

        # a runner that cannot start: every case fails, is reported with its error, and the exit
        # status is 1; --resume alone keeps them failed, --retry-failed runs them
        out2 = os.path.join(self.tmp, 'failing')
        rc, so, se = doe('run', '--out', out2, *grid, env={'DM_RUN_SCENE': '/nonexistent/dm_run_scene'})
        self.assertEqual(rc, 1, so + se)
        self.assertIn('failed 3', so)
        with open(os.path.join(out2, 'runs', 'g0_ci300.log')) as fh:
            self.assertIn('cannot start /nonexistent/dm_run_scene', fh.read())
        rc, so, se = doe('run', '--out', out2, '--resume', *grid)
        self.assertEqual(rc, 1)
        self.assertIn('failed before: g0_ci300', so)
        self.assertIn('0 to run', so)
        rc, so, se = doe('run', '--out', out2, '--resume', '--retry-failed', *grid)
        self.assertEqual(rc, 0, so + se)
        t2 = load(os.path.join(out2, 'doe_table.yaml'))
        self.assertEqual((t2['simulated'], t2['implied'], t2['failed']), (2, 1, 0))

    def test_a_killed_doe_loses_no_finished_case_and_resume_runs_what_is_missing(self):
        import signal
        out = os.path.join(self.tmp, 'killed')
        # (8 s of driving a case: the runner's bookkeeping is what is tested, not the speeds)
        grid = ['--grades', '0,1,2', '--cone-indices', '300', '--runner', 'core', '--progress', 'plain', '--no-prune',
                '--duration', '8']
        env = dict(os.environ, DM_RUN_SCENE=DM_RUN_SCENE)
        p = subprocess.Popen(DOE + ['run', '--out', out] + grid, stdout=subprocess.DEVNULL,
                             stderr=subprocess.DEVNULL, env=env, start_new_session=True)
        first, marker = os.path.join(out, 'runs', 'g0_ci300.result.yaml'), os.path.join(out, 'runs', 'g2_ci300.running')
        t0 = time.time()
        while not (os.path.exists(first) and os.path.exists(marker)) and time.time() - t0 < 120:
            time.sleep(0.2)
        self.assertTrue(os.path.exists(marker), 'the second case never started')
        with open(first) as fh:
            kept = fh.read()
        # the runner and the case's worker killed mid-run (SIGKILL: no clean-up)
        worker = load(marker)['pid']
        os.killpg(p.pid, signal.SIGKILL)
        os.killpg(os.getpgid(worker), signal.SIGKILL)
        p.wait()
        for _ in range(50):  # (the killed worker is gone within moments)
            rc, so, _ = doe('status', '--out', out)
            if 'interrupted' in so:
                break
            time.sleep(0.1)
        self.assertIn('simulated 1,', so)
        self.assertIn('interrupted 1 (stopped mid-run', so)
        rc, so, se = doe('run', '--out', out, '--resume', *grid)
        self.assertEqual(rc, 0, so + se)
        self.assertIn('3 cases: 1 done, 2 to run', so)
        with open(first) as fh:
            self.assertEqual(fh.read(), kept)  # the finished case untouched
        t = load(os.path.join(out, 'doe_table.yaml'))
        self.assertEqual((t['simulated'], t['implied'], t['failed'], t['not_run']), (3, 0, 0, 0))

    def test_a_case_over_its_timeout_is_failed_and_kept_failed(self):
        out = os.path.join(self.tmp, 'timeout')
        grid = ['--grades', '0', '--cone-indices', '300', '--runner', 'core', '--progress', 'plain']
        rc, so, se = doe('run', '--out', out, '--timeout', '2', *grid)
        self.assertEqual(rc, 1, so + se)
        r = load(os.path.join(out, 'runs', 'g0_ci300.result.yaml'))
        self.assertEqual(r['status'], 'error')
        self.assertIn('timed out after', r['error'])
        self.assertFalse(os.path.exists(os.path.join(out, 'runs', 'g0_ci300.running')))
        rc, so, _ = doe('run', '--out', out, '--resume', *grid)
        self.assertEqual(rc, 1)
        self.assertIn('failed before: g0_ci300: timed out after', so)
        self.assertIn('0 to run', so)

    def test_bad_input_is_refused(self):
        for args, what in ((['--jobs', '0'], '--jobs'), (['--duration', '90'], '--duration'),
                           (['--cone-indices', '10,300', '--grades', '0,5'], 'cone index 10')):
            rc, _, se = doe('run', '--out', os.path.join(self.tmp, 'bad'), '--dry-run', *args)
            self.assertEqual(rc, 2, args)
            self.assertIn(what, se)
        # a scene file for the soil cases that is of another kind, or missing: refused naming it
        road = os.path.join(ROOT, 'config', 'scenes', 'road_slope.yaml')
        for args, what in ((['--soil-scene', road], '--soil-scene %s: scene: \'road_slope\'' % road),
                           (['--road-scene', '/nonexistent.yaml'], '--road-scene /nonexistent.yaml')):
            rc, _, se = doe('run', '--out', os.path.join(self.tmp, 'bad'), '--dry-run', '--grades', '0',
                            '--cone-indices', '50,300', *args)
            self.assertEqual(rc, 2, args)
            self.assertIn(what, se)
        rc, _, se = doe('status', '--out', os.path.join(self.tmp, 'nothing_here'))
        self.assertEqual(rc, 2)
        self.assertIn('no DOE here', se)


def have_slurm():
    return all(os.path.exists(p) for p in ('/usr/sbin/slurmctld', '/usr/sbin/slurmd', '/usr/sbin/munged', '/usr/bin/sbatch'))


@unittest.skipUnless(os.access(DM_RUN_SCENE, os.X_OK), 'no dm_run_scene at %s (build the core first)' % DM_RUN_SCENE)
@unittest.skipUnless(have_slurm(), 'no Slurm (scripts/lib.sh DM_SLURM_PACKAGES)')
class SlurmDoe(unittest.TestCase):
    """A 2 x 2 DOE at the tiny level (grades 0, 12 deg x CI 50 psi on the soil and 300, the road) on the local pool and as a job array on a real single-node cluster (dem_mobility_tools.doe.local_cluster:
    its own munge key, slurm.conf and ports in a temporary directory): the two tables are the same,
    bit for bit. The soil cases take a scene file of the test's own (--soil-scene: soil only in
    0.6 m strips under the tracks, a 6 m box, 0.2 s of settling) and every case 0.3 s of driving
    (--duration), so that a soil case costs some 15 s, most of it the soil's preparation; the speeds are those of the
    first 0.3 s (status not_steady), which is what the comparison needs: the same runs on both."""

    def test_a_tiny_soil_doe_as_a_job_array_gives_the_local_pools_table(self):
        tmp = tempfile.mkdtemp(prefix='dm_doe_slurm_')
        try:
            scene = os.path.join(tmp, 'tiny_strips.yaml')
            with open(os.path.join(ROOT, 'config', 'scenes', 'soil_slope.yaml')) as fh:
                doc = yaml.safe_load(fh)
            doc['vehicle'] = os.path.join(ROOT, 'config', 'vehicles', 'hmmwv', 'vehicle.yaml')
            doc['terrain'] = os.path.join(ROOT, 'config', 'terrains', 'soil_patch.yaml')
            doc['terrain_overrides'] = {'fidelity': 'tiny', 'cone_index': 100, 'track_strip_width': 0.6,
                                        'levels': {'tiny': {'length': 6.0}}, 'patch': {'check_window': [0.3, 0.7]}}
            doc['settle_time'] = 0.2
            with open(scene, 'w') as fh:
                yaml.safe_dump(doc, fh)
            grid = ['--grades', '0,12', '--cone-indices', '50,300', '--level', 'tiny', '--soil-scene', scene,
                    '--duration', '0.3', '--runner', 'core', '--progress', 'plain', '--jobs', '2']
            local = os.path.join(tmp, 'local')
            rc, so, se = doe('run', '--out', local, *grid)
            self.assertEqual(rc, 0, so + se)
            a = load(os.path.join(local, 'doe_table.yaml'))
            self.assertEqual((a['cases'], a['simulated'], a['implied'], a['failed']), (4, 4, 0, 0))
            self.assertEqual(a['scene_files']['soil'], scene)
            rows = {(r['grade_deg'], r['cone_index_psi']): r for r in a['cases_table']}
            for (g, c), r in rows.items():
                self.assertEqual(r['source'], 'simulated (%s, %s)' % (('road', 'rigid road') if c == 300 else ('soil', 'tiny')))
                v = r['speed_made_good']
                self.assertTrue(isinstance(v, float) and v == v, (g, c, v))  # a number, not None nor NaN
            # the soil cases ran the given scene: the tracks' strips, the 6 m box, the grade and CI the DOE set
            res = load(os.path.join(local, 'runs', 'g12_ci50.result.yaml'))
            self.assertEqual((res['grade_deg'], res['patch_track_strip_width'], res['fidelity']), (12.0, 0.6, 'tiny'))
            self.assertAlmostEqual(res['cone_index_psi'], 50.0)
            with LocalCluster() as c:
                out = os.path.join(tmp, 'slurm')
                rc, so, se = doe('run', '--out', out, '--backend', 'slurm', *grid, env=c.env)
                self.assertEqual(rc, 0, so + se)
                self.assertIn('submitted job array', so)
                self.assertIn('4 COMPLETED (from sacct -c (job completion log) and squeue)', so)
                jobs = load(os.path.join(out, 'slurm', 'jobs.yaml'))['jobs']
                self.assertEqual((len(jobs), jobs[0]['tasks']), (1, '0-3'))
                # every task wrote its output; the cases their results
                for k in range(4):
                    self.assertTrue(os.path.exists(os.path.join(out, 'slurm', '%s_%d.out' % (jobs[0]['job'], k))))
                rc, so, _ = doe('status', '--out', out, env=c.env)
                self.assertIn('simulated 4, implied 0', so)
                self.assertIn('slurm job %s: 4 COMPLETED' % jobs[0]['job'], so)
                # a case whose task dies without a result: failed, with the task's state
                doc = runner.load_plan(out)
                lost = slurm.record_lost_tasks(out, doc, [0], {0: 'CANCELLED'})
                self.assertEqual(lost, [])  # case 0 has its result: nothing lost
            b = load(os.path.join(out, 'doe_table.yaml'))
            self.assertEqual(a['speed'], b['speed'])  # bit for bit: the runs are deterministic
            self.assertEqual([r['source'] for r in a['cases_table']], [r['source'] for r in b['cases_table']])
            self.assertEqual([r['status'] for r in a['cases_table']], [r['status'] for r in b['cases_table']])
        finally:
            shutil.rmtree(tmp, ignore_errors=True)

    def test_a_cancelled_task_is_recorded_failed_naming_its_state(self):
        tmp = tempfile.mkdtemp(prefix='dm_doe_slurm_')
        try:
            with LocalCluster() as c:
                out = os.path.join(tmp, 'cancelled')
                grid = ['--grades', '0,1', '--cone-indices', '300', '--runner', 'core', '--no-prune']
                rc, so, se = doe('run', '--out', out, '--backend', 'slurm', '--jobs', '1', '--no-wait', *grid, env=c.env)
                self.assertEqual(rc, 0, so + se)
                job = load(os.path.join(out, 'slurm', 'jobs.yaml'))['jobs'][0]['job']
                marker = os.path.join(out, 'runs', 'g0_ci300.running')
                t0 = time.time()
                while not os.path.exists(marker) and time.time() - t0 < 60:
                    time.sleep(0.2)
                self.assertTrue(os.path.exists(marker), 'the first task never started')
                # a task still pending or running: no resume
                rc, _, se = doe('run', '--out', out, '--resume', '--backend', 'slurm', *grid, env=c.env)
                self.assertEqual(rc, 2)
                self.assertIn('still pending or running', se)
                subprocess.run(['scancel', job], env=c.env, check=True)
                for _ in range(100):
                    rc, so, _ = doe('status', '--out', out, env=c.env)
                    if 'failed 2' in so:
                        break
                    time.sleep(0.3)
                self.assertIn('failed 2', so)
                self.assertIn('ended CANCELLED', load(os.path.join(out, 'runs', 'g0_ci300.result.yaml'))['error'])
                self.assertIn('recorded failed', so)
        finally:
            shutil.rmtree(tmp, ignore_errors=True)

    def test_a_task_slurm_no_longer_knows_leaves_no_running_case(self):
        # a marker of a task on another host whose job Slurm does not have (forgotten after
        # MinJobAge, no accounting): status records the case failed instead of running for ever;
        # a marker without a Slurm job (a pool worker elsewhere) stays running
        tmp = tempfile.mkdtemp(prefix='dm_doe_slurm_')
        self.addCleanup(shutil.rmtree, tmp, True)
        out = os.path.join(tmp, 'forgotten')
        os.makedirs(runner.runs_dir(out))
        doc = runner.make_plan(plan.Grid([0.0, 1.0], [300.0]), 'tiny', 'core', 1, 5.0, False, lambda g, c: 1.0)
        runner.write_yaml(os.path.join(out, runner.PLAN_FILE), doc)
        a, b = doc['cases']
        runner.write_yaml(runner.marker_path(out, a), {'host': 'elsewhere', 'pid': 1, 'slurm_job': '987654'})
        runner.write_yaml(runner.marker_path(out, b), {'host': 'elsewhere', 'pid': 1, 'slurm_job': None})
        with LocalCluster() as c:
            rc, so, se = doe('status', '--out', out, env=c.env)
        self.assertIn('%s: its Slurm task (job 987654) is no longer pending or running: recorded failed' % a['name'],
                      so + se)
        states = runner.scan(out, doc)
        self.assertEqual((states[a['index']][0], states[b['index']][0]), ('failed', 'running'))
        self.assertIn('job 987654', states[a['index']][1]['error'])

    def test_array_ranges(self):
        self.assertEqual(slurm.ranges([0, 1, 2, 3, 5, 7, 8]), '0-3,5,7-8')
        self.assertEqual(slurm.ranges([4]), '4')


class SlurmSubmit(unittest.TestCase):
    """The sbatch command line (sbatch itself replaced: what it is given)."""

    def test_the_time_limit_is_whole_minutes_never_below_the_timeout(self):
        tmp = tempfile.mkdtemp(prefix='dm_doe_sbatch_')
        self.addCleanup(shutil.rmtree, tmp, True)
        doc = runner.make_plan(plan.Grid([0.0], [300.0]), 'tiny', 'core', 1, 5.0, True, lambda g, c: 1.0)
        given = []

        def sbatch(argv, what):
            given.append(argv)
            return subprocess.CompletedProcess(argv, 0, '4%d\n' % len(given), '')
        real = slurm._call
        slurm._call = sbatch
        self.addCleanup(setattr, slurm, '_call', real)
        for timeout, minutes in ((150.0, '3'), (120.0, '2'), (10.0, '1')):
            slurm.submit(tmp, doc, [0], 1, time_limit=timeout)
            argv = given[-1]
            self.assertEqual(argv[argv.index('--time') + 1], minutes, timeout)


if __name__ == '__main__':
    unittest.main()
