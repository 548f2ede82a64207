"""dem_mobility_tools.runs and .paths: one scene run's command for either runner, checked against
what each runner takes (every launch argument is declared by its launch file; every dm_run_scene
override passes dm_run_scene --check, which refuses an unknown key), where the core runner is
found (DM_RUN_SCENE, DM_BUILD, the checkout's build/), a free port and a run's result file.

    PYTHONPATH=python python3 -m unittest discover -s test/python -p test_runs.py -v   (from the repository root)
"""
import os
import shutil
import socket
import subprocess
import tempfile
import unittest
import xml.etree.ElementTree as ET
from unittest import mock

from dem_mobility_tools import paths, runs

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
# a value of each parameter that every scene takes
VALUES = {'grade_deg': 12.0, 'duration': 5.0, 'fidelity': 'tiny', 'cone_index': 100.0, 'cohesion_factor': 1.5,
          'dem_threads': 1, 'seed': 3, 'slip': 0.2, 'drive': 'slip', 'friction': 0.1, 'load_mass': 1000.0,
          'speed': 1.0, 'time_step': 1e-4}


def launch_args(launch):
    return {a.get('name') for a in ET.parse(os.path.join(ROOT, 'launch', launch)).getroot().findall('arg')}


class Paths(unittest.TestCase):
    def test_the_checkout_is_found(self):
        self.assertEqual(paths.ROOT, ROOT)
        self.assertTrue(os.path.isfile(os.path.join(paths.CONFIG, 'scenes', 'soil_slope.yaml')))

    def test_the_core_runner_from_option_env_build_folder_or_checkout(self):
        env = {k: v for k, v in os.environ.items() if k not in ('DM_RUN_SCENE', 'DM_BUILD')}
        with mock.patch.dict(os.environ, env, clear=True):
            self.assertEqual(paths.dm_run_scene(), os.path.join(ROOT, 'build', 'core', 'src', 'tools', 'dm_run_scene'))
            os.environ['DM_BUILD'] = '/b'
            self.assertEqual(paths.dm_run_scene(), '/b/core/src/tools/dm_run_scene')
            os.environ['DM_RUN_SCENE'] = '/x/dm_run_scene'
            self.assertEqual(paths.dm_run_scene(), '/x/dm_run_scene')
            self.assertEqual(paths.dm_run_scene('/y/runner'), '/y/runner')


class SceneCommand(unittest.TestCase):
    def test_roslaunch(self):
        argv = runs.scene_command('roslaunch', 'soil_slope.launch', [('grade_deg', 12.0), ('cone_index', 1234.567),
                                  ('dem_threads', 2), ('duration', None)], port=11611, bag='/r/run.bag',
                                  launch_args=[('cloud_rate', 2.0), 'pace:=1'])
        self.assertEqual(argv, ['roslaunch', '-p', '11611', 'dem_mobility', 'soil_slope.launch', 'grade:=12',
                                'cone_index:=1234.567', 'dem_threads:=2', 'bag:=/r/run.bag', 'cloud_rate:=2',
                                'pace:=1', 'rviz:=false', 'end_run:=true'])

    def test_core(self):
        argv = runs.scene_command('core', 'soil_slope.launch', {'grade_deg': 0.1, 'fidelity': 'tiny'},
                                  result='/r/x.result.yaml', history='/r/x.csv', core_args=['settle_time=0'],
                                  core_options=['--quiet'], dm_run_scene='/x/dm_run_scene')
        self.assertEqual(argv, ['/x/dm_run_scene', os.path.join(ROOT, 'config', 'scenes', 'soil_slope.yaml'),
                                'grade_deg=0.1', 'terrain_overrides.fidelity=tiny', 'settle_time=0',
                                '--out', '/r/x.result.yaml', '--history', '/r/x.csv', '--quiet'])

    def test_bad_runner_launch_or_parameter_is_refused_by_name(self):
        with self.assertRaisesRegex(ValueError, "runner 'ros'"):
            runs.scene_command('ros', 'soil_slope.launch')
        with self.assertRaisesRegex(ValueError, 'nowhere.launch'):
            runs.scene_command('core', 'nowhere.launch')
        with self.assertRaisesRegex(ValueError, "road_slope.launch has no parameter 'cone_index'"):
            runs.scene_command('roslaunch', 'road_slope.launch', [('cone_index', 100.0)])

    def test_every_launch_argument_is_declared_by_its_launch_file(self):
        for launch, names in runs.LAUNCHES.items():
            declared = launch_args(launch)
            for param, (arg, _) in names.items():
                self.assertIn(arg, declared, '%s: %s -> %s:=' % (launch, param, arg))
            self.assertLessEqual({'scene', 'bag', 'rviz', 'end_run'}, declared, launch)

    def test_every_core_override_passes_dm_run_scene_check(self):
        exe = paths.dm_run_scene()
        self.assertTrue(os.access(exe, os.X_OK), paths.missing_runner_message(exe))
        # (the check can fail: a key the scene does not have is refused)
        bad = runs.scene_command('core', 'road_slope.launch', core_args=['no_such_key=1'], core_options=['--check'])
        self.assertEqual(subprocess.run(bad, capture_output=True).returncode, 1)
        refused = []
        for launch, names in runs.LAUNCHES.items():
            for param in names:
                argv = runs.scene_command('core', launch, [(param, VALUES[param])], core_options=['--check'])
                p = subprocess.run(argv, capture_output=True, text=True, timeout=120)
                if p.returncode != 0:
                    refused.append('%s %s: %s' % (launch, param, (p.stdout + p.stderr)[-500:]))
        self.assertEqual(refused, [])


class Ports(unittest.TestCase):
    def test_a_busy_port_is_passed_over(self):
        with socket.socket() as s:
            s.bind(('', 0))
            s.listen()
            busy = s.getsockname()[1]
            self.assertFalse(runs.port_free(busy))
            got = runs.free_port(busy, step=2)
            self.assertEqual((got - busy) % 2, 0)
            self.assertGreater(got, busy)
            self.assertTrue(runs.port_free(got))
            with self.assertRaisesRegex(OSError, 'no free TCP port'):
                runs.free_port(busy, step=2, tries=1)
        self.assertTrue(runs.port_free(runs.free_port()))


class ReadResult(unittest.TestCase):
    def setUp(self):
        self.tmp = tempfile.mkdtemp(prefix='dm_runs_')

    def tearDown(self):
        shutil.rmtree(self.tmp)

    def write(self, name, text):
        path = os.path.join(self.tmp, name)
        with open(path, 'w') as fh:
            fh.write(text)
        return path

    def test_a_mapping_or_why_not_naming_the_file(self):
        good = self.write('good.yaml', 'status: ok\nspeed_made_good: 2.5\n')
        self.assertEqual(runs.read_result(good), ({'status': 'ok', 'speed_made_good': 2.5}, None))
        for name, text, why in (('list.yaml', '- 1\n- 2\n', 'not a YAML mapping'), ('empty.yaml', '', 'empty'),
                                ('bad.yaml', 'status: [ok\n', 'not YAML')):
            path = self.write(name, text)
            doc, reason = runs.read_result(path)
            self.assertIsNone(doc)
            self.assertIn(path, reason)
            self.assertIn(why, reason)
        missing = os.path.join(self.tmp, 'none.yaml')
        doc, reason = runs.read_result(missing)
        self.assertIsNone(doc)
        self.assertIn(missing + ': No such file', reason)


if __name__ == '__main__':
    unittest.main()
