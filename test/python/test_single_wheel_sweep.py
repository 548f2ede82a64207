"""dm-wheel-sweep (dem_mobility_tools.wheel.sweep): its cases and commands (the arguments single_wheel.launch takes),
and, without ROS, whole sweeps through stand-in `roslaunch` and `rospack` commands on PATH that
write the result files a single-wheel run would (sunk wheels, failures, towed runs): the lines,
summary.yaml (figures, references at the same slips, sim - VTI), the plots, the exit status and
--resume. With the core built (build/core or $DM_RUN_SCENE), one real tiny run through --runner core.

    PYTHONPATH=python python3 -m unittest discover -s test/python -v      (from the repository root)
"""
import json
import math
import os
import shutil
import stat
import subprocess
import sys
import tempfile
import types
import unittest

import yaml

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
TOOL = [sys.executable, '-m', 'dem_mobility_tools.wheel.sweep']  # dm-wheel-sweep

from dem_mobility_tools import names, paths
from dem_mobility_tools import sweep as dm_sweep
from dem_mobility_tools.terramechanics import wheel_numerics as wn
from dem_mobility_tools.wheel import sweep as sws

# the soil keys: the one names of a cone index [psi] and of the cohesion factor f
CI, F = 'cone_index_psi', 'cohesion_factor'

try:
    import matplotlib  # noqa: F401
    import numpy  # noqa: F401
    HAVE_PLOTS = True
except ImportError:
    HAVE_PLOTS = False

# the arguments of launch/single_wheel.launch
LAUNCH_ARGS = {'scene', 'fidelity', 'cohesion_factor', 'friction', 'cone_index', 'slip', 'drive', 'torque', 'load', 'speed',
               'dem_threads', 'seed', 'bag', 'cloud_rate', 'rviz', 'end_run', 'ns'}

# a stand-in single-wheel run: slip >= 0.7 fails (status error, exit 1); CI < 25 sinks before the
# window; otherwise DP/W = 0.5 s + CI/1000, T/(W r) = DP/W + 0.1, z = 0.05 m (towed: -0.1, 0, 0.06)
ROSLAUNCH = r'''#!%s
import json, os, sys, time, yaml
args = dict(a.split(':=', 1) for a in sys.argv[1:] if ':=' in a)
assert sys.argv[1] == '-p' and os.environ['ROS_MASTER_URI'].endswith(':' + sys.argv[2])
bag = args['bag']
with open(os.path.join(os.path.dirname(bag), 'calls'), 'a') as fh:
    fh.write(json.dumps(sys.argv[1:]) + '\n')
print('[ INFO] progress: t 1.0 s drive travel 0.5 / 2.2 m', flush=True)
time.sleep(0.2)
res = bag[:-4] + '.result.yaml'
ci, drive = float(args['cone_index']), args['drive']
slip = float(args['slip']) if drive == 'slip' else None
doc = {'scene': args['scene'], 'kind': 'single_wheel', 'status': 'ok', 'error': '', 'fidelity': args['fidelity'],
       'particle_diameter': 0.1, 'cohesion_factor': ci / 30.0, 'friction': 0.1, 'requested_cone_index_psi': ci,
       'cone_index_psi': ci, 'drive': drive}
if slip is not None:
    doc['slip_commanded'] = slip
doc.update({'load_mass': 1230.0, 'load': 12066.3, 'carriage_speed': 1.0, 'tire_radius': 0.485,
            'tire_width': 0.254, 'window': [0.8, 2.2], 'window_samples': 10})
if slip is not None and slip >= 0.7:
    doc.update(status='error', error='overlap watchdog: particle 12 overlaps the tire by 0.6 d')
    with open(res, 'w') as fh:
        yaml.safe_dump(doc, fh)
    sys.exit(1)
if drive == 'towed':
    dp, tq, z, s = -0.1, 0.0, 0.06, -0.04
else:
    dp, tq, z, s = 0.5 * slip + ci / 1000.0, 0.5 * slip + ci / 1000.0 + 0.1, 0.05, slip
if ci < 25:
    doc.update(status='sunk', error='the wheel sank 0.25 m (0.5 of its radius) in phase load', window_samples=0)
    dp, tq, z, s = 0.0, 0.0, 0.0, 0.0
doc.update({'drawbar_pull': dp * 12066.3, 'drawbar_pull_std': 241.3, 'dp_over_w': dp, 'dp_over_w_std': 0.02,
            'torque': tq * 12066.3 * 0.485, 'torque_std': 117.0, 'torque_over_wr': tq, 'torque_over_wr_std': 0.02,
            'sinkage': z, 'sinkage_std': 0.004, 'slip': s, 'wall_time': 1.5,
            'history': {'t': [0.0, 1.0, 2.0], 'travel': [0.0, 1.0, 2.0], 'dp_over_w': [0.0, dp, dp],
                        'torque_over_wr': [0.0, tq, tq], 'sinkage': [0.0, z, z]}})
open(bag, 'w').write('bag')
with open(res, 'w') as fh:
    yaml.safe_dump(doc, fh)
''' % sys.executable


def args(**kw):
    a = dict(scene=os.path.join(ROOT, 'config', 'scenes', 'single_wheel.yaml'), fidelity='coarse', mu=None,
             load=None, speed=None, seed=None, dem_threads=1, cloud_rate=5.0, out='/tmp/o',
             dm_run_scene='/x/dm_run_scene')
    a.update(kw)
    return types.SimpleNamespace(**a)


class Cases(unittest.TestCase):
    def test_grid_names_and_order(self):
        cases = sws.make_cases(CI, [60, 100], [0.1, 0.3], towed=True)
        self.assertEqual([c.name for c in cases], ['ci60_slip0.1', 'ci60_slip0.3', 'ci60_towed',
                                                   'ci100_slip0.1', 'ci100_slip0.3', 'ci100_towed'])
        self.assertEqual(cases[2].params, {'soil_key': 'cone_index_psi', 'soil': 60, 'drive': 'towed', 'slip': None})
        self.assertEqual([c.name for c in sws.make_cases(F, [1.5], [0.05])], ['f1.5_slip0.05'])
        with self.assertRaises(ValueError):
            sws.make_cases(CI, [60], [0.1, 0.1])
        with self.assertRaises(ValueError):
            sws.make_cases('mu', [60], [0.1])

    def test_roslaunch_command(self):
        a = args(out='/data/sweep')
        case = sws.make_cases(CI, [100], [0.2])[0]
        self.assertEqual(sws.roslaunch_command(a, case, 11413), [
            'roslaunch', '-p', '11413', 'dem_mobility', 'single_wheel.launch', 'scene:=' + a.scene,
            'fidelity:=coarse', 'cone_index:=100', 'slip:=0.2', 'drive:=slip', 'dem_threads:=1',
            'bag:=/data/sweep/runs/ci100_slip0.2.bag', 'cloud_rate:=5', 'rviz:=false', 'end_run:=true'])
        # every option given, f for the soil (cohesion_factor:=), towed: only the launch file's arguments
        a = args(mu=0.05, load=800, speed=0.5, seed=3, dem_threads=2)
        towed = sws.make_cases(F, [1.5], [], towed=True)[0]
        argv = sws.roslaunch_command(a, towed, 11411)
        given = dict(x.split(':=', 1) for x in argv[5:])
        self.assertLessEqual(set(given), LAUNCH_ARGS)
        self.assertEqual(given, {'scene': a.scene, 'fidelity': 'coarse', 'cohesion_factor': '1.5', 'drive': 'towed',
                                 'dem_threads': '2', 'friction': '0.05', 'load': '800', 'speed': '0.5', 'seed': '3',
                                 'bag': '/tmp/o/runs/f1.5_towed.bag', 'cloud_rate': '5', 'rviz': 'false',
                                 'end_run': 'true'})
        # the result the launch file writes (bag[:-4] + '.result.yaml') is the one the sweep reads
        sweep = dm_sweep.Sweep([towed], lambda c, o: [], os.path.join(tempfile.mkdtemp(), 'runs'))
        self.addCleanup(shutil.rmtree, os.path.dirname(sweep.runs_dir))
        self.assertEqual(os.path.basename(given['bag'])[:-4] + '.result.yaml',
                         os.path.basename(sweep.result_path(towed)))

    def test_core_command(self):
        a = args(mu=0.05, fidelity='tiny')
        case = sws.make_cases(CI, [100], [0.3])[0]
        self.assertEqual(sws.core_command(a, case, 'runs/x.result.yaml'), [
            '/x/dm_run_scene', a.scene, 'fidelity=tiny', 'cone_index=100', 'wheel.slip=0.3', 'wheel.drive=slip',
            'threads=1', 'friction=0.05', '--out', os.path.abspath('runs/x.result.yaml')])
        towed = sws.make_cases(F, [2], [], towed=True)[0]
        self.assertEqual(sws.core_command(args(), towed, '/r.yaml')[3:5], ['cohesion_factor=2', 'wheel.drive=towed'])

    def test_resume_accepts_the_same_run_only(self):
        accept = sws.same_run(args(fidelity='tiny', load=1230))
        case = sws.make_cases(CI, [100], [0.3])[0]
        old = {'fidelity': 'tiny', 'drive': 'slip', 'slip_commanded': 0.3, 'requested_cone_index_psi': 100,
               'cohesion_factor': 3.2, 'load_mass': 1230.0}
        self.assertTrue(accept(case, old))
        for change in ({'fidelity': 'coarse'}, {'slip_commanded': 0.2}, {'requested_cone_index_psi': 60},
                       {'load_mass': 1000.0}, {'drive': 'towed'}):
            self.assertFalse(accept(case, dict(old, **change)), change)
        f_case = sws.make_cases(F, [3.2], [0.3])[0]
        self.assertFalse(accept(f_case, old))  # made from a cone index, not f directly
        del old['requested_cone_index_psi']
        self.assertTrue(accept(f_case, old))
        # a result of an older version (its requested cone index under the old name) is refused, naming it
        with self.assertRaises(names.OldNameError) as e:
            accept(case, dict(old, requested_ci=100))
        self.assertIn("/tmp/o/runs/ci100_slip0.3.result.yaml: 'requested_ci' is an old name: it is "
                      "'requested_cone_index_psi' now", str(e.exception))

    def test_check(self):
        self.assertIsNone(sws.check(None, {'status': 'ok', 'window_samples': 3}))
        self.assertEqual(sws.check(None, {'status': 'ok', 'window_samples': 0}), 'no sample in the window')
        self.assertIsNone(sws.check(None, {'status': 'sunk', 'window_samples': 0}))
        self.assertIn('cone_penetrometer', sws.check(None, {'kind': 'cone_penetrometer', 'window_samples': 3}))


def outcome(case, result, error=None):
    o = dm_sweep.Outcome(case, '/r/%s.result.yaml' % case.name, '/r/%s.log' % case.name)
    o.result, o.error, o.start, o.end = result, error, 0.0, 2.0
    return o


class Summary(unittest.TestCase):
    RESULT = {'kind': 'single_wheel', 'status': 'ok', 'error': '', 'fidelity': 'tiny', 'particle_diameter': 0.1,
              'load': 10000.0, 'tire_radius': 0.5, 'tire_width': 0.25, 'window_samples': 8,
              'dp_over_w_std': 0.01, 'torque_over_wr_std': 0.01, 'sinkage_std': 0.001}

    def test_f_without_a_table_has_no_reference(self):
        cases = sws.make_cases(F, [2.0], [0.2])
        res = dict(self.RESULT, cohesion_factor=2.0, slip=0.2, dp_over_w=0.3, torque_over_wr=0.4, sinkage=0.05,
                   cone_index_psi='unknown: f given directly and no calibration table at this particle size')
        s = sws.soil_summary(F, 2.0, [outcome(cases[0], res)])
        self.assertEqual((s['soil'], s['cohesion_factor']), ('f2', 2.0))
        self.assertNotIn('f', s)
        self.assertIsNone(s['reference'])
        self.assertIn('unknown: f given directly', s['no_reference'])
        self.assertEqual(s['points']['dp_over_w'], [0.3])

    def test_f_with_a_table_uses_its_cone_index(self):
        cases = sws.make_cases(F, [2.0], [0.2])
        res = dict(self.RESULT, cohesion_factor=2.0, slip=0.2, dp_over_w=0.3, torque_over_wr=0.4, sinkage=0.05,
                   cone_index_psi=80.0)
        s = sws.soil_summary(F, 2.0, [outcome(cases[0], res)])
        v = wn.vti(80.0, 0.25, 1.0, 10000.0)
        self.assertEqual(s['cone_index_psi'], 80.0)
        self.assertAlmostEqual(s['reference']['vti_dp_over_w'][0], wn.vti_dp_over_w(0.2, v['nc'], 0.25, 1.0, v['ssp']),
                               places=5)
        self.assertAlmostEqual(s['dp_over_w_minus_vti'][0], 0.3 - wn.vti_dp_over_w(0.2, v['nc'], 0.25, 1.0, v['ssp']),
                               places=4)

    def test_points_sorted_sunk_kept_failed_listed(self):
        cases = sws.make_cases(CI, [50], [0.4, 0.1, 0.2, 0.3], towed=True)
        outs = [outcome(cases[0], dict(self.RESULT, status='sunk', error='sank', window_samples=0, slip=0.0,
                                       dp_over_w=0.0, torque_over_wr=0.0, sinkage=0.0, slip_commanded=0.4,
                                       cone_index_psi=50.0)),
                outcome(cases[1], dict(self.RESULT, slip=0.1, dp_over_w=0.1, torque_over_wr=0.2, sinkage=0.04,
                                       cone_index_psi=50.0)),
                outcome(cases[2], None, 'timed out after 100 s'),
                outcome(cases[3], dict(self.RESULT, slip=0.3, dp_over_w=0.2, torque_over_wr=0.3, sinkage=0.05,
                                       cone_index_psi=50.0)),
                outcome(cases[4], dict(self.RESULT, slip=-0.05, dp_over_w=-0.08, torque_over_wr=0.0, sinkage=0.05,
                                       cone_index_psi=50.0))]
        s = sws.soil_summary(CI, 50, outs)
        self.assertEqual((s['soil'], s['requested_cone_index_psi'], s['cone_index_psi']), ('ci50', 50, 50.0))
        self.assertNotIn('ci', s)
        p = s['points']
        self.assertEqual(p['name'], ['ci50_slip0.1', 'ci50_slip0.3', 'ci50_slip0.4'])
        self.assertEqual(p['status'], ['ok', 'ok', 'sunk'])
        self.assertEqual(p['slip'], [0.1, 0.3, 0.4])  # the sunk wheel at its commanded slip
        self.assertEqual(p['dp_over_w'], [0.1, 0.2, None])  # a sunk wheel's zeros are not measurements
        self.assertEqual(s['failed'], ['ci50_slip0.2'])
        self.assertEqual(s['dp_over_w_minus_vti'][2], None)
        band = wn.reference_band([0.1, 0.3, 0.4], 50.0, 0.25, 1.0, 10000.0)
        self.assertEqual(s['reference']['band_dp_over_w'][1], [round(band['dp_lo'][1], 5), round(band['dp_hi'][1], 5)])
        self.assertEqual(s['reference']['band_gt_over_w'][0], [round(band['gt_lo'][0], 5), round(band['gt_hi'][0], 5)])
        self.assertEqual(s['dp_over_w_in_band'][:2], [band['dp_lo'][0] <= 0.1 <= band['dp_hi'][0],
                                                      band['dp_lo'][1] <= 0.2 <= band['dp_hi'][1]])
        t = s['towed'][0]
        v = wn.vti(50.0, 0.25, 1.0, 10000.0)
        self.assertEqual((t['slip'], t['dp_over_w']), (-0.05, -0.08))
        self.assertEqual(t['vti_dp_over_w'], round(-v['mr_towed'], 5))
        self.assertEqual(t['band_dp_over_w'], [round(band['towed_lo'], 5), round(band['towed_hi'], 5)])
        self.assertAlmostEqual(t['dp_over_w_minus_vti'], -0.08 + v['mr_towed'], places=4)
        self.assertEqual(s['numerics']['wes_nc_rigid'], 0.0)
        self.assertAlmostEqual(s['numerics']['wes_nc_pneumatic']['nc'], wn.wes_nc(50, 0.25, 1.0, 10000.0, 0.15), places=4)


@unittest.skipUnless(HAVE_PLOTS, 'needs python3-numpy and python3-matplotlib')
class SweepWithoutRos(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.tmp = tempfile.mkdtemp(prefix='dm_wheel_sweep_test_')
        bin_dir = os.path.join(cls.tmp, 'bin')
        pkg = os.path.join(cls.tmp, 'pkg')
        os.makedirs(bin_dir)
        os.makedirs(os.path.join(pkg, 'launch'))
        with open(os.path.join(pkg, 'launch', 'single_wheel.launch'), 'w') as fh:
            fh.write('<launch/>\n')
        for name, text in (('roslaunch', ROSLAUNCH), ('rospack', '#!/bin/sh\necho %s\n' % pkg)):
            p = os.path.join(bin_dir, name)
            with open(p, 'w') as fh:
                fh.write(text)
            os.chmod(p, os.stat(p).st_mode | stat.S_IXUSR)
        cls.env = dict(os.environ, PATH=bin_dir + os.pathsep + os.environ.get('PATH', ''), MPLBACKEND='Agg')
        cls.out = os.path.join(cls.tmp, 'out')
        cls.first = cls.sweep('0.1,0.3,0.7')
        with open(os.path.join(cls.out, 'summary.yaml')) as fh:
            cls.first_summary = yaml.safe_load(fh)
        cls.first_calls = cls.calls()
        os.remove(os.path.join(cls.out, 'runs', 'calls'))
        cls.second = cls.sweep('0.1,0.3,0.5,0.7', '--resume')
        with open(os.path.join(cls.out, 'summary.yaml')) as fh:
            cls.second_summary = yaml.safe_load(fh)
        cls.second_calls = cls.calls()

    @classmethod
    def tearDownClass(cls):
        shutil.rmtree(cls.tmp, True)

    @classmethod
    def sweep(cls, slips, *more):
        return subprocess.run(
            TOOL + ['--fidelity', 'tiny', '--ci', '20,100', '--slip', slips, '--towed',
             '--jobs', '2', '--port', '11811', '--progress', 'plain', '--out', cls.out] + list(more),
            stdout=subprocess.PIPE, stderr=subprocess.STDOUT, universal_newlines=True, env=cls.env, timeout=300)

    @classmethod
    def calls(cls):
        with open(os.path.join(cls.out, 'runs', 'calls')) as fh:
            return [json.loads(line) for line in fh]

    def test_commands(self):
        self.assertEqual(len(self.first_calls), 8)
        by = {bag_of(c): c for c in self.first_calls}
        self.assertEqual(sorted(by), sorted(n + '.bag' for n in (
            'ci20_slip0.1', 'ci20_slip0.3', 'ci20_slip0.7', 'ci20_towed',
            'ci100_slip0.1', 'ci100_slip0.3', 'ci100_slip0.7', 'ci100_towed')))
        c = by['ci100_slip0.3.bag']
        self.assertIn(c[1], ('11811', '11813'))
        self.assertEqual(c[2:], ['dem_mobility', 'single_wheel.launch',
                                 'scene:=' + os.path.join(ROOT, 'config', 'scenes', 'single_wheel.yaml'),
                                 'fidelity:=tiny', 'cone_index:=100', 'slip:=0.3', 'drive:=slip', 'dem_threads:=1',
                                 'bag:=' + os.path.join(self.out, 'runs', 'ci100_slip0.3.bag'), 'cloud_rate:=5',
                                 'rviz:=false', 'end_run:=true'])
        self.assertIn('drive:=towed', by['ci20_towed.bag'])
        self.assertFalse([a for a in by['ci20_towed.bag'] if a.startswith('slip:=')])
        for call in self.first_calls:
            self.assertLessEqual({a.split(':=')[0] for a in call if ':=' in a}, LAUNCH_ARGS)

    def test_lines_and_exit_status(self):
        out = self.first.stdout
        self.assertEqual(self.first.returncode, 1, out)
        self.assertIn('sweep: 8 runs (ci 20,100 x slip 0.1,0.3,0.7 + towed), level tiny, 8 to run, 2 at a time', out)
        self.assertRegex(out, r'done   ci100_slip0.3  DP/W 0.250  T/\(Wr\) 0.350  z 0.050 m \(\d+ s\)  \[\d/8\]')
        self.assertRegex(out, r'done   ci20_slip0.1   SUNK: the wheel sank 0.25 m')
        self.assertIn('  failed: ci100_slip0.7: overlap watchdog', out)
        self.assertIn('  failed: ci20_slip0.7: overlap watchdog', out)
        self.assertIn('sweep: 8 runs in', out)
        self.assertIn(', 2 failed', out)  # the sunk wheels are results, not failures
        self.assertRegex(out, r'ci100: CI 100.0 psi; VTI \(rigid\) N_c \d+\.\d\d')
        self.assertRegex(out, r'towed \(slip -0.040\): DP/W -0.100 \(0.020\), VTI -0.\d+, band \[-0.\d\d,-0.\d\d\], ok')

    def test_summary(self):
        doc = self.first_summary
        self.assertEqual(list(doc)[:11], ['sweep', 'runner', 'fidelity', 'particle_diameter', 'scene', 'jobs',
                                          'wall_time', 'cases', 'failed', 'sunk', 'reference'])
        self.assertEqual((doc['runner'], doc['fidelity'], doc['cases'], doc['failed'], doc['sunk']),
                         ('roslaunch', 'tiny', 8, 2, 3))
        self.assertIn('Brixius', doc['reference']['band'])
        self.assertIn('rigid', doc['reference']['wes'])
        self.assertEqual(sorted(f['name'] for f in doc['failed_cases']), ['ci100_slip0.7', 'ci20_slip0.7'])
        rows = {r['name']: r for r in doc['runs']}
        self.assertEqual(rows['ci20_slip0.3']['status'], 'sunk')
        self.assertTrue(rows['ci20_slip0.3']['ok'])
        self.assertIsNone(rows['ci20_slip0.3']['dp_over_w'])
        self.assertEqual(rows['ci100_slip0.7']['status'], 'failed')
        r = rows['ci100_slip0.3']
        self.assertEqual((r['dp_over_w'], r['torque_over_wr'], r['sinkage'], r['window_samples']), (0.25, 0.35, 0.05, 10))
        self.assertGreater(r['wall_time'], 0.0)
        self.assertEqual(rows['ci100_slip0.3']['bag'], os.path.join(self.out, 'runs', 'ci100_slip0.3.bag'))
        soils = {s['soil']: s for s in doc['soils']}
        self.assertEqual(list(soils), ['ci20', 'ci100'])
        s = soils['ci100']
        self.assertEqual(s['points']['slip'], [0.1, 0.3])
        self.assertEqual(s['points']['dp_over_w'], [0.15, 0.25])
        self.assertEqual(s['points']['dp_over_w_std'], [0.02, 0.02])
        self.assertEqual(s['points']['torque_over_wr'], [0.25, 0.35])
        v = wn.vti(100, 0.254, 0.97, 12066.3)
        for i, x in enumerate([0.1, 0.3]):
            dp = wn.vti_dp_over_w(x, v['nc'], 0.254, 0.97, v['ssp'])
            gt = wn.vti_gt_over_w(x, v['nc'], 0.254, 0.97, v['ssp'])
            self.assertAlmostEqual(s['reference']['vti_dp_over_w'][i], dp, places=5)
            self.assertAlmostEqual(s['reference']['vti_gt_over_w'][i], gt, places=5)
            self.assertAlmostEqual(s['dp_over_w_minus_vti'][i], s['points']['dp_over_w'][i] - dp, places=4)
            self.assertAlmostEqual(s['torque_over_wr_minus_vti_gt'][i], s['points']['torque_over_wr'][i] - gt, places=4)
            lo, hi = s['reference']['band_dp_over_w'][i]
            self.assertLessEqual(lo, round(dp, 5))
            self.assertLessEqual(round(dp, 5), hi)
        self.assertEqual(s['failed'], ['ci100_slip0.7'])
        self.assertEqual(s['towed'][0]['dp_over_w'], -0.1)
        self.assertEqual(soils['ci20']['points']['status'], ['sunk', 'sunk'])
        self.assertEqual(soils['ci20']['towed'][0]['status'], 'sunk')

    def test_plots(self):
        for name in ('dp_over_w_vs_slip.png', 'torque_over_wr_vs_slip.png', 'sinkage_vs_slip.png',
                     'histories_ci100.png', 'histories_ci20.png'):
            with open(os.path.join(self.out, name), 'rb') as fh:
                self.assertEqual(fh.read(8), b'\x89PNG\r\n\x1a\n', name)
            self.assertIn('plot: %s' % os.path.join(self.out, name), self.first.stdout)

    def test_resume_keeps_finished_runs_sunk_included(self):
        out = self.second.stdout
        self.assertEqual(self.second.returncode, 1, out)
        self.assertIn('kept   ci100_slip0.1  DP/W 0.150', out)
        self.assertIn('kept   ci20_slip0.1   SUNK:', out)
        ran = sorted(bag_of(c) for c in self.second_calls)
        self.assertEqual(ran, ['ci100_slip0.5.bag', 'ci100_slip0.7.bag', 'ci20_slip0.5.bag', 'ci20_slip0.7.bag'])
        self.assertIn('10 runs (ci 20,100 x slip 0.1,0.3,0.5,0.7 + towed), level tiny, 4 to run', out)
        soils = {s['soil']: s for s in self.second_summary['soils']}
        self.assertEqual(soils['ci100']['points']['slip'], [0.1, 0.3, 0.5])
        rows = {r['name']: r for r in self.second_summary['runs']}
        self.assertTrue(rows['ci100_slip0.1']['kept'])
        self.assertEqual(rows['ci100_slip0.1']['wall_time'], 1.5)  # the kept run's own wall time
        self.assertFalse(rows['ci100_slip0.5']['kept'])

    def test_an_empty_soil_list_is_refused(self):
        # (argparse's floats gives [] for '': that was taken as "not given", CI 100)
        r = self.sweep('0.1', '--ci', '')
        self.assertNotEqual(r.returncode, 0, r.stdout)
        self.assertIn('--ci: no value given', r.stdout)

    def test_a_resume_with_another_seed_or_load_is_refused_naming_it(self):
        # the results hold neither the seed nor the scene's load where none was given: the
        # folder keeps the options its runs were made with
        for more, what in ((['--seed', '7'], '--seed None, not 7'), (['--load', '800'], '--load None, not 800.0')):
            r = self.sweep('0.1', '--resume', *more)
            self.assertNotEqual(r.returncode, 0, r.stdout)
            self.assertIn('--resume: %s holds runs made with %s' % (self.out, what), r.stdout)

    def test_kept_runs_take_a_resume_from_another_folder_past_them(self):
        # --keep DIR: each finished run (ok or sunk; not a failed one) compacted into DIR as it ends,
        # with the sweep's options; a resume into a new OUT (a fresh clone) reruns only the rest
        keep = os.path.join(self.tmp, 'kept')
        a, b = os.path.join(self.tmp, 'keep_a'), os.path.join(self.tmp, 'keep_b')
        r = self.sweep('0.1,0.7', '--keep', keep, '--out', a)
        self.assertEqual(r.returncode, 1, r.stdout)  # the 0.7 runs fail
        self.assertEqual(sorted(os.listdir(keep)), ['ci100_slip0.1.yaml', 'ci100_towed.yaml', 'ci20_slip0.1.yaml',
                                                    'ci20_towed.yaml', 'sweep_options.yaml'])
        self.assertIn('kept   ci20_slip0.1   ' + os.path.join(keep, 'ci20_slip0.1.yaml'), r.stdout)
        with open(os.path.join(keep, 'ci100_slip0.1.yaml')) as fh:
            kept = yaml.safe_load(fh)
        self.assertEqual(kept['status'], 'ok')
        self.assertAlmostEqual(kept['dp_over_w'], 0.5 * 0.1 + 100 / 1000.0)  # the stand-in's
        self.assertIn('kept_from_commit', kept)
        with open(os.path.join(keep, 'sweep_options.yaml')) as fh:
            self.assertNotIn('--scene', yaml.safe_load(fh))  # the scene by its hash only
        r = self.sweep('0.1,0.7', '--keep', keep, '--resume', '--out', b)
        self.assertEqual(r.returncode, 1, r.stdout)
        with open(os.path.join(b, 'runs', 'calls')) as fh:
            ran = sorted(bag_of(json.loads(line)) for line in fh)
        self.assertEqual(ran, ['ci100_slip0.7.bag', 'ci20_slip0.7.bag'])
        self.assertIn('6 runs (ci 20,100 x slip 0.1,0.7 + towed), level tiny, 2 to run', r.stdout)
        # kept runs made with another seed are refused, naming the folder
        r = self.sweep('0.1', '--keep', keep, '--resume', '--seed', '5', '--out', os.path.join(self.tmp, 'keep_c'))
        self.assertNotEqual(r.returncode, 0, r.stdout)
        self.assertIn('--resume: %s holds runs made with --seed None, not 5' % keep, r.stdout)

    def test_commit_without_keep_is_refused(self):
        r = self.sweep('0.1', '--commit', '--out', os.path.join(self.tmp, 'no_keep'))
        self.assertNotEqual(r.returncode, 0, r.stdout)
        self.assertIn('--commit commits what --keep DIR writes', r.stdout)


def bag_of(call):
    """The bag's file name in a recorded roslaunch call."""
    return os.path.basename(dict(a.split(':=', 1) for a in call if ':=' in a)['bag'])


def dm_run_scene():
    p = paths.dm_run_scene()
    return p if os.access(p, os.X_OK) else None


@unittest.skipUnless(HAVE_PLOTS and dm_run_scene(), 'needs the core build (build/core or $DM_RUN_SCENE) and matplotlib')
class RealTinyRun(unittest.TestCase):
    """One real run of the rig (level tiny: d = 0.1 m, about 20 s on one thread) through --runner core:
    the summary's figures are the result file's, and its references those of wheel_numerics for the
    result's tire and load."""

    def test_tiny_run(self):
        tmp = tempfile.mkdtemp(prefix='dm_wheel_sweep_real_')
        self.addCleanup(shutil.rmtree, tmp, True)
        # CI 100 through the table made at tiny's 0.1 m particles (config/calibration/cone_index_mu0.1_d0.1.yaml)
        p = subprocess.run(TOOL + ['--runner', 'core', '--dm-run-scene', dm_run_scene(),
                            '--fidelity', 'tiny', '--ci', '100', '--slip', '0.3', '--jobs', '1', '--progress', 'plain',
                            '--out', tmp], stdout=subprocess.PIPE, stderr=subprocess.STDOUT, universal_newlines=True,
                           env=dict(os.environ, MPLBACKEND='Agg'), timeout=900)
        self.assertEqual(p.returncode, 0, p.stdout)
        self.assertIn('runner: core', p.stdout)
        with open(os.path.join(tmp, 'runs', 'ci100_slip0.3.result.yaml')) as fh:
            res = yaml.safe_load(fh)
        with open(os.path.join(tmp, 'summary.yaml')) as fh:
            doc = yaml.safe_load(fh)
        self.assertEqual((res['kind'], res['fidelity'], res['drive']), ('single_wheel', 'tiny', 'slip'))
        self.assertIn(res['status'], ('ok', 'sunk'))
        s = doc['soils'][0]
        if res['status'] == 'ok':
            self.assertGreater(res['window_samples'], 0)
            self.assertAlmostEqual(s['points']['dp_over_w'][0], res['dp_over_w'], places=5)
            self.assertAlmostEqual(s['points']['torque_over_wr'][0], res['torque_over_wr'], places=5)
            self.assertAlmostEqual(s['points']['sinkage'][0], res['sinkage'], places=5)
        b, d, w = res['tire_width'], 2 * res['tire_radius'], res['load']
        v = wn.vti(res['cone_index_psi'], b, d, w)
        x = s['points']['slip'][0]
        self.assertAlmostEqual(x, 0.3, places=6)
        self.assertAlmostEqual(s['reference']['vti_dp_over_w'][0], wn.vti_dp_over_w(x, v['nc'], b, d, v['ssp']), places=5)
        self.assertTrue(math.isfinite(s['reference']['band_dp_over_w'][0][0]))
        self.assertEqual(doc['runner'], 'core')
        self.assertTrue(os.path.exists(os.path.join(tmp, 'dp_over_w_vs_slip.png')))


if __name__ == '__main__':
    unittest.main()
