"""The stability matrix (dm-stability, docs/stability.md): its judge on made-up
results (a ledger below zero or a NaN is a silent blow-up, an error naming no limit a failure),
and its cheap cells run through the core runner (DM_RUN_SCENE, or build/core's dm_run_scene): the
road scene, the single-wheel rig's runs and refusals and the soil scene's refusals, each stable or
refused naming its limit.

    PYTHONPATH=python python3 -m unittest discover -s test/python -v      (from the repository root)
"""
import os
import subprocess
import sys
import tempfile
import unittest

import yaml

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
from dem_mobility_tools import paths
from dem_mobility_tools.stability import matrix

RUNNER = paths.dm_run_scene()


class Judge(unittest.TestCase):
    def stable_result(self, **kw):
        r = {'status': 'steady', 'error': '', 'speed_made_good': 5.0, 'verdict': 'steady',
             'vehicle_energy_dissipated_least': 0.0, 'vehicle_energy_scale': 1e6}
        r.update(kw)
        return r

    def test_a_bounded_ledger_is_stable_and_one_below_zero_is_a_blow_up(self):
        self.assertEqual(matrix.judge(0, '', self.stable_result())[0], 'stable')
        # within the tolerance: the integrator's error
        self.assertEqual(matrix.judge(0, '', self.stable_result(vehicle_energy_dissipated_least=-0.5e3))[0], 'stable')
        self.assertEqual(matrix.judge(0, '', self.stable_result(vehicle_energy_dissipated_least=-2e3))[0],
                         'SILENT BLOW-UP')
        self.assertEqual(matrix.judge(0, '', self.stable_result(soil_energy_dissipated_least=-1.0,
                                                                soil_energy_scale=10.0))[0], 'SILENT BLOW-UP')
        self.assertEqual(matrix.judge(0, '', self.stable_result(speed_made_good=float('nan')))[0], 'SILENT BLOW-UP')

    def test_refusals_must_name_their_limit(self):
        v, d = matrix.judge(1, 'dm_run_scene: error: x.yaml: time_step: time step dt = 1 s is above the critical step '
                               '2e-4 s of joint j\n', None)
        self.assertEqual(v, 'refused before the run')
        self.assertIn('critical step', d)
        self.assertEqual(matrix.judge(1, 'dm_run_scene: error: something odd\n', None)[0], 'FAILED')
        self.assertEqual(matrix.judge(3, '', {'status': 'error', 'error': 'DEM step 5: particle 3 overlaps a '
                                                                          'neighbour by 0.5 of the diameter (limit 0.4)'})[0],
                         'refused during the run')
        self.assertEqual(matrix.judge(3, '', {'status': 'error', 'error': 'it broke'})[0], 'FAILED')
        # below the critical step with the guard on, stopping for instability is the guard's failure
        unstable = {'status': 'error', 'error': 'step 9: the vehicle\'s energy rose 5 J ...: the explicit integration is '
                                                 'unstable at dt = 1e-4 s (the guard\'s critical step 2e-4 s, body b)'}
        self.assertEqual(matrix.judge(3, '', unstable)[0], 'refused during the run')
        self.assertEqual(matrix.judge(3, '', unstable, guarded=True)[0], 'FAILED')
        self.assertEqual(matrix.judge(-11, 'Segmentation fault', None)[0], 'FAILED')


@unittest.skipUnless(os.path.exists(RUNNER), 'no dm_run_scene (build the core first)')
class CheapCells(unittest.TestCase):
    def test_the_cheap_cells_are_stable_or_refused_naming_the_limit(self):
        with tempfile.TemporaryDirectory() as out:
            p = subprocess.run([sys.executable, '-m', 'dem_mobility_tools.stability.matrix', '--cheap',
                                '--dm-run-scene', RUNNER, '--out', out], capture_output=True, text=True, timeout=1800)
            self.assertEqual(p.returncode, 0, p.stdout + p.stderr)
            with open(os.path.join(out, 'matrix.yaml')) as f:
                m = yaml.safe_load(f)
            cells = {(c['scene'], c['cell']): c for c in m['cells']}
            for scene in ('road', 'wheel', 'soil'):
                self.assertGreater(m['critical_time_step'][scene], 0.0)
                # above the critical step the guard refuses, naming it
                for f in ('dt1.1', 'dt2'):
                    c = cells[(scene, f)]
                    self.assertEqual(c['verdict'], 'refused before the run', c)
                    self.assertIn('critical step', c['detail'])
            for key in [('road', 'dt0.5'), ('road', 'dt0.9'), ('road', 'stiff10'), ('road', 'side20'),
                        ('road', 'speed25'), ('road', 'drop05'), ('wheel', 'dt0.5'), ('wheel', 'dt0.9'),
                        ('wheel', 'f12'), ('wheel', 'f0.05')]:
                self.assertEqual(cells[key]['verdict'], 'stable', cells[key])
            # past the guard the road run either stays stable or stops naming what failed; never silent
            for f in ('dt1.1_noguard', 'dt2_noguard'):
                self.assertIn(cells[('road', f)]['verdict'], ('stable', 'refused during the run'))
            for scene in ('wheel', 'soil'):
                self.assertEqual(cells[(scene, 'ci400')]['verdict'], 'refused before the run')
                self.assertIn('cone_index', cells[(scene, 'ci400')]['detail'])
                self.assertEqual(cells[(scene, 'paper_f12_tiny_dt')]['verdict'], 'refused before the run')
                self.assertIn('critical step', cells[(scene, 'paper_f12_tiny_dt')]['detail'])
            self.assertTrue(os.path.exists(os.path.join(out, 'matrix.md')))


if __name__ == '__main__':
    unittest.main()
