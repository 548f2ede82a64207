"""Progress of a sweep: a line per started and finished run on stdout, and a tqdm bar on stderr when
python3-tqdm is importable and stderr is a terminal (or mode 'tqdm'); the lines then go through
tqdm.write so that they do not break the bar."""
import sys


def load_tqdm():
    """tqdm's class, or None without python3-tqdm."""
    try:
        from tqdm import tqdm
    except ImportError:
        return None
    return tqdm


class Progress:
    """mode: 'auto' (a bar if tqdm is importable and stderr a terminal), 'tqdm' (a bar if tqdm is
    importable), 'plain' (lines only)."""

    def __init__(self, total, initial=0, mode='auto', stream=None, unit='run'):
        if mode not in ('auto', 'tqdm', 'plain'):
            raise ValueError('progress mode %r: expected auto, tqdm or plain' % mode)
        self.stream = stream
        self.bar = None
        tqdm = load_tqdm() if mode != 'plain' else None
        if tqdm is not None and (mode == 'tqdm' or _isatty(sys.stderr)):
            self.bar = tqdm(total=total, initial=initial, unit=unit, file=sys.stderr)

    def line(self, text):
        out = self.stream or sys.stdout
        if self.bar is not None:
            self.bar.write(text, file=out)
            out.flush()
        else:
            print(text, file=out, flush=True)

    def advance(self, n=1):
        if self.bar is not None:
            self.bar.update(n)

    def close(self):
        if self.bar is not None:
            self.bar.close()
            self.bar = None


def _isatty(f):
    try:
        return f.isatty()
    except (AttributeError, ValueError):
        return False
