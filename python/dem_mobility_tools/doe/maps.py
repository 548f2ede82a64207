"""The speed-made-good map (paper section 5, step 3; figs. 25, 26): the case table interpolated at
every cell's (maximum slope, minimum CI), written as
  - a float32 GeoTIFF in m/s with the elevation's CRS and the cells' geotransform (nodata -9999
    where the elevation has none or the table does not reach),
  - a PNG with a colour bar in mph, a scale bar and a title,
  - a ROS map: map_server's YAML and a grey + alpha image (mode scale): a cell's occupancy is
    1 - speed / top speed, so a no-go cell is occupied (100), one at the top speed free (0) and
    unknown (-1) where the map has no value; `load_ros_map` reads it back by map_server's rules
    (map_server is not packaged in Debian 12; dm-publish-map publishes the same grid as
    nav_msgs/OccupancyGrid).
"""
import os

import numpy as np
import yaml

from . import interp, raster

MPH = 0.44704  # m/s


def speed_map(table, slope, ci, clamp_ci=False):
    """table: {'grades', 'cone_indices', 'speed'} (m/s); slope [deg], ci [psi] per cell."""
    return interp.bilinear(table['grades'], table['cone_indices'], table['speed'], slope, ci, clamp_ci=clamp_ci)


def _map_picture(path, shown, cell_size, title, cmap_name, vmin, vmax, label, scale_bar=True):
    """A map's picture: the cells (NaN grey, and said so), a colour bar, a scale bar, a title."""
    import matplotlib
    matplotlib.use('Agg')
    import matplotlib.pyplot as plt
    from matplotlib import colormaps
    from matplotlib.patches import Patch
    ny, nx = shown.shape
    w_km, h_km = nx * cell_size / 1e3, ny * cell_size / 1e3
    fig, ax = plt.subplots(figsize=(7.5, 7.5 * max(0.4, min(2.0, h_km / w_km)) + 0.6))
    cmap = colormaps[cmap_name].copy()
    cmap.set_bad('0.6')
    im = ax.imshow(np.ma.masked_invalid(shown), cmap=cmap, vmin=vmin, vmax=vmax, extent=(0, w_km, 0, h_km),
                   origin='upper', interpolation='nearest')
    fig.colorbar(im, ax=ax, label=label, shrink=0.85)
    if np.isnan(shown).any():
        ax.legend(handles=[Patch(color='0.6', label='no value (beyond the table, or no data)')], loc='upper right',
                  fontsize=8, framealpha=0.8)
    if scale_bar:  # a round length near a quarter of the width
        b = ([b for b in (0.1, 0.2, 0.5, 1, 2, 5, 10, 20, 50) if b <= w_km / 4.0] or [w_km / 4.0])[-1]
        x0, y0 = 0.05 * w_km, 0.05 * h_km
        ax.plot([x0, x0 + b], [y0, y0], color='k', lw=4, solid_capstyle='butt')
        ax.text(x0 + b / 2, y0 + 0.02 * h_km, '%g km' % b, ha='center', va='bottom', fontsize=9,
                bbox=dict(facecolor='white', alpha=0.7, lw=0))
    ax.set_xlabel('east [km]')
    ax.set_ylabel('north [km]')
    ax.set_title(title, fontsize=10)
    fig.tight_layout()
    # zlib level 1: the same pixels (PNG is lossless), a third of the encoding time of the default 6
    fig.savefig(path, dpi=110, pil_kwargs={'compress_level': 1})
    plt.close(fig)


def write_png(path, values, cell_size, title, vmax, label='speed-made-good [mph]', scale=1.0 / MPH):
    """A picture of a map (values in m/s shown in mph by default): colour bar, scale bar, title;
    cells without a value in grey."""
    _map_picture(path, values * scale, cell_size, title, 'RdYlGn', 0.0, vmax * scale, label)


def write_difference_png(path, diff, cell_size, title):
    """A difference map (m/s, shown in mph) on a diverging scale centred on 0."""
    lim = float(np.nanmax(np.abs(diff))) / MPH if np.isfinite(diff).any() else 1.0
    _map_picture(path, diff / MPH, cell_size, title, 'RdBu', -max(lim, 1e-9), max(lim, 1e-9), 'difference [mph]')


def write_ros_map(stem, values, geotransform, top_speed):
    """map_server's files: <stem>.png (grey + alpha) and <stem>.yaml (mode scale, negate 0).
    Grey p = 255 (1 - occ) with occ = 1 - speed / top_speed, so map_server reads occ back: a no-go
    cell (occ 1 > occupied_thresh 0.999) is 100, one at the top speed (occ 0 < free_thresh 0.001)
    is 0, the rest 1-99; a cell without a value is transparent (alpha 0), which scale mode reads
    as unknown (-1)."""
    from PIL import Image
    if not (np.isfinite(top_speed) and top_speed > 0):
        raise ValueError('the ROS map\'s top speed must be a positive speed, got %r m/s' % top_speed)
    occ = np.clip(1.0 - values / top_speed, 0.0, 1.0)
    grey = np.where(np.isnan(values), 205, np.round(255.0 * (1.0 - np.nan_to_num(occ)))).astype(np.uint8)
    alpha = np.where(np.isnan(values), 0, 255).astype(np.uint8)
    Image.fromarray(np.dstack([grey, alpha]), mode='LA').save(stem + '.png', compress_level=1)
    ny = values.shape[0]
    x0, cell, y0 = geotransform[0], geotransform[1], geotransform[3]
    doc = {
        'image': os.path.basename(stem) + '.png',
        'resolution': float(cell),
        # map_server's origin is the pose of the image's lower-left corner in the map frame; the
        # map frame is the raster's CRS shifted so that this corner is at (0, 0)
        'origin': [0.0, 0.0, 0.0],
        'negate': 0,
        'occupied_thresh': 0.999,
        'free_thresh': 0.001,
        'mode': 'scale',
        # not map_server's keys (it ignores them): where the map frame sits in the raster's CRS,
        # and what a cell means
        'crs_origin': [float(x0), float(y0 - ny * cell)],
        'meaning': 'occupancy = 1 - speed-made-good / %g m/s (no-go: 100, top speed: 0, no value: -1)' % top_speed,
    }
    with open(stem + '.yaml', 'w') as fh:
        yaml.safe_dump(doc, fh, sort_keys=False)
    return doc


def load_ros_map(yaml_path):
    """A map_server YAML and image read by map_server's rules (ROS noetic map_server,
    src/image_loader.cpp: modes trinary, scale and raw): the OccupancyGrid's data as rows from the
    bottom (its order), its resolution and origin."""
    from PIL import Image
    with open(yaml_path) as fh:
        doc = yaml.safe_load(fh)
    mode = doc.get('mode', 'trinary')
    img = Image.open(os.path.join(os.path.dirname(yaml_path), doc['image']))
    has_alpha = img.mode in ('RGBA', 'LA') or (img.mode == 'P' and 'transparency' in img.info)
    px = np.asarray(img.convert('RGBA' if has_alpha else ('L' if img.mode in ('L', '1') else 'RGB')), dtype=float)
    if px.ndim == 2:
        px = px[..., None]
    n = px.shape[2]
    # trinary mode averages the alpha in with the colours; the other modes leave it out
    avg = n if (mode == 'trinary' or not has_alpha) else n - 1
    color = px[..., :avg].sum(axis=2) / avg
    alpha = px[..., -1] if n > 1 else np.ones(color.shape)
    if doc.get('negate', 0):
        color = 255.0 - color
    if mode == 'raw':
        data = color.astype(int)
    else:
        occ = (255.0 - color) / 255.0
        occ_th, free_th = doc['occupied_thresh'], doc['free_thresh']
        data = np.full(color.shape, -1, dtype=int)
        mid = (occ <= occ_th) & (occ >= free_th)
        if mode == 'scale':
            scaled = mid & (alpha >= 1.0)
            data[scaled] = (1.0 + 98.0 * (occ[scaled] - free_th) / (occ_th - free_th)).astype(int)
        data[occ > occ_th] = 100
        data[occ < free_th] = 0
    return {'data': data[::-1].copy(), 'resolution': doc['resolution'], 'origin': doc['origin'], 'doc': doc}


def write_all(out_dir, name, values, cells, title, top_speed):
    """GeoTIFF, PNG and ROS map of one map; returns their paths."""
    os.makedirs(out_dir, exist_ok=True)
    tif = os.path.join(out_dir, name + '.tif')
    png = os.path.join(out_dir, name + '.png')
    raster.write_geotiff(tif, values, cells.gt, cells.wkt, title)
    write_png(png, values, cells.cell_size, title, top_speed)
    write_ros_map(os.path.join(out_dir, name + '_ros'), values, cells.gt, top_speed)
    return {'geotiff': tif, 'png': png, 'ros_map': os.path.join(out_dir, name + '_ros.yaml')}
