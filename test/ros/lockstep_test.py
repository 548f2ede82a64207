#!/usr/bin/env python3
"""rostest node: the lock-step exchange of a road run, every step logged.

Checks, from the bag the run wrote and the result file beside it:
- exactly one terrain exchange per vehicle step, in order: the logged wheel states carry steps
  0, 1, 2, ... N without a gap or a repeat, each wrench answers the state of its own step, and the
  terrain's own count of answered exchanges equals step + 1;
- the driver acted exactly every control period (in vehicle steps) from the driver's start;
- nothing was lost: every topic holds as many messages as the vehicle counted publishing.
"""
import os
import sys
import time
import unittest

import rosbag
import rospy
import rostest
import yaml

from dem_mobility.msg import MobilityResult

NS = '/mobility/'


class LockStep(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        rospy.init_node('lockstep_test')
        cls.bag_path = rospy.get_param('~bag')
        cls.result_path = rospy.get_param('~result_file')
        cls.scene = yaml.safe_load(open(rospy.get_param('~scene')))
        cls.msg = rospy.wait_for_message(NS + 'result', MobilityResult, timeout=240)
        # the recorder closes the bag as soon as it has the result; wait until it can be read
        deadline = time.time() + 60
        while True:
            try:
                cls.bag = rosbag.Bag(cls.bag_path)
                break
            except Exception:
                if time.time() > deadline:
                    raise
                time.sleep(0.2)
        cls.result = yaml.safe_load(open(cls.result_path))

    def test_run_finished(self):
        self.assertEqual(self.msg.error, '')
        self.assertEqual(self.result['error'], '')
        self.assertGreater(self.msg.steps, 10000)

    def test_one_exchange_per_step_in_order(self):
        states = [m.step for _, m, _ in self.bag.read_messages(topics=[NS + 'wheel_states'])]
        wrenches = [(m.step, m.served, len(m.wrenches)) for _, m, _ in
                    self.bag.read_messages(topics=[NS + 'wheel_wrenches'])]
        n = self.result['steps'] + 1  # steps 0..N
        self.assertEqual(states, list(range(n)))
        self.assertEqual([w[0] for w in wrenches], list(range(n)))
        self.assertEqual([w[1] for w in wrenches], [k + 1 for k in range(n)])
        self.assertTrue(all(w[2] == 4 for w in wrenches))
        self.assertEqual(self.result['exchanges'], n)

    def test_driver_every_control_period(self):
        steps = [m.step for _, m, _ in self.bag.read_messages(topics=[NS + 'driver_command'])]
        dt = self.result['time_step']
        every = max(1, round(self.scene['driver']['control_period'] / dt))
        first = round(self.scene['settle_time'] / dt)
        self.assertEqual(steps[0], first)
        self.assertEqual(steps, list(range(first, first + every * len(steps), every)))
        self.assertEqual(len(steps), self.result['driver_updates'])

    def test_bag_holds_every_published_message(self):
        info = self.bag.get_type_and_topic_info().topics
        published = self.result['published']
        for topic, count in published.items():
            if topic == 'clock':
                continue  # /clock is not recorded (a replay makes its own)
            full = '/' + topic if topic in ('tf', 'tf_static') else NS + topic
            self.assertIn(full, info, 'topic %s missing from the bag' % full)
            self.assertEqual(info[full].message_count, count, 'topic %s' % full)
        self.assertEqual(info[NS + 'terrain/markers'].message_count, 1)


if __name__ == '__main__':
    rostest.rosrun('dem_mobility', 'lockstep', LockStep, sys.argv)
