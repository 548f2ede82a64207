"""dem_mobility_tools.sweep: the generic machinery of the project's parameter sweeps (the cone index calibration,
single-wheel rig sweeps, designs of experiments): the cases (named axes -> cases with stable names),
a local pool running a command per case N at a time (a free ROS master port, a timeout and a log
file per run), resume, progress, and a summary file with every case's outcome. See docs/sweeps.md.

    from dem_mobility_tools import sweep as dm_sweep
    cases = dm_sweep.grid([('slip', [0.1, 0.3]), ('load', [100, 200])])    # slip0.1_load100, ...
    sweep = dm_sweep.run_sweep(cases, ['my_rig', '--slip={slip}', '--load={load}', '--out={result}'],
                               'results/rig/runs', summary='results/rig/sweep.yaml', jobs=2, resume=True)
    sys.exit(sweep.exit_status())
"""
from .cases import Case, cases, default_name, format_value, grid
from ..runs import port_free, read_result
from .pool import Outcome, Sweep, last_progress, run_sweep
from .progress import Progress, load_tqdm

__all__ = ['Case', 'cases', 'default_name', 'format_value', 'grid', 'Outcome', 'Sweep', 'last_progress',
           'port_free', 'read_result', 'run_sweep', 'Progress', 'load_tqdm']
