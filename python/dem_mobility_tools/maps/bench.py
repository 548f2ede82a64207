"""dm-bench-doe-map: the `doe_map` benchmark (./scripts/bench.sh doe_map): the time to map a 22 km x 22 km region
(1101 x 1101 cells of 20 m) from a finished table, the issue's goal being under 5 s.

The region: the shipped Big Tujunga DEM (30 m, UTM 11N; 20.0 x 19.3 km) extended to 22.02 km
square by mirroring it at its east and south edges (real terrain, no seam in the slopes but the
mirror line), written as a GeoTIFF with the source's CRS. The table: the NRMM-style table on the
paper's 14 x 12 grid (`dm-doe nrmm`). Timed: the whole `dm-doe map` command (read the raster, the cells'
maximum slope, a generated CI field, the interpolation, the GeoTIFF, PNG and ROS map, the cells'
slope and CI rasters), and, inside it, the interpolation alone (map.yaml). Prints
  doe_map cells VALUE count
  doe_map map_22km_wall_s VALUE s
  doe_map interpolation_s VALUE s

    dm-bench-doe-map [WORK_DIR]
"""
import argparse
import os
import subprocess
import sys
import tempfile
import time

import numpy as np
import yaml

from ..paths import ROOT, tool_command

DOE = tool_command('dem_mobility_tools.doe')
SOURCE = os.path.join(os.path.dirname(ROOT), 'shared', 'data', 'big_tujunga_west_30m_utm11n.tif')
SIDE = 22020.0  # [m]: 734 posts of 30 m


def region(path):
    from osgeo import gdal
    gdal.UseExceptions()
    src = gdal.Open(SOURCE)
    z = src.GetRasterBand(1).ReadAsArray().astype(np.float32)
    gt = src.GetGeoTransform()
    n = int(round(SIDE / gt[1]))
    big = np.pad(z, ((0, max(0, n - z.shape[0])), (0, max(0, n - z.shape[1]))), mode='symmetric')[:n, :n]
    drv = gdal.GetDriverByName('GTiff')
    dst = drv.Create(path, n, n, 1, gdal.GDT_Float32, ['COMPRESS=DEFLATE', 'TILED=YES'])
    dst.SetGeoTransform(gt)
    dst.SetProjection(src.GetProjection())
    dst.GetRasterBand(1).WriteArray(big)
    dst.FlushCache()
    dst = None
    return n


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split('\n\n')[0], formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument('work', nargs='?', help='folder for the region, the table and the map (default: a new temporary one)')
    a = ap.parse_args(argv)
    work = a.work or tempfile.mkdtemp(prefix='dm_bench_map_')
    os.makedirs(work, exist_ok=True)
    dem = os.path.join(work, 'region_22km.tif')
    region(dem)
    nrmm = os.path.join(work, 'nrmm')
    subprocess.run(DOE + ['nrmm', '--out', nrmm], check=True, capture_output=True)
    out = os.path.join(work, 'map')
    t0 = time.time()
    p = subprocess.run(DOE + ['map', '--table', os.path.join(nrmm, 'nrmm_table.yaml'),
                        '--elevation', dem, '--out', out], capture_output=True, text=True)
    wall = time.time() - t0
    if p.returncode != 0:
        sys.stderr.write(p.stdout + p.stderr)
        return 1
    with open(os.path.join(out, 'map.yaml')) as fh:
        m = yaml.safe_load(fh)
    print('doe_map cells %d count' % (m['cells'][0] * m['cells'][1]))
    print('doe_map map_22km_wall_s %.2f s' % wall)
    print('doe_map interpolation_s %.3f s' % m['interpolation_wall_time'])
    return 0


if __name__ == '__main__':
    sys.exit(main())
