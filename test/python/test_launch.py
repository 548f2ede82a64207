"""dm-launch (dem_mobility_tools.launch) without ROS: a stand-in `roslaunch` on PATH that names a
result file in --dump-params and then writes a result (or none, or a damaged one); dm-launch's exit
status and message follow what the result says (0 a verdict, 1 a failed run, 3 no result).

    PYTHONPATH=python python3 -m unittest discover -s test/python -p test_launch.py -v   (from the repository root)
"""
import os
import shutil
import stat
import subprocess
import sys
import tempfile
import unittest

ROSLAUNCH = r'''#!%s
import os, sys
result = os.environ['STAND_IN_RESULT']
if '--dump-params' in sys.argv:
    print('/mobility/vehicle/result_file: %%s' %% result)
    sys.exit(0)
text = {'steady': 'status: steady\nspeed_made_good: 2.5\n', 'error': 'status: error\nerror: the terrain did not answer\n',
        'list': '- 1\n- 2\n', 'none': None}[os.environ['STAND_IN_MODE']]
if text is not None:
    with open(result, 'w') as fh:
        fh.write(text)
''' % sys.executable


class DmLaunch(unittest.TestCase):
    def setUp(self):
        self.tmp = tempfile.mkdtemp(prefix='dm_launch_')
        bin_dir = os.path.join(self.tmp, 'bin')
        os.makedirs(bin_dir)
        exe = os.path.join(bin_dir, 'roslaunch')
        with open(exe, 'w') as fh:
            fh.write(ROSLAUNCH)
        os.chmod(exe, os.stat(exe).st_mode | stat.S_IXUSR)
        self.result = os.path.join(self.tmp, 'run.result.yaml')
        self.env = dict(os.environ, PATH=bin_dir + os.pathsep + os.environ['PATH'], STAND_IN_RESULT=self.result)

    def tearDown(self):
        shutil.rmtree(self.tmp)

    def launch(self, mode, stale=False):
        if stale:  # a result of an earlier run: removed before this one starts
            with open(self.result, 'w') as fh:
                fh.write('status: steady\n')
        return subprocess.run([sys.executable, '-m', 'dem_mobility_tools.launch', 'dem_mobility', 'road_slope.launch'],
                              capture_output=True, text=True, env=dict(self.env, STAND_IN_MODE=mode), timeout=60)

    def test_the_exit_status_follows_the_result(self):
        p = self.launch('steady')
        self.assertEqual(p.returncode, 0, p.stderr)
        self.assertIn('dm-launch: steady', p.stdout)
        p = self.launch('error')
        self.assertEqual(p.returncode, 1)
        self.assertIn('dm-launch: the run failed: the terrain did not answer', p.stderr)
        p = self.launch('none', stale=True)
        self.assertEqual(p.returncode, 3)
        self.assertIn('dm-launch: the run wrote no result (%s: No such file' % self.result, p.stderr)
        p = self.launch('list')
        self.assertEqual(p.returncode, 3)
        self.assertIn('not a YAML mapping', p.stderr)
        self.assertNotIn('Traceback', p.stderr)

    def test_help(self):
        p = subprocess.run([sys.executable, '-m', 'dem_mobility_tools.launch', '--help'], capture_output=True, text=True)
        self.assertEqual(p.returncode, 0)
        self.assertIn('dm-launch [roslaunch arguments]', p.stdout)


if __name__ == '__main__':
    unittest.main()
