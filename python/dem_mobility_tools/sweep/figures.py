"""Writing a figure the way every plot script of the project does: into a folder that is made if
it is not there yet, and an error naming the file (exit status 1, no traceback) when it cannot."""
import os
import sys


def save_figure(fig, path, who, dpi=110):
    """fig.savefig(path) after making its folder; sys.exit('WHO: cannot write PATH: why') on failure."""
    try:
        if os.path.dirname(path):
            os.makedirs(os.path.dirname(path), exist_ok=True)
        fig.savefig(path, dpi=dpi)
    except OSError as e:
        sys.exit('%s: cannot write %s: %s' % (who, path, e))
