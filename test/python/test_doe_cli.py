"""Tests of the `dm-doe` command (dem_mobility_tools.doe): every command's --help, the NRMM table and its map on
the shipped raster (GeoTIFF with the input's CRS, PNG, ROS map, difference map), the plan's cost
with and without pruning, and the refusals (a raster without CRS, an empty grid, a cone index
outside the level's calibration range).

    PYTHONPATH=python python3 -m unittest discover -s test/python -v      (from the repository root)
"""
import os
import re
import shutil
import subprocess
import sys
import tempfile
import unittest

import numpy as np
import yaml

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
from osgeo import gdal, osr

from dem_mobility_tools.doe import interp, raster
from dem_mobility_tools.terramechanics import nrmm

DOE = [sys.executable, '-m', 'dem_mobility_tools.doe']  # dm-doe
ST_HELENS = os.path.join(os.path.dirname(ROOT), 'shared', 'data', 'mount_st_helens_30m_utm10n_nad27.tif')


def doe(*args, env=None):
    p = subprocess.run(DOE + list(args), capture_output=True, text=True, env=env)
    return p.returncode, p.stdout, p.stderr


class Doe(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.tmp = tempfile.mkdtemp(prefix='dm_doe_')

    @classmethod
    def tearDownClass(cls):
        shutil.rmtree(cls.tmp, ignore_errors=True)

    def test_every_command_has_help(self):
        for cmd in ([], ['plan'], ['nrmm'], ['map']):
            rc, out, _ = doe(*(cmd + ['--help']))
            self.assertEqual(rc, 0, cmd)
            self.assertIn('usage: dm-doe', out)

    def test_nrmm_table_and_its_map_beside_itself(self):
        out = os.path.join(self.tmp, 'nrmm')
        rc, so, se = doe('nrmm', '--out', out, '--grades', '0,12,24,36', '--cone-indices', '30,70,150,300')
        self.assertEqual(rc, 0, se)
        with open(os.path.join(out, 'nrmm_table.yaml')) as fh:
            t = yaml.safe_load(fh)
        v = nrmm.Vehicle.load(os.path.join(ROOT, 'config', 'vehicles', 'hmmwv', 'nrmm.yaml'))
        self.assertAlmostEqual(t['speed'][1][1], v.speed(12, 70)['speed'], places=5)
        self.assertEqual(len(t['cases']), 16)
        for f in ('nrmm_table.csv', 'nrmm_speed_vs_ci.png', 'nrmm_speed_vs_grade.png'):
            self.assertTrue(os.path.getsize(os.path.join(out, f)) > 100, f)
        m = os.path.join(self.tmp, 'map')
        table = os.path.join(out, 'nrmm_table.yaml')
        rc, so, se = doe('map', '--table', table, '--compare', table, '--elevation', ST_HELENS, '--out', m)
        self.assertEqual(rc, 0, se)
        ds = gdal.Open(os.path.join(m, 'nrmm_smg.tif'))
        src = gdal.Open(ST_HELENS)
        self.assertTrue(osr.SpatialReference(wkt=ds.GetProjection()).IsSame(osr.SpatialReference(wkt=src.GetProjection())))
        gt, sgt = ds.GetGeoTransform(), src.GetGeoTransform()
        self.assertEqual((gt[0], gt[3]), (sgt[0], sgt[3]))
        self.assertEqual((gt[1], gt[5]), (20.0, -20.0))
        diff = raster.read(os.path.join(m, 'nrmm_minus_nrmm.tif'))
        self.assertEqual(np.nanmax(np.abs(diff.values)), 0.0)   # a table against itself
        # every cell's speed is the table at that cell's own slope and CI (the cells' rasters), so
        # the two are not swapped nor the cells shifted; the map is float32
        smg = raster.read(os.path.join(m, 'nrmm_smg.tif')).values
        slope = raster.read(os.path.join(m, 'cells_max_slope_deg.tif')).values
        ci = raster.read(os.path.join(m, 'cells_min_ci_psi.tif')).values
        want = interp.bilinear(t['grades'], t['cone_indices'], t['speed'], slope, ci)
        self.assertGreater(np.sum(~np.isnan(want)), 1000)
        np.testing.assert_array_equal(np.isnan(smg), np.isnan(want))
        np.testing.assert_allclose(smg[~np.isnan(want)], want[~np.isnan(want)].astype(np.float32), rtol=0, atol=1e-5)
        for f in ('nrmm_smg.png', 'nrmm_smg_ros.yaml', 'nrmm_smg_ros.png', 'nrmm_minus_nrmm.png', 'map.yaml'):
            self.assertTrue(os.path.exists(os.path.join(m, f)), f)

    def test_the_plan_prints_its_cost_with_and_without_pruning(self):
        rc, out, se = doe('plan', '--level', 'tiny')
        self.assertEqual(rc, 0, se)
        # the paper's whole grid: every CI of table 3 lies inside the tiny table (20.4-269.2 psi)
        self.assertIn('x 12 cone indices (30, 40, 50, 60, 70, 80, 100, 120, 150, 200, 242, 300), level tiny', out)
        self.assertNotIn('left out', out)
        self.assertIn('every case run:', out)
        self.assertIn('with pruning:', out)
        # 2 grades x (CI 50, the road): the bound "if none ended early" worked out from the measured
        # costs (a soil run: preparation + (settling + 40 s) x wall per simulated second; a road run
        # without preparation); every case run costs no more, the pruned plan no more than that
        with open(os.path.join(ROOT, 'config', 'doe', 'run_costs.yaml')) as fh:
            c = yaml.safe_load(fh)
        sim = c['settle'] + c['duration']
        upper = 2 * (c['levels']['tiny']['prepare'] + sim * c['levels']['tiny']['wall_per_sim_s']) + \
            2 * sim * c['road']['wall_per_sim_s']
        rc, out, se = doe('plan', '--level', 'tiny', '--grades', '0,12', '--cone-indices', '50,300')
        self.assertEqual(rc, 0, se)
        full = re.search(r'every case run: +([0-9.]+) h \(4 runs; at most ([0-9.]+) h', out)
        pruned = re.search(r'with pruning: +([0-9.]+) h \((\d+) runs, (\d+) implied', out)
        self.assertIsNotNone(full, out)
        self.assertIsNotNone(pruned, out)
        self.assertAlmostEqual(float(full.group(2)), upper / 3600, delta=0.05)
        self.assertLessEqual(float(full.group(1)), float(full.group(2)))
        self.assertLessEqual(float(pruned.group(1)), float(full.group(1)))
        self.assertEqual(int(pruned.group(2)) + int(pruned.group(3)), 4)

    def test_a_map_grid_spans_the_map_within_what_the_level_and_the_scenes_take(self):
        rc, out, se = doe('plan', '--grid', 'map', '--grid-size', '5x4', '--elevation', ST_HELENS, '--level', 'tiny')
        self.assertEqual(rc, 0, se)
        self.assertIn('the grid stops at 45 deg', out)     # St. Helens' crater walls are steeper
        self.assertIn('5 grades (0, 11.25, 22.5, 33.75, 45)', out)
        self.assertIn('4 cone indices (30, 120, 210, 300)', out)   # inside the tiny table, and the road
        rc, _, err = doe('plan', '--grid', 'map', '--grid-size', '14', '--elevation', ST_HELENS)
        self.assertEqual(rc, 2)
        self.assertIn('--grid-size', err)

    def test_bad_input_is_refused_naming_it(self):
        bare = os.path.join(self.tmp, 'bare.tif')
        raster.write_geotiff(bare, np.zeros((5, 5)), (0, 30.0, 0, 0, 0, -30.0), '')
        rc, _, err = doe('plan', '--elevation', bare, '--level', 'tiny')
        self.assertEqual(rc, 2)
        self.assertIn('bare.tif: the elevation has no CRS', err)
        rc, _, err = doe('plan', '--grades', '', '--cone-indices', '30')
        self.assertEqual(rc, 2)
        self.assertIn('empty grid', err)
        south_up = os.path.join(self.tmp, 'south_up.tif')
        srs = osr.SpatialReference()
        srs.ImportFromEPSG(32611)
        raster.write_geotiff(south_up, np.zeros((5, 5)), (0, 30.0, 0, 0, 0, 30.0), srs.ExportToWkt())
        rc, _, err = doe('plan', '--elevation', south_up)
        self.assertEqual(rc, 2)
        self.assertIn('not north-up', err)
        rc, _, err = doe('plan', '--grades', '0,50', '--cone-indices', '30')
        self.assertEqual(rc, 2)
        self.assertIn('steeper than the scenes take', err)
        rc, _, err = doe('plan', '--level', 'tiny', '--grades', '0,12', '--cone-indices', '20,100')
        self.assertEqual(rc, 2)
        self.assertIn('cone index 20 psi: outside the tiny level', err)
        self.assertIn('cone_index_mu0.1_d0.1.yaml', err)

    def test_a_run_where_ros_cannot_find_the_package_is_refused_before_anything_is_written(self):
        # a shell without the workspace's setup.bash: every roslaunch would fail at once with
        # roslaunch's own error; the DOE says what is missing and writes nothing
        empty = tempfile.mkdtemp(dir=self.tmp)
        out = os.path.join(self.tmp, 'no_ros')
        env = dict(os.environ, ROS_PACKAGE_PATH=empty, ROS_HOME=empty)
        rc, _, err = doe('run', '--out', out, '--level', 'tiny', '--grades', '0', '--cone-indices', '300', env=env)
        self.assertEqual(rc, 2, err)
        self.assertIn('--runner roslaunch: ROS cannot find the package dem_mobility', err)
        self.assertIn('devel/setup.bash', err)
        self.assertIn('--runner core', err)
        self.assertFalse(os.path.exists(out))

    def test_a_bad_table_is_refused_naming_it_before_any_map_is_written(self):
        good = {'grades': [0.0, 12.0], 'cone_indices': [30.0, 300.0], 'speed': [[10.0, 20.0], [5.0, 15.0]]}
        cases = (('not_yaml', 'grades: [0, 12\n', 'not YAML'),
                 ('rows', dict(good, speed=[[10.0, 20.0]]), 'speed: not a 2 x 2 matrix'),
                 ('columns', dict(good, speed=[[10.0], [5.0, 15.0]]), 'speed: not a 2 x 2 matrix'),
                 ('text', dict(good, speed=[[10.0, 'fast'], [5.0, 15.0]]), 'speed: a value that is not a number'),
                 ('negative', dict(good, speed=[[10.0, -1.0], [5.0, 15.0]]), 'speed: a speed below 0'),
                 ('grades', dict(good, grades=[12.0, 0.0]), 'grades/cone_indices:'),
                 # a table of an older version: its cases' cone index under the old key
                 ('old_key', dict(good, cases=[{'grade_deg': 0.0, 'cone_index': 30.0, 'speed_made_good': 10.0}]),
                  "cases[0]: 'cone_index' is an old name: it is 'cone_index_psi' now"),
                 ('old_doe_table', dict(good, cases=1, cases_table=[{'grade_deg': 0.0, 'cone_index': 30.0}]),
                  "cases_table[0]: 'cone_index' is an old name: it is 'cone_index_psi' now"),
                 ('no_speed', {'grades': [0.0]}, 'not a case table'))
        for name, doc, what in cases:
            path = os.path.join(self.tmp, name + '_table.yaml')
            with open(path, 'w') as fh:
                fh.write(doc if isinstance(doc, str) else yaml.safe_dump(doc))
            out = os.path.join(self.tmp, 'map_' + name)
            for args in (['--table', path], ['--table', self.good_table(good), '--compare', path]):
                rc, _, err = doe('map', *args, '--elevation', ST_HELENS, '--out', out)
                self.assertEqual(rc, 2, (name, err))
                self.assertIn(path + ': ' + what, err)
                self.assertFalse(os.path.exists(out), name)

    def good_table(self, doc):
        path = os.path.join(self.tmp, 'good_table.yaml')
        with open(path, 'w') as fh:
            yaml.safe_dump(doc, fh)
        return path

    def test_a_cone_index_raster_beside_the_elevation_is_refused(self):
        # a CI raster 100 km east of the elevation's cells: no cell has a cone index
        src = gdal.Open(ST_HELENS)
        gt = list(src.GetGeoTransform())
        gt[0] += 100000.0
        ci = os.path.join(self.tmp, 'ci_elsewhere.tif')
        raster.write_geotiff(ci, np.full((20, 20), 100.0), tuple(gt), src.GetProjection())
        table = self.good_table({'grades': [0.0, 45.0], 'cone_indices': [30.0, 300.0],
                                 'speed': [[10.0, 20.0], [5.0, 15.0]]})
        out = os.path.join(self.tmp, 'map_ci_elsewhere')
        rc, _, err = doe('map', '--table', table, '--elevation', ST_HELENS, '--ci', ci, '--out', out)
        self.assertEqual(rc, 2, err)
        self.assertIn('ci_elsewhere.tif: the cone index raster has no value in any cell', err)


if __name__ == '__main__':
    unittest.main()
