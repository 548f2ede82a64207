"""dm-calibrate (dem_mobility_tools.calibration) without ROS: stand-in `roslaunch` and `rospack` commands on PATH
write the result files a cone run would; the sweep's lines, files and exit status are those the
end-to-end test (test/ros/test_cone_sweep.py) checks, --resume keeps the good runs, and with several
seeds the table holds each f's mean and scatter over the seeds, the particle diameter of the level
and its provenance.

    PYTHONPATH=python python3 -m unittest discover -s test/python -v      (from the repository root)
"""
import hashlib
import os
import shutil
import stat
import subprocess
import sys
import tempfile
import unittest

import yaml

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))

try:
    import matplotlib  # noqa: F401
    import numpy  # noqa: F401
    HAVE_PLOTS = True
except ImportError:
    HAVE_PLOTS = False

ROSLAUNCH = r'''#!%s
import os, sys, time, yaml
args = dict(a.split(':=', 1) for a in sys.argv[1:] if ':=' in a)
f, mu, seed, bag = float(args['cohesion_factor']), float(args['friction']), int(args['seed']), args['bag']
assert sys.argv[1] == '-p' and os.environ['ROS_MASTER_URI'].endswith(':' + sys.argv[2])
dt = float(args.get('time_step') or 1.2e-4)   # (the tiny level's step unless one is given)
ck, restart = args.get('checkpoint', ''), args.get('restart', '')
with open(os.path.join(os.path.dirname(bag), 'calls'), 'a') as fh:
    fh.write('%%g %%g %%s %%d %%g %%s\n' %% (f, mu, sys.argv[2], seed, dt, restart or '-'))
if args.get('overrides'):
    with open(os.path.join(os.path.dirname(bag), 'overrides'), 'a') as fh:
        fh.write(args['overrides'] + '\n')
res = bag[:-4] + '.result.yaml'
# as the rig nodelet: a checkpoint it cannot take up fails the run naming it; one of this run is
# taken up; the run's checkpoint is written as it begins, its bag as it goes
if restart and open(restart).read().startswith('refuse'):
    with open(res, 'w') as fh:
        yaml.safe_dump({'status': 'error', 'error': '%%s: checkpoint of the run of x: it was written by another '
                                                    'build' %% restart}, fh)
    sys.exit(1)
if ck:
    open(ck, 'w').write('the state of %%s' %% bag)
open(bag, 'w').write('bag from %%s' %% ('the restart' if restart else 'the start'))
print('[ INFO] terrain: progress: t = 0.1 s', flush=True)
time.sleep(60 if f == 7 and not restart else 0.2)   # (f 7: a run still going when the sweep is interrupted)
if f > 15:
    with open(res, 'w') as fh:
        yaml.safe_dump({'status': 'error', 'error': 'parameter cohesion_factor: %%g is out of range' %% f}, fh)
    sys.exit(1)
ci = 30 + 20 * f + 2 * (seed - 1)   # seeds 1, 2, 3: mean 30 + 20 f + 2, sample std 2
if ck:
    os.remove(ck)   # (a run that ended: its result is what remains)
with open(res, 'w') as fh:
    yaml.safe_dump({'fidelity': args['fidelity'], 'cohesion_factor': f, 'friction': mu, 'seed': seed, 'time_step': dt,
                    'cone_index_psi': ci,
                    'window_samples': 4, 'wall_time': 1.5, 'error': '',
                    'history': {'t': [0.0, 0.5, 1.0], 'cone_index_psi': [0.0, ci / 2, ci]}}, fh)
''' % sys.executable


@unittest.skipUnless(HAVE_PLOTS, 'needs python3-numpy and python3-matplotlib')
class CalibrationSweepWithoutRos(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.tmp = tempfile.mkdtemp(prefix='dm_calibrate_test_')
        bin_dir = os.path.join(cls.tmp, 'bin')
        os.makedirs(bin_dir)
        for name, text in (('roslaunch', ROSLAUNCH), ('rospack', '#!/bin/sh\necho /stand-in/dem_mobility\n')):
            p = os.path.join(bin_dir, name)
            with open(p, 'w') as fh:
                fh.write(text)
            os.chmod(p, os.stat(p).st_mode | stat.S_IXUSR)
        cls.env = dict(os.environ, PATH=bin_dir + os.pathsep + os.environ.get('PATH', ''), MPLBACKEND='Agg')
        cls.out = os.path.join(cls.tmp, 'out')
        cls.first = cls.sweep('0.5,8,20')
        with open(os.path.join(cls.out, 'sweep.yaml')) as fh:
            cls.first_summary = yaml.safe_load(fh)
        os.remove(os.path.join(cls.out, 'runs', 'calls'))
        cls.second = cls.sweep('0.5,8,20,3', '--resume')
        # three seeds per f, against a finest level's runs, installed into a directory
        cls.seeds_out = os.path.join(cls.tmp, 'seeds')
        cls.install = os.path.join(cls.tmp, 'installed')
        os.makedirs(cls.install)
        cls.finest = os.path.join(cls.tmp, 'finest.yaml')
        with open(cls.finest, 'w') as fh:
            # the stand-in's CI is 30 + 20 f + 2 (mean over the seeds): the finest level reads 10 % below at f = 1
            yaml.safe_dump({'level': 'medium', 'friction': 0.1, 'particle_diameter': 0.05, 'source': 'a test',
                            'points': {'f': [1.0], 'ci': [52.0 / 1.1]}}, fh)
        cls.seeded = cls.sweep('0.5,1,3', '--seeds', '1,2,3', '--seeds-at', '3=1,2,4', '--time-step-at', '3=6e-5', '--jobs', '1',
                               '--finest', cls.finest, '--install', cls.install, '--note', 'a note',
                               out=cls.seeds_out)
        with open(os.path.join(ROOT, 'config', 'scenes', 'cone_penetrometer.yaml')) as fh:
            cls.tiny = yaml.safe_load(fh)['levels']['tiny']

    @classmethod
    def tearDownClass(cls):
        shutil.rmtree(cls.tmp, True)

    @classmethod
    def sweep(cls, f, *more, out=None):
        return subprocess.run(
            [sys.executable, '-m', 'dem_mobility_tools.calibration.cone_index', '--fidelity', 'tiny',
             '--f', f, '--mu', '0.1', '--jobs', '2', '--cloud-rate', '10', '--port', '11711', '--out', out or cls.out]
            + list(more), stdout=subprocess.PIPE, stderr=subprocess.STDOUT, universal_newlines=True,
            env=cls.env, timeout=300)

    def test_failed_run_reported_rest_kept(self):
        self.assertEqual(self.first.returncode, 1, self.first.stdout)
        self.assertIn('FAILED', self.first.stdout)
        self.assertIn('sweep: 3 runs (f 0.5,8,20 x mu 0.1 x seeds 1), level tiny, 2 at a time\n', self.first.stdout)
        self.assertRegex(self.first.stdout, r'\[ +\d+ s\] done   mu0.1_f8_s1    CI 190.0 psi \(\d+ s\)  \[\d/3\]')
        self.assertIn('  failed: mu0.1_f20_s1: parameter cohesion_factor: 20 is out of range', self.first.stdout)
        sweep = self.first_summary
        self.assertEqual(list(sweep), ['fidelity', 'wall_time', 'jobs', 'seeds', 'runs'])
        self.assertEqual((sweep['fidelity'], sweep['jobs'], sweep['seeds']), ('tiny', 2, [1]))
        runs = {r['f']: r for r in sweep['runs']}
        self.assertEqual(list(runs[0.5]), ['f', 'mu', 'seed', 'ok', 'cone_index_psi', 'wall_time', 'error', 'bag'])
        self.assertFalse(runs[20.0]['ok'])
        self.assertIsNone(runs[20.0]['cone_index_psi'])
        self.assertIn('cohesion_factor', runs[20.0]['error'])
        self.assertTrue(runs[0.5]['ok'] and runs[8.0]['ok'])
        self.assertGreater(runs[8.0]['cone_index_psi'], runs[0.5]['cone_index_psi'])
        self.assertEqual(runs[0.5]['bag'], os.path.join(self.out, 'runs', 'mu0.1_f0.5_s1.bag'))

    def test_table_and_plots(self):
        with open(os.path.join(self.out, 'cone_index_mu0.1_d%g.yaml' % self.tiny['particle_diameter'])) as fh:
            cal = yaml.safe_load(fh)
        self.assertEqual(cal['fidelity'], 'tiny')
        self.assertEqual(len(cal['cubic']), 4)
        self.assertEqual(cal['runs'], {'f': [0.5, 3.0, 8.0], 'seed': [1, 1, 1], 'ci': [40.0, 90.0, 190.0]})
        # one seed per f: the points hold the runs and no scatter
        self.assertEqual(cal['points'], {'f': [0.5, 3.0, 8.0], 'ci_mean': [40.0, 90.0, 190.0], 'seeds': [1, 1, 1]})
        for name in ('ci_vs_time_mu0.1.png', 'ci_vs_f.png'):
            with open(os.path.join(self.out, name), 'rb') as fh:
                self.assertEqual(fh.read(8), b'\x89PNG\r\n\x1a\n', name)

    def test_resume_keeps_good_runs(self):
        out = self.second.stdout
        self.assertEqual(self.second.returncode, 1, out)
        self.assertIn('kept   mu0.1_f0.5_s1  CI 40.0 psi (from %s)' % os.path.join(self.out, 'runs', 'mu0.1_f0.5_s1.result.yaml'), out)
        self.assertIn('kept   mu0.1_f8_s1    CI 190.0 psi', out)
        with open(os.path.join(self.out, 'runs', 'calls')) as fh:
            calls = [line.split() for line in fh]
        self.assertEqual(sorted(c[0] for c in calls), ['20', '3'])
        self.assertEqual(sorted(c[2] for c in calls), ['11711', '11713'])
        self.assertRegex(out, r'\[4/4\]')
        with open(os.path.join(self.out, 'sweep.yaml')) as fh:
            runs = {r['f']: r for r in yaml.safe_load(fh)['runs']}
        self.assertEqual(runs[0.5]['wall_time'], 1.5)  # a kept run's own wall time
        self.assertTrue(runs[3.0]['ok'])
        self.assertFalse(runs[20.0]['ok'])

    def test_seeds_give_each_point_its_mean_and_scatter(self):
        self.assertEqual(self.seeded.returncode, 0, self.seeded.stdout)
        self.assertIn('x seeds 1,2,3), level tiny, 1 at a time', self.seeded.stdout)
        with open(os.path.join(self.seeds_out, 'runs', 'calls')) as fh:
            calls = sorted((float(c[0]), int(c[3])) for c in (line.split() for line in fh))
        cases = [(f, s) for f in (0.5, 1.0) for s in (1, 2, 3)] + [(3.0, s) for s in (1, 2, 4)]  # --seeds-at 3=1,2,4
        self.assertEqual(calls, cases)
        # --time-step-at 3=6e-5: the runs at f 3 get that step, the others the level's
        with open(os.path.join(self.seeds_out, 'runs', 'calls')) as fh:
            steps = {float(c[0]): float(c[4]) for c in (line.split() for line in fh)}
        self.assertEqual(steps, {0.5: 1.2e-4, 1.0: 1.2e-4, 3.0: 6e-5})
        name = 'cone_index_mu0.1_d%g.yaml' % self.tiny['particle_diameter']
        with open(os.path.join(self.seeds_out, name)) as fh:
            cal = yaml.safe_load(fh)
        self.assertEqual(cal['particle_diameter'], self.tiny['particle_diameter'])
        self.assertEqual(cal['friction'], 0.1)
        pts = cal['points']
        self.assertEqual(pts['f'], [0.5, 1.0, 3.0])
        self.assertEqual(pts['seeds'], [3, 3, 3])
        for f, mean, sd in zip(pts['f'], pts['ci_mean'], pts['ci_std']):
            # the stand-in's CI (30 + 20 f + 2 (seed - 1)), its mean and sample std over the seeds run
            ci = [30 + 20 * f + 2 * (s - 1) for s in ((1, 2, 4) if f == 3.0 else (1, 2, 3))]
            m = sum(ci) / 3.0
            self.assertAlmostEqual(mean, m, places=3)
            self.assertAlmostEqual(sd, (sum((c - m) ** 2 for c in ci) / 2.0) ** 0.5, places=3)
        self.assertEqual(sorted(zip(cal['runs']['f'], cal['runs']['seed'])), cases)
        # the table is fitted to the means: it passes through them at the ends
        self.assertAlmostEqual(cal['table'][0][0], round(pts['ci_mean'][0], 1), places=6)
        self.assertAlmostEqual(cal['table'][-1][0], round(pts['ci_mean'][-1], 1), places=6)

    def test_provenance(self):
        name = 'cone_index_mu0.1_d%g.yaml' % self.tiny['particle_diameter']
        with open(os.path.join(self.seeds_out, name)) as fh:
            prov = yaml.safe_load(fh)['provenance']
        head = subprocess.run(['git', '-C', ROOT, 'rev-parse', 'HEAD'], stdout=subprocess.PIPE,
                              universal_newlines=True).stdout.strip()
        self.assertTrue(prov['commit'].startswith(head), prov['commit'])
        self.assertEqual(prov['seeds'], [1, 2, 3, 4])
        self.assertEqual(prov['note'], 'a note')
        self.assertEqual(prov['soil_file'], 'config/soils/nominal_clay.yaml')
        with open(os.path.join(ROOT, 'config', 'soils', 'nominal_clay.yaml'), 'rb') as fh:
            self.assertEqual(prov['soil_sha256'], hashlib.sha256(fh.read()).hexdigest())
        self.assertEqual(prov['scene_file'], 'config/scenes/cone_penetrometer.yaml')
        self.assertRegex(str(prov['date']), r'^\d{4}-\d\d-\d\d$')
        for key in ('container_diameter', 'soil_depth', 'cone_speed', 'ci_window', 'time_step'):
            self.assertEqual(prov['conditions'][key], self.tiny[key], key)
        self.assertEqual(prov['conditions']['time_step_at'], {3.0: 6e-5})

    def test_error_vs_finest_and_install(self):
        name = 'cone_index_mu0.1_d%g.yaml' % self.tiny['particle_diameter']
        with open(os.path.join(self.install, name)) as fh:
            cal = yaml.safe_load(fh)   # --install DIR: the table under its own name
        err = cal['error_vs_finest']
        self.assertEqual(err['level'], 'medium')
        self.assertAlmostEqual(err['relative'], 0.1, places=2)
        self.assertIn('finest.yaml', err['note'])
        # without --finest the file says that only its own level was run, and gives no number
        with open(os.path.join(self.out, name)) as fh:
            err = yaml.safe_load(fh)['error_vs_finest']
        self.assertEqual(err['level'], 'tiny')
        self.assertNotIn('relative', err)
        self.assertIn('only this level', err['note'])

    def test_bad_input_is_refused_before_any_run(self):
        bad = os.path.join(self.tmp, 'bad_finest.yaml')
        with open(bad, 'w') as fh:
            yaml.safe_dump({'level': 'medium', 'friction': 0.1}, fh)   # no points
        for args, what in ((['--f', '1,2', '--finest', bad], 'not a finest-level file'),
                           (['--f', '1'], '--f needs two cohesion factors'),
                           (['--f', '1,2', '--finest', os.path.join(self.tmp, 'none.yaml')], 'No such file'),
                           (['--f', '1,2', '--seeds-at', '3=1,2'], '--seeds-at 3: not one of the --f values'),
                           (['--f', '1,2', '--time-step-at', '3=6e-5'], '--time-step-at 3: not one of the --f values'),
                           (['--f', '1,2', '--time-step-at', '2=0.01'], 'the time step must lie in (0, 1e-3] s'),
                           (['--f', '1,2', '--install', os.path.join(self.tmp, 'nowhere') + os.sep],
                            'nowhere/: no such directory')):
            out = os.path.join(self.tmp, 'refused_%d' % len(what))
            r = subprocess.run(
                [sys.executable, '-m', 'dem_mobility_tools.calibration.cone_index', '--fidelity', 'tiny',
                 '--mu', '0.1', '--port', '11711', '--out', out] + args, stdout=subprocess.PIPE,
                stderr=subprocess.STDOUT, universal_newlines=True, env=self.env, timeout=60)
            self.assertNotEqual(r.returncode, 0, r.stdout)
            self.assertIn(what, r.stdout)
            self.assertFalse(os.path.exists(os.path.join(out, 'runs', 'calls')), 'a run was made: ' + what)

    def test_a_finest_file_at_another_friction_is_not_compared_and_both_tables_are_written(self):
        out = os.path.join(self.tmp, 'two_mu')
        r = self.sweep('0.5,3', '--mu', '0.1,0.05', '--finest', self.finest, out=out)
        self.assertEqual(r.returncode, 0, r.stdout)
        d = self.tiny['particle_diameter']
        with open(os.path.join(out, 'cone_index_mu0.05_d%g.yaml' % d)) as fh:
            self.assertIn('not compared', yaml.safe_load(fh)['error_vs_finest']['note'])
        with open(os.path.join(out, 'cone_index_mu0.1_d%g.yaml' % d)) as fh:
            self.assertIn('relative', yaml.safe_load(fh)['error_vs_finest'])

    def test_a_finest_file_of_particles_no_smaller_is_not_compared(self):
        same = os.path.join(self.tmp, 'same_size.yaml')
        with open(same, 'w') as fh:
            yaml.safe_dump({'level': 'tiny', 'friction': 0.1, 'particle_diameter': self.tiny['particle_diameter'],
                            'points': {'f': [1.0], 'ci': [40.0]}}, fh)
        out = os.path.join(self.tmp, 'same_size')
        r = self.sweep('0.5,3', '--finest', same, out=out)
        self.assertEqual(r.returncode, 0, r.stdout)
        with open(os.path.join(out, 'cone_index_mu0.1_d%g.yaml' % self.tiny['particle_diameter'])) as fh:
            err = yaml.safe_load(fh)['error_vs_finest']
        self.assertNotIn('relative', err)
        self.assertIn('not finer than', err['note'])

    def test_an_interrupted_sweep_leaves_its_own_summary_not_an_old_one(self):
        import signal
        import time
        out = os.path.join(self.tmp, 'interrupted')
        os.makedirs(out)
        with open(os.path.join(out, 'sweep.yaml'), 'w') as fh:
            fh.write('stale: a summary of an earlier sweep\n')
        p = subprocess.Popen(
            [sys.executable, '-m', 'dem_mobility_tools.calibration.cone_index', '--fidelity', 'tiny',
             '--f', '0.5,7', '--mu', '0.1', '--jobs', '2', '--port', '11731', '--out', out],
            stdout=subprocess.PIPE, stderr=subprocess.STDOUT, universal_newlines=True, env=self.env)
        done = os.path.join(out, 'runs', 'mu0.1_f0.5_s1.result.yaml')
        t0 = time.time()
        while not (os.path.exists(done) and os.path.getsize(done) > 0) and time.time() - t0 < 60:
            time.sleep(0.2)
        time.sleep(1.5)  # (the sweep sees the first run end)
        # (SIGTERM, as a scheduler or `kill` sends it: a test run in the background, as CI runs
        # it, inherits SIGINT ignored)
        p.send_signal(signal.SIGTERM)
        text = p.communicate(timeout=60)[0]
        self.assertNotEqual(p.returncode, 0, text)
        self.assertIn('interrupted', text)
        with open(os.path.join(out, 'sweep.yaml')) as fh:
            s = yaml.safe_load(fh)
        self.assertNotIn('stale', s)
        self.assertTrue(s['interrupted'])
        runs = {r['f']: r for r in s['runs']}
        self.assertTrue(runs[0.5]['ok'], runs)
        self.assertFalse(runs[7.0]['ok'], runs)

    def test_a_resume_takes_a_stopped_run_up_from_its_checkpoint_and_runs_one_refused_afresh(self):
        import signal
        import time
        out = os.path.join(self.tmp, 'taken_up')
        runs, cks = os.path.join(out, 'runs'), os.path.join(out, 'checkpoints')
        p = subprocess.Popen(
            [sys.executable, '-m', 'dem_mobility_tools.calibration.cone_index', '--fidelity', 'tiny',
             '--f', '0.5,7', '--mu', '0.1', '--jobs', '2', '--port', '11741', '--out', out],
            stdout=subprocess.PIPE, stderr=subprocess.STDOUT, universal_newlines=True, env=self.env)
        done = os.path.join(runs, 'mu0.1_f0.5_s1.result.yaml')
        t0 = time.time()
        while not (os.path.exists(done) and os.path.getsize(done) > 0) and time.time() - t0 < 60:
            time.sleep(0.2)
        time.sleep(1.5)
        p.send_signal(signal.SIGTERM)
        text = p.communicate(timeout=60)[0]
        self.assertNotEqual(p.returncode, 0, text)
        ck = os.path.join(cks, 'mu0.1_f7_s1.ckpt')
        self.assertTrue(os.path.isfile(ck), text)                     # the stopped run's checkpoint
        self.assertFalse(os.path.exists(os.path.join(cks, 'mu0.1_f0.5_s1.ckpt')), text)  # (ended: removed)
        os.remove(os.path.join(runs, 'calls'))

        def calls():
            with open(os.path.join(runs, 'calls')) as fh:
                made = {float(c[0]): c[5] for c in (line.split() for line in fh)}
            os.remove(os.path.join(runs, 'calls'))
            return made

        # taken up from it: the bag of the part before is kept beside the new part's
        r = self.sweep('0.5,7', '--resume', out=out)
        self.assertEqual(r.returncode, 0, r.stdout)
        self.assertIn('mu0.1_f7_s1    taken up from its checkpoint %s' % ck, r.stdout)
        self.assertEqual(calls(), {7.0: ck})
        with open(os.path.join(runs, 'mu0.1_f7_s1.part1.bag')) as fh:
            self.assertEqual(fh.read(), 'bag from the start')
        with open(os.path.join(runs, 'mu0.1_f7_s1.bag')) as fh:
            self.assertEqual(fh.read(), 'bag from the restart')
        self.assertFalse(os.path.exists(ck))
        # a checkpoint the run refuses (another build's) is removed; the next resume runs it afresh
        stale = os.path.join(cks, 'mu0.1_f1_s1.ckpt')
        with open(stale, 'w') as fh:
            fh.write('refuse: written by another build')
        r = self.sweep('0.5,1,7', '--resume', out=out)
        self.assertEqual(r.returncode, 1, r.stdout)
        self.assertIn('mu0.1_f1_s1    its checkpoint was refused and is removed', r.stdout)
        self.assertFalse(os.path.exists(stale))
        self.assertEqual(calls(), {1.0: stale})
        r = self.sweep('0.5,1,7', '--resume', out=out)
        self.assertEqual(r.returncode, 0, r.stdout)
        self.assertEqual(calls(), {1.0: '-'})
        # a sweep started afresh takes up no checkpoint of an earlier one
        with open(stale, 'w') as fh:
            fh.write('the state of an earlier sweep')
        r = self.sweep('0.5,1', out=out)
        self.assertEqual(r.returncode, 0, r.stdout)
        self.assertEqual(calls(), {0.5: '-', 1.0: '-'})

    def test_no_table_runs_one_f_alone_and_refuses_what_needs_a_table(self):
        out = os.path.join(self.tmp, 'no_table')
        r = self.sweep('1', '--no-table', '--time-step-at', '1=6e-5', out=out)
        self.assertEqual(r.returncode, 0, r.stdout)
        with open(os.path.join(out, 'runs', 'mu0.1_f1_s1.result.yaml')) as fh:
            self.assertEqual(yaml.safe_load(fh)['time_step'], 6e-5)
        self.assertFalse([n for n in os.listdir(out) if n.startswith('cone_index_')], os.listdir(out))
        r = self.sweep('1', out=os.path.join(self.tmp, 'one_f'))
        self.assertNotEqual(r.returncode, 0, r.stdout)
        self.assertIn('--f needs two cohesion factors at least', r.stdout)
        r = self.sweep('1,2', '--no-table', '--install', self.tmp, out=os.path.join(self.tmp, 'no_install'))
        self.assertNotEqual(r.returncode, 0, r.stdout)
        self.assertIn('--no-table makes no table to --install', r.stdout)

    def test_set_passes_other_scene_keys_to_every_run_and_a_resume_checks_them(self):
        out = os.path.join(self.tmp, 'set')
        r = self.sweep('1', '--no-table', '--set', 'levels.tiny.container_diameter=0.9', '--set', 'pid.kp=2e8',
                       out=out)
        self.assertEqual(r.returncode, 0, r.stdout)
        with open(os.path.join(out, 'runs', 'overrides')) as fh:
            self.assertEqual(yaml.safe_load(fh.read()), {'levels': {'tiny': {'container_diameter': 0.9}},
                                                         'pid': {'kp': '2e8'}})  # (YAML 1.1: the scene reads it as 2e8)
        with open(os.path.join(out, 'sweep_options.yaml')) as fh:
            self.assertEqual(yaml.safe_load(fh)['--set'], ['levels.tiny.container_diameter=0.9', 'pid.kp=2e8'])
        # a resume with other keys, or none, is refused naming --set; a folder made before --set holds none
        for more in (['--set', 'levels.tiny.container_diameter=1.0'], []):
            r = self.sweep('1', '--no-table', '--resume', *more, out=out)
            self.assertNotEqual(r.returncode, 0, r.stdout)
            self.assertIn('holds runs made with --set', r.stdout)
        r = self.sweep('0.5,8', '--resume', '--set', 'levels.tiny.container_diameter=1.0')
        self.assertNotEqual(r.returncode, 0, r.stdout)
        self.assertIn('holds runs made with --set []', r.stdout)
        # the sweep's own keys, and what is no KEY=VALUE, are refused before any run
        for bad, said in (('seed=3', 'seed is set by the sweep itself'), ('levels..x=1', 'KEY=VALUE'),
                          ('container', 'KEY=VALUE')):
            r = self.sweep('1', '--no-table', '--set', bad, out=os.path.join(self.tmp, 'set_bad'))
            self.assertEqual(r.returncode, 2, r.stdout)
            self.assertIn(said, r.stdout)

    def test_a_resume_reruns_a_run_made_at_another_time_step(self):
        out = os.path.join(self.tmp, 'steps')

        def calls(*more):
            r = self.sweep('0.5,1', '--resume', *more, out=out)
            self.assertEqual(r.returncode, 0, r.stdout)
            path = os.path.join(out, 'runs', 'calls')
            made = []
            if os.path.exists(path):
                with open(path) as fh:
                    made = sorted((float(c[0]), float(c[4])) for c in (line.split() for line in fh))
                os.remove(path)
            return made

        self.assertEqual(calls('--time-step-at', '1=6e-5'), [(0.5, 1.2e-4), (1.0, 6e-5)])
        self.assertEqual(calls('--time-step-at', '1=6e-5'), [])             # the same runs: kept
        self.assertEqual(calls('--time-step-at', '1=5e-5'), [(1.0, 5e-5)])  # another step at f 1: rerun
        self.assertEqual(calls(), [(1.0, 1.2e-4)])                          # the level's step again

    def test_a_resume_at_another_level_is_refused_naming_it(self):
        # (the runs' own results would let a kept run through the f, mu and seed checks: the
        # level's conditions and the scene's and soil's files are kept in the folder)
        r = self.sweep('0.5,8', '--resume', '--fidelity', 'test')
        self.assertNotEqual(r.returncode, 0, r.stdout)
        self.assertIn('--resume: %s holds runs made with --fidelity tiny, not test' % self.out, r.stdout)


@unittest.skipUnless(HAVE_PLOTS, 'needs python3-numpy')
class TableThroughTheMeans(unittest.TestCase):
    def test_the_table_passes_through_every_mean_where_a_cubic_cannot(self):
        from dem_mobility_tools.calibration.cone_index import PAPER_TABLE, fit
        # means on the paper's CI values, bending as the measured curves do (steep, then flat)
        means = [(0.1, 30.0), (0.5, 50.0), (2.0, 80.0), (4.0, 100.0), (9.0, 150.0), (20.0, 200.0), (24.0, 242.0)]
        cubic, table, band, method, cubic_residual = fit(means, [c for c, _ in PAPER_TABLE])
        rows = dict((c, f) for c, f in table)
        for f, ci in means:
            self.assertAlmostEqual(rows[ci], f, places=9)
        self.assertEqual([c for c, _ in table], [30, 40, 50, 60, 70, 80, 100, 120, 150, 200, 242])
        self.assertTrue(all(b[1] > a[1] for a, b in zip(table, table[1:])))   # f rises with CI
        self.assertEqual(band, 0.0)             # every point on the table
        self.assertIn('PCHIP', method)
        self.assertEqual(len(cubic), 4)
        self.assertGreater(cubic_residual, 0.02)  # the paper's cubic misses some mean by more than 2 %


if __name__ == '__main__':
    unittest.main()
