"""dm-doe: the design of experiments over grade x cone index, from a raster to a speed-made-good
map: plan | nrmm | run | status | case | map (each with --help; docs/doe.md).

    dm-doe plan --elevation ../shared/data/mount_st_helens_30m_utm10n_nad27.tif --level tiny
    dm-doe nrmm --out results/doe_nrmm
    dm-doe map --table results/doe_nrmm/nrmm_table.yaml --elevation DEM.tif --out results/doe_map
"""
import sys

from .cli import main

if __name__ == '__main__':
    sys.exit(main())
