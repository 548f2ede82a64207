"""Where things are: the checkout (its config/ and launch/), the build folder and the core runner.

The checkout is $DM_ROOT if set, else the one this package lives in (python/dem_mobility_tools/,
also through catkin's devel space, which relays to the source), else the ROS package dem_mobility
(rospkg), else the current folder. The build folder is $DM_BUILD, else <checkout>/build (as
scripts/lib.sh). The core runner is $DM_RUN_SCENE, else <build>/core/src/tools/dm_run_scene.
"""
import os


def _is_checkout(folder):
    try:
        with open(os.path.join(folder, 'package.xml')) as fh:
            return '<name>dem_mobility</name>' in fh.read()
    except OSError:
        return False


def checkout_root():
    """The dem_mobility checkout (see the module's doc)."""
    if os.environ.get('DM_ROOT'):
        return os.path.abspath(os.environ['DM_ROOT'])
    here = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
    if _is_checkout(here):
        return here
    try:
        import rospkg
        return rospkg.RosPack().get_path('dem_mobility')
    except Exception:  # no rospkg, or ROS does not know the package: not an error until a file is missing
        return os.getcwd()


ROOT = checkout_root()
CONFIG = os.path.join(ROOT, 'config')


def build_dir():
    """$DM_BUILD, else <checkout>/build (scripts/lib.sh's DM_BUILD)."""
    return os.path.abspath(os.environ.get('DM_BUILD') or os.path.join(ROOT, 'build'))


def dm_run_scene(explicit=None):
    """The core runner: `explicit` (an option's value) if given, else $DM_RUN_SCENE, else
    <build>/core/src/tools/dm_run_scene. An absolute path."""
    return os.path.abspath(explicit or os.environ.get('DM_RUN_SCENE')
                           or os.path.join(build_dir(), 'core', 'src', 'tools', 'dm_run_scene'))


RUNNER_HELP = ('the core runner (default $DM_RUN_SCENE, else $DM_BUILD/core/src/tools/dm_run_scene, '
               'DM_BUILD defaulting to the checkout\'s build/)')


def missing_runner_message(path):
    """What to say when the core runner is not at `path`."""
    return ('no dm_run_scene at %s (build the core: cmake -S . -B build/core -DDM_BUILD_ROS=OFF && '
            'cmake --build build/core; or set DM_RUN_SCENE or DM_BUILD)' % path)


# the folder that holds this package (python/ of the checkout, or site-packages)
PYTHON_DIR = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def tool_command(module):
    """The argv that runs one of this package's tools in a child process (this Python, -m)."""
    import sys
    return [sys.executable, '-m', module]
