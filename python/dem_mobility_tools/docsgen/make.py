"""dm-docs: rewrites the generated tables of docs/ from docs/data/*.yaml, and docs/launch.md.

    dm-docs [--root DIR] [--check] [--figures]

Without options it rewrites, in place, every block between `<!-- generated: NAME -->` and
`<!-- end generated -->` in the docs that docs/data/*.yaml name, and docs/launch.md. `--check`
writes nothing and exits 1 naming each doc and table that differs from what it would write.
`--figures` also redraws the plots whose data is committed (matplotlib, Agg).
"""
import argparse
import datetime
import glob
import os
import re
import sys
import xml.etree.ElementTree as ET

import yaml

BEGIN = '<!-- generated: {} -->'
END = '<!-- end generated -->'
BLOCK = re.compile(r'<!-- generated: (?P<name>[\w./-]+) -->\n(?P<body>.*?)<!-- end generated -->', re.S)
LAUNCH_GLOBS = ('launch/*.launch', 'launch/components/*.launch')
GOAL_COLUMNS = (('what', 'figure'), ('conditions', 'conditions'), ('value', 'value'),
                ('goal', 'goal'), ('status', 'status'))


class DocsError(Exception):
    """Bad input: the message names the file and the key."""


def default_root():
    """The checkout: the working folder if it has docs/data, else the one this file sits in."""
    if os.path.isdir(os.path.join(os.getcwd(), 'docs', 'data')):
        return os.getcwd()
    return os.path.abspath(os.path.join(os.path.dirname(__file__), '..', '..', '..'))


def write_data(root, name, data, soil_law=None):
    """Writes a data file docs/data/NAME (with the soil law its figures were measured with, if
    given, in its provenance); returns its path."""
    if soil_law:
        data['provenance']['soil_law'] = soil_law
    path = os.path.join(root, 'docs', 'data', name)
    with open(path, 'w') as f:
        yaml.safe_dump(data, f, sort_keys=False, allow_unicode=True, width=110)
    return path


def _need(d, key, where, kind=None):
    if not isinstance(d, dict) or key not in d:
        raise DocsError('{}: missing key {}'.format(where, key))
    v = d[key]
    if kind is not None and not isinstance(v, kind):
        raise DocsError('{}: {} must be a {}, got {!r}'.format(where, key, kind.__name__, v))
    return v


def load_tables(root):
    """Every docs/data/*.yaml, checked: {name: table}."""
    tables = {}
    for path in sorted(glob.glob(os.path.join(root, 'docs', 'data', '*.yaml'))):
        rel = os.path.relpath(path, root)
        with open(path) as f:
            try:
                t = yaml.safe_load(f)
            except yaml.YAMLError as e:
                raise DocsError('{}: not YAML: {}'.format(rel, e))
        name = _need(t, 'table', rel, str)
        _need(t, 'doc', rel, str)
        prov = _need(t, 'provenance', rel, dict)
        if isinstance(prov.get('date'), datetime.date):
            prov['date'] = prov['date'].isoformat()  # YAML reads a bare date as a date
        for key in ('commit', 'machine', 'date', 'command'):
            _need(prov, key, rel + ': provenance', str)
        rows = _need(t, 'rows', rel, list)
        if not rows:
            raise DocsError('{}: rows: empty'.format(rel))
        for i, row in enumerate(rows):
            if not isinstance(row, dict):
                raise DocsError('{}: rows[{}]: must be a mapping'.format(rel, i))
        if name in tables:
            raise DocsError('{}: table {} is also in {}'.format(rel, name, tables[name]['_file']))
        t['_file'] = rel
        tables[name] = t
    return tables


def _number(v):
    if isinstance(v, bool):
        return str(v)
    if isinstance(v, int) and abs(v) >= 10000:
        return '{:,}'.format(v)
    return str(v)


def _cell(v):
    if v is None:
        return ''
    if isinstance(v, list):
        return ' / '.join(_number(x) for x in v)
    return _number(v).replace('|', '\\|').replace('\n', ' ')


def _value(row, where):
    if 'range' in row:
        lo, hi = row['range']
        text = '{}-{}'.format(_number(lo), _number(hi))
    else:
        text = _cell(_need(row, 'value', where))
    unit = row.get('unit')
    return text + (' ' + unit if unit else '')


def _status(row, where):
    """met / not met from the goal and the measured figure(s), never typed in."""
    goal = row.get('goal')
    if goal is None:
        return '', ''
    if not isinstance(goal, dict) or not ({'min', 'max'} & set(goal)):
        raise DocsError('{}: goal must have min or max'.format(where))
    measured = row.get('compare', row.get('range', row.get('value')))
    measured = measured if isinstance(measured, list) else [measured]
    if not all(isinstance(m, (int, float)) and not isinstance(m, bool) for m in measured):
        raise DocsError('{}: goal needs a numeric value, range or compare'.format(where))
    ok = all(('min' not in goal or m >= goal['min']) and ('max' not in goal or m <= goal['max'])
             for m in measured)
    unit = row.get('unit', '')
    unit = ' ' + unit if unit and '(' not in unit else ''
    text = goal.get('text') or ' '.join(
        p for p in (('>= {}{}'.format(_number(goal['min']), unit) if 'min' in goal else ''),
                    ('<= {}{}'.format(_number(goal['max']), unit) if 'max' in goal else '')) if p)
    status = 'met' if ok else '**not met**'
    if row.get('status_note'):
        status += ' ' + row['status_note']
    return _cell(text), _cell(status)


def render_table(t):
    """The block's text (without the markers)."""
    prov = t['provenance']
    where = t['_file']
    head = ('{}; {}'.format(prov['machine'], prov['date']) if t.get('show_command') is False
            else '{}; {}; `{}`'.format(prov['machine'], prov['date'], prov['command']))
    if prov.get('soil_law'):  # which reading of the soil law the figures were measured with
        head += '; soil law: {}'.format(prov['soil_law'])
    lines = ['*{}.*'.format(head), '']
    if 'columns' in t:
        cols = [(_need(c, 'key', where + ': columns', str), _need(c, 'title', where + ': columns', str))
                for c in t['columns']]
        lines.append('| ' + ' | '.join(title for _, title in cols) + ' |')
        lines.append('|' + '---|' * len(cols))
        for i, row in enumerate(t['rows']):
            unknown = set(row) - {k for k, _ in cols}
            if unknown:
                raise DocsError('{}: rows[{}]: unknown key {}'.format(where, i, sorted(unknown)[0]))
            lines.append('| ' + ' | '.join(_cell(row.get(k)) for k, _ in cols) + ' |')
    else:
        lines.append('| ' + ' | '.join(title for _, title in GOAL_COLUMNS) + ' |')
        lines.append('|' + '---|' * len(GOAL_COLUMNS))
        allowed = {'what', 'conditions', 'value', 'range', 'unit', 'goal', 'compare', 'status_note', 'figure'}
        for i, row in enumerate(t['rows']):
            w = '{}: rows[{}]'.format(where, i)
            unknown = set(row) - allowed
            if unknown:
                raise DocsError('{}: unknown key {}'.format(w, sorted(unknown)[0]))
            what = _cell(_need(row, 'what', w, str))
            if row.get('figure'):
                what += ' (`{}`)'.format(row['figure'])
            goal, status = _status(row, w)
            lines.append('| ' + ' | '.join((what, _cell(row.get('conditions')), _value(row, w), goal, status)) + ' |')
    for note in t.get('notes', []):
        lines += ['', note.strip()]
    return '\n'.join(lines) + '\n'


def render_doc(text, tables, doc):
    """The doc with every generated block rewritten; errors name the doc and the table."""
    names = [m.group('name') for m in BLOCK.finditer(text)]
    for name in names:
        if name not in tables:
            raise DocsError('docs/{}: table {}: no docs/data file holds it'.format(doc, name))
        if tables[name]['doc'] != doc:
            raise DocsError('docs/{}: table {}: its data file names docs/{}'.format(doc, name, tables[name]['doc']))
    for name, t in tables.items():
        if t['doc'] == doc and name not in names:
            raise DocsError('docs/{}: table {} ({}): no marker {}'.format(doc, name, t['_file'], BEGIN.format(name)))
    return BLOCK.sub(lambda m: BEGIN.format(m.group('name')) + '\n' + render_table(tables[m.group('name')]) + END,
                     text)


def changed_blocks(old, new):
    """Names of the generated blocks that differ between two versions of a doc."""
    a = {m.group('name'): m.group('body') for m in BLOCK.finditer(old)}
    b = {m.group('name'): m.group('body') for m in BLOCK.finditer(new)}
    return sorted(n for n in b if a.get(n) != b[n]) or ['(outside the tables)']


def launch_args(path, rel):
    """[(name, default, doc)] of a launch file's top-level arguments (value= ones are constants)."""
    try:
        tree = ET.parse(path)
    except ET.ParseError as e:
        raise DocsError('{}: not XML: {}'.format(rel, e))
    out = []
    for arg in tree.getroot().findall('arg'):
        if 'value' in arg.attrib:
            continue
        name = arg.get('name')
        doc = arg.get('doc')
        if not doc:
            raise DocsError('{}: arg {}: no doc= attribute'.format(rel, name))
        out.append((name, arg.get('default'), ' '.join(doc.split())))
    return out


def render_launch(root):
    lines = ['# Launch files', '',
             'Every argument of every launch file, with its default and what it does. Generated from the',
             'launch files\' `<arg doc="...">` attributes (`roslaunch --ros-args dem_mobility FILE` lists',
             'the same) by `dm-docs`; edit the launch file, not this page.']
    for pattern in LAUNCH_GLOBS:
        for path in sorted(glob.glob(os.path.join(root, pattern))):
            rel = os.path.relpath(path, root)
            lines += ['', '## `{}`'.format(rel), '', '| argument | default | doc |', '|---|---|---|']
            for name, default, doc in launch_args(path, rel):
                d = '(required)' if default is None else ('`{}`'.format(default) if default != '' else '(empty)')
                lines.append('| `{}` | {} | {} |'.format(name, d, doc.replace('|', '\\|')))
    return '\n'.join(lines) + '\n'


def generate(root):
    """{doc path: (old text, new text)} for every doc this tool writes."""
    tables = load_tables(root)
    out = {}
    for doc in sorted({t['doc'] for t in tables.values()}):
        path = os.path.join(root, 'docs', doc)
        if not os.path.exists(path):
            raise DocsError('{}: doc: docs/{} does not exist'.format(
                next(t['_file'] for t in tables.values() if t['doc'] == doc), doc))
        with open(path) as f:
            old = f.read()
        out['docs/' + doc] = (old, render_doc(old, tables, doc))
    path = os.path.join(root, 'docs', 'launch.md')
    old = open(path).read() if os.path.exists(path) else ''
    out['docs/launch.md'] = (old, render_launch(root))
    return out


def main(argv=None):
    p = argparse.ArgumentParser(prog='dm-docs', description=__doc__.split('\n')[0])
    p.add_argument('--root', default=None, help='the checkout (default: the working folder)')
    p.add_argument('--check', action='store_true', help='write nothing; exit 1 if a doc is out of date')
    p.add_argument('--figures', action='store_true', help='also redraw the plots of committed data')
    a = p.parse_args(argv)
    root = a.root or default_root()
    try:
        docs = generate(root)
    except DocsError as e:
        print('dm-docs: error: {}'.format(e), file=sys.stderr)
        return 1
    stale = []
    for doc, (old, new) in docs.items():
        if old == new:
            continue
        if a.check:
            for name in (changed_blocks(old, new) if doc != 'docs/launch.md' else ['(the whole page)']):
                stale.append('{}: {}'.format(doc, name))
        else:
            with open(os.path.join(root, doc), 'w') as f:
                f.write(new)
            print('dm-docs: wrote {}'.format(doc))
    if a.figures and not a.check:
        from . import figures
        for path in figures.draw_all(root):
            print('dm-docs: drew {}'.format(os.path.relpath(path, root)))
    if stale:
        for s in stale:
            print('dm-docs: out of date: {} (run dm-docs)'.format(s), file=sys.stderr)
        return 1
    return 0


if __name__ == '__main__':
    sys.exit(main())
