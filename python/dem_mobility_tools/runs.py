"""One run of a scene: its command for either runner, a free port for its ROS master, its result.

Two runners make the same run: `roslaunch` of the scene's launch file (the launch files and
nodelets a user runs, a bag beside the result) and `core`, the core runner dm_run_scene (the same
co-simulation loop in one process, without ROS and without a bag: a developer's check, or a sweep
on a machine without the ROS build). `scene_command` builds either from one set of parameters,
named as the scene keys name them; LAUNCHES says which launch argument and which dm_run_scene
override each parameter is.
"""
import os
import socket

import yaml

from . import paths

RUNNERS = ('roslaunch', 'core')

# per launch file: parameter -> (its launch argument, its dm_run_scene override)
LAUNCHES = {
    'road_slope.launch': {
        'grade_deg': ('grade', 'grade_deg'),
        'duration': ('duration', 'duration'),
    },
    'soil_slope.launch': {
        'grade_deg': ('grade', 'grade_deg'),
        'duration': ('duration', 'duration'),
        'fidelity': ('fidelity', 'terrain_overrides.fidelity'),
        'cone_index': ('cone_index', 'terrain_overrides.cone_index'),
        'cohesion_factor': ('cohesion_factor', 'terrain_overrides.cohesion_factor'),
        'dem_threads': ('dem_threads', 'terrain_overrides.threads'),
        'seed': ('seed', 'terrain_overrides.seed'),
    },
    'single_wheel.launch': {
        'fidelity': ('fidelity', 'fidelity'),
        'cone_index': ('cone_index', 'cone_index'),
        'cohesion_factor': ('cohesion_factor', 'cohesion_factor'),
        'slip': ('slip', 'wheel.slip'),
        'drive': ('drive', 'wheel.drive'),
        'dem_threads': ('dem_threads', 'threads'),
        'friction': ('friction', 'friction'),
        'load_mass': ('load', 'wheel.load_mass'),
        'speed': ('speed', 'wheel.speed'),
        'seed': ('seed', 'seed'),
    },
    'cone_penetrometer.launch': {
        'fidelity': ('fidelity', 'fidelity'),
        'cone_index': ('cone_index', 'cone_index'),
        'cohesion_factor': ('cohesion_factor', 'cohesion_factor'),
        'friction': ('friction', 'friction'),
        'seed': ('seed', 'seed'),
        'dem_threads': ('dem_threads', 'threads'),
        'time_step': ('time_step', 'time_step'),
    },
}

# dm_run_scene overrides that go with a parameter: soil_slope.yaml's terrain_overrides name a cone
# index of their own, which an f must clear (the launch file's nodelet takes either in the other's place)
CORE_ALSO = {('soil_slope.launch', 'cohesion_factor'): ['terrain_overrides.cone_index=~']}


def number(x):
    """A number for a command line with every digit kept: the shortest form that reads back as the
    same float ('%g' would run 1234.567 as 1234.57), a whole number without '.0'."""
    text = repr(float(x))
    return text[:-2] if text.endswith('.0') else text


def text(value):
    """A parameter's value on a command line: every digit of a float kept (number),
    booleans as true/false, text as it is."""
    if isinstance(value, bool):
        return 'true' if value else 'false'
    if isinstance(value, int):
        return '%d' % value
    if isinstance(value, float):
        return number(value)
    return str(value)


def default_scene(launch):
    """The scene file a launch file runs by default: config/scenes/<launch's name>.yaml."""
    return os.path.join(paths.CONFIG, 'scenes', launch[:-len('.launch')] + '.yaml')


def scene_command(runner, launch, params=(), scene=None, port=None, bag=None, launch_args=(), result=None,
                  history=None, core_args=(), core_options=(), dm_run_scene=None):
    """The argv of one run of `launch`'s scene.

    runner: 'roslaunch' or 'core'. params: (name, value) pairs or a mapping, names of
    LAUNCHES[launch] (a value None is left out). scene: the scene file (default: the launch's own
    for roslaunch, default_scene(launch) for core).
    roslaunch only: port (its master's, -p), bag (the run's bag; the result YAML goes beside it),
      launch_args ((argument, value) pairs or 'argument:=value' strings, e.g. ('cloud_rate', 5)).
      A scripted run opens no rviz and ends with its run (rviz:=false end_run:=true).
    core only: result (--out), history (--history), core_args (more 'key=value' overrides, as
      dm_run_scene takes them), core_options (more options, e.g. ['--quiet']), dm_run_scene (the
      binary; default paths.dm_run_scene()).
    """
    if launch not in LAUNCHES:
        raise ValueError('scene_command: unknown launch file %r (have %s)' % (launch, ', '.join(sorted(LAUNCHES))))
    names = LAUNCHES[launch]
    items = list(params.items()) if hasattr(params, 'items') else [tuple(p) for p in params]
    for key, _ in items:
        if key not in names:
            raise ValueError('scene_command: %s has no parameter %r (have %s)' % (launch, key, ', '.join(names)))
    items = [(k, v) for k, v in items if v is not None]
    if runner == 'roslaunch':
        argv = ['roslaunch'] + (['-p', str(port)] if port is not None else []) + ['dem_mobility', launch]
        if scene is not None:
            argv.append('scene:=' + os.path.abspath(scene))
        argv += ['%s:=%s' % (names[k][0], text(v)) for k, v in items]
        if bag is not None:
            argv.append('bag:=' + os.path.abspath(bag))
        for a in launch_args:
            argv.append(a if isinstance(a, str) else '%s:=%s' % (a[0], text(a[1])))
        return argv + ['rviz:=false', 'end_run:=true']
    if runner == 'core':
        argv = [paths.dm_run_scene(dm_run_scene), os.path.abspath(scene or default_scene(launch))]
        for k, v in items:
            argv += CORE_ALSO.get((launch, k), []) + ['%s=%s' % (names[k][1], text(v))]
        argv += list(core_args)
        if result is not None:
            argv += ['--out', os.path.abspath(result)]
        if history is not None:
            argv += ['--history', os.path.abspath(history)]
        return argv + list(core_options)
    raise ValueError('scene_command: runner %r: expected one of %s' % (runner, ', '.join(RUNNERS)))


def port_free(port):
    """True if nothing listens on the TCP port (a port in TIME_WAIT counts as free, as for a ROS
    master, which binds with SO_REUSEADDR)."""
    s = socket.socket(socket.AF_INET, socket.SOCK_STREAM)
    try:
        s.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
        s.bind(('', port))
        return True
    except OSError:
        return False
    finally:
        s.close()


def free_port(start=None, step=2, tries=100):
    """A TCP port nothing listens on: without `start`, one the system picks; else the first free
    one of start, start + step, ... (ROS masters side by side: a master takes its port and the
    next). OSError when none of `tries` is free."""
    if start is None:
        with socket.socket(socket.AF_INET, socket.SOCK_STREAM) as s:
            s.bind(('', 0))
            return s.getsockname()[1]
    for k in range(tries):
        if port_free(start + step * k):
            return start + step * k
    raise OSError('no free TCP port among %d, %d, ..., %d' % (start, start + step, start + step * (tries - 1)))


def read_result(path):
    """A run's result file (or any YAML mapping the tools write): (the mapping, None), or (None,
    why not: no such file, unreadable, not YAML, empty, not a mapping), the reason naming the file."""
    try:
        with open(path) as fh:
            doc = yaml.safe_load(fh)
    except OSError as e:
        return None, '%s: %s' % (path, e.strerror or e)
    except yaml.YAMLError as e:
        return None, '%s: not YAML (%s)' % (path, str(e).splitlines()[0] if str(e) else 'parse error')
    if not isinstance(doc, dict):
        return None, '%s: %s' % (path, 'empty' if doc is None else 'not a YAML mapping (%s)' % type(doc).__name__)
    return doc, None
