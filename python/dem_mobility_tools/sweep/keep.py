"""Keeping a long sweep's finished runs in git, so that it outlives the machine it runs on: each good
run's result, compacted (its histories decimated; no bag, no checkpoint), is written into a folder
of the checkout and, with `commit`, committed on its own as soon as the run ends. A sweep started
again (on another machine, from a fresh clone) with --resume takes those runs as done; a run lost
with its machine is run again, never guessed."""
import os
import subprocess

import yaml

from ..runs import read_result
from .args import OPTIONS_FILE  # noqa: F401 (the sweep's options, kept beside its runs)

MAX_ROWS = 200


def decimate(columns, max_rows=MAX_ROWS):
    """A columnar history ({name: [values...]}, equal lengths) with at most `max_rows` rows: every
    k-th row from the first, and the last."""
    lengths = {len(v) for v in columns.values() if isinstance(v, list)}
    if len(lengths) != 1:
        return columns
    n = lengths.pop()
    if n <= max_rows:
        return columns
    step = -(-(n - 1) // (max_rows - 1))  # ceil((n - 1) / (max_rows - 1)): the last row lands within max_rows
    rows = list(range(0, n, step))
    if rows[-1] != n - 1:
        rows.append(n - 1)
    return {k: ([v[i] for i in rows] if isinstance(v, list) else v) for k, v in columns.items()}


def compact(doc, max_rows=MAX_ROWS):
    """A result document with every columnar history (a mapping of equal-length lists) decimated,
    and a note saying so."""
    out = {}
    for key, value in doc.items():
        if isinstance(value, dict) and value and all(isinstance(v, list) for v in value.values()):
            small = decimate(value, max_rows)
            if small is not value:
                out[key + '_decimated_from'] = len(next(iter(value.values())))
            out[key] = small
        else:
            out[key] = value
    return out


def kept_path(keep_dir, name):
    return os.path.join(keep_dir, name + '.yaml')


def keep_run(result_file, keep_dir, name, commit=False, message=None, root=None, extra=None, also=()):
    """Writes the compacted result of a finished run into keep_dir/<name>.yaml (through a temporary
    file and a rename; `extra` added to it, e.g. the commit the sweep ran) and, with `commit`,
    commits that file and the files `also` names (those that exist: e.g. the sweep's options) alone
    (whatever else is staged stays staged). Returns (path, None), or (path or None, why not) when it could not be read, written or
    committed: the run itself stays where it is."""
    doc, why = read_result(result_file)
    if why is not None:
        return None, why
    os.makedirs(keep_dir, exist_ok=True)
    path = kept_path(keep_dir, name)
    tmp = path + '.tmp%d' % os.getpid()
    try:
        with open(tmp, 'w') as fh:
            fh.write('# a finished run kept by its sweep (dem_mobility_tools.sweep.keep): its result, histories\n'
                     '# decimated to at most %d rows\n' % MAX_ROWS)
            yaml.safe_dump(dict(compact(doc), **(extra or {})), fh, default_flow_style=None, sort_keys=False, width=110)
        os.replace(tmp, path)
    except OSError as e:
        return None, 'cannot write %s: %s' % (path, e.strerror)
    if not commit:
        return path, None
    root = root or os.path.dirname(os.path.abspath(path))
    rel = [os.path.relpath(os.path.abspath(p), root) for p in [path] + [p for p in also if os.path.isfile(p)]]
    for argv in (['git', '-C', root, 'add', '--'] + rel,
                 ['git', '-C', root, 'commit', '-q', '-m', message or 'sweep: kept run %s' % name, '--'] + rel):
        p = subprocess.run(argv, capture_output=True, text=True)
        if p.returncode != 0:
            said = (p.stderr or p.stdout).strip().splitlines()
            return path, 'git %s: %s' % (argv[3], said[-1] if said else 'exit status %d' % p.returncode)
    return path, None


def keeper(keep_dir, commit, root, message, extra, line):
    """A sweep's on_done callback: each good run (outcome.ok) compacted into keep_dir (committed with
    `commit`) as it ends, with the sweep's options file; `message(outcome)` is the commit's message,
    `line(text)` prints where the run went (or why it was not kept). No keep_dir: does nothing."""
    def keep(o):
        if not keep_dir or not o.ok:
            return
        path, why = keep_run(o.result_file, keep_dir, o.name, commit=commit, root=root, message=message(o),
                             extra=extra, also=[os.path.join(keep_dir, OPTIONS_FILE)])
        line('           kept   %-14s %s' % (o.name, path if why is None else 'NOT KEPT: %s' % why))
    return keep


def restore_kept(keep_dir, runs_dir, names, outcome_file):
    """For a resume: every kept run of `names` (keep_dir/<name>.yaml) that runs_dir does not hold a
    result of is copied there as its result, with an outcome file (outcome_file(name)) saying the
    run ended well, so that the sweep's own resume judges it like any other finished run. Returns
    the names restored."""
    restored = []
    for name in names:
        src = kept_path(keep_dir, name)
        dst = os.path.join(runs_dir, name + '.result.yaml')
        if not os.path.isfile(src) or os.path.exists(dst):
            continue
        doc, why = read_result(src)
        if why is not None or not isinstance(doc, dict):
            continue
        os.makedirs(runs_dir, exist_ok=True)
        with open(dst, 'w') as fh:
            yaml.safe_dump(doc, fh, default_flow_style=None, sort_keys=False, width=110)
        with open(outcome_file(name), 'w') as fh:
            yaml.safe_dump({'ended_well': True, 'returncode': 0, 'timed_out': False, 'stopped': False,
                            'kept_from': os.path.abspath(src)}, fh, sort_keys=False)
        restored.append(name)
    return restored
