"""Tests of the `doe` command (scripts/doe): every command's --help, the NRMM table and its map on
the shipped raster (GeoTIFF with the input's CRS, PNG, ROS map, difference map), the plan's cost
with and without pruning, and the refusals (a raster without CRS, an empty grid, a cone index
outside the level's calibration range).

    python3 -m unittest discover -s test/python -v      (from the repository root)
"""
import os
import shutil
import subprocess
import sys
import tempfile
import unittest

import numpy as np
import yaml

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
sys.path.insert(0, os.path.join(ROOT, 'scripts'))
from dm_doe import nrmm, raster  # noqa: E402
from osgeo import gdal, osr  # noqa: E402

DOE = os.path.join(ROOT, 'scripts', 'doe')
ST_HELENS = os.path.join(os.path.dirname(ROOT), 'shared', 'data', 'mount_st_helens_30m_utm10n_nad27.tif')


def doe(*args):
    p = subprocess.run([sys.executable, DOE] + list(args), capture_output=True, text=True)
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
            self.assertIn('usage: doe', out)

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
        for f in ('nrmm_smg.png', 'nrmm_smg_ros.yaml', 'nrmm_smg_ros.png', 'nrmm_minus_nrmm.png', 'map.yaml'):
            self.assertTrue(os.path.exists(os.path.join(m, f)), f)

    def test_the_plan_prints_its_cost_with_and_without_pruning(self):
        rc, out, se = doe('plan', '--level', 'tiny')
        self.assertEqual(rc, 0, se)
        self.assertIn('left out', out)                 # the paper's CIs beyond the tiny table
        self.assertIn('every case run:', out)
        self.assertIn('with pruning:', out)

    def test_a_map_grid_spans_the_map_within_what_the_level_and_the_scenes_take(self):
        rc, out, se = doe('plan', '--grid', 'map', '--grid-size', '5x4', '--elevation', ST_HELENS, '--level', 'tiny')
        self.assertEqual(rc, 0, se)
        self.assertIn('the grid stops at 45 deg', out)     # St. Helens' crater walls are steeper
        self.assertIn('5 grades (0, 11.25, 22.5, 33.75, 45)', out)
        self.assertIn('left out', out)                     # generated CIs above the tiny table
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
        rc, _, err = doe('plan', '--level', 'tiny', '--grades', '0,12', '--cone-indices', '30,200')
        self.assertEqual(rc, 2)
        self.assertIn('cone index 200 psi: outside the tiny level', err)
        self.assertIn('cone_index_mu0.1_d0.1.yaml', err)


if __name__ == '__main__':
    unittest.main()
