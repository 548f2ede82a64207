"""dm-docs: the docs' generated tables match docs/data/, and a hand edit is caught."""
import contextlib
import io
import os
import re
import shutil
import tempfile
import unittest

from dem_mobility_tools.docsgen import make

ROOT = os.path.abspath(os.path.join(os.path.dirname(__file__), '..', '..'))


def run(argv):
    err = io.StringIO()
    with contextlib.redirect_stderr(err), contextlib.redirect_stdout(io.StringIO()):
        rc = make.main(argv)
    return rc, err.getvalue()


class RepoCopy(unittest.TestCase):
    """A temporary copy of the parts of the checkout the generator reads."""

    def setUp(self):
        self.tmp = tempfile.mkdtemp(prefix='docsgen-')
        for d in ('docs', 'launch'):
            shutil.copytree(os.path.join(ROOT, d), os.path.join(self.tmp, d),
                            ignore=shutil.ignore_patterns('*.png'))

    def tearDown(self):
        shutil.rmtree(self.tmp)

    def edit(self, rel, old, new):
        path = os.path.join(self.tmp, rel)
        with open(path) as f:
            text = f.read()
        self.assertEqual(text.count(old), 1, '{!r} not once in {}'.format(old, rel))
        with open(path, 'w') as f:
            f.write(text.replace(old, new))

    def line_of(self, rel, pattern, after=''):
        """The first line of `rel` (after the text `after`) that matches `pattern`: what a test edits,
        whatever figures the docs hold now."""
        with open(os.path.join(self.tmp, rel)) as f:
            text = f.read()
        start = text.index(after) if after else 0
        m = re.search(pattern, text[start:], re.M)
        self.assertIsNotNone(m, '{}: no line {!r}'.format(rel, pattern))
        return m.group(0)


class TheRepo(unittest.TestCase):
    def test_docs_are_what_the_data_generate(self):
        rc, err = run(['--root', ROOT, '--check'])
        self.assertEqual(rc, 0, err)

    def test_every_data_file_has_its_provenance(self):
        tables = make.load_tables(ROOT)
        self.assertTrue(tables)
        for t in tables.values():
            for key in ('commit', 'machine', 'date', 'command'):
                self.assertTrue(t['provenance'][key].strip(), '{}: provenance {}'.format(t['_file'], key))


class HandEdits(RepoCopy):
    def dem_step_row(self):
        """The first row of dem_step's generated table (bed (a)'s rates)."""
        return self.line_of('docs/performance.md', r'^\| bed \(a\).*$', '<!-- generated: performance/dem_step -->')

    def test_a_hand_edited_table_fails_the_check_naming_doc_and_table(self):
        row = self.dem_step_row()
        self.edit('docs/performance.md', row, row.replace('M particle-steps/s', 'M particle-steps/s, edited'))
        rc, err = run(['--root', self.tmp, '--check'])
        self.assertEqual(rc, 1)
        self.assertIn('docs/performance.md: performance/dem_step', err)

    def test_regenerating_undoes_the_edit(self):
        row = self.dem_step_row()
        self.edit('docs/performance.md', row, row.replace('M particle-steps/s', 'M particle-steps/s, edited'))
        self.assertEqual(run(['--root', self.tmp])[0], 0)
        self.assertEqual(run(['--root', self.tmp, '--check'])[0], 0)
        with open(os.path.join(self.tmp, 'docs', 'performance.md')) as f, \
                open(os.path.join(ROOT, 'docs', 'performance.md')) as g:
            self.assertEqual(f.read(), g.read())

    def test_a_hand_edited_launch_page_fails_the_check(self):
        self.edit('docs/launch.md', '| `rate` | `1.0` |', '| `rate` | `2.0` |')
        rc, err = run(['--root', self.tmp, '--check'])
        self.assertEqual(rc, 1)
        self.assertIn('docs/launch.md', err)

    def test_a_launch_argument_without_doc_is_refused_naming_file_and_argument(self):
        self.edit('launch/replay.launch', ' doc="playback rate"', '')
        rc, err = run(['--root', self.tmp, '--check'])
        self.assertEqual(rc, 1)
        self.assertIn('launch/replay.launch: arg rate: no doc=', err)

    def test_a_marker_without_data_is_refused(self):
        with open(os.path.join(self.tmp, 'docs', 'performance.md'), 'a') as f:
            f.write('\n<!-- generated: performance/nothing -->\n<!-- end generated -->\n')
        rc, err = run(['--root', self.tmp, '--check'])
        self.assertEqual(rc, 1)
        self.assertIn('performance/nothing', err)

    def test_a_data_file_without_provenance_is_refused_naming_file_and_key(self):
        self.edit('docs/data/performance-doe_map.yaml', self.line_of('docs/data/performance-doe_map.yaml', r'^  commit: .*\n'), '')
        rc, err = run(['--root', self.tmp, '--check'])
        self.assertEqual(rc, 1)
        self.assertIn('docs/data/performance-doe_map.yaml: provenance: missing key commit', err)


class Figures(RepoCopy):
    """--figures redraws every plot of committed data, each from its file."""

    def setUp(self):
        super().setUp()
        shutil.copytree(os.path.join(ROOT, 'config', 'calibration'), os.path.join(self.tmp, 'config', 'calibration'))

    def test_every_plot_is_drawn_and_is_a_png_the_docs_show(self):
        rc, err = run(['--root', self.tmp, '--figures'])
        self.assertEqual(rc, 0, err)
        from dem_mobility_tools.docsgen import figures
        with contextlib.redirect_stdout(io.StringIO()):
            drawn = figures.draw_all(self.tmp)
        # the fixed plots and one CI-versus-f plot per installed mu 0.1 table
        tables = [f for f in os.listdir(os.path.join(ROOT, 'config', 'calibration')) if f.startswith('cone_index_mu0.1_d')]
        self.assertEqual(len(drawn), 6 + len(tables))
        docs = ''.join(open(os.path.join(ROOT, 'docs', f)).read()
                       for f in os.listdir(os.path.join(ROOT, 'docs')) if f.endswith('.md'))
        for path in drawn:
            with open(path, 'rb') as f:
                self.assertEqual(f.read(8), b'\x89PNG\r\n\x1a\n', path)
            self.assertIn('(' + os.path.basename(path) + ')', docs, 'no doc shows ' + path)

    def test_a_broken_data_file_is_refused_naming_it(self):
        self.edit('docs/data/single-wheel-slip-sweep.yaml', "dp_w_std: 0.206 (0.065)", "dp_w_std: about a fifth")
        from dem_mobility_tools.docsgen import figures
        with self.assertRaises(make.DocsError) as e:
            figures.wheel_sweep(self.tmp)
        self.assertIn('docs/data/single-wheel-slip-sweep.yaml: dp_w_std', str(e.exception))


class Status(unittest.TestCase):
    """met / not met follow from the goal and the figure, for every value of it."""

    def status(self, **row):
        row.setdefault('what', 'x')
        return make._status(row, 'test')[1]

    def test_bounds(self):
        self.assertEqual(self.status(value=1.0, goal={'min': 1.0}), 'met')
        self.assertEqual(self.status(value=0.99, goal={'min': 1.0}), '**not met**')
        self.assertEqual(self.status(value=5.0, goal={'max': 5}), 'met')
        self.assertEqual(self.status(value=5.01, goal={'max': 5}), '**not met**')

    def test_a_range_meets_the_goal_only_if_all_of_it_does(self):
        self.assertEqual(self.status(range=[3.4, 4.7], goal={'max': 5}), 'met')
        self.assertEqual(self.status(range=[3.4, 5.1], goal={'max': 5}), '**not met**')
        self.assertEqual(self.status(value=[1.95, 1.89], goal={'min': 1.9}), '**not met**')

    def test_no_goal_no_status(self):
        self.assertEqual(self.status(value=3), '')

    def test_a_text_value_needs_a_figure_to_compare(self):
        with self.assertRaises(make.DocsError):
            self.status(value='12-14 us', goal={'max': 15})


if __name__ == '__main__':
    unittest.main()


class ConeData(RepoCopy):
    """dm-docs-cone: a table's runs become the seeds table (mean and std recomputed from the runs
    agree with the table's points) and its rows the CI -> f table, and dm-docs renders them."""

    def test_seeds_and_table_from_a_calibration_table(self):
        import yaml
        from dem_mobility_tools.docsgen import cone_data
        runs = {0.5: [10.0, 12.0, 14.0], 4.0: [100.0, 90.0, 110.0]}
        f_list, seeds, ci = [], [], []
        for f, cis in runs.items():
            for s, c in enumerate(cis, 1):
                f_list.append(f)
                seeds.append(s)
                ci.append(c)
        table = {'particle_diameter': 0.07, 'friction': 0.1, 'fidelity': 'x_cal',
                 'table': [[12.0, 0.5], [50.0, 2.0], [100.0, 4.0]],
                 'points': {'f': [0.5, 4.0], 'ci_mean': [12.0, 100.0], 'ci_std': [2.0, 10.0], 'seeds': [3, 3]},
                 'runs': {'f': f_list, 'seed': seeds, 'ci': ci},
                 'provenance': {'commit': '0123456789', 'date': '2026-12-07', 'conditions': {'cone_speed': 0.1}}}
        path = os.path.join(self.tmp, 'cone_index_mu0.1_d0.07.yaml')
        with open(path, 'w') as f:
            yaml.safe_dump(table, f)
        seeds_path, table_path = cone_data.write(self.tmp, path, 'a test machine', 'dm-calibrate ...')
        with open(seeds_path) as f:
            s = yaml.safe_load(f)
        self.assertEqual(s['table'], 'cone/seeds_d0.07')
        self.assertEqual([r['cohesion_factor'] for r in s['rows']], [0.5, 4.0])
        row = s['rows'][1]
        got = [float(row['seed_%d' % k]) for k in (1, 2, 3)]
        self.assertEqual(got, [100.0, 90.0, 110.0])
        self.assertEqual(row['mean'], '**100.0**')
        self.assertEqual(row['relative'], '10.0 %')  # std 10 of mean 100
        with open(table_path) as f:
            t = yaml.safe_load(f)
        self.assertEqual([c['title'] for c in t['columns']], ['CI [psi]', '12', '50', '100'])
        self.assertEqual(float(t['rows'][0]['50']), 2.0)
        # dm-docs renders both into a doc that names them
        with open(os.path.join(self.tmp, 'docs', 'cone-penetrometer.md'), 'a') as f:
            f.write('\n<!-- generated: cone/seeds_d0.07 -->\n<!-- end generated -->\n'
                    '<!-- generated: cone/table_d0.07 -->\n<!-- end generated -->\n')
        rc, err = run(['--root', self.tmp])
        self.assertEqual(rc, 0, err)
        with open(os.path.join(self.tmp, 'docs', 'cone-penetrometer.md')) as f:
            text = f.read()
        self.assertIn('| 4.0 | 100.00 | 90.00 | 110.00 | **100.0** | 10.0 | 10.0 % |', text)
        # a table whose f 4 ran at a step of its own: the seeds table gives each f its step
        table['provenance']['conditions'].update(time_step=8e-5, time_step_at={4.0: 6e-5})
        with open(path, 'w') as f:
            yaml.safe_dump(table, f)
        seeds_path, _ = cone_data.write(self.tmp, path, 'a test machine', 'dm-calibrate ...')
        with open(seeds_path) as f:
            s = yaml.safe_load(f)
        self.assertEqual([c['title'] for c in s['columns']][:3], ['f', 'dt [s]', 'seed 1'])
        self.assertEqual([r['time_step'] for r in s['rows']], ['8e-05', '6e-05'])


    def test_f_per_paper_ci_per_size(self):
        import yaml
        from dem_mobility_tools.docsgen import cone_data, make
        folder = os.path.join(self.tmp, 'tables')
        os.makedirs(folder)

        def table(d, rows):
            t = {'particle_diameter': d, 'friction': 0.1, 'fidelity': 'd%g_cal' % d, 'table': rows, 'runs': {},
                 'points': {}, 'provenance': {'commit': 'abcdef123', 'date': '2026-12-07'}}
            with open(os.path.join(folder, 'cone_index_mu0.1_d%g.yaml' % d), 'w') as f:
                yaml.safe_dump(t, f)
        # reaches from below 30 to 150 psi (rows at table 3's CIs inside); the other starts above 30
        table(0.1, [[25.0, 0.05], [30.0, 0.0787], [40.0, 0.2], [50.0, 0.35], [60.0, 0.6], [70.0, 0.9], [80.0, 1.1],
                    [100.0, 1.5], [120.0, 1.9], [150.0, 2.5], [160.0, 2.8]])
        table(0.07, [[33.0, 0.05], [40.0, 0.16], [50.0, 0.5], [60.0, 1.0], [70.0, 1.3], [80.0, 1.5], [100.0, 1.9],
                     [120.0, 2.3], [150.0, 2.9], [200.0, 4.1], [242.0, 5.25], [300.0, 7.0]])
        with open(cone_data.write_sizes(self.tmp, folder, 'a test machine')) as f:
            s = yaml.safe_load(f)
        self.assertEqual(s['table'], 'cone/sizes')
        self.assertEqual([r['source'] for r in s['rows']],
                         ['paper (0.03 m, table 3)', '0.07 m (`d0.07_cal`)', '0.1 m (`d0.1_cal`)'])
        paper, d07, d1 = s['rows']
        self.assertEqual((paper['ci_30'], paper['ci_242']), ('0.06', '12.1'))
        self.assertEqual(d07['ci_30'], '— (33.0 at f 0.05)')   # below the table's least CI
        self.assertEqual(d07['ci_242'], '5.25')
        self.assertEqual(d1['ci_30'], '0.079')
        self.assertEqual(d1['ci_200'], '— (160.0 at f 2.8)')   # above its largest
        # a CI inside the range without its row is an error, not a guess
        table(0.1, [[25.0, 0.05], [40.0, 0.2], [160.0, 2.8]])
        with self.assertRaises(make.DocsError):
            cone_data.write_sizes(self.tmp, folder, 'a test machine')

class WheelData(RepoCopy):
    """dm-docs-wheel: the kept runs of a calibrated-wheel sweep become a row per CI and case, with
    the references of wheel_numerics at the same CI, tire and load, and the seeds' mean and std."""

    RUN = {'kind': 'single_wheel', 'status': 'ok', 'fidelity': 'coarse', 'particle_diameter': 0.06,
           'cohesion_factor': 1.5, 'requested_cone_index_psi': 100, 'tire_radius': 0.485, 'tire_width': 0.254,
           'load': 12066.3, 'load_mass': 1230, 'carriage_speed': 1, 'window': [0.8, 2.2], 'particles': 9653,
           'wall_time': 120.0, 'kept_from_commit': '0123456789abc'}

    def kept(self, name, seed, runs):
        import yaml
        folder = os.path.join(self.tmp, name)
        os.makedirs(folder)
        with open(os.path.join(folder, 'sweep_options.yaml'), 'w') as f:
            yaml.safe_dump({'--seed': seed}, f)
        for case, extra in runs.items():
            with open(os.path.join(folder, case + '.yaml'), 'w') as f:
                yaml.safe_dump(dict(self.RUN, **extra), f)
        return folder

    def test_rows_references_and_seeds(self):
        import yaml
        from dem_mobility_tools.docsgen import wheel_data
        from dem_mobility_tools.terramechanics import wheel_numerics as wn
        s1 = self.kept('s1', 1, {
            'ci100_slip0.2': dict(drive='slip', slip_commanded=0.2, slip=0.2, dp_over_w=0.30, dp_over_w_std=0.05,
                                  torque_over_wr=0.4, torque_over_wr_std=0.06, sinkage=0.05),
            'ci100_towed': dict(drive='towed', slip=-0.05, dp_over_w=-0.15, dp_over_w_std=0.04, sinkage=0.05)})
        s2 = self.kept('s2', 2, {'ci100_slip0.2': dict(drive='slip', slip_commanded=0.2, slip=0.2, dp_over_w=0.20)})
        path = wheel_data.write(self.tmp, [s1, s2], 'a test machine', '2026-12-07')
        with open(path) as f:
            t = yaml.safe_load(f)
        self.assertEqual(t['table'], 'single-wheel/calibrated')
        self.assertEqual([r['case'] for r in t['rows']], ['towed (slip -0.050)', 'slip 0.2'])
        towed, driven = t['rows']
        self.assertEqual(driven['dp_w'], '0.300 (0.050)')
        self.assertEqual(driven['dp_w_seeds'], '0.250 (0.071; 2 seeds)')  # mean 0.25, sample std 0.0707
        self.assertEqual(towed['dp_w_seeds'], '—')  # one seed only
        b, d, w = 0.254, 0.97, 12066.3
        v = wn.vti(100, b, d, w, 0.0)
        self.assertAlmostEqual(float(driven['vti_dp_w']), wn.vti_dp_over_w(0.2, v['nc'], b, d, v['ssp']), places=3)
        self.assertAlmostEqual(float(driven['brixius_dp_w']), wn.brixius(0.2, 100, b, d, w)[2], places=3)
        self.assertAlmostEqual(float(towed['vti_dp_w']), -v['mr_towed'], places=3)
        self.assertIn('seed 1', t['provenance']['recorded_in'])
        # the CI at which VTI pulls the seeds' mean (0.25 at 20 % slip): VTI's pull there is 0.25
        eq = float(driven['vti_ci'])
        v = wn.vti(eq, b, d, w, 0.0)
        self.assertAlmostEqual(wn.vti_dp_over_w(0.2, v['nc'], b, d, v['ssp']), 0.25, places=2)
        self.assertEqual(towed['vti_ci'], '—')
        # an empty folder is refused, naming it
        empty = os.path.join(self.tmp, 'empty')
        os.makedirs(empty)
        with self.assertRaises(make.DocsError) as e:
            wheel_data.write(self.tmp, [empty], 'm', 'd')
        self.assertIn(empty, str(e.exception))


class ConeSetupData(RepoCopy):
    """dm-docs-cone-setup: a set-up folder's runs against the table's runs of the same f and seed, the
    table's scatter over its seeds, the seeds' means of a knob run at several; what cannot be compared is
    refused naming it."""

    RUN = {'kind': 'cone_penetrometer', 'status': 'ok', 'fidelity': 'coarse_cal', 'particle_diameter': 0.06,
           'friction': 0.1, 'container_diameter': 1.2, 'soil_depth': 1.6, 'cone_speed': 0.1,
           'kept_from_commit': 'abc1234'}

    def kept(self, name, runs, options):
        import yaml
        folder = os.path.join(self.tmp, name)
        os.makedirs(folder)
        with open(os.path.join(folder, 'sweep_options.yaml'), 'w') as f:
            yaml.safe_dump(dict({'--fidelity': 'coarse_cal'}, **options), f)
        for (f_, seed), ci in runs.items():
            with open(os.path.join(folder, 'mu0.1_f%g_s%d.yaml' % (f_, seed)), 'w') as f:
                yaml.safe_dump(dict(self.RUN, cohesion_factor=f_, seed=seed, cone_index_psi=ci), f)
        return folder

    SETUP = {'container_diameter': 1.2, 'soil_depth': 1.6, 'cone_speed': 0.1, 'ci_window': [0.78, 0.92]}

    def test_rows_against_the_same_seed(self):
        import yaml
        from dem_mobility_tools.docsgen import cone_setup
        table = self.kept('table', {(1, 1): 60.0, (1, 2): 66.0, (1, 3): 63.0, (5, 1): 230.0, (5, 2): 240.0},
                          {'conditions': self.SETUP})
        wide = self.kept('wide', {(1, 1): 63.0, (5, 1): 220.0, (5, 2): 252.0},
                         {'conditions': self.SETUP, '--set': ['levels.coarse_cal.container_diameter=2.0']})
        with open(cone_setup.write(self.tmp, table, [wide], 'a test machine')) as f:
            t = yaml.safe_load(f)
        self.assertEqual(t['table'], 'cone/setup_d0.06')
        r = t['rows']
        self.assertEqual([(x['f'], x['seeds'], x['ci'], x['change']) for x in r],
                         [(1, '1, 2, 3', 63.0, '—'), (1, '1', 63.0, '+5.0 %'),
                          (5, '1, 2', 235.0, '—'), (5, '1', 220.0, '-4.3 %'), (5, '2', 252.0, '+5.0 %'),
                          (5, '1, 2', 236.0, '+0.4 %')])
        self.assertEqual(r[1]['what'], 'container 2.0 m (1.2)')
        self.assertEqual(r[0]['seed_scatter'], '3.0 (4.8 %; 3 seeds: 60.0, 66.0, 63.0)')
        # another table's runs of the level, made in another set-up (no --set): what differs is named,
        # the table's value in brackets; the block's name as asked
        older = self.kept('older', {(1, 1): 57.0}, {'conditions': dict(self.SETUP, container_diameter=2.0,
                                                                           ci_window=[0.78, 1.0])})
        path = cone_setup.write(self.tmp, table, [older], 'm', name='setup_d0.06_before')
        self.assertTrue(path.endswith('cone-setup-d0.06-before.yaml'), path)
        with open(path) as f:
            t = yaml.safe_load(f)
        self.assertEqual(t['table'], 'cone/setup_d0.06_before')
        self.assertEqual(t['rows'][1]['what'], 'CI window 0.78-1.0 m (0.78-0.92); container 2.0 m (1.2)')
        self.assertEqual(t['rows'][1]['change'], '-5.0 %')
        # a seed the table does not hold, a folder of the table's own set-up, another level: refused, naming it
        for bad, said in ((self.kept('s9', {(1, 9): 60.0}, {'--set': ['seed_x=1']}), 'seed 9'),
                          (self.kept('plain', {(1, 1): 60.0}, {'conditions': self.SETUP}), 'set-up of the table'),
                          (self.kept('other', {(1, 1): 60.0}, {'--fidelity': 'tiny_cal', '--set': ['a=1']}), 'tiny_cal')):
            with self.assertRaises(make.DocsError) as e:
                cone_setup.write(self.tmp, table, [bad], 'm')
            self.assertIn(said, str(e.exception))
