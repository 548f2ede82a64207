#!/usr/bin/env python3
"""The speed-made-good map on ROS (issue 14): mobility_map.launch publishes a ROS map written by
dm_doe.maps.write_ros_map as nav_msgs/OccupancyGrid on /map, latched, with the cells map_server
would read from the same file: a no-go cell 100, one at the top speed 0, one at half of it 50,
one without a value -1; rows from the bottom; the resolution and origin of the YAML. A file that
cannot be read ends the launch with an error naming it.

    python3 test/ros/test_map_publisher.py   (after the catkin build; needs the workspace sourced)
"""
import os
import shutil
import subprocess
import sys
import tempfile
import time
import unittest

import numpy as np

from dem_mobility_tools.doe import maps
from dem_mobility_tools.runs import free_port
from launch_run import stop_group  # beside this file


class MapPublisher(unittest.TestCase):
    def setUp(self):
        self.tmp = tempfile.mkdtemp(prefix='dm_map_pub_')
        self.port = free_port()
        self.env = dict(os.environ, ROS_HOME=self.tmp, ROS_MASTER_URI='http://localhost:%d' % self.port)

    def tearDown(self):
        shutil.rmtree(self.tmp, ignore_errors=True)

    def launch(self, yaml_path):
        log = open(os.path.join(self.tmp, 'roslaunch.log'), 'w')
        p = subprocess.Popen(['roslaunch', '-p', str(self.port), 'dem_mobility', 'mobility_map.launch',
                              'map:=' + yaml_path], stdout=log, stderr=subprocess.STDOUT, env=self.env,
                             start_new_session=True)
        log.close()
        return p

    def stop(self, p):
        stop_group(p)

    def test_publishes_the_grid_map_server_would_read(self):
        # 3 rows x 4 columns (north up) of 20 m cells; top speed 20 m/s
        v = np.array([[0.0, 10.0, 20.0, np.nan],
                      [5.0, 10.0, 15.0, 20.0],
                      [np.nan, 0.0, 2.0, 19.0]])
        stem = os.path.join(self.tmp, 'smg_ros')
        maps.write_ros_map(stem, v, (500000.0, 20.0, 0.0, 4000000.0, 0.0, -20.0), 20.0)
        want = maps.load_ros_map(stem + '.yaml')['data']
        p = self.launch(stem + '.yaml')
        try:
            script = ('import rospy, sys\nfrom nav_msgs.msg import OccupancyGrid\nrospy.init_node("check", anonymous=True)\n'
                      'g = rospy.wait_for_message("/map", OccupancyGrid, timeout=60)\n'
                      'print(g.header.frame_id, g.info.width, g.info.height, g.info.resolution, '
                      'g.info.origin.position.x, g.info.origin.position.y, g.info.origin.orientation.w)\n'
                      'print(" ".join(str(x) for x in g.data))\n'
                      'from tf2_msgs.msg import TFMessage\n'
                      't = rospy.wait_for_message("/tf_static", TFMessage, timeout=60).transforms[0]\n'
                      'print(t.header.frame_id, t.child_frame_id, t.transform.translation.x, t.transform.translation.y)\n')
            q = subprocess.run([sys.executable, '-c', script], capture_output=True, text=True, env=self.env, timeout=90)
            self.assertEqual(q.returncode, 0, q.stderr)
            head, data, tf = q.stdout.strip().split('\n')[-3:]
            # the map frame in the raster's CRS: its lower-left corner (the geotransform's west
            # edge, and its north edge less 3 rows of 20 m)
            tf = tf.split()
            self.assertEqual(tf[:2], ['map_crs', 'map'])
            self.assertEqual([float(x) for x in tf[2:]], [500000.0, 4000000.0 - 60.0])
            f = head.split()
            self.assertEqual((f[0], int(f[1]), int(f[2])), ('map', 4, 3))
            self.assertEqual([float(x) for x in f[3:]], [20.0, 0.0, 0.0, 1.0])
            got = np.array([int(x) for x in data.split()]).reshape(3, 4)
            np.testing.assert_array_equal(got, want)
            # rows from the bottom: the grid's first row is the picture's last (south) row
            self.assertEqual(got[0].tolist()[0], -1)     # no value
            self.assertEqual(got[0].tolist()[1], 100)    # 0 m/s: no-go
            self.assertEqual(got[2].tolist()[2], 0)      # the top speed: free
            self.assertTrue(49 <= got[2][1] <= 51, got[2][1])  # half the top speed: half occupied
        finally:
            self.stop(p)

    def test_an_unreadable_map_ends_the_launch_naming_it(self):
        bad = os.path.join(self.tmp, 'missing_ros.yaml')
        p = self.launch(bad)
        try:
            p.wait(60)
        except subprocess.TimeoutExpired:
            self.stop(p)
            self.fail('the launch did not end')
        with open(os.path.join(self.tmp, 'roslaunch.log')) as fh:
            out = fh.read()
        self.assertIn('missing_ros.yaml: cannot read the map', out)


if __name__ == '__main__':
    t0 = time.time()
    unittest.main()
