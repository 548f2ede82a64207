#!/usr/bin/env python3
"""The speed-made-good map on ROS (issue 14): the DOE map step (dm_doe.maps.write_all) writes the
map as a GeoTIFF and as a ROS map (map_server's YAML and image), and mobility_map.launch publishes
the ROS map as nav_msgs/OccupancyGrid on /map, latched.

The ROS map is checked against GDAL's reading of the GeoTIFF, cell by cell, through a reader of
its own written here (not dm_doe's load_ros_map): it parses the PNG's chunks and scanlines and the
YAML's resolution, origin, mode and thresholds, and applies map_server's rules (ROS noetic
map_server, image_loader.cpp) to the grey and alpha. The value each cell must have follows from
the documented mapping alone: occupancy = 1 - speed / top speed (clipped to 0-1), grey
p = round(255 (1 - occupancy)); map_server reads occ = (255 - p) / 255 back and makes 100 above
occupied_thresh, 0 below free_thresh, 1 + 98 (occ - free) / (occupied - free) between, and -1
where the GeoTIFF has no value (a transparent cell). The published grid is that reading, rows from
the bottom, with the YAML's resolution and origin. A file that cannot be read ends the launch with
an error naming it.

    python3 test/ros/test_map_publisher.py   (after the catkin build; needs the workspace sourced)
    (MapFiles runs without ROS: python3 test/ros/test_map_publisher.py MapFiles)
"""
import os
import shutil
import struct
import subprocess
import sys
import tempfile
import unittest
import zlib

import numpy as np
import yaml
from osgeo import gdal, osr

from dem_mobility_tools.doe import maps
from dem_mobility_tools.runs import free_port
from launch_run import stop_group  # beside this file

gdal.UseExceptions()
TOP = 20.0  # [m/s] the maps' top speed


def read_png(path):
    """An 8-bit PNG's pixels (rows from the top) as an array of (rows, columns, channels), read from
    its chunks: IHDR, the IDAT stream inflated, each scanline's filter undone (PNG spec, 9.2)."""
    with open(path, 'rb') as fh:
        raw = fh.read()
    if raw[:8] != b'\x89PNG\r\n\x1a\n':
        raise ValueError('%s: not a PNG' % path)
    pos, idat, head = 8, b'', None
    while pos < len(raw):
        n, kind = struct.unpack('>I4s', raw[pos:pos + 8])
        body = raw[pos + 8:pos + 8 + n]
        if zlib.crc32(kind + body) != struct.unpack('>I', raw[pos + 8 + n:pos + 12 + n])[0]:
            raise ValueError('%s: chunk %s fails its CRC' % (path, kind))
        if kind == b'IHDR':
            head = struct.unpack('>IIBBBBB', body)
        elif kind == b'IDAT':
            idat += body
        elif kind == b'IEND':
            break
        pos += 12 + n
    width, height, depth, colour, _, _, interlace = head
    channels = {0: 1, 2: 3, 4: 2, 6: 4}.get(colour)
    if depth != 8 or channels is None or interlace:
        raise ValueError('%s: only 8-bit grey, grey + alpha, RGB and RGBA without interlace (got depth %d, colour %d)'
                         % (path, depth, colour))
    data, stride = zlib.decompress(idat), width * channels
    out = np.zeros((height, stride), dtype=np.int64)
    prev = np.zeros(stride, dtype=np.int64)
    for r in range(height):
        line = data[r * (stride + 1):(r + 1) * (stride + 1)]
        ftype, cur = line[0], list(line[1:])
        for i in range(stride):
            a = cur[i - channels] if i >= channels else 0
            b = int(prev[i])
            c = int(prev[i - channels]) if i >= channels else 0
            if ftype == 1:
                cur[i] = (cur[i] + a) & 255
            elif ftype == 2:
                cur[i] = (cur[i] + b) & 255
            elif ftype == 3:
                cur[i] = (cur[i] + (a + b) // 2) & 255
            elif ftype == 4:
                p = a + b - c
                pa, pb, pc = abs(p - a), abs(p - b), abs(p - c)
                cur[i] = (cur[i] + (a if pa <= pb and pa <= pc else (b if pb <= pc else c))) & 255
            elif ftype != 0:
                raise ValueError('%s: scanline %d has filter type %d' % (path, r, ftype))
        out[r] = cur
        prev = out[r]
    return out.reshape(height, width, channels)


def read_ros_map(yaml_path):
    """A map_server map (mode scale or trinary, 8-bit image with or without alpha) read by
    map_server's rules: its OccupancyGrid data as rows from the bottom, resolution and origin."""
    with open(yaml_path) as fh:
        doc = yaml.safe_load(fh)
    px = read_png(os.path.join(os.path.dirname(yaml_path), doc['image']))
    has_alpha = px.shape[2] in (2, 4)
    colours = px[..., :-1] if has_alpha and doc['mode'] != 'trinary' else px
    grey = colours.sum(axis=2) / colours.shape[2]
    if doc.get('negate', 0):
        grey = 255.0 - grey
    alpha = px[..., -1] if has_alpha else np.full(grey.shape, 255)
    occ_th, free_th = float(doc['occupied_thresh']), float(doc['free_thresh'])
    grid = np.empty(grey.shape, dtype=int)
    for (r, c), g in np.ndenumerate(grey):
        occ = (255.0 - g) / 255.0
        if occ > occ_th:
            grid[r, c] = 100
        elif occ < free_th:
            grid[r, c] = 0
        elif doc['mode'] == 'trinary' or alpha[r, c] < 255:
            grid[r, c] = -1
        else:
            grid[r, c] = int(1 + 98 * (occ - free_th) / (occ_th - free_th))
    return {'data': grid[::-1], 'resolution': float(doc['resolution']), 'origin': [float(x) for x in doc['origin']],
            'doc': doc, 'shape': grey.shape}


def geotiff_as_grid(tif, top):
    """What each cell of the ROS map must hold, from GDAL's reading of the GeoTIFF and the
    documented mapping (rows from the top, as GDAL gives them), and the GeoTIFF's geotransform."""
    ds = gdal.Open(tif)
    band = ds.GetRasterBand(1)
    v, nodata = band.ReadAsArray().astype(float), band.GetNoDataValue()
    want = np.empty(v.shape, dtype=int)
    for (r, c), s in np.ndenumerate(v):
        if s == nodata:
            want[r, c] = -1
            continue
        occupancy = min(max(1.0 - s / top, 0.0), 1.0)
        p = int(round(255.0 * (1.0 - occupancy)))  # the grey
        occ = (255 - p) / 255.0                    # map_server's reading of it
        want[r, c] = 100 if occ > 0.999 else (0 if occ < 0.001 else int(1 + 98 * (occ - 0.001) / 0.998))
    return want, ds.GetGeoTransform(), (ds.RasterYSize, ds.RasterXSize)


class Cells:
    """The cell grid write_all needs: geotransform, CRS and cell size (UTM 11N, 20 m cells)."""
    def __init__(self, x0, y0, cell):
        self.gt = (x0, cell, 0.0, y0, 0.0, -cell)
        s = osr.SpatialReference()
        s.ImportFromEPSG(32611)
        self.wkt = s.ExportToWkt()
        self.cell_size = cell


def write_map(out_dir, values):
    """The DOE map step's files for `values` (m/s, NaN: no value): GeoTIFF and ROS map."""
    return maps.write_all(out_dir, 'smg', values, Cells(500000.0, 4000000.0, 20.0), 'test map', TOP)


class MapFiles(unittest.TestCase):
    """The ROS map against GDAL's reading of the GeoTIFF (no ROS needed)."""

    def setUp(self):
        self.tmp = tempfile.mkdtemp(prefix='dm_map_files_')

    def tearDown(self):
        shutil.rmtree(self.tmp, ignore_errors=True)

    def test_the_ros_map_holds_the_geotiffs_speeds_cell_by_cell(self):
        # 9 x 13 cells: random speeds, every mapping's edge (0, the top, above it, half the top,
        # one grey step from 0 and from the top) and cells without a value
        rng = np.random.default_rng(3)
        v = rng.uniform(0.0, TOP, (9, 13))
        v[rng.uniform(size=v.shape) < 0.15] = np.nan
        v[0, :6] = [0.0, TOP, 1.3 * TOP, 0.5 * TOP, TOP / 255.0, TOP * 254.0 / 255.0]
        v[8, 12] = np.nan
        out = write_map(self.tmp, v)
        want, gt, shape = geotiff_as_grid(out['geotiff'], TOP)
        got = read_ros_map(out['ros_map'])
        # the same grid, cell by cell (the ROS map's rows from the bottom: flipped back)
        self.assertEqual(got['shape'], shape)
        np.testing.assert_array_equal(got['data'][::-1], want)
        # and the edges as documented (rows from the top here)
        self.assertEqual(want[0, :3].tolist(), [100, 0, 0])  # no-go, the top speed, above it
        self.assertTrue(49 <= want[0, 3] <= 51, want[0, 3])  # half the top speed: half occupied
        # one grey step from either end: the ends of the scale between the thresholds (1-98)
        self.assertEqual(want[0, 4:6].tolist(), [98, 1])
        self.assertEqual(want[8, 12], -1)
        self.assertEqual(int(np.sum(want == -1)), int(np.sum(np.isnan(v))))
        # the YAML: the GeoTIFF's cell size, the lower-left corner at the map frame's origin, and
        # where that corner is in the raster's CRS
        self.assertEqual(got['resolution'], gt[1])
        self.assertEqual(got['origin'], [0.0, 0.0, 0.0])
        self.assertEqual(got['doc']['crs_origin'], [gt[0], gt[3] + shape[0] * gt[5]])
        self.assertEqual((got['doc']['mode'], got['doc']['negate']), ('scale', 0))

    def test_the_reader_reads_every_png_filter(self):
        # PIL picks the scanline filters it likes; this PNG is written here with each of the five
        # filters in turn, so the reader's undoing of each is checked against the pixels put in
        rng = np.random.default_rng(5)
        px = rng.integers(0, 256, (10, 7, 2))
        rows = []
        prev = np.zeros(14, dtype=int)
        for r in range(10):
            cur = px[r].reshape(-1)
            left = np.concatenate([[0, 0], cur[:-2]])
            upleft = np.concatenate([[0, 0], prev[:-2]])
            ftype = r % 5
            if ftype == 0:
                f = cur
            elif ftype == 1:
                f = cur - left
            elif ftype == 2:
                f = cur - prev
            elif ftype == 3:
                f = cur - (left + prev) // 2
            else:
                p = left + prev - upleft
                pa, pb, pc = abs(p - left), abs(p - prev), abs(p - upleft)
                f = cur - np.where((pa <= pb) & (pa <= pc), left, np.where(pb <= pc, prev, upleft))
            rows.append(bytes([ftype]) + bytes((f % 256).astype(np.uint8).tolist()))
            prev = cur

        def chunk(kind, body):
            return struct.pack('>I', len(body)) + kind + body + struct.pack('>I', zlib.crc32(kind + body))
        path = os.path.join(self.tmp, 'filters.png')
        with open(path, 'wb') as fh:
            fh.write(b'\x89PNG\r\n\x1a\n' + chunk(b'IHDR', struct.pack('>IIBBBBB', 7, 10, 8, 4, 0, 0, 0))
                     + chunk(b'IDAT', zlib.compress(b''.join(rows))) + chunk(b'IEND', b''))
        np.testing.assert_array_equal(read_png(path), px)


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
        out = write_map(self.tmp, v)
        # the grid map_server would read from the file, read here on its own, and what GDAL reads
        # in the GeoTIFF says it must be (rows from the bottom)
        want = read_ros_map(out['ros_map'])['data']
        np.testing.assert_array_equal(want, geotiff_as_grid(out['geotiff'], TOP)[0][::-1])
        p = self.launch(out['ros_map'])
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
    unittest.main(verbosity=2)  # each test named, a skip too (test/check_skips.py)
