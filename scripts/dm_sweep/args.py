"""Small helpers the sweep scripts share: comma-separated number lists for argparse, and the
checkout's commit for a result's provenance."""
import argparse
import subprocess


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
