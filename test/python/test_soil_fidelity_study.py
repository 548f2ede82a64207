"""Unit tests of dem_mobility_tools.fidelity.study's summary (no runs): the levels' error estimates
and the default level by the issue's rule (the cheapest within 1 m/s of the finest in every case).

    PYTHONPATH=python python3 -m unittest discover -s test/python -v      (from the repository root)
"""
import argparse
import os
import shutil
import sys
import tempfile
import unittest

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
from dem_mobility_tools import names
from dem_mobility_tools.fidelity import plot, study


def rows_of(runs):
    """runs: {(grade, ci): {level: (speed, wall)}} -> the rows summarize() makes."""
    rows = []
    for (g, ci), by_level in runs.items():
        finest = next(l for l in study.LEVEL_ORDER if l in by_level)
        for level in study.LEVEL_ORDER:
            if level in by_level:
                v, wall = by_level[level]
                rows.append(dict(grade_deg=g, cone_index_psi=ci, level=level, speed_made_good=v, wall_time=wall,
                                 reference=finest, error_vs_finest=abs(v - by_level[finest][0])))
    return rows


class LevelSummary(unittest.TestCase):
    def test_the_cheapest_level_within_a_metre_per_second_in_every_case_is_chosen(self):
        s = study.level_summary(rows_of({(12, 100): {'coarse': (6.0, 7000), 'tiny': (6.9, 1700)},
                                         (0, 50): {'coarse': (8.0, 9000), 'tiny': (7.2, 2400)}}))
        self.assertEqual(s['default_level'], 'tiny')
        self.assertEqual(s['reference_level'], 'coarse')
        self.assertFalse(s['provisional'])
        self.assertAlmostEqual(s['levels']['tiny']['speed_error'], 0.9)  # the larger of 0.9 and 0.8
        self.assertIsNone(s['levels']['coarse']['speed_error'])  # nothing finer ran
        self.assertEqual(s['levels']['tiny']['wall_time'], 4100)

    def test_one_case_out_of_tolerance_keeps_the_finer_level(self):
        s = study.level_summary(rows_of({(12, 100): {'coarse': (6.0, 7000), 'tiny': (6.5, 1700)},
                                         (0, 50): {'coarse': (8.0, 9000), 'tiny': (9.2, 2400)}}))
        self.assertEqual(s['default_level'], 'coarse')
        self.assertTrue(s['provisional'])  # coarse is the finest run: its own error not measured
        self.assertAlmostEqual(s['levels']['tiny']['speed_error'], 1.2)

    def test_a_level_that_did_not_run_every_case_is_no_candidate_but_rules_out_those_off_in_its_case(self):
        # medium ran one case only: not a candidate, but that case's reference. Tiny is 1.5 m/s off
        # medium there (out), coarse 1.0 (in); coarse is the finest run at (0, 50): provisional
        s = study.level_summary(rows_of({(12, 100): {'medium': (5.0, 20000), 'coarse': (6.0, 7000), 'tiny': (6.5, 1700)},
                                         (0, 50): {'coarse': (8.0, 9000), 'tiny': (8.5, 2400)}}))
        self.assertEqual(s['reference_level'], 'coarse')
        self.assertEqual(s['default_level'], 'coarse')
        self.assertTrue(s['provisional'])
        self.assertIn('0 deg, CI 50', s['why'])
        self.assertAlmostEqual(s['levels']['tiny']['speed_error'], 1.5)
        self.assertEqual(s['levels']['tiny']['reference'], ['coarse', 'medium'])
        # with medium 1.2 m/s below coarse, neither complete level is within 1 m/s there
        s = study.level_summary(rows_of({(12, 100): {'medium': (4.8, 20000), 'coarse': (6.0, 7000), 'tiny': (6.5, 1700)},
                                         (0, 50): {'coarse': (8.0, 9000), 'tiny': (8.5, 2400)}}))
        self.assertIsNone(s['default_level'])
        self.assertIn('no level that ran every case', s['why'])
        self.assertIn('no default level', study.summary_text(s))

    def test_a_single_level_gives_only_a_provisional_choice(self):
        s = study.level_summary(rows_of({(12, 100): {'tiny': (6.5, 1700)}}))
        self.assertEqual(s['default_level'], 'tiny')
        self.assertTrue(s['provisional'])
        self.assertIn('no default level', study.summary_text(study.level_summary([])))
        self.assertIn('provisional', study.summary_text(s))


class Resume(unittest.TestCase):
    """--resume keeps a run only if it is of this scene, level, grade and cone index, and refuses a
    folder whose runs were made with another driving time, runner or scene."""

    def setUp(self):
        self.tmp = tempfile.mkdtemp(prefix='dm_fidelity_')
        self.scene = os.path.join(ROOT, 'config', 'scenes', 'soil_slope.yaml')

    def tearDown(self):
        shutil.rmtree(self.tmp, ignore_errors=True)

    def args(self, **kw):
        a = dict(scene=self.scene, duration=40.0, runner='core', resume=False, out=self.tmp)
        a.update(kw)
        return argparse.Namespace(**a)

    def test_only_a_result_of_the_same_case_is_kept(self):
        accept = study.same_run(self.args())
        case = {'level': 'coarse', 'grade_deg': 0.0, 'cone_index_psi': 50.0}
        good = {'scene': self.scene, 'fidelity': 'coarse', 'grade_deg': 0, 'requested_cone_index_psi': 50}
        self.assertTrue(accept(case, good))
        for key, v in (('scene', '/elsewhere/soil_slope.yaml'), ('fidelity', 'tiny'), ('grade_deg', 12),
                       ('requested_cone_index_psi', 100), ('grade_deg', None)):
            self.assertFalse(accept(case, dict(good, **{key: v})), key)

    def test_a_result_of_an_older_version_is_refused_naming_the_file_and_the_new_key(self):
        accept = study.same_run(self.args())
        case = {'level': 'coarse', 'grade_deg': 0.0, 'cone_index_psi': 50.0}
        old = {'scene': self.scene, 'fidelity': 'coarse', 'grade_deg': 0, 'requested_ci': 50}
        with self.assertRaises(names.OldNameError) as e:
            accept(case, old)
        self.assertEqual(str(e.exception).split(' (')[0], "%s: 'requested_ci' is an old name: it is "
                         "'requested_cone_index_psi' now" % os.path.join(self.tmp, 'runs', 'coarse_g0_ci50.result.yaml'))


    def test_a_resume_with_another_driving_time_is_refused_naming_it(self):
        study.check_options(self.args(), self.tmp)
        study.check_options(self.args(resume=True), self.tmp)  # the same: fine
        with self.assertRaises(SystemExit) as e:
            study.check_options(self.args(resume=True, duration=10.0), self.tmp)
        self.assertIn('--duration 40.0, not 10.0', str(e.exception))
        with self.assertRaises(SystemExit) as e:
            study.check_options(self.args(resume=True, runner='roslaunch'), self.tmp)
        self.assertIn('--runner core', str(e.exception))

    def test_a_run_keeps_a_checkpoint_and_a_stopped_one_is_taken_up_from_it(self):
        a = self.args(dm_run_scene='/bin/dm_run_scene', dem_threads=2, checkpoint_every=600.0)
        case = {'level': 'coarse', 'grade_deg': 0.0, 'cone_index_psi': 50.0}
        result = os.path.join(self.tmp, 'coarse_g0_ci50.result.yaml')
        ckpt = os.path.join(self.tmp, 'coarse_g0_ci50.ckpt')
        cmd = study.core_command(a, case, result)
        self.assertEqual(cmd[cmd.index('--checkpoint') + 1], ckpt)
        self.assertEqual(cmd[cmd.index('--checkpoint-every') + 1], '600')
        self.assertNotIn('--restart', cmd)  # nothing to take up yet
        open(ckpt, 'wb').close()
        log = os.path.join(self.tmp, 'coarse_g0_ci50.log')
        with open(log, 'w') as fh:
            fh.write('the first part\n')
        cmd = study.core_command(a, case, result)
        self.assertEqual(cmd[cmd.index('--restart') + 1], ckpt)
        # the first part's log is kept beside the one the sweep writes afresh
        with open(os.path.join(self.tmp, 'coarse_g0_ci50.part1.log')) as fh:
            self.assertEqual(fh.read(), 'the first part\n')
        # (the case's overrides are the same either way: a restart refuses other ones)
        self.assertEqual([x for x in cmd if '=' in x], [x for x in study.core_command(
            self.args(dm_run_scene='/bin/dm_run_scene', dem_threads=2, checkpoint_every=0.0), case, result) if '=' in x])
        self.assertNotIn('--checkpoint', study.core_command(
            self.args(dm_run_scene='/bin/dm_run_scene', dem_threads=2, checkpoint_every=0.0), case, result))

    def test_a_study_stopped_by_sigterm_says_how_to_go_on_without_a_traceback(self):
        import signal
        import subprocess
        import time
        runner = os.path.join(self.tmp, 'dm_run_scene')
        with open(runner, 'w') as fh:  # a stand-in run that takes a minute
            fh.write('#!/bin/sh\nexec sleep 60\n')
        os.chmod(runner, 0o755)
        out = os.path.join(self.tmp, 'out')
        p = subprocess.Popen([sys.executable, '-m', 'dem_mobility_tools.fidelity.study', '--runner',
                              'core', '--dm-run-scene', runner, '--levels', 'tiny', '--cases', '0:50', '--out', out],
                             stdout=subprocess.PIPE, stderr=subprocess.STDOUT, universal_newlines=True)
        t0 = time.time()
        while not os.path.exists(os.path.join(out, 'runs', 'tiny_g0_ci50.log')) and time.time() - t0 < 30:
            time.sleep(0.1)
        time.sleep(0.5)
        p.send_signal(signal.SIGTERM)
        text = p.communicate(timeout=60)[0]
        self.assertEqual(p.returncode, 1, text)
        self.assertNotIn('Traceback', text)
        self.assertIn('interrupted', text)
        self.assertIn('--resume goes on (a stopped run from its checkpoint)', text)


class PlotOfMeasuredRuns(unittest.TestCase):
    """dm-plot-fidelity's rows from a file of measured runs; a file with the old keys is refused."""

    def test_each_run_is_compared_with_its_cases_finest_and_old_keys_are_refused(self):
        runs = [{'grade_deg': 12, 'cone_index_psi': 100, 'level': 'tiny', 'speed_made_good': 11.0, 'wall_time': 10},
                {'grade_deg': 12, 'cone_index_psi': 100, 'level': 'coarse', 'speed_made_good': 12.5, 'wall_time': 50},
                {'grade_deg': 0, 'cone_index_psi': 50, 'level': 'tiny', 'speed_made_good': 8.0, 'wall_time': 9}]
        rows = plot.rows_of(runs, 'runs.yaml')
        self.assertEqual([(r['reference'], r['error_vs_finest']) for r in rows],
                         [('coarse', 1.5), ('coarse', 0.0), ('tiny', 0.0)])
        old = [dict(runs[0])]
        old[0]['grade'] = old[0].pop('grade_deg')
        with self.assertRaises(SystemExit) as e:
            plot.rows_of(old, 'runs.yaml')
        self.assertIn("runs.yaml: runs: 'grade' is an old name: it is 'grade_deg' now", str(e.exception))


if __name__ == '__main__':
    unittest.main()
