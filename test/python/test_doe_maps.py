"""Unit tests of dem_mobility_tools.doe.maps: the ROS map read back by map_server's rules gives the
occupancy the speeds mean (no-go 100, top speed 0, no value -1, bottom row first), and the three
products of a map are written with the raster's CRS and geotransform.

    PYTHONPATH=python python3 -m unittest discover -s test/python -v      (from the repository root)
"""
import os
import shutil
import tempfile
import unittest

import numpy as np

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
from osgeo import gdal, osr

from dem_mobility_tools.doe import maps, raster


class RosMap(unittest.TestCase):
    def setUp(self):
        self.tmp = tempfile.mkdtemp()

    def tearDown(self):
        shutil.rmtree(self.tmp)

    def test_map_server_reads_the_occupancy_the_speeds_mean(self):
        top = 25.0
        v = np.array([[0.0, 25.0, np.nan],
                      [12.5, 5.0, 30.0]])          # 30 m/s: above the top speed, free
        stem = os.path.join(self.tmp, 'm')
        doc = maps.write_ros_map(stem, v, (1000.0, 20.0, 0.0, 5000.0, 0.0, -20.0), top)
        m = maps.load_ros_map(stem + '.yaml')
        self.assertEqual(m['resolution'], 20.0)
        self.assertEqual(doc['crs_origin'], [1000.0, 4960.0])
        data = m['data']                              # rows from the bottom: the raster's last row first
        self.assertEqual(data.shape, (2, 3))
        self.assertEqual(list(data[1]), [100, 0, -1])
        # 12.5 m/s: occ 0.5 (grey 128 after rounding) -> 1 + 98 (occ' - 0.001) / 0.998
        occ = (255.0 - np.round(255.0 * 0.5)) / 255.0
        self.assertEqual(data[0][0], int(1 + 98 * (occ - 0.001) / 0.998))
        self.assertEqual(data[0][2], 0)
        self.assertGreater(data[0][1], data[0][0])    # slower: more occupied

    def test_a_map_has_its_geotiff_png_and_ros_map(self):
        srs = osr.SpatialReference()
        srs.ImportFromEPSG(26710)

        class Cells:
            gt = (560000.0, 20.0, 0.0, 5120000.0, 0.0, -20.0)
            wkt = srs.ExportToWkt()
            cell_size = 20.0
        v = np.linspace(0, 25, 40 * 60).reshape(40, 60)
        v[:5, :5] = np.nan
        out = maps.write_all(self.tmp, 'smg', v, Cells, 'test map', 25.0)
        ds = gdal.Open(out['geotiff'])
        self.assertEqual(ds.GetGeoTransform(), Cells.gt)
        self.assertEqual(osr.SpatialReference(wkt=ds.GetProjection()).GetAuthorityCode(None), '26710')
        back = raster.read(out['geotiff'])
        self.assertTrue(np.isnan(back.values[:5, :5]).all())
        np.testing.assert_allclose(back.values[5:], v[5:], rtol=1e-6)
        self.assertGreater(os.path.getsize(out['png']), 1000)
        self.assertEqual(maps.load_ros_map(out['ros_map'])['data'].shape, (40, 60))


if __name__ == '__main__':
    unittest.main()
