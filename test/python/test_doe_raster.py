"""Unit tests of dem_mobility_tools.doe.raster (GDAL): slopes against gdaldem on the shipped raster,
per-cell maximum slope and minimum cone index on planes (exact), the GeoTIFF keeping its CRS and
geotransform, the CI generator, and the refusals (no CRS, bad cell size).

    PYTHONPATH=python python3 -m unittest discover -s test/python -v      (from the repository root)
"""
import math
import os
import shutil
import subprocess
import tempfile
import unittest

import numpy as np

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
from osgeo import gdal, osr

from dem_mobility_tools.doe import raster

DATA = os.path.join(os.path.dirname(ROOT), 'shared', 'data')
ST_HELENS = os.path.join(DATA, 'mount_st_helens_30m_utm10n_nad27.tif')


def wkt_of(epsg):
    s = osr.SpatialReference()
    s.ImportFromEPSG(epsg)
    return s.ExportToWkt()


def plane_raster(path, gt, shape, f, epsg=32611):
    ny, nx = shape
    x = gt[0] + gt[1] * (np.arange(nx) + 0.5)
    y = gt[3] + gt[5] * (np.arange(ny) + 0.5)
    raster.write_geotiff(path, f(x[None, :], y[:, None]), gt, wkt_of(epsg) if epsg else '')
    return path


class Raster(unittest.TestCase):
    def setUp(self):
        self.tmp = tempfile.mkdtemp()

    def tearDown(self):
        shutil.rmtree(self.tmp)

    def test_slopes_match_gdaldem_on_the_shipped_raster(self):
        self.assertTrue(os.path.exists(ST_HELENS), 'the shipped raster is not at ' + ST_HELENS)
        out = os.path.join(self.tmp, 'slope.tif')
        subprocess.check_call(['gdaldem', 'slope', ST_HELENS, out, '-q'])
        ref = raster.read(out)
        e = raster.read(ST_HELENS)
        s = raster.horn_slope(e.values, e.gt[1], -e.gt[5])
        m = ~np.isnan(ref.values)
        self.assertGreater(m.sum(), 0.99 * (e.shape[0] - 2) * (e.shape[1] - 2))
        np.testing.assert_allclose(s[m], ref.values[m], rtol=0, atol=1e-4)   # gdaldem writes float32
        self.assertTrue(np.isnan(s[~m]).all())

    def test_horn_slope_of_a_plane_is_its_analytic_slope(self):
        # z = 0.3 x - 0.7 y on posts 25 m apart east, 40 m north: slope atan(hypot(0.3, 0.7))
        # everywhere inside; no value on the outer ring (no neighbour on one side) nor around a hole
        x, y = 25.0 * np.arange(12), 40.0 * np.arange(9)
        z = 0.3 * x[None, :] - 0.7 * (-y[:, None])
        z[4, 6] = np.nan
        s = raster.horn_slope(z, 25.0, 40.0)
        want = math.degrees(math.atan(math.hypot(0.3, 0.7)))
        hole = np.zeros(z.shape, dtype=bool)
        hole[3:6, 5:8] = True
        inner = np.zeros(z.shape, dtype=bool)
        inner[1:-1, 1:-1] = True
        np.testing.assert_allclose(s[inner & ~hole], want, rtol=0, atol=1e-12)
        self.assertTrue(np.isnan(s[~inner | hole]).all())

    def test_per_cell_slope_and_cone_index_are_exact_on_planes(self):
        # elevation: a plane rising 0.3 to the east and 0.4 to the north (slope atan 0.5 everywhere),
        # 30 m posts; CI: a plane in another CRS-equal grid, 10 m posts, falling to the east
        elev = plane_raster(os.path.join(self.tmp, 'z.tif'), (500000.0, 30.0, 0, 4000000.0, 0, -30.0), (40, 50),
                            lambda x, y: 0.3 * (x - 500000.0) + 0.4 * (y - 4000000.0))
        ci = plane_raster(os.path.join(self.tmp, 'ci.tif'), (499900.0, 10.0, 0, 4000100.0, 0, -10.0), (150, 180),
                          lambda x, y: 300.0 - 0.1 * (x - 499900.0) + 0 * y)
        g = raster.CellGrid(raster.read(elev), cell_size=20.0, oversample=2)
        self.assertEqual(g.shape, (60, 75))
        self.assertEqual(g.gt, (500000.0, 20.0, 0.0, 4000000.0, 0.0, -20.0))
        s = g.max_slope()
        np.testing.assert_allclose(s[1:-1, 1:-1], math.degrees(math.atan(0.5)), atol=1e-9)
        c = g.min_cone_index(raster.read(ci))
        # the smallest CI of a cell is at its easternmost posts (centres 15 m from its west edge)
        x_east = 500000.0 + 20.0 * np.arange(75) + 15.0
        want = 300.0 - 0.1 * (x_east - 499900.0)
        np.testing.assert_allclose(c[5], want, atol=1e-6)

    def test_the_geotiff_keeps_crs_and_geotransform(self):
        path = os.path.join(self.tmp, 'm.tif')
        gt = (352000.0, 20.0, 0.0, 3800000.0, 0.0, -20.0)
        v = np.arange(12.0).reshape(3, 4)
        v[1, 2] = np.nan
        raster.write_geotiff(path, v, gt, wkt_of(32611), 'speed-made-good [m/s]')
        ds = gdal.Open(path)
        self.assertEqual(ds.GetGeoTransform(), gt)
        srs = osr.SpatialReference(wkt=ds.GetProjection())
        self.assertEqual(srs.GetAuthorityCode(None), '32611')
        b = ds.GetRasterBand(1)
        self.assertEqual(b.DataType, gdal.GDT_Float32)
        self.assertEqual(b.GetNoDataValue(), raster.NODATA)
        back = raster.read(path)
        self.assertTrue(np.isnan(back.values[1, 2]))
        self.assertEqual(back.values[2, 3], 11.0)

    def test_a_raster_without_crs_is_refused_and_one_in_degrees_is_mapped_in_utm(self):
        bare = plane_raster(os.path.join(self.tmp, 'bare.tif'), (0.0, 30.0, 0, 0.0, 0, -30.0), (5, 5),
                            lambda x, y: x + y, epsg=None)
        with self.assertRaisesRegex(raster.RasterError, 'bare.tif: the elevation has no CRS'):
            raster.read(bare, 'elevation')
        with self.assertRaisesRegex(raster.RasterError, 'no such'):
            raster.read(os.path.join(self.tmp, 'none.tif'))
        geo = plane_raster(os.path.join(self.tmp, 'geo.tif'), (-118.3, 0.0003, 0, 34.3, 0, -0.0003), (50, 50),
                           lambda x, y: 0 * x, epsg=4326)
        g = raster.CellGrid(raster.read(geo), 20.0, 1)
        self.assertTrue(g.reprojected)
        self.assertEqual(osr.SpatialReference(wkt=g.wkt).GetAuthorityCode(None), '32611')
        with self.assertRaisesRegex(raster.RasterError, 'cell_size'):
            raster.CellGrid(raster.read(geo), -20.0, 1)

    def test_the_generated_cone_index_is_seeded_smooth_and_spans_the_range(self):
        elev = plane_raster(os.path.join(self.tmp, 'z.tif'), (500000.0, 30.0, 0, 4000000.0, 0, -30.0), (200, 300),
                            lambda x, y: 0 * x)
        g = raster.CellGrid(raster.read(elev), 20.0, 1)
        a, b = raster.generate_ci(g, seed=4), raster.generate_ci(g, seed=4)
        np.testing.assert_array_equal(a, b)
        self.assertFalse(np.array_equal(a, raster.generate_ci(g, seed=5)))
        self.assertGreaterEqual(a.min(), 30.0)
        self.assertLessEqual(a.max(), 300.0)
        self.assertGreater(a.max() - a.min(), 260.0)
        # smooth: neighbouring cells differ by a small part of the range (white noise: about a third)
        self.assertLess(np.median(np.abs(np.diff(a, axis=1))), 0.05 * 270.0)


if __name__ == '__main__':
    unittest.main()
