#!/usr/bin/env python3
"""End-to-end runs of the road scene through roslaunch, as a user starts it (each run gets its own
master). Checks what one run cannot: the same scene twice gives the same messages; the vehicle
follows the commanded 1 m/s^2 while torque allows; the nodelet run gives the in-process core
runner's numbers exactly; a terrain nodelet unloaded from the manager mid-run, or a terrain
process killed mid-run, stops the run with a clear error instead of a hang; SIGTERM mid-run ends
the run at once with an `interrupted` result and a closed bag; a bag that cannot be written (a
file size limit, as a full disk) stops the run with that error; bad input is refused with the file
and key.

    python3 test/ros/test_road_runs.py   (after the catkin build; needs the workspace sourced)
"""
import collections
import os
import shutil
import signal
import subprocess
import sys
import tempfile
import time
import unittest

import rosbag
import yaml

from dem_mobility_tools import paths
from launch_run import LaunchRun  # beside this file

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))
DM_LAUNCH = [sys.executable, '-m', 'dem_mobility_tools.launch']  # dm-launch: roslaunch with the run's exit status
SCENE = os.path.join(ROOT, 'config', 'scenes', 'road_slope.yaml')
RUNNER = paths.dm_run_scene()
NS = '/mobility/'


class Run(LaunchRun):
    """One roslaunch of road_slope.launch (or `launch`) with its own master, in its own folder; its
    messages are compared raw."""

    def __init__(self, tmp, name, *args, launch='road_slope.launch', prefix=(), program='roslaunch'):
        super().__init__(tmp, name, launch, *args, prefix=prefix, program=program)

    def messages(self, topics=None):
        return super().messages(topics, raw=True)


class RoadRuns(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.tmp = tempfile.mkdtemp(prefix='dm_road_runs_')
        # two identical runs at the same time would share the two cores unevenly; one after another
        # on level ground, where the speed controller has no grade to work off (the grade itself is
        # checked by the core's power-balance test, and the core-runner comparison covers the rest)
        cls.a = Run(cls.tmp, 'a', 'duration:=8', 'grade:=0').wait(240)
        cls.b = Run(cls.tmp, 'b', 'duration:=8', 'grade:=0').wait(240)

    @classmethod
    def tearDownClass(cls):
        if os.environ.get('DM_KEEP_TEST_RUNS') is None:
            shutil.rmtree(cls.tmp, ignore_errors=True)

    def test_runs_finish_without_error(self):
        for r in (self.a, self.b):
            self.assertEqual(r.result()['error'], '', r.output()[-3000:])
            self.assertEqual(r.proc.returncode, 0)

    def test_same_scene_twice_gives_identical_messages(self):
        ma, mb = self.a.messages(), self.b.messages()
        self.assertGreater(len(ma), 1000)
        # per topic first, so that a difference names the topic
        self.assertEqual(collections.Counter(t for t, _, _ in ma), collections.Counter(t for t, _, _ in mb))
        self.assertEqual(len(ma), len(mb))
        for (ta, da, sa), (tb, db, sb) in zip(ma, mb):
            if ta.endswith('result'):
                continue  # holds the wall time of the run
            self.assertEqual((ta, sa), (tb, sb))
            self.assertEqual(da, db, 'message on %s at %s differs' % (ta, sa))

    def test_vehicle_accelerates_at_the_commanded_rate(self):
        with open(SCENE) as f:
            settle = yaml.safe_load(f)['settle_time']
        t, v = [], []
        with rosbag.Bag(self.a.bag) as b:
            for _, m, _ in b.read_messages(topics=[NS + 'odom']):
                ts = m.header.stamp.to_sec() - settle
                if 3.0 <= ts <= 8.0:
                    t.append(ts)
                    v.append(m.twist.twist.linear.x)
            wot = [m.wot_limited for _, m, _ in b.read_messages(topics=[NS + 'driver_command'])]
        self.assertFalse(any(wot), 'the engine limited the acceleration; the check needs torque to spare')
        n = len(t)
        mt, mv = sum(t) / n, sum(v) / n
        slope = sum((a - mt) * (b - mv) for a, b in zip(t, v)) / sum((a - mt) ** 2 for a in t)
        self.assertAlmostEqual(slope, 1.0, delta=0.03)

    def test_nodelets_give_the_core_runners_numbers(self):
        out = os.path.join(self.tmp, 'core.yaml')
        subprocess.run([RUNNER, SCENE, 'duration=8', 'grade_deg=0', '--quiet', '--out', out], check=True,
                       stdout=subprocess.DEVNULL)
        with open(out) as f:
            core = yaml.safe_load(f)
        ros = self.a.result()
        for key in ('speed_made_good', 'window_slope', 'time_step', 'steps', 'exchanges', 'status'):
            self.assertEqual(ros[key], core[key], key)


class Failures(unittest.TestCase):
    def setUp(self):
        self.tmp = tempfile.mkdtemp(prefix='dm_road_fail_')

    def tearDown(self):
        shutil.rmtree(self.tmp, ignore_errors=True)

    def wait_for_progress(self, run, timeout=60):
        # the bag grows once the run is stepping (the console output reaches the log file in blocks)
        deadline = time.time() + timeout
        while not (os.path.exists(run.bag) and os.path.getsize(run.bag) > 2e6):
            self.assertLess(time.time(), deadline, 'the run did not start: ' + run.output()[-2000:])
            time.sleep(0.2)

    def test_unloaded_terrain_nodelet_stops_the_run_with_an_error(self):
        run = Run(self.tmp, 'unload', 'duration:=300')
        self.wait_for_progress(run)
        said = ''
        for _ in range(5):
            # its own session: the nodelet tool signals its process group when it gives up
            try:
                u = subprocess.run(['/usr/lib/nodelet/nodelet', 'unload', NS + 'terrain', NS + 'manager',
                                    '__name:=dm_test_unloader'], env=run.env, capture_output=True, text=True,
                                   timeout=20, start_new_session=True, stdin=subprocess.DEVNULL)
            except subprocess.TimeoutExpired as e:
                self.fail('nodelet unload hung: %s %s\n%s' % (e.stdout, e.stderr, run.output()[-3000:]))
            said += u.stdout + u.stderr
            if u.returncode == 0:
                break
            time.sleep(2)
        self.assertEqual(u.returncode, 0, said)
        run.wait(60)
        r = run.result()
        self.assertEqual(r['status'], 'error', run.output()[-3000:])
        self.assertIn('the terrain left the exchange', r['error'])
        self.assertIn('unloaded', r['error'])
        self.assertGreater(r['steps'], 0)
        # the bag up to the failure is kept and readable
        self.assertGreater(len(run.messages([NS + 'odom'])), 10)

    def test_killed_terrain_process_stops_the_run_after_the_peer_timeout(self):
        # through dm-launch: roslaunch itself exits 0 after such an error, dm-launch with 1
        run = Run(self.tmp, 'kill', 'duration:=300', 'standalone:=true', 'peer_timeout:=3', program=DM_LAUNCH)
        self.wait_for_progress(run, 90)
        pids = subprocess.run(['pgrep', '-f', 'standalone dem_mobility/TerrainNodelet.*' + run.dir],
                              capture_output=True, text=True).stdout.split()
        if not pids:  # roslaunch passes the log path (in run.dir) to the node
            pids = subprocess.run(['pgrep', '-f', 'TerrainNodelet.*__log:=' + run.dir],
                                  capture_output=True, text=True).stdout.split()
        self.assertTrue(pids, 'terrain process not found')
        for p in pids:
            os.kill(int(p), signal.SIGKILL)
        t0 = time.time()
        run.wait(60)
        r = run.result()
        self.assertEqual(r['status'], 'error')
        self.assertIn('did not answer step', r['error'])
        self.assertLess(time.time() - t0, 30)
        self.assertEqual(run.returncode, 1, run.output()[-2000:])
        self.assertIn('dm-launch: the run failed: the terrain did not answer step', run.output())

    def test_sigterm_mid_run_closes_the_bag_and_the_result_says_interrupted(self):
        # SIGTERM to dm-launch alone (a scheduler's stop, `kill`): it passes it on to roslaunch,
        # which stops its nodes with SIGINT, as Ctrl-C does (test_soil_slope.py sends that one)
        run = Run(self.tmp, 'sigterm', 'duration:=300', program=DM_LAUNCH)
        self.wait_for_progress(run)
        # the run stopped at once: its result was written within seconds of the signal (roslaunch
        # then takes the master down), and says how far it came
        self.assertLess(run.stop(signal.SIGTERM, group=False), 3.0)
        self.assertEqual(run.returncode, 4, run.output()[-2000:])  # dm-launch passed it on: interrupted
        r = run.result()
        self.assertEqual(r['status'], 'interrupted', run.output()[-3000:])
        self.assertTrue(r['interrupted'])
        self.assertGreater(r['simulated_time'], 0.0)
        self.assertLess(r['simulated_time'], 300.0)
        # the terrain's own figures were reached (the rigid road has none to add): no note of them missing
        self.assertNotIn('terrain_report', r)
        # the bag is closed (indexed): rosbag info reads it, and it holds the run up to the signal
        code, info = run.bag_info()
        self.assertEqual(code, 0, info)
        self.assertNotIn('unindexed', info)
        self.assertGreater(len(run.messages([NS + 'odom'])), 10)

    def test_a_bag_that_cannot_be_written_stops_the_run_with_an_error(self):
        # a file size limit of 3 MB (as a full disk): the bag's writes fail once it is reached; the
        # recorder says so, the vehicle stops the run with that error and the result says it
        # (before, SIGXFSZ killed the manager: an unindexed bag, an empty result file)
        run = Run(self.tmp, 'full', 'duration:=60', prefix=['prlimit', '--fsize=3000000']).wait(60)
        self.assertLessEqual(os.path.getsize(run.bag), 3000000)
        r = run.result()
        self.assertEqual(r['status'], 'error', run.output()[-3000:])
        self.assertIn('the bag recorder cannot write ' + run.bag, r['error'])
        self.assertIn('disk full or a file size limit', r['error'])
        self.assertLess(r['simulated_time'], 60.0)
        self.assertIn('the bag recorder cannot write', run.output())

    def test_bad_grade_is_refused_naming_the_file_and_key(self):
        run = Run(self.tmp, 'bad', 'grade:=95').wait(60)
        r = run.result()
        self.assertEqual(r['status'], 'error')
        self.assertIn('road_slope.yaml: grade_deg', r['error'])

    def test_a_parameter_of_the_wrong_type_is_refused_naming_it(self):
        # roslaunch gives `fast` as a string: the vehicle refuses it instead of logging at 100 Hz
        # without a word (ros's NodeHandle::param would take its default)
        run = Run(self.tmp, 'bad_rate', 'log_rate:=fast').wait(60)
        r = run.result()
        self.assertEqual(r['status'], 'error')
        self.assertIn('parameter /mobility/vehicle/log_rate is not a number', r['error'])
        run = Run(self.tmp, 'tiny_rate', 'log_rate:=1e-300').wait(60)  # (a string to roslaunch: no '.')
        self.assertIn('parameter /mobility/vehicle/log_rate: ', run.result()['error'])
        self.assertIn('a rate is from 1e-6 to 1e9 Hz (0: every step)', run.result()['error'])


if __name__ == '__main__':
    unittest.main(verbosity=2)
