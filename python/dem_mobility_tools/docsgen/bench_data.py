"""Puts the figures a benchmark printed into its data file (docs/data/performance-NAME.yaml).

    python3 -m dem_mobility_tools.docsgen.bench_data LOG --commit HASH [--machine TEXT]
        [--conditions TEXT] [--root DIR]

LOG holds what `./scripts/bench.sh NAME` printed: its `# DATE ARCH N cores, CPU` line and lines
`NAME FIGURE VALUE UNIT`. Every row of the data file `table: performance/NAME` whose figures are
all in the log takes the log's values; the file's provenance takes the commit, the machine (the
log's CPU line unless --machine), the date (the log's) and the command. A row whose figures are
not in the log is left as it was and named on stderr (it was not measured again). The file's text
is edited line by line (its comments and layout stay); then run dm-docs to rewrite the tables.
"""
import argparse
import os
import re
import sys

import yaml

LINE = re.compile(r'^(?P<name>\w+) (?P<figure>\S+) (?P<value>[-+0-9.eE]+) (?P<unit>\S+)$')
HEADER = re.compile(r'^# (?P<date>\d{4}-\d\d-\d\dT\d\d:\d\dZ) \S+ (?P<cores>\d+) cores, (?P<cpu>.*)$')


class BenchDataError(Exception):
    """Bad input: the message names the file."""


def read_log(path):
    """{(name, figure): value text}, and the log's date and CPU (None when it has no header)."""
    figures, date, cpu = {}, None, None
    with open(path) as f:
        for line in f:
            line = line.rstrip('\n')
            m = HEADER.match(line)
            if m and date is None:
                date, cpu = m.group('date'), '{} cores, {}'.format(m.group('cores'), m.group('cpu'))
                continue
            m = LINE.match(line)
            if m:
                figures[(m.group('name'), m.group('figure'))] = m.group('value')
    if not figures:
        raise BenchDataError('{}: no benchmark line (NAME FIGURE VALUE UNIT)'.format(path))
    return figures, date, cpu


def _number(text):
    v = float(text)
    return int(v) if v == int(v) and 'e' not in text.lower() and '.' not in text else v


def update_text(text, name, figures):
    """The data file's text with the measured rows' values replaced; (text, updated, kept)."""
    lines = text.split('\n')
    updated, kept = [], []
    i = 0
    while i < len(lines):
        m = re.match(r'^(\s*)figure: (.*)$', lines[i])
        if not m:
            i += 1
            continue
        indent, names = m.group(1), [n.strip() for n in m.group(2).split(',')]
        # the row's value line: the next line at the same indent starting with value:
        j = i + 1
        while j < len(lines) and not re.match(r'^{}value: '.format(indent), lines[j]):
            if re.match(r'^\s*- ', lines[j]):
                j = len(lines)
                break
            j += 1
        found = [figures.get((name, n)) for n in names]
        if j < len(lines) and all(v is not None for v in found):
            values = [_number(v) for v in found]
            lines[j] = '{}value: {}'.format(indent, values[0] if len(values) == 1 else
                                            '[' + ', '.join(str(v) for v in values) + ']')
            updated.extend(names)
        else:
            kept.extend(names)
        i += 1
    return '\n'.join(lines), updated, kept


def set_provenance(text, key, value):
    """The provenance's `key:` line set to `value` (quoted as YAML needs)."""
    dumped = yaml.safe_dump(value, default_flow_style=True, width=10 ** 6).strip()
    if dumped.endswith('...'):
        dumped = dumped[:-3].strip()
    pattern = re.compile(r'^(  {}: ).*$'.format(re.escape(key)), re.M)
    if pattern.search(text):
        return pattern.sub(lambda m: m.group(1) + dumped, text, count=1)
    # a key the provenance lacks: after its command
    command = re.compile(r'^(  command: .*)$', re.M)
    if not command.search(text):
        raise BenchDataError('provenance has no key {} (nor command)'.format(key))
    return command.sub(lambda m: '{}\n  {}: {}'.format(m.group(1), key, dumped), text, count=1)


def main(argv=None):
    p = argparse.ArgumentParser(prog='bench_data', description=__doc__.split('\n')[0])
    p.add_argument('log')
    p.add_argument('--commit', required=True, help='the commit the benchmark ran at')
    p.add_argument('--machine', help='the machine (default: the log\'s CPU line)')
    p.add_argument('--conditions', help='what else ran, and other conditions of the run')
    p.add_argument('--root', default=os.getcwd())
    a = p.parse_args(argv)
    try:
        figures, date, cpu = read_log(a.log)
        names = sorted({n for n, _ in figures})
        for name in names:
            path = os.path.join(a.root, 'docs', 'data', 'performance-{}.yaml'.format(name))
            if not os.path.exists(path):
                print('bench_data: {}: no data file {}'.format(name, path), file=sys.stderr)
                continue
            with open(path) as f:
                text = f.read()
            text, updated, kept = update_text(text, name, figures)
            if not updated:
                print('bench_data: {}: no row measured in {}'.format(path, a.log), file=sys.stderr)
                continue
            text = set_provenance(text, 'commit', a.commit)
            text = set_provenance(text, 'date', date.replace('T', ' ').replace('Z', ' UTC') if date else 'unknown')
            text = set_provenance(text, 'command', './scripts/bench.sh {}'.format(name))
            if a.machine or cpu:
                text = set_provenance(text, 'machine', a.machine or cpu)
            if a.conditions:
                text = set_provenance(text, 'conditions', a.conditions)
            yaml.safe_load(text)  # (still YAML)
            with open(path, 'w') as f:
                f.write(text)
            print('bench_data: {}: {} figures measured again{}'.format(
                os.path.relpath(path, a.root), len(updated),
                '; not in the log (kept as they were): ' + ', '.join(kept) if kept else ''))
    except (OSError, BenchDataError) as e:
        print('bench_data: error: {}'.format(e), file=sys.stderr)
        return 1
    return 0


if __name__ == '__main__':
    sys.exit(main())
