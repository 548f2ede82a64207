"""`dm-doe`: the design of experiments over grade x cone index, from a raster to a map (docs/doe.md).

    dm-doe plan  --elevation DEM.tif [--ci CI.tif | --ci-seed N] --level tiny
    dm-doe run   --out DIR [--grades ... --cone-indices ...] --level tiny --jobs 2 [--backend slurm] [--resume] [--dry-run]
                 [--refine N]
    dm-doe status --out DIR
    dm-doe nrmm  --out DIR [--grades ... --cone-indices ...]
    dm-doe map   --table TABLE.yaml --elevation DEM.tif [--ci CI.tif | --ci-seed N] --out DIR [--compare OTHER.yaml]

Every command has --help. Bad input (a raster without CRS, an empty grid, a CI outside the range
a level can simulate) is refused naming the input, with exit status 2.
"""
import argparse
import sys

from .. import paths
from ..sweep.args import floats
from ..terramechanics import nrmm
from . import plan, raster, runner
from .commands import cmd_case, cmd_map, cmd_nrmm, cmd_plan, cmd_run, cmd_status
from .design import NRMM_VEHICLE, UsageError, grid_size

# -- the command line -------------------------------------------------------------------------

def grid_args(p):
    """The grid's own axes (grade [deg], cone index [psi])."""
    p.add_argument('--grades', type=floats, help='grades [deg], rising (default: the paper\'s 0, 3, ..., 39)')
    p.add_argument('--cone-indices', type=floats,
                   help='cone indices [psi], rising (default: the paper\'s 12 of table 3, 30-300)')


def map_args(p, required=True):
    """The map: its elevation raster, its cone index raster [psi] (or a generated one), its cells."""
    p.add_argument('--elevation', required=required, help='elevation raster (GeoTIFF or anything GDAL reads; with a CRS)')
    p.add_argument('--ci', help='cone index raster [psi] (any grid and CRS); default: a generated one')
    p.add_argument('--ci-seed', type=int, default=1, help='seed of the generated CI field (default 1)')
    p.add_argument('--cell-size', type=float, default=20.0, help='map cell size [m] (default 20)')
    p.add_argument('--oversample', type=int, default=2, help='slope posts per cell side (default 2)')


def design_args(p):
    """The design's options: plan and run take the same."""
    grid_args(p)
    map_args(p, required=False)
    p.add_argument('--grid', choices=('paper', 'map'), default='paper',
                   help='paper: 14 x 12 (default); map: --grid-size values over the ranges found on the map')
    p.add_argument('--grid-size', type=grid_size, default=[14, 12], help='G x C for --grid map (default 14x12)')
    p.add_argument('--level', default='tiny', help='soil fidelity level of the runs (default tiny)')


def add_run(sub):
    """`dm-doe run` and its options."""
    p = sub.add_parser('run', help='runs the DOE\'s cases on a local pool or as a Slurm job array (resume, pruning, table, plots)',
                       description='Runs every case of the design (the plan as dm-doe plan prints it) through the '
                       'same launch files and nodelets a user runs (soil_slope.launch; road_slope.launch for CI 300), '
                       '--jobs at a time, in the plan\'s order, on a local pool or as one Slurm job array; a case whose outcome the finished ones fix is '
                       'recorded as implied, not run. Writes OUT/doe.yaml, OUT/runs/ (a result, log and bag per '
                       'case), OUT/doe_table.csv/.yaml and the plots. --resume keeps the finished cases.')
    design_args(p)
    p.add_argument('--runner', choices=('roslaunch', 'core'), default='roslaunch',
                   help='roslaunch (default: the launch files, a bag per case) or core (dm_run_scene, the same loop '
                   'in one process, no bag; ' + paths.RUNNER_HELP + ')')
    p.add_argument('--backend', choices=('local', 'slurm'), default='local',
                   help='local: a process pool here (default); slurm: one job array (sbatch --array), a task per '
                   'case, in --out (a folder every node sees)')
    p.add_argument('--jobs', type=int, default=1, help='cases at a time: the pool\'s size, or the array\'s %%N (default 1)')
    p.add_argument('--partition', help='slurm: the partition (default: the cluster\'s)')
    p.add_argument('--no-wait', action='store_true', help='slurm: submit and return (dm-doe status follows it)')
    p.add_argument('--dem-threads', type=int, default=1, help='soil threads of each run (default 1; slurm: --cpus-per-task)')
    p.add_argument('--duration', type=float, help='longest driving time [s] (default: the scenes\' 40 s)')
    p.add_argument('--soil-scene', help='a scene file of kind soil_slope for the soil cases, instead of '
                   'config/scenes/soil_slope.yaml (e.g. soil only under the tracks, a shorter box, your vehicle); '
                   'the DOE still sets grade, level, cone index, soil threads and duration')
    p.add_argument('--road-scene', help='a scene file of kind road_slope for the CI 300 cases, instead of '
                   'config/scenes/road_slope.yaml')
    p.add_argument('--no-prune', action='store_true', help='run every case (no implied cases)')
    p.add_argument('--refine', type=int, default=0, metavar='N',
                   help='once the grid is finished, add grid lines (N in all) where the speed changes fastest '
                        'between neighbours, at the midpoints, and run their cases (default 0)')
    p.add_argument('--resume', action='store_true', help='go on with the DOE in --out: finished cases are kept')
    p.add_argument('--retry-failed', action='store_true', help='with --resume: run the failed cases again')
    p.add_argument('--dry-run', action='store_true', help='print the plan and its estimated cost, run nothing')
    p.add_argument('--timeout', type=float, help='longest a case may take [s] (slurm: the tasks\' --time)')
    p.add_argument('--port', type=int, default=11611, help='first ROS master port of the pool (default 11611)')
    p.add_argument('--progress', choices=('auto', 'tqdm', 'plain'), default='auto',
                   help='a progress bar (tqdm, in s of estimated cost) on a terminal; plain: lines only')
    p.add_argument('--out', required=True, help='the DOE folder')
    p.set_defaults(func=cmd_run)


def parser():
    ap = argparse.ArgumentParser(prog='dm-doe', description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    sub = ap.add_subparsers(dest='command', metavar='COMMAND')
    sub.required = True

    p = sub.add_parser('plan', help='the grid, its run order and the estimated cost with and without pruning',
                       description='Prints the design: the grid (the paper\'s, the map\'s ranges or given), the '
                       'order the cases run in, and the estimated cost with and without pruning (a dry run: '
                       'nothing is simulated).')
    design_args(p)
    p.set_defaults(func=cmd_plan)

    add_run(sub)

    p = sub.add_parser('status', help='what the DOE in a folder has done: cases simulated, implied, failed, left; ETA',
                       description='Prints the state of every case of the DOE in --out (from its files: it works '
                       'while a dm-doe run is going on), the failed ones with their error, and the ETA.')
    p.add_argument('--out', required=True, help='the DOE folder')
    p.add_argument('--jobs', type=int, default=1, help='cases at a time, for the ETA (default 1)')
    p.add_argument('--table', action='store_true', help='also write the case table as it stands')
    p.set_defaults(func=cmd_status)

    p = sub.add_parser('case', help='one case\'s turn (what dm-doe run\'s pool and a Slurm array task run)',
                       description='Runs case --index of the DOE in --out, unless it is done or the finished cases '
                       'fix its outcome (then it is recorded as implied). Exit status 0 when the case is done, 1 '
                       'when its run failed.')
    p.add_argument('--out', required=True, help='the DOE folder')
    p.add_argument('--index', type=int, required=True, help='the case\'s place in the plan\'s order')
    p.add_argument('--port', type=int, help='ROS master port (default: ROS_MASTER_URI\'s, else 11611)')
    p.set_defaults(func=cmd_case)

    p = sub.add_parser('nrmm', help='the NRMM-style speed table on the grid, with its plots',
                       description='Writes the NRMM-style model\'s speed-made-good table (CSV, YAML) on the grid '
                       'and its plots against CI per grade and against grade per CI (docs/doe.md).')
    grid_args(p)
    p.add_argument('--vehicle', default=NRMM_VEHICLE, help='the vehicle\'s NRMM inputs (default %(default)s)')
    p.add_argument('--out', required=True, help='output folder')
    p.set_defaults(func=cmd_nrmm)

    p = sub.add_parser('map', help='a speed-made-good map from a finished table',
                       description='Interpolates a finished case table at every cell\'s (maximum slope, minimum '
                       'CI) and writes the map as GeoTIFF, PNG and ROS map (and, with --compare, the difference '
                       'map against another table).')
    map_args(p)
    p.add_argument('--table', required=True, help='a case table (YAML: dm-doe nrmm, or a finished DOE)')
    p.add_argument('--compare', help='another table: writes the difference map (table minus it)')
    p.add_argument('--clamp-ci', action='store_true', help='take CIs above the table\'s highest as its last column (a CI below its lowest keeps no value)')
    p.add_argument('--top-speed', type=float, help='the ROS map\'s free speed [m/s] (default: the table\'s highest)')
    p.add_argument('--name', help='file name stem of the map')
    p.add_argument('--out', required=True, help='output folder')
    p.set_defaults(func=cmd_map)
    return ap


def main(argv=None):
    ap = parser()
    a = ap.parse_args(argv)
    try:
        return a.func(a)
    except (UsageError, plan.PlanError, nrmm.NrmmError, raster.RasterError, runner.RunnerError) as e:
        print('dm-doe %s: %s' % (a.command, e), file=sys.stderr)
        return 2
