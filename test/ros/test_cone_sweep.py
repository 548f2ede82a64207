#!/usr/bin/env python3
"""The calibration sweep command on two tiny cone penetrometer cases (plus one it must refuse):
it runs them through roslaunch in parallel, keeps the good runs when one fails, and writes the
table, the fit and the plots; each run's bag holds the particles, the CI history and the result;
each run kept a checkpoint while it ran, and a run stopped through roslaunch and taken up from its
checkpoint reads the sweep's cone index to the last bit.

    python3 test/ros/test_cone_sweep.py      (in a sourced catkin workspace)
"""
import os
import signal
import subprocess
import sys
import tempfile
import time
import unittest

import rosbag
import yaml

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))


class ConeSweep(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.out = tempfile.mkdtemp(prefix='dm_cone_sweep_')
        cls.proc = subprocess.run(
            [sys.executable, '-m', 'dem_mobility_tools.calibration.cone_index', '--fidelity', 'tiny',  # dm-calibrate
             '--f', '0.5,8,41', '--mu', '0.1', '--jobs', '2', '--cloud-rate', '10', '--port', '11711',
             '--out', cls.out], stdout=subprocess.PIPE, stderr=subprocess.STDOUT, universal_newlines=True,
            timeout=900)
        print(cls.proc.stdout)

    def test_failed_run_reported_rest_kept(self):
        self.assertEqual(self.proc.returncode, 1)  # one run failed
        self.assertIn('FAILED', self.proc.stdout)
        with open(os.path.join(self.out, 'sweep.yaml')) as fh:
            sweep = yaml.safe_load(fh)
        runs = {r['f']: r for r in sweep['runs']}
        self.assertFalse(runs[41.0]['ok'])   # f above the 40 a soil takes
        self.assertIn('cohesion_factor', runs[41.0]['error'])
        self.assertTrue(runs[0.5]['ok'] and runs[8.0]['ok'])
        self.assertGreater(runs[8.0]['cone_index_psi'], runs[0.5]['cone_index_psi'])

    def test_table_and_fit(self):
        with open(os.path.join(ROOT, 'config', 'scenes', 'cone_penetrometer.yaml')) as fh:
            d = yaml.safe_load(fh)['levels']['tiny']['particle_diameter']
        with open(os.path.join(self.out, 'cone_index_mu0.1_d%g.yaml' % d)) as fh:
            cal = yaml.safe_load(fh)
        self.assertEqual(cal['fidelity'], 'tiny')
        self.assertEqual(cal['particle_diameter'], d)
        self.assertEqual(cal['provenance']['seeds'], [1])
        self.assertEqual(len(cal['cubic']), 4)
        rows = cal['table']
        self.assertGreaterEqual(len(rows), 2)
        for a, b in zip(rows, rows[1:]):
            self.assertLess(a[0], b[0])
            self.assertLess(a[1], b[1])
        # the table passes through the two runs (a line through two points)
        for f, ci in zip(cal['runs']['f'], cal['runs']['ci']):
            self.assertTrue(any(abs(r[0] - round(ci, 1)) < 0.06 and abs(r[1] - f) < 0.01 * f for r in rows),
                            (f, ci, rows))

    def test_plots(self):
        for name in ('ci_vs_time_mu0.1.png', 'ci_vs_f.png'):
            with open(os.path.join(self.out, name), 'rb') as fh:
                self.assertEqual(fh.read(8), b'\x89PNG\r\n\x1a\n', name)

    def test_bag_holds_particles_ci_history_and_result(self):
        bag_path = os.path.join(self.out, 'runs', 'mu0.1_f0.5_s1.bag')
        with open(bag_path[:-4] + '.result.yaml') as fh:
            res = yaml.safe_load(fh)
        counts, result, clouds = {}, None, 0
        with rosbag.Bag(bag_path) as bag:
            for topic, msg, _ in bag.read_messages():
                counts[topic] = counts.get(topic, 0) + 1
                if topic == '/cone/result':
                    result = msg
                if topic == '/cone/terrain/particles':
                    clouds += 1
                    self.assertEqual([f.name for f in msg.fields], ['x', 'y', 'z', 'plastic_strain'])
                    self.assertEqual(msg.width, res['particles'])
        self.assertEqual(counts.get('/cone/cone/penetration'), len(res['history']['t']))
        self.assertGreater(clouds, 10)
        self.assertGreater(counts.get('/cone/terrain/tools', 0), 10)
        self.assertEqual(counts.get('/cone/terrain/markers'), 1)
        self.assertIsNotNone(result)
        self.assertEqual(result.status, 'ok')
        self.assertAlmostEqual(result.cone_index_psi, res['cone_index_psi'], places=6)

    def test_runs_kept_checkpoints_and_removed_them_once_ended(self):
        for name in ('mu0.1_f0.5_s1', 'mu0.1_f8_s1'):
            with open(os.path.join(self.out, 'runs', name + '.result.yaml')) as fh:
                res = yaml.safe_load(fh)
            self.assertGreaterEqual(res['checkpoints_written'], 1, name)  # (the first as the run began)
        self.assertEqual(os.listdir(os.path.join(self.out, 'checkpoints')), [])

    def test_a_run_stopped_and_taken_up_from_its_checkpoint_reads_the_same_cone_index(self):
        with open(os.path.join(self.out, 'runs', 'mu0.1_f0.5_s1.result.yaml')) as fh:
            swept = yaml.safe_load(fh)
        out = tempfile.mkdtemp(prefix='dm_cone_restart_')
        ck, bag = os.path.join(out, 'run.ckpt'), os.path.join(out, 'run.bag')
        # the sweep's own arguments for the case (the checkpoint records them; a restart takes the same)
        args = ['fidelity:=tiny', 'cohesion_factor:=0.5', 'friction:=0.1', 'seed:=1', 'dem_threads:=1',
                'cloud_rate:=10', 'checkpoint:=' + ck, 'checkpoint_every:=1']

        def launch(*more):
            return subprocess.Popen(['roslaunch', '-p', '11791', 'dem_mobility', 'cone_penetrometer.launch',
                                     'bag:=' + bag] + args + list(more),
                                    stdout=subprocess.PIPE, stderr=subprocess.STDOUT, universal_newlines=True,
                                    env=dict(os.environ, ROS_MASTER_URI='http://127.0.0.1:11791'))
        p = launch()
        t0 = time.time()
        while not os.path.exists(ck) and time.time() - t0 < 120:
            time.sleep(0.1)
        time.sleep(1.0)
        p.send_signal(signal.SIGINT)
        text = p.communicate(timeout=120)[0]
        with open(bag[:-4] + '.result.yaml') as fh:
            stopped = yaml.safe_load(fh)
        self.assertEqual(stopped['status'], 'interrupted', text)
        self.assertEqual(stopped['checkpoint'], ck)
        self.assertTrue(os.path.isfile(ck))
        p = launch('restart:=' + ck)
        text = p.communicate(timeout=300)[0]
        with open(bag[:-4] + '.result.yaml') as fh:
            again = yaml.safe_load(fh)
        self.assertEqual(again['status'], 'ok', text)
        self.assertEqual(again['restarted_from'], ck)
        self.assertAlmostEqual(again['restarted_at'], stopped['checkpoint_at'], places=12)
        self.assertEqual(again['cone_index_psi'], swept['cone_index_psi'])  # bit for bit
        self.assertFalse(os.path.exists(ck))

    def test_the_rig_launch_files_put_overrides_among_the_scene_keys(self):
        # overrides:= (dm-calibrate --set) lands where the rig reads its scene's overrides, beside
        # the named ones, in both rig launch files; without it, nothing more is set
        for launch, ns, yaml_map, want in (
                ('cone_penetrometer.launch', 'cone', '{levels: {tiny: {container_diameter: 0.9}}, seed: 2}',
                 {'/cone/override/levels/tiny/container_diameter': 0.9, '/cone/override/seed': 2}),
                ('single_wheel.launch', 'wheel', '{carriage: {damping: 2000}}',
                 {'/wheel/override/carriage/damping': 2000})):
            for given in (yaml_map, None):
                args = ['roslaunch', '--dump-params', 'dem_mobility', launch] + (['overrides:=' + given] if given else [])
                out = subprocess.run(args, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, universal_newlines=True,
                                     timeout=60)
                self.assertEqual(out.returncode, 0, out.stdout)
                params = yaml.safe_load(out.stdout)
                for key, value in want.items():
                    if given:
                        self.assertEqual(params.get(key), value, (launch, key, out.stdout))
                    elif key.endswith('/seed'):
                        self.assertEqual(params.get(key), '', launch)  # (the named argument's empty default)
                    else:
                        self.assertNotIn(key, params, launch)


if __name__ == '__main__':
    unittest.main()
