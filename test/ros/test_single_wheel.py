#!/usr/bin/env python3
"""The single-wheel rig through roslaunch, as a user starts it (each run with its own master): a
tiny run finishes; its bag holds the particles, the tools, the wheel's wrench and samples and the
result; the result message and the result YAML agree and say ok; a slip outside [-1, 1) is refused
with the scene file and the key in the log and the result YAML (status error).

    python3 test/ros/test_single_wheel.py   (after the catkin build; needs the workspace sourced)
"""
import math
import os
import shutil
import tempfile
import unittest

import rosbag
import yaml

from launch_run import LaunchRun  # beside this file

NS = '/wheel/'


def run(tmp, name, *args, timeout=150):
    """One roslaunch of single_wheel.launch; returns (returncode, log text, bag path)."""
    r = LaunchRun(tmp, name, 'single_wheel.launch', 'fidelity:=tiny', 'dem_threads:=1', *args).wait(timeout)
    return r.returncode, r.output(), r.bag


def load_result(bag):
    with open(bag[:-4] + '.result.yaml') as fh:
        return yaml.safe_load(fh)


class SingleWheelRun(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.tmp = tempfile.mkdtemp(prefix='dm_single_wheel_')
        cls.code, cls.log, cls.bag = run(cls.tmp, 'ok', 'cohesion_factor:=1.5', 'slip:=0.2', 'cloud_rate:=10')
        cls.res = load_result(cls.bag)
        cls.counts, cls.msgs = {}, {}
        with rosbag.Bag(cls.bag) as b:
            for topic, msg, _ in b.read_messages():
                cls.counts[topic] = cls.counts.get(topic, 0) + 1
                cls.msgs.setdefault(topic, []).append(msg)

    @classmethod
    def tearDownClass(cls):
        if os.environ.get('DM_KEEP_TEST_RUNS') is None:
            shutil.rmtree(cls.tmp, ignore_errors=True)

    def test_run_finishes_ok(self):
        self.assertEqual(self.code, 0, self.log[-3000:])
        self.assertEqual(self.res['status'], 'ok', self.log[-3000:])
        self.assertEqual(self.res['error'], '')
        self.assertEqual(self.res['kind'], 'single_wheel')
        self.assertEqual(self.res['slip_commanded'], 0.2)
        self.assertGreater(self.res['window_samples'], 10)

    def test_bag_holds_the_topics(self):
        c = self.counts
        self.assertEqual(c.get(NS + 'terrain/markers'), 1)
        for t in ('terrain/tools', 'terrain/particles', 'terrain/particles_section'):
            self.assertGreater(c.get(NS + t, 0), 10, t)
        self.assertEqual(c.get(NS + 'result'), 1)
        self.assertEqual(c.get(NS + 'wheel/sample'), len(self.res['history']['t']))
        self.assertGreater(c.get(NS + 'wheel/wrench', 0), 100)
        self.assertEqual(c.get('/tf'), c.get(NS + 'wheel/wrench'))
        cloud = self.msgs[NS + 'terrain/particles'][-1]
        self.assertEqual([f.name for f in cloud.fields], ['x', 'y', 'z', 'plastic_strain'])
        self.assertEqual(cloud.width, self.res['particles'])
        self.assertLess(self.msgs[NS + 'terrain/particles_section'][-1].width, cloud.width)
        names = {m.ns for a in self.msgs[NS + 'terrain/tools'] for m in a.markers}
        self.assertTrue({'tire', 'carriage', 'lid', 'status'} <= names, names)

    def test_wrench_is_the_soils_force_at_the_wheel(self):
        wrenches = self.msgs[NS + 'wheel/wrench']
        self.assertTrue(all(m.header.frame_id == 'wheel' for m in wrenches))
        tf = self.msgs['/tf'][-1].transforms[0]
        self.assertEqual((tf.header.frame_id, tf.child_frame_id), ('map', 'wheel'))
        self.assertEqual(tf.header.stamp, wrenches[-1].header.stamp)
        # the soil carries the wheel: over the last half its mean upward force is near the load
        last = wrenches[len(wrenches) // 2:]
        fz = sum(m.wrench.force.z for m in last) / len(last)
        print('wheel: mean upward force over the last half %.1f N, load %.1f N' % (fz, self.res['load']))
        # within 3 % (measured 2026-12-02: 12107.7 N against 12066.3 N, 0.3 %; the core rig test
        # asserts 1 % over a longer run)
        self.assertLess(abs(fz - self.res['load']), 0.03 * self.res['load'])

    def test_samples_are_the_history(self):
        h = self.res['history']
        samples = self.msgs[NS + 'wheel/sample']
        for key in ('t', 'travel', 'speed', 'omega', 'slip', 'sinkage', 'drawbar_pull', 'torque', 'vertical_force'):
            self.assertEqual([getattr(m, key) for m in samples], h[key], key)

    def test_result_message_and_yaml_agree(self):
        m, r = self.msgs[NS + 'result'][0], self.res
        self.assertEqual((m.status, m.error), (r['status'], r['error']))
        self.assertEqual(m.fidelity, 'tiny')
        self.assertEqual(m.drive, r['drive'])
        for key in ('cohesion_factor', 'friction', 'slip_commanded', 'load', 'dp_over_w', 'dp_over_w_std',
                    'torque_over_wr', 'torque_over_wr_std', 'sinkage', 'sinkage_std', 'slip', 'window_samples',
                    'particles', 'simulated_time'):
            self.assertEqual(getattr(m, key), r[key], key)
        if isinstance(r['cone_index_psi'], float):
            self.assertEqual(m.cone_index_psi, r['cone_index_psi'])
        else:  # no table at this particle size: the YAML says why, the message has NaN
            self.assertTrue(math.isnan(m.cone_index_psi))
        self.assertTrue(math.isnan(m.torque_commanded))


class BadSlip(unittest.TestCase):
    def test_bad_slip_is_refused_naming_the_file_and_key(self):
        tmp = tempfile.mkdtemp(prefix='dm_single_wheel_bad_')
        try:
            code, log, bag = run(tmp, 'bad', 'slip:=1.5', timeout=60)
            r = load_result(bag)  # roslaunch itself ends with 0 when a required node stops: the status says it
            self.assertEqual(r['status'], 'error', log[-3000:])
            self.assertIn('single_wheel.yaml: wheel.slip', r['error'])
            self.assertIn('single_wheel.yaml: wheel.slip', log)
        finally:
            shutil.rmtree(tmp, ignore_errors=True)


if __name__ == '__main__':
    unittest.main(verbosity=2)
