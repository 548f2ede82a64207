"""Small helpers the sweep scripts share: comma-separated number lists for argparse, the
checkout's commit for a result's provenance, and the options a sweep's results depend on kept
in its folder (so that a resume with others is refused)."""
import argparse
import hashlib
import os
import subprocess

import yaml

OPTIONS_FILE = 'sweep_options.yaml'


def floats(text):
    """'0.1,0.3' -> [0.1, 0.3] (an argparse type; '' gives [])."""
    try:
        return [float(v) for v in text.split(',') if v.strip()]
    except ValueError:
        raise argparse.ArgumentTypeError('expected a comma-separated list of numbers, got %r' % text)


def ints(text):
    """'1,2,3' -> [1, 2, 3] (an argparse type)."""
    try:
        return [int(v) for v in text.split(',') if v.strip()]
    except ValueError:
        raise argparse.ArgumentTypeError('expected a comma-separated list of whole numbers, got %r' % text)


def git_commit(root):
    """The checkout's commit, with '-dirty' when tracked files differ from it."""
    try:
        head = subprocess.run(['git', '-C', root, 'rev-parse', 'HEAD'], stdout=subprocess.PIPE,
                              stderr=subprocess.DEVNULL, universal_newlines=True, check=True).stdout.strip()
        dirty = subprocess.run(['git', '-C', root, 'diff', '--quiet', 'HEAD', '--'],
                               stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL).returncode != 0
        return head + ('-dirty' if dirty else '')
    except (OSError, subprocess.CalledProcessError):
        return 'unknown (not a git checkout)'


def ros_package(package='dem_mobility'):
    """(its folder, None) where a run through roslaunch can start here: roslaunch on the PATH and
    the package found by ROS; else (None, why not). A shell without the catkin workspace's
    devel/setup.bash has neither, and every run would fail at once with roslaunch's own error."""
    import shutil
    if shutil.which('roslaunch') is None:
        return None, 'roslaunch is not on the PATH'
    try:
        p = subprocess.run(['rospack', 'find', package], capture_output=True, text=True, timeout=60)
    except (OSError, subprocess.TimeoutExpired) as e:
        return None, 'rospack find %s: %s' % (package, e)
    if p.returncode != 0:
        return None, 'ROS cannot find the package %s (rospack find %s: %s; ROS_PACKAGE_PATH=%s)' % (
            package, package, (p.stderr.strip().splitlines() or ['exit status %d' % p.returncode])[-1],
            os.environ.get('ROS_PACKAGE_PATH', ''))
    return p.stdout.strip(), None


def sha256(path):
    """The sha256 of a file's bytes (hex)."""
    h = hashlib.sha256()
    with open(path, 'rb') as fh:
        for block in iter(lambda: fh.read(1 << 16), b''):
            h.update(block)
    return h.hexdigest()


def keep_options(out, options, resume, defaults=None):
    """The options a sweep's results depend on and no result file holds (a driving time, a seed,
    a scene file and its hash, ...), written to OUT/sweep_options.yaml; with `resume`, ValueError
    naming the first option whose value differs from the one the folder's runs were made with
    (an option the folder's file does not name, written by an older version, is not compared,
    unless `defaults` gives the value it had then)."""
    path = os.path.join(out, OPTIONS_FILE)
    if resume and os.path.exists(path):
        with open(path) as fh:
            old = yaml.safe_load(fh) or {}
        old = dict(defaults or {}, **old)
        for key, value in options.items():
            if key in old and old[key] != value:
                raise ValueError('--resume: %s holds runs made with %s %s, not %s' % (out, key, old[key], value))
    os.makedirs(out, exist_ok=True)
    tmp = path + '.tmp%d' % os.getpid()
    with open(tmp, 'w') as fh:
        yaml.safe_dump(dict(options), fh, sort_keys=False)
    os.replace(tmp, path)
