"""Rasters for the maps (GDAL, Debian's python3-gdal): an elevation raster and a cone index raster in,
the map's cells out (paper section 5, step 1), GeoTIFFs written with the input's CRS.

- The map's grid: square cells of `cell_size` metres (20 by default) in the elevation raster's CRS,
  from its top-left corner; a strip narrower than a cell at the right and bottom edges is left
  out. A post at the raster's edge has no neighbour on one side: its slope has no value, so an
  edge cell takes its largest slope from its inner posts (with --oversample 1 the outer ring of
  cells has none). A raster in geographic coordinates (degrees) is first
  warped to the UTM zone of its centre (WGS 84), so that slopes and cells are in metres; one with no
  CRS at all is refused.
- Per cell, the maximum positive slope: the elevation is resampled (bilinear) to `oversample` x
  `oversample` posts per cell, its slope taken at every post by Horn's method (the 3 x 3 weights of
  gdaldem slope, in degrees: the gradient's magnitude, which is the steepest climb there), and the
  largest of the cell's posts kept.
- Per cell, the minimum cone index: the CI raster is resampled (bilinear, any CRS and grid) to the
  same posts and the smallest kept.
- Without a CI raster, `generate_ci` makes one: a smooth random field (seeded value noise, octaves
  of bilinearly upsampled uniform grids), mapped by rank onto [ci_min, ci_max] (the paper's 30-300
  psi by default), so that a user sees what the tool does before they have soil data.
"""
import math
import os

import numpy as np

try:
    from osgeo import gdal, osr
    gdal.UseExceptions()
except ImportError:  # pragma: no cover - the packages install it (scripts/lib.sh)
    gdal = osr = None

NODATA = -9999.0


class RasterError(ValueError):
    pass


def _need_gdal():
    if gdal is None:
        raise RasterError('GDAL for python3 is missing (Debian: python3-gdal; ./scripts/lib.sh installs it)')


class Raster:
    """A single-band raster in memory: values (float64, NaN where no data), geotransform, CRS (WKT)."""

    def __init__(self, values, geotransform, wkt, path='<memory>'):
        self.values = values
        self.gt = tuple(geotransform)
        self.wkt = wkt
        self.path = path

    @property
    def shape(self):
        return self.values.shape

    def srs(self):
        s = osr.SpatialReference()
        s.ImportFromWkt(self.wkt)
        s.SetAxisMappingStrategy(osr.OAMS_TRADITIONAL_GIS_ORDER)
        return s

    def dataset(self):
        """An in-memory GDAL dataset of it (NaN written as NODATA)."""
        ny, nx = self.values.shape
        ds = gdal.GetDriverByName('MEM').Create('', nx, ny, 1, gdal.GDT_Float64)
        ds.SetGeoTransform(self.gt)
        ds.SetProjection(self.wkt)
        b = ds.GetRasterBand(1)
        b.SetNoDataValue(NODATA)
        b.WriteArray(np.where(np.isnan(self.values), NODATA, self.values))
        return ds


def read(path, what='raster'):
    """Reads band 1 of anything GDAL opens; refuses a raster without CRS or with a rotated grid."""
    _need_gdal()
    if not os.path.exists(path):
        raise RasterError('%s: no such %s file' % (path, what))
    try:
        ds = gdal.Open(path)
    except RuntimeError as e:
        raise RasterError('%s: GDAL cannot read this %s (%s)' % (path, what, str(e).strip()))
    wkt = ds.GetProjection()
    if not wkt:
        raise RasterError('%s: the %s has no CRS (coordinate reference system): give it one, e.g. '
                          'gdal_edit.py -a_srs EPSG:32611 %s' % (path, what, path))
    gt = ds.GetGeoTransform()
    if gt[2] != 0 or gt[4] != 0:
        raise RasterError('%s: the %s grid is rotated (geotransform %s); warp it first (gdalwarp)' % (path, what, gt))
    if gt[1] <= 0 or gt[5] >= 0:
        raise RasterError('%s: the %s is not north-up (pixel size %g x %g); warp it first (gdalwarp)'
                          % (path, what, gt[1], gt[5]))
    b = ds.GetRasterBand(1)
    v = b.ReadAsArray().astype(np.float64)
    nd = b.GetNoDataValue()
    if nd is not None:
        v[v == nd] = np.nan
    return Raster(v, gt, wkt, path)


def write_geotiff(path, values, geotransform, wkt, description=''):
    """A float32 GeoTIFF with the CRS and geotransform given, NaN written as NODATA (-9999)."""
    _need_gdal()
    ny, nx = values.shape
    ds = gdal.GetDriverByName('GTiff').Create(path, nx, ny, 1, gdal.GDT_Float32, options=['COMPRESS=DEFLATE'])
    ds.SetGeoTransform(tuple(geotransform))
    ds.SetProjection(wkt)
    b = ds.GetRasterBand(1)
    b.SetNoDataValue(NODATA)
    if description:
        b.SetDescription(description)
    b.WriteArray(np.where(np.isnan(values), NODATA, values).astype(np.float32))
    ds.FlushCache()
    ds = None


def utm_of(raster):
    """The WGS 84 UTM zone's WKT for a raster's centre (a raster in degrees is mapped in it)."""
    ny, nx = raster.shape
    gt = raster.gt
    x, y = gt[0] + gt[1] * nx / 2.0, gt[3] + gt[5] * ny / 2.0
    src = raster.srs()
    ll = osr.SpatialReference()
    ll.ImportFromEPSG(4326)
    ll.SetAxisMappingStrategy(osr.OAMS_TRADITIONAL_GIS_ORDER)
    lon, lat, _ = osr.CoordinateTransformation(src, ll).TransformPoint(x, y)
    zone = int(math.floor((lon + 180.0) / 6.0)) + 1
    utm = osr.SpatialReference()
    utm.ImportFromEPSG((32600 if lat >= 0 else 32700) + zone)
    return utm.ExportToWkt()


def horn_slope(z, ewres, nsres):
    """Slope [deg] at every post by Horn's method (gdaldem slope's weights); NaN on the outer ring
    and next to missing values (gdaldem without -compute_edges).

    In double precision, not GDAL's DEMProcessing: GDAL takes the elevation in single precision,
    which on the map's resampled posts (St Helens and Big Tujunga, 1 and 2 posts per cell) moves
    the cells' largest slope by up to 1.3e-3 deg and their speed by up to 2.6e-3 m/s, and takes
    one cell per map across the table's edge (a value or none). Its -compute_edges is no better at
    the edges: a missing neighbour takes the centre's value, so a plane of slope 26.6 deg reads
    23.1 deg at its edge and a post next to a hole errs by up to 6 deg (an optimistic slope)."""
    z = np.asarray(z, dtype=float)
    out = np.full(z.shape, np.nan)
    if z.shape[0] < 3 or z.shape[1] < 3:
        return out
    a, b, c = z[:-2, :-2], z[:-2, 1:-1], z[:-2, 2:]
    d, f = z[1:-1, :-2], z[1:-1, 2:]
    g, h, i = z[2:, :-2], z[2:, 1:-1], z[2:, 2:]
    dzdx = ((c + 2 * f + i) - (a + 2 * d + g)) / (8.0 * ewres)
    dzdy = ((g + 2 * h + i) - (a + 2 * b + c)) / (8.0 * nsres)
    inner = np.degrees(np.arctan(np.hypot(dzdx, dzdy)))
    inner[np.isnan(z[1:-1, 1:-1])] = np.nan
    out[1:-1, 1:-1] = inner
    return out


class CellGrid:
    """The map's cells over an elevation raster: geotransform, CRS, shape; the post grid beneath."""

    def __init__(self, elevation, cell_size=20.0, oversample=2):
        if not (isinstance(cell_size, (int, float)) and math.isfinite(cell_size) and cell_size > 0):
            raise RasterError('cell_size: expected a positive length in metres, got %r' % cell_size)
        if not (isinstance(oversample, int) and 1 <= oversample <= 16):
            raise RasterError('oversample: expected a whole number of posts per cell side in [1, 16], got %r'
                              % oversample)
        srs = elevation.srs()
        self.reprojected = srs.IsGeographic()
        self.wkt = utm_of(elevation) if self.reprojected else elevation.wkt
        if not self.reprojected and abs(srs.GetLinearUnits() - 1.0) > 1e-9:
            raise RasterError('%s: the elevation raster\'s CRS is in %s, not metres; warp it to a metric CRS'
                              % (elevation.path, srs.GetLinearUnitsName()))
        self.cell_size = float(cell_size)
        self.oversample = oversample
        # the extent of the elevation raster in the map's CRS
        src = elevation.dataset()
        if self.reprojected:
            src = gdal.Warp('', src, format='MEM', dstSRS=self.wkt, resampleAlg='bilinear')
        gt = src.GetGeoTransform()
        x0, y0 = gt[0], gt[3]
        x1, y1 = x0 + gt[1] * src.RasterXSize, y0 + gt[5] * src.RasterYSize
        self.nx = max(1, int(math.floor((x1 - x0) / cell_size)))
        self.ny = max(1, int(math.floor((y0 - y1) / cell_size)))
        self.gt = (x0, cell_size, 0.0, y0, 0.0, -cell_size)
        self._src = src
        post = cell_size / oversample
        self.post_gt = (x0, post, 0.0, y0, 0.0, -post)

    @property
    def shape(self):
        return (self.ny, self.nx)

    def posts(self, raster_or_ds, resample='bilinear'):
        """A raster resampled onto the posts (oversample x oversample per cell), NaN where it has
        no data or does not reach."""
        ds = raster_or_ds.dataset() if isinstance(raster_or_ds, Raster) else raster_or_ds
        k = self.oversample
        x0, y0 = self.gt[0], self.gt[3]
        out = gdal.Warp('', ds, format='MEM', dstSRS=self.wkt, outputType=gdal.GDT_Float64,
                        outputBounds=(x0, y0 - self.ny * self.cell_size, x0 + self.nx * self.cell_size, y0),
                        width=self.nx * k, height=self.ny * k, resampleAlg=resample,
                        srcNodata=NODATA, dstNodata=NODATA)
        v = out.GetRasterBand(1).ReadAsArray().astype(np.float64)
        v[v == NODATA] = np.nan
        return v

    def cell_max(self, posts):
        k = self.oversample
        return _reduce(posts.reshape(self.ny, k, self.nx, k), np.fmax)

    def cell_min(self, posts):
        k = self.oversample
        return _reduce(posts.reshape(self.ny, k, self.nx, k), np.fmin)

    def max_slope(self):
        """Per cell the largest slope of its posts [deg] (NaN where the elevation has no data)."""
        post = self.cell_size / self.oversample
        # slope on a one-post margin: the posts at the map's edge take their neighbours from a
        # grid one post wider, so the outer cells are not lost
        k = self.oversample
        x0, y0 = self.gt[0] - post, self.gt[3] + post
        wide = gdal.Warp('', self._src, format='MEM', dstSRS=self.wkt, outputType=gdal.GDT_Float64,
                         outputBounds=(x0, y0 - (self.ny * k + 2) * post, x0 + (self.nx * k + 2) * post, y0),
                         width=self.nx * k + 2, height=self.ny * k + 2, resampleAlg='bilinear',
                         srcNodata=NODATA, dstNodata=NODATA)
        zw = wide.GetRasterBand(1).ReadAsArray().astype(np.float64)
        zw[zw == NODATA] = np.nan
        s = horn_slope(zw, post, post)[1:-1, 1:-1]       # (NaN next to a post without elevation)
        return self.cell_max(s)

    def min_cone_index(self, ci):
        return self.cell_min(self.posts(ci))


def _reduce(blocks, op):
    """op over the (k, k) posts of each cell, ignoring NaN posts (all NaN gives NaN)."""
    with np.errstate(invalid='ignore'):
        out = blocks[:, 0, :, 0].copy()
        k = blocks.shape[1]
        for a in range(k):
            for b in range(k):
                out = op(out, blocks[:, a, :, b])
    return out


def generate_ci(grid, seed=1, ci_min=30.0, ci_max=300.0, correlation=1000.0, octaves=4):
    """A smooth random cone index field [psi] on the map's cells: value noise (uniform random values
    on grids of spacing correlation, correlation/2, ... upsampled bilinearly, amplitudes halving),
    mapped by rank onto [ci_min, ci_max] (uniformly distributed over the range). Seeded."""
    if not (0 < ci_min < ci_max):
        raise RasterError('ci_min, ci_max: expected 0 < ci_min < ci_max, got %r, %r' % (ci_min, ci_max))
    rng = np.random.default_rng(seed)
    ny, nx = grid.shape
    field = np.zeros((ny, nx))
    amp, spacing = 1.0, float(correlation)
    for _ in range(octaves):
        step = max(1.0, spacing / grid.cell_size)          # cells per lattice spacing
        gy, gx = int(math.ceil(ny / step)) + 2, int(math.ceil(nx / step)) + 2
        lattice = rng.uniform(-1.0, 1.0, (gy, gx))
        y = np.arange(ny) / step
        x = np.arange(nx) / step
        j0, i0 = np.floor(y).astype(int), np.floor(x).astype(int)
        ty, tx = (y - j0)[:, None], (x - i0)[None, :]
        v00 = lattice[j0][:, i0]
        v01 = lattice[j0][:, i0 + 1]
        v10 = lattice[j0 + 1][:, i0]
        v11 = lattice[j0 + 1][:, i0 + 1]
        field += amp * ((1 - ty) * (1 - tx) * v00 + (1 - ty) * tx * v01 + ty * (1 - tx) * v10 + ty * tx * v11)
        amp *= 0.5
        spacing *= 0.5
    rank = field.ravel().argsort(kind='stable').argsort(kind='stable').reshape(field.shape)
    u = (rank + 0.5) / rank.size
    return ci_min + (ci_max - ci_min) * u
