#!/usr/bin/env python3
"""The bag recorder nodelet on its own (standalone, its own master): a latching publisher's
message that arrives again with the same bytes is recorded once (roscpp can deliver a latched
message twice when a subscriber connects while it is published; the road runs' bags once differed
by one message so), a latching publisher's new message is recorded, and a publisher that does not
latch keeps every message, repeated bytes too; the bag closes when the end topic arrives.

    python3 test/ros/test_bag_recorder.py   (after the catkin build; needs the workspace sourced)
"""
import os
import shutil
import subprocess
import sys
import tempfile
import time
import unittest

import rosbag

from dem_mobility_tools.runs import free_port
from launch_run import stop_group  # beside this file

PUBLISHER = r'''
import time
import rospy
from geometry_msgs.msg import PointStamped
from std_msgs.msg import String
rospy.init_node('publisher')
latched = rospy.Publisher('/latched', String, queue_size=100, latch=True)
plain = rospy.Publisher('/plain', String, queue_size=100)
stream = rospy.Publisher('/stream', PointStamped, queue_size=100)
result = rospy.Publisher('/result', String, queue_size=100, latch=True)
deadline = time.time() + 60
while any(p.get_num_connections() == 0 for p in (latched, plain, stream, result)):
    if time.time() > deadline:
        raise SystemExit('the recorder did not subscribe within 60 s')
    time.sleep(0.05)
for text in ('state 1', 'state 1', 'state 2'):
    latched.publish(String(text))
for text in ('same', 'same'):
    plain.publish(String(text))
for k in range(3):
    m = PointStamped()
    m.header.stamp = rospy.Time(k + 1)
    stream.publish(m)
time.sleep(1.0)  # one connection per topic: let the others arrive before the end topic
result.publish(String('done'))
time.sleep(1.0)
'''


class BagRecorder(unittest.TestCase):
    def setUp(self):
        self.tmp = tempfile.mkdtemp(prefix='dm_recorder_')
        self.port = free_port()
        self.env = dict(os.environ, ROS_HOME=self.tmp, ROS_MASTER_URI='http://localhost:%d' % self.port)
        self.procs = []

    def tearDown(self):
        # each process in a session of its own: a roslaunch that did not end takes its master
        # and nodes down with it
        for p in self.procs:
            stop_group(p)
        if os.environ.get('DM_KEEP_TEST_RUNS') is None:
            shutil.rmtree(self.tmp, ignore_errors=True)

    def start(self, args, name):
        log = open(os.path.join(self.tmp, name + '.log'), 'w')
        p = subprocess.Popen(args, stdout=log, stderr=subprocess.STDOUT, env=self.env, start_new_session=True)
        log.close()
        self.procs.append(p)
        return p

    def log(self, name):
        with open(os.path.join(self.tmp, name + '.log')) as f:
            return f.read()

    def test_a_latched_message_delivered_twice_is_recorded_once(self):
        bag = os.path.join(self.tmp, 'run.bag')
        # the recorder as the launch files load it (launch/components/recorder.launch), standalone:
        # the launch ends when the recorder has closed the bag on the end topic (`result`)
        launch = os.path.join(self.tmp, 'recorder.launch')
        with open(launch, 'w') as f:
            f.write('<launch><include file="$(find dem_mobility)/launch/components/recorder.launch">'
                    '<arg name="standalone" value="true"/><arg name="bag" value="%s"/>'
                    '<arg name="topics" value="[latched, plain, stream, result]"/>'
                    '<arg name="stream_topics" value="[stream]"/>'
                    '<arg name="latched_topics" value="[latched, result]"/></include></launch>' % bag)
        recorder = self.start(['roslaunch', '-p', str(self.port), launch], 'recorder')
        publisher = self.start([sys.executable, '-c', PUBLISHER], 'publisher')
        self.assertEqual(publisher.wait(120), 0, self.log('publisher'))
        deadline = time.time() + 30
        while recorder.poll() is None and time.time() < deadline:
            time.sleep(0.1)
        self.assertIsNotNone(recorder.poll(), 'the recorder did not end with the end topic:\n' + self.log('recorder'))
        with rosbag.Bag(bag) as b:
            got = {}
            for topic, m, _ in b.read_messages():
                got.setdefault(topic, []).append(getattr(m, 'data', None) if topic != '/stream'
                                                 else m.header.stamp.to_sec())
        self.assertEqual(got['/latched'], ['state 1', 'state 2'], self.log('recorder'))
        self.assertEqual(got['/plain'], ['same', 'same'])
        self.assertEqual(got['/stream'], [1.0, 2.0, 3.0])
        self.assertEqual(got['/result'], ['done'])


if __name__ == '__main__':
    unittest.main(verbosity=2)
